//! The rules beyond the paper for effects that look right (docs/model.md,
//! "beyond the paper"), each against the paper's rule on the scene where
//! the difference shows.

use mpca::{Boundary, Collisions, Description, Drag, Stats, Vortex, World};
use mpca_tests::scenes::{self, Scene};

fn run(scene: &Scene, steps: u64) -> (Stats, Stats) {
    let mut memory = Vec::new();
    let w = scenes::build(scene, &mut memory).unwrap();
    let before = w.stats();
    w.step(steps);
    (before, w.stats())
}

/// M5.2b on the e = 1 cluster collision (4.2): with the paper's rule the
/// clamp removes about a third of the kinetic energy in 130 steps; with
/// speed-limited collisions no collision needs the clamp, so the energy
/// changes only by stochastic rounding (M1: at most a quarter of a quantum
/// squared per rounded component, about 0.2 % of this scene's energy over
/// its ~11,000 collisions), and the bound is 1 %.
#[test]
fn speed_limited_collisions_keep_the_cluster_energy() {
    let change = |a: &Stats, b: &Stats| b.kinetic_energy / a.kinetic_energy - 1.0;
    let mut scene = scenes::cluster();
    let (before, paper) = run(&scene, 130);
    assert!(change(&before, &paper) < -0.2 && paper.clamps > 100, "the paper's rule loses energy to the clamp: {paper:?}");

    scene.desc.collisions = Collisions::SpeedLimited;
    let (before, after) = run(&scene, 130);
    assert!(after.collisions > 5000, "{after:?}");
    assert_eq!(after.clamps, 0, "no collision needs the clamp");
    assert!(change(&before, &after).abs() <= 0.01, "energy {:+.4}", change(&before, &after));
}

/// M5.2b keeps momentum up to rounding: in the cluster scene made periodic
/// (no walls to push), only collisions change velocities, each rounding two
/// particles' components with an error of variance at most 1/4 quantum^2,
/// so each momentum component drifts with sd at most
/// `sqrt(collisions / 2) / 127`; 5 sd is the band.
#[test]
fn speed_limited_collisions_keep_momentum_up_to_rounding() {
    let mut scene = scenes::cluster();
    scene.desc = scene.desc.with_boundary(Boundary::Periodic);
    scene.desc.collisions = Collisions::SpeedLimited;
    let (before, after) = run(&scene, 130);
    let sd = (after.collisions as f64 / 2.0).sqrt() / 127.0;
    for k in 0..2 {
        let drift = after.momentum[k] - before.momentum[k];
        assert!(drift.abs() < 5.0 * sd, "axis {k}: drift {drift}, sd {sd}");
    }
    assert_eq!(after.clamps, 0);
}

/// A 3D box with walls and gravity `g`, restitution `e` for particles and
/// walls, and 2,048 particles at rest in a block at the top: the pool of
/// M5.7, poured.
fn pool(contacts: bool, g: f32, e: f32) -> Scene {
    let mut desc = Description::new_3d(32, 32, 32).with_boundary(Boundary::Wall);
    desc.forces.uniform = true;
    desc.gravity = [0.0, -g, 0.0];
    desc.restitution = e;
    desc.wall_restitution = e;
    desc.contacts = contacts;
    desc.seed = 5;
    Scene { name: "pool", section: "-", desc, steps: 1200, paper_seconds: f64::NAN, setup: fill_pool }
}

fn fill_pool(w: &mut World) -> Result<(), mpca::Error> {
    for y in 20..28 {
        for z in 8..24 {
            for x in 8..24 {
                w.add_particle([x, y, z], [0.0; 3])?;
            }
        }
    }
    Ok(())
}

fn mean_speed(w: &World) -> f64 {
    let n = w.particle_count() as f64;
    w.particles().map(|p| f64::from(p.velocity.iter().map(|c| c * c).sum::<f32>()).sqrt()).sum::<f64>() / n
}

