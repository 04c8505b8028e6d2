//! Sequences of C ABI calls on one world, against a reference model of
//! what each call may do:
//!
//! - particles are accounted for: the count is always what was added,
//!   less what was removed, plus what emitters placed, less what left by
//!   open faces or expired; nothing exits a world without open faces,
//!   expires without lifetimes, or is emitted without an emitter;
//! - a refused call changes nothing: the world's image (every byte of state
//!   it saves) and hash are the same after it as before;
//! - an add or remove does what the model predicts from the cell it names:
//!   an empty cell takes a particle of |v| <= 1, an occupied or obstacle
//!   cell or a position outside the world refuses it, a removal returns
//!   exactly what the cell held;
//! - the exports agree with the statistics: as many particles, in cell
//!   order, each where `mpca_world_cell` finds it with the same velocity
//!   and mass; momentum and energy summed from them, a region covering
//!   the world, and a density at full resolution give the statistics'
//!   figures bit for bit;
//! - an image saved and loaded into a world built from its description
//!   hashes equal and steps on equal;
//! - bodies (M13) added, moved and removed at random push particles out
//!   or crush them, and every particle stays accounted for.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mpca_ffi::{mpca_cell_kind, mpca_emitter, mpca_shape, mpca_status};
use mpca_fuzz::{desc_from_image, scene, validate, Input, World};

/// What the model knows of the world between calls.
struct Model {
    size: [u32; 3],
    dim: usize,
    cells: usize,
    added: u64,
    removed: u64,
    steps: u64,
    emitters: bool,
    open: bool,
    lifetimes: bool,
    quantum: f32,
}

impl Model {
    /// The accounting that must hold after every call.
    fn check(&self, w: &World) {
        let s = w.stats();
        assert_eq!(s.step, self.steps, "step count");
        assert_eq!(s.particles + self.removed + s.exited + s.expired + s.crushed, self.added + s.emitted, "particles not accounted for: {s:?}");
        assert_eq!(w.count() as u64, s.particles, "count and statistics disagree");
        assert!(self.open || s.exited == 0, "a particle exited a world without open faces");
        assert!(self.lifetimes || s.expired == 0, "a particle expired in a world without lifetimes");
        assert!(self.emitters || s.emitted == 0, "a particle was emitted without an emitter");
    }
}

/// Length of `v` in f64, 2D dropping the third component as the library does.
fn speed(v: [f32; 3], dim: usize) -> f64 {
    v[..dim].iter().map(|&c| f64::from(c) * f64::from(c)).sum::<f64>().sqrt()
}

/// The exports, checked against the statistics and each other.
fn check_exports(w: &World, m: &Model) {
    let s = w.stats();
    let n = s.particles as usize;
    // Too small a buffer: the count and nothing else.
    if n > 0 {
        let (st, count, out) = w.export(0, n - 1);
        assert_eq!((st, count), (mpca_status::OutputTooSmall, n));
        assert!(out.iter().all(|&f| f == -7.0), "a refused export wrote into the buffer");
    }
    let (st, count, pos) = w.export(0, n);
    assert_eq!((st, count), (mpca_status::Ok, n));
    let (_, _, vel) = w.export(1, n);
    let (_, _, mass) = w.export(2, n);
    let mut momentum = [0.0f64; 3];
    let mut energy = 0.0f64;
    let mut last = None;
    let mut occupied = vec![0.0f32; m.cells];
    for i in 0..n {
        let p: [u32; 3] = core::array::from_fn(|k| {
            let c = pos[3 * i + k] - 0.5;
            assert!(c >= 0.0 && c.fract() == 0.0, "position {c} is not a cell centre");
            c as u32
        });
        let index = p[0] as usize + m.size[0] as usize * (p[1] as usize + m.size[1] as usize * p[2] as usize);
        assert!(last.is_none_or(|l| l < index), "exports out of cell order");
        last = Some(index);
        occupied[index] = 1.0;
        let cell = w.cell(p).expect("an exported position is in the world");
        assert_eq!(cell.kind, mpca_cell_kind::Particle as u32, "no particle where one was exported");
        assert_eq!(cell.particle.velocity[..], vel[3 * i..3 * i + 3], "velocity export and cell disagree");
        assert_eq!(cell.particle.mass, mass[i], "mass export and cell disagree");
        // Summed as the statistics are: in f64, in cell order.
        let mm = f64::from(mass[i]);
        let mut v2 = 0.0;
        for k in 0..3 {
            let v = f64::from(vel[3 * i + k]);
            momentum[k] += mm * v;
            v2 += v * v;
        }
        energy += 0.5 * mm * v2;
    }
    assert_eq!(momentum, s.momentum, "momentum of the exports");
    assert_eq!(energy.to_bits(), s.kinetic_energy.to_bits(), "kinetic energy of the exports");
    let all = w.region_stats([0; 3], m.size).expect("the whole world is a region");
    assert_eq!((all.particles, all.momentum, all.kinetic_energy.to_bits()), (s.particles, s.momentum, s.kinetic_energy.to_bits()));
    let density = w.density(m.size, m.cells).expect("density at the world's resolution");
    assert_eq!(density, occupied, "density at full resolution is not the occupancy");
}

