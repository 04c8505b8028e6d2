//! M13: bodies, obstacles the caller moves. No particle is ever inside an
//! obstacle and the count stays exact however bodies move; a particle a
//! body takes goes where the rule says with the velocity it says; eq. 9
//! acts in the frame of the moving surface and the momentum a body hands
//! over is what the particles received; refusals change nothing; ids follow
//! their particles; the same calls give the same world at any thread count.

mod common;

use common::{memory, Z};
use mpca::{Boundary, Cell, Description, Error, ErrorKind, Identity, Quantization, Shape, World};
use mpca_tests::setup::SetupRng;

/// A description with room for bodies.
fn with_bodies(mut d: Description, bodies: u32, entries: u32) -> Description {
    d.obstacles = true;
    d.surface_capacity = 4096;
    d.body_capacity = bodies;
    d.body_surface_capacity = entries;
    d
}

/// Every cell of the world.
fn cells(w: &World) -> impl Iterator<Item = [u32; 3]> + '_ {
    let n = w.description().size;
    let nz = if w.description().dim == 2 { 1 } else { n[2] };
    (0..nz).flat_map(move |z| (0..n[1]).flat_map(move |y| (0..n[0]).map(move |x| [x, y, z])))
}

/// Checks what must hold after any call: no particle on an obstacle, the
/// particle count what the counters say and what the world holds.
fn check_world(w: &World, added: u64, what: &str) {
    let s = w.stats();
    let mut held = 0u64;
    for pos in cells(w) {
        if let Ok(Cell::Particle(_)) = w.cell(pos) {
            held += 1;
            assert!(!w.obstacle_at(pos), "{what}: a particle at {pos:?} lies in an obstacle");
        }
    }
    assert_eq!(held, s.particles, "{what}: the world holds another count than its stats");
    assert_eq!(s.particles, added + s.emitted - s.exited - s.expired - s.crushed, "{what}: the count does not add up: {s:?}");
}

/// A random velocity of speed below `max`.
fn velocity(rng: &mut SetupRng, dim: u32, max: f32) -> [f32; 3] {
    rng.velocity(dim, max)
}

/// A random body shape around `centre` for a world of `dim` dimensions.
fn shape(rng: &mut SetupRng, dim: u32, centre: [f32; 3]) -> Shape {
    let r = 1.0 + rng.below(40) as f32 / 10.0;
    match rng.below(3) {
        0 if dim == 2 => Shape::Disc { centre: [centre[0], centre[1]], radius: r },
        0 => Shape::Sphere { centre, radius: r },
        1 => Shape::Box { min: centre.map(|c| c - r), max: centre.map(|c| c + r * 0.7) },
        _ => {
            let d = velocity(rng, dim, 4.0);
            Shape::Capsule { a: centre, b: [0, 1, 2].map(|k| centre[k] + d[k]), radius: r * 0.6 }
        }
    }
}