/// The pool after `steps`: mean speed, clamps per particle-step and the
/// share of the particles below y = 10.
fn poured(scene: &Scene, steps: u64) -> (f64, f64, f64) {
    let mut memory = Vec::new();
    let w = scenes::build(scene, &mut memory).unwrap();
    let n = w.particle_count();
    w.step(steps);
    assert_eq!(w.particle_count(), n, "nothing leaves a closed box");
    let low = w.particles().filter(|p| p.pos[1] < 10).count() as u64;
    (mean_speed(w), w.stats().clamps as f64 / (n * steps) as f64, low as f64 / n as f64)
}

/// M5.7: under the paper's rules a particle pressing on a resting
/// neighbour keeps its stored speed, so a pool never rests and the clamp
/// keeps firing (g = 0.01, e = 0.5, the default calibrated drift: measured
/// mean |v| 0.22, 0.069 clamps per particle-step; 0.32 and 0.209 under the
/// paper's drift rule). With contacts the pressing particle hands its
/// momentum down the pile: clamps fall below 1 % of the particle-steps
/// (measured 0, and 0.0002 under the paper's drift) and the pool moves at
/// about half the speed (0.12). It does not come fully to rest: momentum
/// leaves a resting particle only when it tries a move, at a rate that
/// grows with its speed, so a pile of depth h keeps speeds near sqrt(h g)
/// (docs/model.md, M5.7).
#[test]
fn contacts_let_a_pool_settle() {
    let (paper_speed, paper_clamps, _) = poured(&pool(false, 0.01, 0.5), 1200);
    let (speed, clamps, _) = poured(&pool(true, 0.01, 0.5), 1200);
    assert!(paper_clamps > 0.03, "{paper_clamps}");
    assert!(clamps <= 0.01, "clamps per particle-step {clamps}");
    assert!(speed < 0.6 * paper_speed, "mean |v| {speed} against the paper's {paper_speed}");
}

/// M5.7 under weaker gravity: the same poured pool at g = 0.001 comes to
/// rest, mean |v| at most 0.05 after 2,400 steps (measured 0.041) and no
/// clamp, as sqrt(h g) says: at g = 0.01 it stays near 0.12.
#[test]
fn a_pool_under_weak_gravity_comes_to_rest() {
    let (speed, clamps, _) = poured(&pool(true, 0.001, 0.5), 2400);
    assert!(speed <= 0.05, "mean |v| {speed}");
    assert!(clamps <= 0.01, "clamps per particle-step {clamps}");
}

/// The poured water scene (scenes::water_pool): a block of water released
/// above the sphere splashes off it and ends as a pool on the floor, in a
/// closed box: after 1,200 steps every particle lies below y = 10, no
/// clamp fires (the issue asks at most 1 % of
/// particle-steps), and the pool moves at a mean speed below 0.1 (measured
/// 0.074). Under the paper's rules (no contacts, e = 1) the same water
/// still bounces round the box: 29 % of it below y = 10, mean speed 0.43.
#[test]
fn poured_water_forms_a_pool_on_the_floor() {
    let scene = scenes::water_pool();
    let (speed, clamps, low) = poured(&scene, scene.steps);
    let mut paper = scene;
    paper.desc.contacts = false;
    paper.desc.restitution = 1.0;
    paper.desc.wall_restitution = 1.0;
    let (paper_speed, _, paper_low) = poured(&paper, paper.steps);
    assert_eq!(low, 1.0, "share of the water below y = 10");
    assert!(clamps <= 0.01, "clamps per particle-step {clamps}");
    assert!(speed < 0.1, "mean |v| {speed}");
    assert!(paper_low < 0.5 && paper_speed > 0.3, "paper's rules: {paper_low} below y = 10, mean |v| {paper_speed}");
}