/// Saves, builds a world from the image's description, loads, and steps
/// both on.
fn check_image(w: &mut World, input: &mut Input<'_>) -> Result<(), mpca_status> {
    let image = w.save();
    let d = desc_from_image(&image).expect("a saved image is accepted");
    let mut copy = World::create(&d).expect("the description of an image builds a world");
    copy.load(&image).expect("a saved image loads into a world built from its description");
    assert_eq!(copy.hash(), w.hash(), "a loaded world hashes otherwise");
    assert_eq!(copy.save(), image, "a loaded world saves another image");
    let n = 1 + input.pick(3) as u64;
    copy.step(n)?;
    let mut other = World::create(&d).expect("as above");
    other.load(&image).expect("as above");
    other.step(n)?;
    assert_eq!(copy.hash(), other.hash(), "two loads of one image step apart");
    Ok(())
}

fuzz_target!(|data: &[u8]| {
    let mut input = Input::new(data);
    let d = scene(&mut input);
    if validate(&d) != mpca_status::Ok {
        return;
    }
    let in_caller_memory = input.bit();
    let mut w = if in_caller_memory {
        let bytes = mpca_fuzz::world_bytes(&d).expect("valid");
        World::init(&d, vec![0u8; bytes + 7], input.pick(8)).map_err(|e| e.0).expect("a valid description builds")
    } else {
        World::create(&d).expect("a valid description builds")
    };
    let stored = w.desc();
    let mut m = Model {
        size: stored.size,
        dim: d.dim as usize,
        cells: stored.size.iter().map(|&n| n as usize).product(),
        added: 0,
        removed: 0,
        steps: 0,
        emitters: false,
        open: d.boundary.iter().flatten().any(|&b| b == 2),
        lifetimes: d.lifetimes == 1,
        quantum: if d.quantization == 16 { 1.0 / 32767.0 } else { 1.0 / 127.0 },
    };
    let n = m.size;
    for _ in 0..64 {
        if input.is_empty() {
            break;
        }
        let before = (w.save(), w.hash());
        let op = input.pick(24);
        let result: Result<(), mpca_status> = match op {
            0 | 1 => {
                let (pos, v) = (input.position(n), input.vector());
                let mass = if op == 1 { Some([d.mass, 0.5, 2.0, input.value()][input.pick(4)]) } else { None };
                let cell = w.cell(pos);
                let r = match mass {
                    Some(mass) => w.add_particle_mass(pos, v, mass),
                    None => w.add_particle(pos, v),
                };
                let finite = v.iter().all(|c| c.is_finite());
                match cell {
                    Err(e) => assert_eq!(r, Err(e), "a position outside the world"),
                    Ok(c) if finite && speed(v, m.dim) <= 1.0 => {
                        let kind = c.kind;
                        let want = if kind == mpca_cell_kind::Particle as u32 {
                            Err(mpca_status::CellOccupied)
                        } else if kind == mpca_cell_kind::Obstacle as u32 {
                            Err(mpca_status::CellObstacle)
                        } else {
                            Ok(())
                        };
                        // A mass the world cannot take is the last check.
                        if !(want.is_ok() && r.is_err() && mass.is_some_and(|x| x != d.mass)) {
                            assert_eq!(r, want, "add_particle({pos:?}, {v:?}) into a cell of kind {kind}");
                        }
                    }
                    Ok(_) if !finite || v[..m.dim].iter().any(|c| c.abs() > 1.0) => {
                        assert!(r.is_err(), "a velocity {v:?} out of range was taken");
                    }
                    Ok(_) => {}
                }
                if r.is_ok() {
                    m.added += 1;
                    let p = w.cell(pos).expect("in the world").particle;
                    for k in 0..m.dim {
                        assert!((p.velocity[k] - v[k]).abs() <= m.quantum / 2.0 + f32::EPSILON, "stored {p:?} for {v:?}");
                    }
                    assert_eq!(p.mass, mass.unwrap_or(d.mass));
                }
                r
            }
            2 => {
                let pos = input.position(n);
                let cell = w.cell(pos);
                let r = w.remove_particle(pos);
                match (cell, r) {
                    (Ok(c), Ok(p)) => {
                        assert_eq!(c.kind, mpca_cell_kind::Particle as u32);
                        assert_eq!(c.particle, p, "remove_particle returned another particle than the cell held");
                        assert_eq!(w.cell(pos).map(|c| c.kind), Ok(mpca_cell_kind::Empty as u32));
                        m.removed += 1;
                    }
                    (Ok(c), Err(e)) => {
                        assert_ne!(c.kind, mpca_cell_kind::Particle as u32, "a particle was not removed");
                        assert_eq!(e, mpca_status::NoParticle);
                    }
                    (Err(a), r) => assert_eq!(r.err(), Some(a)),
                }
                r.map(|_| ())
            }
            3 | 4 => {
                let steps = 1 + input.pick(4) as u64;
                w.step(steps).expect("a step is never refused");
                m.steps += steps;
                Ok(())
            }
            5 => {
                let min = input.position(n);
                let max = input.position(n).map(|c| c + 1);
                let e = mpca_emitter {
                    struct_size: size_of::<mpca_emitter>() as u32,
                    min,
                    max,
                    rate: input.value().abs() * 3.0,
                    velocity: input.vector().map(|c| c / 2.0),
                    spread: input.value().abs() / 2.0,
                    mass: [d.mass, 1.0, 0.5][input.pick(3)],
                    lifetime: [0, 1, 5, 70000][input.pick(4)],
                };
                let r = w.add_emitter(&e);
                m.emitters |= r.is_ok();
                r.map(|_| ())
            }
            6 => w.set_emitter_rate(input.pick(5) as u32, input.value() * 2.0),
            7 => w.add_obstacle(input.position(n), input.vector(), input.value()),
            8 => {
                let scale = n.map(|c| c as f32);
                let p: [f32; 3] = core::array::from_fn(|k| input.value() * scale[k]);
                let q: [f32; 3] = core::array::from_fn(|k| input.value() * scale[k]);
                let (r, e) = (input.value() * scale[0], input.value());
                match input.pick(4) {
                    0 => w.add_half_space(p, q, e),
                    1 => w.add_box(p, q, e),
                    2 => w.add_disc([p[0], p[1]], r, e),
                    _ => w.add_sphere(p, r, e),
                }
            }
            9 => {
                let len = if input.bit() { m.cells } else { input.pick(m.cells + 2) };
                let mut mask = vec![0u8; len];
                for _ in 0..input.pick(8) {
                    let (at, run) = (input.u16() as usize, input.pick(8));
                    for b in mask.iter_mut().skip(at % len.max(1)).take(run) {
                        *b = 1;
                    }
                }
                w.add_obstacle_mask(&mask, input.value())
            }
            10 => w.set_gravity(input.vector().map(|g| g / 10.0)),
            11 => {
                let len = if input.bit() { m.cells * m.dim } else { input.pick(m.cells * m.dim + 2) };
                let f: Vec<f32> = (0..len).map(|i| if i % 7 == 0 { input.value() / 10.0 } else { 0.0 }).collect();
                w.set_force_field(&f)
            }
            12 => w.set_cell_force(input.position(n), input.vector().map(|f| f / 10.0)),
            13 => {
                let len = if input.bit() { m.cells } else { input.pick(m.cells + 2) };
                let u: Vec<f32> = (0..len).map(|i| (i % 5) as f32 * input.value() / 10.0).collect();
                w.set_potential(&u)
            }
            14 => w.set_cell_potential(input.position(n), input.value()),
            15 => w.set_vortex([input.value() * n[0] as f32, input.value() * n[1] as f32], input.value() * 4.0, input.value()),
            16 => {
                check_exports(&w, &m);
                Ok(())
            }
            17 => {
                let r = check_image(&mut w, &mut input);
                assert_eq!(r, Ok(()), "stepping a loaded world was refused");
                Ok(())
            }
            18 => {
                let pos = input.position(n);
                let r = w.surface(pos);
                if let Ok((normal, e)) = r {
                    assert_eq!(w.cell(pos).map(|c| c.kind), Ok(mpca_cell_kind::Obstacle as u32), "a surface that is not an obstacle");
                    let len = speed(normal, 3);
                    assert!((len - 1.0).abs() < 1e-5, "surface normal {normal:?} is not a unit vector");
                    assert!((0.0..=1.0).contains(&e), "restitution {e} out of range");
                }
                r.map(|_| ())
            }
            19 => {
                // Winds near the speed limit of 1, now and then past it or
                // not finite: refused whole.
                let len = if input.bit() { m.cells * m.dim } else { input.pick(m.cells * m.dim + 2) };
                let u: Vec<f32> = (0..len).map(|i| if i % 3 == 0 { input.value() * 0.8 } else { 0.0 }).collect();
                w.set_wind_field(&u)
            }
            20 => w.set_cell_wind(input.position(n), input.vector().map(|u| u * 0.8)),
            21 | 22 => {
                // A body added or moved anywhere, now and then too fast or
                // degenerate (refused whole), or removed.
                let scale = n.map(|c| c as f32);
                let shape = mpca_shape {
                    struct_size: size_of::<mpca_shape>() as u32,
                    kind: input.pick(6) as u32,
                    a: core::array::from_fn(|k| input.value() * scale[k]),
                    b: core::array::from_fn(|k| input.value() * scale[k]),
                    radius: input.value() * 4.0,
                };
                let (u, e, id) = (input.vector().map(|c| c * 0.8), input.value(), input.pick(4) as u32);
                match (op, input.pick(3)) {
                    (21, _) => w.add_body(&shape, u, e).map(drop),
                    (_, 0) => w.remove_body(id),
                    _ => w.move_body(id, &shape, u),
                }
            }
            _ => Err(w.refused_calls(input.u8() as usize)),
        };
        if result.is_err() {
            assert_eq!((w.save(), w.hash()), before, "refused call {op} ({result:?}) changed the world");
        }
        m.check(&w);
    }
    check_exports(&w, &m);
});