#[test]
fn bodies_moving_at_random_leave_no_particle_inside_and_lose_none_uncounted() {
    // Expect: in 2D and 3D worlds with walls, open and periodic faces and
    // a static box, bodies added, moved by up to two cells, given new
    // shapes and removed at random between steps of a gas: after every
    // call no particle lies in an obstacle and the count adds up, crushed
    // particles included.
    let steps = 300;
    for (case, dim) in [(0u64, 2u32), (1, 2), (2, 3)] {
        let mut rng = SetupRng::new(1300 + case);
        let mut d = if dim == 2 { Description::new_2d(32, 24) } else { Description::new_3d(16, 12, 10) };
        d.boundary[0] = [Boundary::Wall; 2];
        if case == 1 {
            d.boundary[1] = [Boundary::Open; 2];
        }
        d.seed = 77 + case;
        let d = with_bodies(d, 4, 4096);
        let mut mem = memory(&d);
        let w = World::init(&d, &mut mem).unwrap();
        w.add_shape(Shape::Box { min: [10.0, 2.0, 2.0], max: [13.0, 6.0, 5.0] }, 0.5).unwrap();
        let mut added = 0u64;
        for pos in cells(w).collect::<Vec<_>>() {
            if rng.below(3) == 0 && w.add_particle(pos, velocity(&mut rng, dim, 0.9)).is_ok() {
                added += 1;
            }
        }
        let n = d.size.map(|s| s as f32);
        let mut places: Vec<Option<[f32; 3]>> = vec![None; 4];
        for step in 0..steps {
            let i = rng.below(4) as usize;
            match places[i] {
                None => {
                    let c = [0, 1, 2].map(|k| if k < dim as usize { rng.unit() * n[k] } else { 0.5 });
                    let id = w.add_body(shape(&mut rng, dim, c), velocity(&mut rng, dim, 0.5), 0.8);
                    if let Ok(id) = id {
                        places[id as usize] = Some(c);
                    }
                }
                Some(c) if rng.below(10) == 0 => {
                    w.remove_body(i as u32).unwrap();
                    places[i] = None;
                    let _ = c;
                }
                Some(c) => {
                    let u = velocity(&mut rng, dim, 1.0);
                    let c2 = [0, 1, 2].map(|k| if k < dim as usize { (c[k] + 2.0 * u[k]).clamp(0.0, n[k]) } else { 0.5 });
                    if w.move_body(i as u32, shape(&mut rng, dim, c2), u).is_ok() {
                        places[i] = Some(c2);
                    }
                }
            }
            check_world(w, added, &format!("case {case}, after the move before step {step}"));
            w.step(1);
            check_world(w, added, &format!("case {case}, after step {step}"));
        }
        let s = w.stats();
        assert!(s.particles > 0, "case {case}: the gas must not be gone: {s:?}");
        eprintln!("case {case}: {s:?}");
    }
}

/// The world's image (M12): every byte of its state, so that two images
/// are equal exactly where the worlds are.
fn image(w: &World) -> Vec<u8> {
    let mut out = vec![0u8; w.snapshot_bytes()];
    w.save(&mut out).unwrap();
    out
}

/// A 2D world of `n x n` cells with walls on x and room for `bodies`
/// bodies, 16-bit velocities where `wide`.
fn world_2d(n: u32, bodies: u32, wide: bool) -> Description {
    let mut d = Description::new_2d(n, n);
    d.boundary[0] = [Boundary::Wall; 2];
    if wide {
        d.quantization = Quantization::Bits16;
    }
    with_bodies(d, bodies, 1024)
}

#[test]
fn a_particle_a_wall_takes_leaves_ahead_of_it_with_the_walls_speed_into_the_free_side() {
    // Expect: a half-space body whose surface faces -x, moved over a
    // particle moving +x at 38/127 with the wall's velocity -64/127: the
    // particle goes to the cell straight ahead of the surface (d.N largest,
    // then nearest: (-1, 0)) and leaves with the wall's velocity (its
    // velocity into the surface, relative to it, removed); the wall tallies
    // one push and m (v' - v).
    let d = world_2d(32, 2, false);
    let mut mem = memory(&d);
    let w = World::init(&d, &mut mem).unwrap();
    let (v, u) = (38.0 / 127.0, -64.0 / 127.0);
    w.add_particle([20, 11, 0], [v, 0.0, 0.0]).unwrap();
    let id = w.add_body(Shape::HalfSpace { point: [20.2, 0.0, 0.0], normal: [-1.0, 0.0, 0.0] }, [u, 0.0, 0.0], 1.0).unwrap();
    assert_eq!(id, 0);
    assert!(w.obstacle_at([20, 11, 0]) && w.obstacle_at([31, 0, 0]) && !w.obstacle_at([19, 11, 0]));
    let p = common::particle(w, [19, 11, 0]);
    assert_eq!(p.velocity, [u, 0.0, 0.0]);
    w.step(1);
    let s = w.body_stats(id).unwrap();
    assert_eq!((s.pushed, s.crushed), (1, 0));
    assert!((s.momentum[0] - f64::from(u - v)).abs() < 1e-6 && s.momentum[1] == 0.0, "{s:?}");
    check_world(w, 1, "after the push");
}