/// M5.7 keeps momentum up to rounding: a dense periodic gas drifting at
/// (0.3, 0.1) without force, e = 0.9, speed-limited collisions and speeds
/// below 0.62, so that no clamp changes momentum (an elastic contact can
/// need one: its R is fixed); only collisions and contacts change
/// velocities. Each particle is
/// rounded at most three times a step (after the collision, a reflection
/// and a contact; none here reflects), each component with an error of
/// variance at most 1/4 quantum^2, so a momentum component drifts with sd
/// at most sqrt(3 n steps / 4) / 127; 5 sd is the band. A contact that
/// forgot the holder would lose the gas's drift, hundreds of units.
#[test]
fn contacts_keep_momentum_up_to_rounding() {
    let mut desc = Description::new_2d(48, 48);
    desc.collisions = Collisions::SpeedLimited;
    desc.restitution = 0.9;
    desc.contacts = true;
    desc.seed = 8;
    let mut memory = vec![0u8; mpca::world_bytes(&desc).unwrap()];
    let w = World::init(&desc, &mut memory).unwrap();
    let mut rng = mpca_tests::setup::SetupRng::new(3);
    for pos in mpca_tests::setup::cells(&desc) {
        if rng.unit() < 0.6 {
            let v = rng.velocity(2, 0.3);
            w.add_particle(pos, [0.3 + v[0], 0.1 + v[1], 0.0]).unwrap();
        }
    }
    let (n, before) = (w.particle_count(), w.stats());
    let steps = 200;
    w.step(steps);
    let after = w.stats();
    let sd = (3.0 * (n * steps) as f64 / 4.0).sqrt() / 127.0;
    for k in 0..2 {
        let drift = after.momentum[k] - before.momentum[k];
        assert!(drift.abs() < 5.0 * sd, "axis {k}: drift {drift}, sd {sd}");
    }
    assert!(after.displaced > 2_000, "refused moves, and so contacts, happen: {after:?}");
    assert_eq!(after.clamps, 0, "a clamp would change momentum beyond rounding");
}


/// The elastic box ([`scenes::elastic_box`]) and memory for it.
fn elastic_box(energy_neutral: bool, boundary: Boundary) -> (Vec<u8>, Description) {
    let desc = scenes::elastic_box(energy_neutral, boundary);
    (vec![0u8; mpca::world_bytes(&desc).unwrap()], desc)
}

/// M1b. Unbiased rounding adds `f (1 - f)` quanta^2 per rounded component
/// on average, so the elastic box heats: +38 % in 20,000 steps (measured;
/// +189 % in 10^5). With energy-neutral rounding the mean gain is given
/// back by each collision, and the energy only wanders by the rounding
/// noise: each rounded component changes the energy by `m q d / SCALE^2`
/// with `d` of variance `f (1 - f)`, 1/6 on average, and `q^2` averaging
/// `2 E SCALE^2 / (N m D)`, so over `C` collisions (2 D roundings each) the
/// energy's sd is `sqrt(2/3 C m E / N) / SCALE`. The band is 5 sd. (Over
/// 10^5 steps the energy ended +0.46 % off, never more than 1.6 %.)
#[test]
fn energy_neutral_rounding_keeps_an_elastic_box_from_heating() {
    const STEPS: u64 = 20_000;
    let mut change = [0.0; 2];
    for (i, neutral) in [false, true].into_iter().enumerate() {
        let (mut memory, desc) = elastic_box(neutral, Boundary::Wall);
        let w = World::init(&desc, &mut memory).unwrap();
        scenes::fill_elastic(w);
        let (n, e0) = (w.particle_count() as f64, w.stats().kinetic_energy);
        w.step(STEPS);
        let s = w.stats();
        assert_eq!(s.clamps, 0);
        change[i] = s.kinetic_energy / e0 - 1.0;
        if neutral {
            let sd = (2.0 / 3.0 * s.collisions as f64 * e0 / n).sqrt() / 127.0 / e0;
            assert!(change[i].abs() < 5.0 * sd, "energy {:+.4}, sd {sd:.4}", change[i]);
        }
    }
    assert!(change[0] > 0.3, "unbiased rounding heats the box: {:+.4}", change[0]);
}