#[test]
fn a_moving_wall_reflects_by_eq_9_in_its_own_frame() {
    // Expect: a particle moving +x at v (0.5 stored in 16 bits) into a
    // wall moving at u = -0.25: w = v - u turns to -e w, so v' =
    // u - e (v - u), clamped to speed 1 (M5.5): -1 at e = 1, about -0.625
    // at e = 0.5; the wall's tally of that step is one reflection and
    // m (v' - v), to a fine unit (it is taken before the rounding to
    // storage).
    let v = f64::from((0.5f32 * 32767.0).round()) / 32767.0;
    for e in [1.0f32, 0.5] {
        let want = (-0.25 - f64::from(e) * (v + 0.25)).max(-1.0);
        let d = world_2d(32, 1, true);
        let mut mem = memory(&d);
        let w = World::init(&d, &mut mem).unwrap();
        w.add_particle([17, 11, 0], [0.5, 0.0, 0.0]).unwrap();
        let id = w.add_body(Shape::HalfSpace { point: [20.0, 0.0, 0.0], normal: [-1.0, 0.0, 0.0] }, [-0.25, 0.0, 0.0], e).unwrap();
        let mut reflected = None;
        for _ in 0..200 {
            w.step(1);
            let s = w.body_stats(id).unwrap();
            if s.reflected > 0 {
                reflected = Some(s);
                break;
            }
        }
        let s = reflected.expect("the particle must reach the wall");
        assert_eq!(s.reflected, 1);
        let p = w.particles().next().unwrap();
        let quantum = 1.0 / 32767.0;
        assert!((f64::from(p.velocity[0]) - want).abs() <= quantum && p.velocity[1] == 0.0, "e = {e}: {:?}", p.velocity);
        assert!((s.momentum[0] - (want - v)).abs() < 1e-7 && s.momentum[1] == 0.0, "e = {e}: {s:?}");
    }
}

#[test]
fn the_momentum_bodies_hand_over_is_what_the_particles_receive() {
    // Expect: a gas in a periodic box (no walls, no force, speeds low
    // enough that nothing is clamped) with a disc moved along a circle by
    // its own velocity every step: the change of the particles' total
    // momentum over the run equals the sum of the body's tallies (its
    // reflections and push-outs) up to the stochastic rounding of each
    // changed velocity (M1: mean zero, variance at most 1/4 quantum^2 a
    // component), counted from the collisions, reflections and pushes.
    // 16-bit velocities: the rounding's band is far below the exchange.
    let mut d = Description::new_2d(48, 48);
    d.seed = 5;
    d.quantization = Quantization::Bits16;
    let d = with_bodies(d, 1, 1024);
    let mut mem = memory(&d);
    let w = World::init(&d, &mut mem).unwrap();
    let mut c = [24.0f32, 12.0];
    let id = w.add_body(Shape::Disc { centre: c, radius: 4.0 }, [0.2, 0.0, 0.0], 1.0).unwrap();
    let mut rng = SetupRng::new(71);
    for pos in cells(w).collect::<Vec<_>>() {
        if rng.below(8) == 0 && !w.obstacle_at(pos) {
            w.add_particle(pos, rng.velocity(2, 0.3)).unwrap();
        }
    }
    let start = w.stats();
    let (mut given, mut roundings) = ([0.0f64; 2], 0u64);
    let steps = 400;
    for t in 0..steps {
        let a = t as f32 * 0.02;
        let u = [0.2 * a.cos(), 0.2 * a.sin()];
        c = [c[0] + u[0], c[1] + u[1]];
        w.move_body(id, Shape::Disc { centre: c, radius: 4.0 }, [u[0], u[1], 0.0]).unwrap();
        let before = w.stats().collisions;
        w.step(1);
        let s = w.body_stats(id).unwrap();
        given[0] += s.momentum[0];
        given[1] += s.momentum[1];
        roundings += 2 * (w.stats().collisions - before) + u64::from(s.reflected + s.pushed);
    }
    let end = w.stats();
    assert_eq!((end.clamps, end.crushed), (0, 0), "the test's premise: no clamp, no crush");
    assert!(roundings > 1000, "the body must have met the gas: {roundings}");
    let quantum = 1.0 / 32767.0;
    let band = Z * (roundings as f64 / 4.0).sqrt() * quantum;
    for (k, given) in given.iter().enumerate() {
        let received = end.momentum[k] - start.momentum[k];
        assert!((received - given).abs() <= band, "axis {k}: the particles received {received}, the body gave {given}, band {band}");
    }
    assert!(given[0].abs() + given[1].abs() > 10.0 * band, "the exchange must be larger than the band: {given:?}, {band}");
}

#[test]
fn a_refused_body_call_changes_nothing() {
    // Expect: every refusal of add_body, move_body, remove_body and
    // body_stats returns its error and leaves the world's image (every
    // byte of its state, the body table included) as it was.
    let mut d = world_2d(32, 2, false);
    d.body_surface_capacity = 32;
    let mut mem = memory(&d);
    let w = World::init(&d, &mut mem).unwrap();
    w.add_particle([5, 5, 0], [0.2, 0.1, 0.0]).unwrap();
    let disc = |x: f32, r: f32| Shape::Disc { centre: [x, 16.0], radius: r };
    let low = |r: f32| Shape::Disc { centre: [8.0, 8.0], radius: r };
    w.add_body(disc(16.0, 3.0), [0.1, 0.0, 0.0], 0.5).unwrap();
    w.step(3);
    let before = image(w);
    type Call = Box<dyn Fn(&mut World) -> Result<(), Error>>;
    // Each with the kind, and the detail naming the argument or field.
    let cases: Vec<(&str, ErrorKind, &str, Call)> = vec![
        ("radius 0", ErrorKind::BadShape, "shape: radius", Box::new(move |w| w.add_body(disc(8.0, 0.0), [0.0; 3], 1.0).map(drop))),
        ("NaN centre", ErrorKind::NotFinite, "shape", Box::new(move |w| w.add_body(disc(f32::NAN, 2.0), [0.0; 3], 1.0).map(drop))),
        ("NaN velocity", ErrorKind::NotFinite, "velocity", Box::new(move |w| w.add_body(disc(8.0, 2.0), [f32::NAN, 0.0, 0.0], 1.0).map(drop))),
        ("NaN e", ErrorKind::NotFinite, "e", Box::new(move |w| w.add_body(disc(8.0, 2.0), [0.0; 3], f32::NAN).map(drop))),
        ("too fast", ErrorKind::SpeedRange, "velocity", Box::new(move |w| w.add_body(disc(8.0, 2.0), [0.8, 0.8, 0.0], 1.0).map(drop))),
        ("e = 2", ErrorKind::RestitutionRange, "e", Box::new(move |w| w.add_body(disc(8.0, 2.0), [0.0; 3], 2.0).map(drop))),
        ("a sphere in 2D", ErrorKind::BadDimension, "shape: a sphere in 2D", Box::new(|w| w.add_body(Shape::Sphere { centre: [8.0; 3], radius: 2.0 }, [0.0; 3], 1.0).map(drop))),
        ("no room", ErrorKind::SurfaceTableFull, "desc.body_surface_capacity", Box::new(move |w| w.add_body(low(6.0), [0.0; 3], 1.0).map(drop))),
        ("move: no room", ErrorKind::SurfaceTableFull, "desc.body_surface_capacity", Box::new(move |w| w.move_body(0, disc(16.0, 12.0), [0.0; 3]))),
        ("move: unknown id", ErrorKind::NoBody, "id", Box::new(move |w| w.move_body(1, disc(8.0, 2.0), [0.0; 3]))),
        ("move: too fast", ErrorKind::SpeedRange, "velocity", Box::new(move |w| w.move_body(0, disc(8.0, 2.0), [1.5, 0.0, 0.0]))),
        ("remove: unknown id", ErrorKind::NoBody, "id", Box::new(|w| w.remove_body(7))),
        ("stats: unknown id", ErrorKind::NoBody, "id", Box::new(|w| w.body_stats(1).map(drop))),
        ("a static obstacle over a body", ErrorKind::CellObstacle, "the obstacle", Box::new(|w| w.add_shape(Shape::Box { min: [15.0, 15.0, 0.0], max: [17.0, 17.0, 0.0] }, 1.0))),
    ];
    for (what, kind, detail, call) in &cases {
        assert_eq!(call(w).map_err(|e| (e.kind(), e.detail())), Err((*kind, *detail)), "{what}");
        assert!(image(w) == before, "{what}: the world changed");
    }
    // The body table full: the second slot taken, a third refused.
    w.add_body(disc(6.0, 1.5), [0.0; 3], 1.0).unwrap();
    let before = image(w);
    let full = w.add_body(disc(26.0, 1.5), [0.0; 3], 1.0).unwrap_err();
    assert_eq!((full.kind(), full.detail()), (ErrorKind::BodyTableFull, "desc.body_capacity"));
    assert!(image(w) == before, "a full table: the world changed");
    // A world without bodies: none to add.
    let mut plain = Description::new_2d(16, 16);
    plain.obstacles = true;
    let mut mem = memory(&plain);
    let p = World::init(&plain, &mut mem).unwrap();
    let none = p.add_body(disc(8.0, 2.0), [0.0; 3], 1.0).unwrap_err();
    assert_eq!((none.kind(), none.detail()), (ErrorKind::NotEnabled, "desc.obstacles or desc.body_capacity"));
    assert_eq!(p.body_stats(0).map_err(Error::kind), Err(ErrorKind::NotEnabled));
}