/// M1b scales the pair about its centre of mass: momentum moves only by
/// the rounding noise, as without it (periodic box, 5 sd of
/// `sqrt(collisions / 2) / 127` per component, as for M5.2b).
#[test]
fn energy_neutral_rounding_keeps_momentum_up_to_rounding() {
    let (mut memory, desc) = elastic_box(true, Boundary::Periodic);
    let w = World::init(&desc, &mut memory).unwrap();
    scenes::fill_elastic(w);
    let before = w.stats();
    w.step(2_000);
    let after = w.stats();
    let sd = (after.collisions as f64 / 2.0).sqrt() / 127.0;
    for k in 0..2 {
        let drift = after.momentum[k] - before.momentum[k];
        assert!(drift.abs() < 5.0 * sd, "axis {k}: drift {drift}, sd {sd}");
    }
}

/// M5.1b, one step of a particle at rest in a flow: backward Euler gives
/// `v = dt k u / (1 + dt k)` exactly, here u / 3 (k = 0.5, dt = 1), stored
/// to within one quantum by stochastic rounding; the flow at the cell is
/// the uniform wind, plus the wind plane's value at that cell (not a
/// neighbour's), plus the Rankine field with the vortex read as a velocity.
#[test]
fn drag_relaxes_towards_the_flow_by_backward_euler() {
    for (vortex, field) in [(false, false), (true, false), (false, true), (true, true)] {
        let mut desc = Description::new_2d(32, 32);
        desc.vortex = Vortex { centre: [16.0, 16.0], core_radius: 4.0, circulation: 3.0 };
        desc.drag = Drag { rate: 0.5, wind: [0.4, -0.2, 0.0], field, vortex, ..Drag::OFF };
        desc.seed = 2;
        let mut memory = vec![0u8; mpca::world_bytes(&desc).unwrap()];
        let w = World::init(&desc, &mut memory).unwrap();
        let pos = [22u32, 13, 0];
        if field {
            // Every other cell blows the other way.
            w.set_wind_field(&[-0.5, 0.5].repeat(32 * 32)).unwrap();
            w.set_cell_wind(pos, [-0.3, 0.5, 0.0]).unwrap();
        }
        w.add_particle(pos, [0.0; 3]).unwrap();
        w.step(1);
        let p = w.particles().next().unwrap();
        // The drag acts before the move: the flow is that of the start cell.
        let mut u = [0.4f32, -0.2];
        if field {
            u = [u[0] - 0.3, u[1] + 0.5];
        }
        if vortex {
            let (dx, dy) = (pos[0] as f32 + 0.5 - 16.0, pos[1] as f32 + 0.5 - 16.0);
            let s = 3.0 / (std::f32::consts::TAU * (dx * dx + dy * dy).max(16.0));
            u[0] -= dy * s;
            u[1] += dx * s;
        }
        for k in 0..2 {
            assert!((p.velocity[k] - u[k] / 3.0).abs() <= 1.0 / 127.0, "vortex {vortex}, field {field}, axis {k}: {:?} vs {u:?} / 3", p.velocity);
        }
    }
}