#[test]
fn ids_ages_and_tags_follow_the_particles_a_body_pushes() {
    // Expect: a box swept across a dense patch of particles with ids, ages
    // and tags: after each move every id is held exactly once, by a
    // particle with the same age and tag as before, and the pushed ones
    // moved to cells at most two away.
    let mut d = world_2d(32, 1, false);
    d.identity = Identity::ALL;
    let mut mem = memory(&d);
    let w = World::init(&d, &mut mem).unwrap();
    for x in 8..16 {
        for y in 8..16 {
            w.add_particle([x, y, 0], [0.0; 3]).unwrap();
            w.set_tag([x, y, 0], (x * 16 + y) as u8).unwrap();
        }
    }
    let id = w.add_body(Shape::Box { min: [2.0, 9.0, 0.0], max: [4.0, 14.0, 0.0] }, [1.0, 0.0, 0.0], 1.0).unwrap();
    let mut pushed = 0;
    for k in 0..14 {
        let before: std::collections::HashMap<u32, mpca::Particle> = w.particles().map(|p| (p.id, p)).collect();
        let crushed = w.stats().crushed;
        let x = 3.0 + k as f32;
        w.move_body(id, Shape::Box { min: [x, 9.0, 0.0], max: [x + 2.0, 14.0, 0.0] }, [1.0, 0.0, 0.0]).unwrap();
        let after: Vec<mpca::Particle> = w.particles().collect();
        assert_eq!(after.len() as u64, before.len() as u64 - (w.stats().crushed - crushed), "move {k}");
        for p in &after {
            let b = before.get(&p.id).expect("an id not held before");
            assert_eq!((p.age, p.tag), (b.age, b.tag), "move {k}: id {}", p.id);
            let far = (0..2).map(|j| p.pos[j].abs_diff(b.pos[j])).max().unwrap();
            assert!(far <= 2, "move {k}: id {} jumped from {:?} to {:?}", p.id, b.pos, p.pos);
            pushed += usize::from(far > 0);
        }
        let mut ids: Vec<u32> = after.iter().map(|p| p.id).collect();
        ids.sort_unstable();
        ids.dedup();
        assert_eq!(ids.len(), after.len(), "move {k}: an id held twice");
        w.step(1);
    }
    assert!(pushed > 20, "the box must push particles: {pushed}");
}

/// A run of bodies moving through a 3D gas, stepped by `step`.
fn body_run(step: &dyn Fn(&mut World)) -> (u64, Vec<u8>, Vec<mpca::BodyStats>) {
    let mut d = Description::new_3d(20, 16, 12);
    d.boundary[1] = [Boundary::Wall; 2];
    d.seed = 9;
    let d = with_bodies(d, 3, 4096);
    let mut mem = memory(&d);
    let w = World::init(&d, &mut mem).unwrap();
    let mut rng = SetupRng::new(5);
    for pos in cells(w).collect::<Vec<_>>() {
        if rng.below(3) == 0 {
            w.add_particle(pos, rng.velocity(3, 0.7)).unwrap();
        }
    }
    let mut stats = Vec::new();
    for t in 0..40 {
        let x = 4.0 + 0.3 * t as f32;
        w.remove_body(0).ok();
        w.add_body(Shape::Sphere { centre: [x, 8.0, 6.0], radius: 3.0 }, [0.3, 0.0, 0.0], 0.7).unwrap();
        let a = [12.0, 4.0 + 0.2 * t as f32, 3.0];
        if t == 0 {
            w.add_body(Shape::Capsule { a, b: [16.0, 6.0, 9.0], radius: 1.5 }, [0.0, 0.2, 0.0], 1.0).unwrap();
        } else {
            w.move_body(1, Shape::Capsule { a, b: [16.0, 6.0 + 0.2 * t as f32, 9.0], radius: 1.5 }, [0.0, 0.2, 0.0]).unwrap();
        }
        step(w);
        stats.push(w.body_stats(0).unwrap());
        stats.push(w.body_stats(1).unwrap());
    }
    (w.state_hash(), image(w), stats)
}

#[test]
fn the_same_calls_give_the_same_world_at_any_thread_count() {
    // Expect: one run of moving bodies stepped serially, in reverse block
    // order, and on 2 and 3 threads: the same hash, image and tallies.
    let serial = body_run(&|w| w.step(1));
    let reverse = body_run(&|w| w.step_in_order(mpca::Order::Reverse));
    let two = body_run(&|w| w.step_threads(1, 2));
    let three = body_run(&|w| w.step_threads(1, 3));
    assert!(serial.2.iter().any(|s| s.reflected > 0 && s.pushed > 0), "the bodies must reflect and push");
    for (name, other) in [("reverse", &reverse), ("2 threads", &two), ("3 threads", &three)] {
        assert_eq!(serial.0, other.0, "{name}: hash");
        assert!(serial.1 == other.1, "{name}: image");
        assert_eq!(serial.2, other.2, "{name}: tallies");
    }
}

#[test]
fn an_image_keeps_the_bodies_and_the_world_steps_on_as_before() {
    // Expect: a world with bodies saved mid-run (version 3) and loaded
    // into fresh memory: the same hash, body tallies and image; both step
    // on through the same moves to the same world. A world without bodies
    // is still written as version 2. An image with a particle put inside
    // a body (checksum made good) is refused and changes nothing.
    let d = world_2d(40, 2, false);
    let mut mem = memory(&d);
    let w = World::init(&d, &mut mem).unwrap();
    w.add_shape(Shape::Box { min: [30.0, 5.0, 0.0], max: [33.0, 9.0, 0.0] }, 0.5).unwrap();
    let mut rng = SetupRng::new(8);
    for pos in cells(w).collect::<Vec<_>>() {
        if rng.below(3) == 0 && !w.obstacle_at(pos) {
            w.add_particle(pos, rng.velocity(2, 0.6)).unwrap();
        }
    }
    let disc = |t: u32| Shape::Disc { centre: [10.0 + 0.4 * t as f32, 20.0], radius: 4.0 };
    let id = w.add_body(disc(0), [0.4, 0.0, 0.0], 0.9).unwrap();
    w.add_body(Shape::Capsule { a: [20.0, 30.0, 0.0], b: [28.0, 34.0, 0.0], radius: 2.0 }, [0.0; 3], 1.0).unwrap();
    for t in 1..10 {
        w.move_body(id, disc(t), [0.4, 0.0, 0.0]).unwrap();
        w.step(1);
    }
    let saved = image(w);
    assert_eq!(u32::from_le_bytes(saved[8..12].try_into().unwrap()), 3);
    let mut other_mem = memory(&mpca::image_description(&saved).unwrap());
    let copy = World::init_from_image(&saved, &mut other_mem).unwrap();
    assert_eq!(copy.state_hash(), w.state_hash());
    assert!(image(copy) == saved, "saved again, the image differs");
    for t in 10..30 {
        for x in [&mut *w, &mut *copy] {
            x.move_body(id, disc(t), [0.4, 0.0, 0.0]).unwrap();
            x.step(1);
        }
        assert_eq!(copy.state_hash(), w.state_hash(), "step {t}");
        assert_eq!(copy.body_stats(id), w.body_stats(id), "step {t}");
    }
    assert!(image(copy) == image(w));

    // A particle inside the disc: put in the occupancy plane of the image.
    let mut forged = image(w);
    let n = 40usize;
    let planes = 24 + 120 + 24 + 120;
    let (x, y) = (10 + 12, 20); // the disc's centre at t = 29 is (21.6, 20)
    assert!(w.obstacle_at([x as u32, y as u32, 0]));
    let bit = y * n.div_ceil(64) * 64 + x;
    forged[planes + bit / 8] |= 1 << (bit % 8);
    common::reseal(&mut forged);
    let before = image(w);
    assert!(w.load(&forged).is_err());
    assert!(image(w) == before);

    // A world without bodies: version 2, as before bodies existed.
    let plain = Description::new_2d(16, 16);
    let mut mem = memory(&plain);
    let p = World::init(&plain, &mut mem).unwrap();
    assert_eq!(u32::from_le_bytes(image(p)[8..12].try_into().unwrap()), 2);
}