/// M5.1b's wind plane takes only what a flow can be: finite values, no
/// cell faster than 1, the whole plane, a cell inside the world; a world
/// built without the plane refuses both setters. A refused call sets
/// nothing: the world's image, which holds the plane (M12), is the same
/// byte for byte. The plane costs `dim` floats a cell when on, nothing off.
#[test]
fn the_wind_plane_refuses_what_no_flow_is_and_costs_nothing_when_off() {
    for dim in [2u32, 3] {
        let mut desc = if dim == 2 { Description::new_2d(8, 8) } else { Description::new_3d(4, 4, 4) };
        let (cells, d) = (64usize, dim as usize);
        desc.drag = Drag { rate: 0.2, wind: [0.1, 0.0, 0.0], field: false, vortex: false, ..Drag::OFF };
        let without = mpca::world_bytes(&desc).unwrap();
        let mut memory = vec![0u8; without];
        let w = World::init(&desc, &mut memory).unwrap();
        assert_eq!(w.set_wind_field(&vec![0.0; cells * d]).map_err(mpca::Error::kind), Err(mpca::ErrorKind::NotEnabled));
        assert_eq!(w.set_cell_wind([1, 1, 0], [0.1, 0.0, 0.0]).map_err(mpca::Error::kind), Err(mpca::ErrorKind::NotEnabled));

        desc.drag.field = true;
        assert_eq!(mpca::world_bytes(&desc).unwrap(), without + cells * d * 4, "{dim}D");
        let mut memory = vec![0u8; mpca::world_bytes(&desc).unwrap()];
        let w = World::init(&desc, &mut memory).unwrap();
        let plane: Vec<f32> = (0..cells * d).map(|i| (i % 5) as f32 * 0.1 - 0.2).collect();
        w.set_wind_field(&plane).unwrap();
        w.add_particle([1, 2, 0], [0.2, 0.0, 0.0]).unwrap();
        let image = |w: &World| {
            let mut out = vec![0u8; w.snapshot_bytes()];
            w.save(&mut out).unwrap();
            out
        };
        let before = image(w);
        let too_fast = if dim == 2 { [0.8, 0.61, 0.0] } else { [0.6, 0.6, 0.6] };
        use mpca::ErrorKind::{BadLength, NotFinite, OutOfBounds, SpeedRange};
        let mut calls = vec![];
        for (at, value, want) in
            [(0, f32::NAN, NotFinite), (cells * d - 1, f32::INFINITY, NotFinite), (d, f32::NEG_INFINITY, NotFinite), (3, 1.01, SpeedRange), (cells * d - 2, -1.5, SpeedRange)]
        {
            let mut bad = plane.clone();
            bad[at] = value;
            calls.push((format!("plane[{at}] = {value}"), w.set_wind_field(&bad), want));
        }
        let mut fast = plane.clone();
        fast[d * 9..d * 10].copy_from_slice(&too_fast[..d]);
        calls.push(("a cell of speed above 1".into(), w.set_wind_field(&fast), SpeedRange));
        for len in [0, cells * d - 1, cells * d + 1, cells] {
            calls.push((format!("length {len}"), w.set_wind_field(&vec![0.0; len]), BadLength));
        }
        calls.push(("cell of speed above 1".into(), w.set_cell_wind([1, 1, 0], too_fast), SpeedRange));
        calls.push(("cell wind NaN".into(), w.set_cell_wind([1, 1, 0], [0.0, f32::NAN, 0.0]), NotFinite));
        calls.push(("cell outside".into(), w.set_cell_wind([8, 1, 0], [0.1, 0.0, 0.0]), OutOfBounds));
        for (what, got, want) in calls {
            assert_eq!(got.map_err(mpca::Error::kind), Err(want), "{dim}D {what}");
        }
        assert!(image(w) == before, "{dim}D: a refused call changed the world");
        // A cell's value is taken as given, in the world's dimension: the
        // cell (1, 1, 0) is plane cell 9.
        let mut u = [0.0f32; 3];
        u[..d].copy_from_slice(&plane[9 * d..10 * d]);
        u[2] += 0.5;
        w.set_cell_wind([1, 1, 0], u).unwrap();
        assert_eq!(image(w) == before, dim == 2, "{dim}D: the third component counts in 3D only");
    }
}