#[test]
fn the_body_surface_entries_a_shape_takes_are_known_before_it_is_added() {
    // Expect: for random discs, boxes and capsules in a 2D world and
    // spheres and capsules in a 3D one, with walls and open faces, the
    // description's count for the shape is exactly what a body of it
    // takes in a fresh world: a table of that size takes it, one fewer
    // refuses it (SurfaceTableFull). Two bodies together take at most the
    // sum of their counts.
    let mut rng = SetupRng::new(4242);
    for dim in [2u32, 3] {
        let mut d = if dim == 2 { Description::new_2d(40, 30) } else { Description::new_3d(20, 16, 12) };
        d.boundary[0] = [Boundary::Wall; 2];
        d.boundary[1] = [Boundary::Open; 2];
        let n = d.size.map(|s| s as f32);
        for case in 0..40 {
            let c = [0, 1, 2].map(|k| if k < dim as usize { rng.unit() * n[k] } else { 0.5 });
            let (s1, s2) = (shape(&mut rng, dim, c), shape(&mut rng, dim, [0, 1, 2].map(|k| c[k] + 2.0)));
            let counts = [s1, s2].map(|s| with_bodies(d, 2, 1).body_surface_entries(s).unwrap());
            for (s, count) in [(s1, counts[0]), (s2, counts[1])] {
                for room in [count, count.saturating_sub(1)] {
                    let desc = with_bodies(d, 2, room);
                    let mut mem = memory(&desc);
                    let w = World::init(&desc, &mut mem).unwrap();
                    let r = w.add_body(s, [0.0; 3], 1.0);
                    if room == count {
                        assert_eq!(r, Ok(0), "{dim}D case {case}: {s:?} in {room}");
                    } else if count > 0 {
                        assert_eq!(r.map_err(Error::kind), Err(ErrorKind::SurfaceTableFull), "{dim}D case {case}: {s:?} in {room}");
                    }
                }
            }
            let desc = with_bodies(d, 2, counts[0] + counts[1]);
            let mut mem = memory(&desc);
            let w = World::init(&desc, &mut mem).unwrap();
            w.add_body(s1, [0.0; 3], 1.0).unwrap();
            w.add_body(s2, [0.0; 3], 1.0).unwrap();
        }
    }
    let plain = Description::new_2d(8, 8);
    assert_eq!(plain.body_surface_entries(Shape::Disc { centre: [4.0, 4.0], radius: 2.0 }).map_err(Error::kind), Err(ErrorKind::NotEnabled));
}