/// M5.1b: under a uniform acceleration g and drag at rate k towards a wind
/// u, a particle's velocity tends to u + g / k (the fixed point of
/// `v <- (v + g + k u) / (1 + k)`): here (0.2, 0.1). Stochastic rounding is
/// unbiased, so the mean over the particles sits within 5 sd of it, each
/// stored component having variance at most 1/4 quantum^2.
#[test]
fn drag_gives_a_terminal_velocity() {
    let mut desc = Description::new_2d(64, 64);
    desc.forces.uniform = true;
    desc.gravity = [0.0, 0.01, 0.0];
    desc.drag = Drag { rate: 0.1, wind: [0.2, 0.0, 0.0], field: false, vortex: false, ..Drag::OFF };
    desc.seed = 3;
    let mut memory = vec![0u8; mpca::world_bytes(&desc).unwrap()];
    let w = World::init(&desc, &mut memory).unwrap();
    for y in (0..64).step_by(4) {
        for x in (0..64).step_by(4) {
            w.add_particle([x, y, 0], [-0.3, 0.5, 0.0]).unwrap();
        }
    }
    w.step(400);
    let n = w.particle_count() as f64;
    let sd = 0.5 / 127.0 / n.sqrt();
    for (k, want) in [(0, 0.2), (1, 0.1)] {
        let mean = w.particles().map(|p| f64::from(p.velocity[k])).sum::<f64>() / n;
        assert!((mean - want).abs() < 5.0 * sd, "axis {k}: {mean} vs {want} (sd {sd})");
    }
}

/// Issue 10's smoke: under the paper's vortex force the 4.3 scene's
/// particles run to the speed cap (480 steps: mean speed 0.84, 0.34 clamps
/// per particle-step, measured); with buoyancy and drag towards the air's
/// flow (scenes::smoke_flow) they move at the terminal speed and the clamp
/// does not fire (the issue asks at most 1 % of particle-steps).
///
/// And the plume rolls up: after the scene's 1,200 steps a share of its
/// particles lies within 1.5 core radii of the vortex's centre. With the
/// tangential vortex flow alone (the scene before the wind plane: the
/// circulation 9 it had, no inflow) the plume passes the vortex's side and
/// hardly any does. Each share is a count out of `n` particles, so its
/// binomial sd is `sqrt(p (1 - p) / n)`: the two differ by more than 5
/// combined sd, and the rolled-up share is at least a tenth.
#[test]
fn smoke_with_flow_drag_moves_at_terminal_speed_without_clamps_and_rolls_up() {
    let run = |scene: Scene, steps: u64| {
        let mut memory = Vec::new();
        let w = scenes::build(&scene, &mut memory).unwrap();
        let mut particle_steps = 0;
        for _ in 0..steps {
            w.step(1);
            particle_steps += w.particle_count();
        }
        let n = w.particle_count() as f64;
        let speed = w.particles().map(|p| f64::from(p.velocity[0].hypot(p.velocity[1]))).sum::<f64>() / n;
        let v = scene.desc.vortex;
        let near = w
            .particles()
            .filter(|p| {
                let (dx, dy) = (p.pos[0] as f32 + 0.5 - v.centre[0], p.pos[1] as f32 + 0.5 - v.centre[1]);
                dx.hypot(dy) <= 1.5 * v.core_radius
            })
            .count() as f64;
        (speed, w.stats().clamps as f64 / particle_steps as f64, near / n, n)
    };
    let (paper_speed, paper_clamps, _, _) = run(scenes::smoke(), 480);
    let (speed, clamps, share, n) = run(scenes::smoke_flow(), 1200);
    assert!(paper_clamps > 0.1 && paper_speed > 0.6, "{paper_speed} {paper_clamps}");
    assert!(clamps <= 0.01, "clamps per particle-step {clamps}");
    assert!(speed < 0.25, "mean speed {speed}");

    let mut tangential = scenes::smoke_flow();
    tangential.desc.vortex.circulation = 9.0;
    tangential.desc.drag.field = false;
    let (_, old_clamps, old_share, old_n) = run(tangential, 1200);
    let sd = (share * (1.0 - share) / n + old_share * (1.0 - old_share) / old_n).sqrt();
    println!("within 1.5 core radii: {share:.3} of {n} (tangential flow: {old_share:.3} of {old_n}); clamps {clamps} ({old_clamps}); mean speed {speed:.3}");
    assert!(share - old_share > 5.0 * sd && share >= 0.1, "rolled up {share} vs {old_share} (sd {sd})");
}
