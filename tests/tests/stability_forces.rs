//! Numerical stability under stiff forces and time steps (issue #5): forces
//! far beyond a cell per step, undefined force components, extreme and zero
//! time steps, and a force of a hundredth of a quantum per step.


mod common;
mod stability;

use common::{cells, mean_and_se, memory, quanta, scale, Z};
use mpca::{Boundary, Description, Drift, Quantization, Vortex, World};
use stability::*;

// ------------------------------------------------------------- huge forces

/// Runs `steps` steps of a world of `desc` filled by `fill`, checking it
/// after every step; returns the world's clamps.
fn run_checked(desc: &Description, steps: u64, what: &str, fill: &dyn Fn(&mut World) -> u64) -> u64 {
    let mut mem = memory(desc);
    let world = World::init(desc, &mut mem).unwrap();
    let n = fill(world);
    check_sane(world, n, what);
    for t in 0..steps {
        world.step(1);
        check_sane(world, n, &format!("{what}, step {t}"));
    }
    world.stats().clamps
}

/// Every variant of a stiff world: 2D and 3D, 8 and 16 bits, periodic and
/// walled.
fn variants(make: impl Fn(u32) -> Description) -> Vec<(String, Description)> {
    let mut v = vec![];
    for dim in [2u32, 3] {
        for q in QUANTS {
            for faces in [Boundary::Periodic, Boundary::Wall] {
                let mut d = make(dim);
                d.boundary = [[faces; 2]; 3];
                d.quantization = q;
                d.seed = 500 + u64::from(dim);
                v.push((format!("{dim}D {q:?} {faces:?}"), d));
            }
        }
    }
    v
}

fn fill_half(world: &mut World, masses: &[f32]) -> u64 {
    let mut rng = common::test_rng(world.description().seed);
    scatter(world, 0.5, 1.0, masses, &mut rng)
}

/// M5.1 with forces far beyond one cell per step, M5.5 clamps them.
/// Uniform gravity of 1e30 (and 3e38, whose dt * g * SCALE overflows f32),
/// a force field with dt |F| / m = 1e6, the same field on masses of 1e-30
/// (the acceleration overflows), a potential with a jump of 1e30 between
/// neighbouring cells (a near-vertical wall) and one jumping from f32::MAX to
/// -f32::MAX (its central difference overflows), and a vortex with a core of
/// 1e-30 cells and circulation 1e30 centred on an occupied cell.
/// Expected after every step: `check_sane` (so no NaN, no infinity,
/// |v| <= 1 + sqrt(dim)/SCALE, exact count), and clamps fired.
#[test]
fn huge_forces_keep_speeds_bounded() {
    type Describe = Box<dyn Fn(&mut Description)>;
    type Prepare = Box<dyn Fn(&mut World)>;
    let cases: Vec<(&str, Describe, Prepare)> = vec![
        (
            "gravity 1e30",
            Box::new(|d| {
                d.forces.uniform = true;
                d.gravity = [1e30, -1e30, 1e30];
            }),
            Box::new(|_| {}),
        ),
        (
            "gravity 3e38",
            Box::new(|d| {
                d.forces.uniform = true;
                d.gravity = [3e38, -3e38, 0.0];
            }),
            Box::new(|_| {}),
        ),
        (
            "field 1e6 per step",
            Box::new(|d| d.forces.field = true),
            Box::new(|w| {
                let dim = w.description().dim as usize;
                let n = w.description().size[..dim].iter().product::<u32>() as usize;
                let mut rng = common::test_rng(9);
                let f: Vec<f32> = (0..n * dim).map(|_| 2e6 * (rng.unit() - 0.5)).collect();
                w.set_force_field(&f).unwrap();
            }),
        ),
        (
            "field 1e30 on masses 1e-30",
            Box::new(|d| {
                d.forces.field = true;
                d.per_particle_mass = true;
                d.mass_classes = 2;
            }),
            Box::new(|w| {
                let dim = w.description().dim as usize;
                let n = w.description().size[..dim].iter().product::<u32>() as usize;
                let f: Vec<f32> = (0..n * dim).map(|i| if i % 3 == 0 { -1e30 } else { 1e30 }).collect();
                w.set_force_field(&f).unwrap();
            }),
        ),
        (
            "potential cliff 1e30",
            Box::new(|d| d.forces.potential = true),
            Box::new(|w| {
                let desc = *w.description();
                let u: Vec<f32> = cells(&desc).map(|p| if p[0] < desc.size[0] / 2 { 0.0 } else { 1e30 }).collect();
                w.set_potential(&u).unwrap();
            }),
        ),
        (
            "potential MAX to -MAX",
            Box::new(|d| d.forces.potential = true),
            Box::new(|w| {
                let desc = *w.description();
                let u: Vec<f32> =
                    cells(&desc).map(|p| if (p[0] + p[1]) < desc.size[0] / 2 { f32::MAX } else { -f32::MAX }).collect();
                w.set_potential(&u).unwrap();
            }),
        ),
        (
            "vortex core 1e-30",
            Box::new(|d| {
                d.forces.vortex = true;
                d.vortex = Vortex { centre: [4.5, 4.5], core_radius: 1e-30, circulation: 1e30 };
            }),
            Box::new(|_| {}),
        ),
    ];
    for (name, describe, prepare) in &cases {
        for (variant, desc) in variants(|dim| {
            let mut d = cube(dim, if dim == 2 { 16 } else { 8 });
            describe(&mut d);
            d
        }) {
            let what = format!("{name}, {variant}");
            let masses: &[f32] = if desc.per_particle_mass { &[1e-30, 1.0] } else { &[1.0] };
            let clamps = run_checked(&desc, 20, &what, &|w| {
                prepare(w);
                let n = fill_half(w, masses);
                // The vortex case puts a particle on the centre cell.
                let _ = w.add_particle_with_mass([4, 4, if desc.dim == 3 { 4 } else { 0 }], [0.0; 3], masses[0]);
                n + u64::from(w.particle_count() > n)
            });
            assert!(clamps > 0, "{what}: no clamp fired");
        }
    }
}

/// M5.5 keeps the direction of a clamped velocity: with a uniform
/// acceleration of 1e30 cells per step^2 along -y, or a force field with
/// dt |F| / m = 1e6 along a fixed unit direction `u` in every cell, every
/// particle of a periodic world leaves each step with velocity `u` (the
/// velocity it had adds less than 1e-6 of a quantum after the clamp, equal
/// velocities collide into themselves). Expected: every stored component
/// within one quantum (its stochastic rounding) of `u * SCALE`.
#[test]
fn clamped_velocities_point_along_the_force() {
    for dim in [2u32, 3] {
        for q in QUANTS {
            let u: [f32; 3] = if dim == 2 { [0.6, 0.8, 0.0] } else { [0.48, 0.6, -0.64] };
            for use_field in [false, true] {
                let mut desc = cube(dim, if dim == 2 { 16 } else { 8 });
                desc.quantization = q;
                desc.seed = 31;
                let dir = if use_field {
                    desc.forces.field = true;
                    u
                } else {
                    desc.forces.uniform = true;
                    desc.gravity = [0.0, -1e30, 0.0];
                    [0.0, -1.0, 0.0]
                };
                let mut mem = memory(&desc);
                let world = World::init(&desc, &mut mem).unwrap();
                if use_field {
                    let n = cells(&desc).count();
                    let f: Vec<f32> = (0..n).flat_map(|_| u[..dim as usize].iter().map(|c| c * 1e6)).collect();
                    world.set_force_field(&f).unwrap();
                }
                let n = fill_half(world, &[1.0]);
                let s = scale(q);
                for t in 0..10 {
                    world.step(1);
                    check_sane(world, n, "direction");
                    for p in world.particles() {
                        let x = stored(p.velocity, q);
                        for k in 0..3 {
                            let want = f64::from(dir[k]) * s;
                            assert!(
                                (x[k] as f64 - want).abs() < 1.0 + 1e-5 * s + 1e-3,
                                "{dim}D {q:?} field {use_field} step {t}: {x:?} vs {dir:?} * SCALE"
                            );
                        }
                    }
                }
            }
        }
    }
}

/// M5.5 on a velocity whose force terms overflow. In integers (M1c) a term
/// whose conversion overflows saturates at `±2^61` fine units, so two
/// opposite overflowing terms cancel exactly, and the sum is fitted to the
/// working bound with its direction kept; the clamp only ever scales a
/// velocity back to |v| = 1 (M5.5). Here, in 3D, at cell (4, 4, z) a
/// potential cliff gives F_x = +MAX and a force field F_x = -MAX (so F_x
/// cancels); nothing overflows along z, where gravity adds 0.001 per step.
/// A particle there at rest, alone in its block. Expected after one step:
/// the stored velocity is (0, 0, 0.001) within one quantum per axis (its
/// rounding), and in particular |v| stays far below 1. With the field off,
/// the cliff alone clamps the velocity to +x.
#[test]
fn opposite_overflowing_force_terms_cancel() {
    for q in QUANTS {
        for field in [true, false] {
            let mut desc = cube(3, 8);
            desc.quantization = q;
            desc.forces.uniform = true;
            desc.forces.potential = true;
            desc.forces.field = field;
            desc.gravity = [0.0, 0.0, 0.001];
            desc.seed = 20;
            let mut mem = memory(&desc);
            let world = World::init(&desc, &mut mem).unwrap();
            let u: Vec<f32> = cells(&desc).map(|p| if p[0] < 5 { f32::MAX } else { -f32::MAX }).collect();
            world.set_potential(&u).unwrap();
            if field {
                let f: Vec<f32> = cells(&desc).flat_map(|_| [-f32::MAX, 0.0, 0.0]).collect();
                world.set_force_field(&f).unwrap();
            }
            world.add_particle([4, 4, 4], [0.0; 3]).unwrap();
            world.step(1);
            check_sane(world, 1, &format!("{q:?}"));
            let p = world.particles().next().unwrap();
            let x = stored(p.velocity, q);
            let s = scale(q);
            let want = if field { [0.0, 0.0, 0.001 * s] } else { [s, 0.0, 0.0] };
            for k in 0..3 {
                assert!((x[k] as f64 - want[k]).abs() < 1.0 + 1e-3, "{q:?} field {field}: stored {x:?} quanta, expected {want:?} within a quantum");
            }
        }
    }
}

// ------------------------------------------------------------- time steps

/// A world with all four force terms at ordinary strengths (gravity 0.01, a
/// field up to 0.02, a potential with gradient up to 0.01, a vortex of
/// circulation 2) and `dt`.
fn forced(dim: u32, q: Quantization, dt: f32, scale_forces: f32) -> Description {
    let mut d = cube(dim, if dim == 2 { 16 } else { 8 }).with_boundary(Boundary::Wall);
    d.quantization = q;
    d.dt = dt;
    d.forces.uniform = true;
    d.forces.field = true;
    d.forces.potential = true;
    d.forces.vortex = true;
    d.gravity = [0.0, -0.01 * scale_forces, 0.0];
    d.vortex = Vortex { centre: [4.0, 4.0], core_radius: 2.0, circulation: 2.0 * scale_forces };
    d.seed = 3;
    d
}

fn set_fields(w: &mut World, scale_forces: f32) {
    let desc = *w.description();
    let dim = desc.dim as usize;
    let n = cells(&desc).count();
    let mut rng = common::test_rng(4);
    let f: Vec<f32> = (0..n * dim).map(|_| 0.04 * scale_forces * (rng.unit() - 0.5)).collect();
    w.set_force_field(&f).unwrap();
    let u: Vec<f32> = cells(&desc).map(|p| 0.01 * scale_forces * (p[0] as f32 + 0.5 * p[1] as f32)).collect();
    w.set_potential(&u).unwrap();
}

/// M5.1 with dt = 0, 1e-30 and 1e30 and every force term on. Expected:
/// `check_sane` after every step for each; with dt = 0 the forces vanish
/// (dt a = 0 for finite a), so the world matches, bit for bit, one with
/// every force term on but zero (same seed, particles and step path).
#[test]
fn extreme_time_steps_stay_finite() {
    for dim in [2u32, 3] {
        for q in QUANTS {
            for dt in [0.0f32, 1e-30, 1e30] {
                let desc = forced(dim, q, dt, 1.0);
                let what = format!("{dim}D {q:?} dt {dt}");
                let mut mem = memory(&desc);
                let world = World::init(&desc, &mut mem).unwrap();
                set_fields(world, 1.0);
                let n = fill_half(world, &[1.0]);
                let mut twin_desc = forced(dim, q, 1.0, 0.0);
                twin_desc.vortex.circulation = 0.0;
                let mut twin_mem = memory(&twin_desc);
                let twin = World::init(&twin_desc, &mut twin_mem).unwrap();
                set_fields(twin, 0.0);
                assert_eq!(fill_half(twin, &[1.0]), n);
                for t in 0..50 {
                    world.step(1);
                    twin.step(1);
                    check_sane(world, n, &format!("{what}, step {t}"));
                    if dt == 0.0 {
                        assert_eq!(world.state_hash(), twin.state_hash(), "{what}: dt = 0 differs from zero forces at step {t}");
                    }
                }
                if dt == 1e30 {
                    assert!(world.stats().clamps > 0, "{what}: no clamp");
                }
            }
        }
    }
}

/// M5.1 with dt = 0: `v <- v + dt F / m` leaves every velocity as it is,
/// whatever the force, even one that overflows f32 (a potential jumping
/// from f32::MAX to -f32::MAX, whose central difference is infinite, and a
/// force of 1e30 on a mass of 1e-30). Particles alone in their blocks (4
/// cells apart), speeds up to 0.5, periodic, no obstacle: nothing else can
/// change a velocity in one step. Expected: every stored velocity after the
/// step equals the one before, exactly.
#[test]
fn zero_time_step_ignores_even_infinite_forces() {
    for dim in [2u32, 3] {
        for q in QUANTS {
            let what = format!("{dim}D {q:?}");
            let mut desc = cube(dim, 16);
            desc.quantization = q;
            desc.dt = 0.0;
            desc.forces.potential = true;
            desc.forces.field = true;
            desc.per_particle_mass = true;
            desc.mass_classes = 2;
            desc.seed = 19;
            let mut mem = memory(&desc);
            let world = World::init(&desc, &mut mem).unwrap();
            // The cliff runs through x = 8.5: cells 8 and 9 see an infinite
            // central difference.
            let u: Vec<f32> = cells(&desc).map(|p| if p[0] < 9 { f32::MAX } else { -f32::MAX }).collect();
            world.set_potential(&u).unwrap();
            let f: Vec<f32> = cells(&desc).flat_map(|_| [1e30f32, -1e30, 1e30].into_iter().take(dim as usize)).collect();
            world.set_force_field(&f).unwrap();
            let mut rng = common::test_rng(19);
            let mut before = std::collections::BTreeMap::new();
            for pos in cells(&desc).filter(|p| p.iter().take(dim as usize).all(|&c| c % 4 == 1)) {
                let m = if (pos[0] / 4) % 2 == 0 { 1.0 } else { 1e-30 };
                world.add_particle_with_mass(pos, rng.velocity(dim, 0.5), m).unwrap();
                before.insert(pos.map(|c| c / 4), stored(common::particle(world, pos).velocity, q));
            }
            world.step(1);
            check_sane(world, before.len() as u64, &what);
            let mut changed = vec![];
            for p in world.particles() {
                let x = stored(p.velocity, q);
                if before[&p.pos.map(|c| c / 4)] != x {
                    changed.push(format!("{:?}: {:?} -> {x:?}", p.pos, before[&p.pos.map(|c| c / 4)]));
                }
            }
            assert!(changed.is_empty(), "{what}: dt = 0 changed {} velocities:\n  {}", changed.len(), changed.join("\n  "));
        }
    }
}

// ------------------------------------------------------------- sub-quantum

/// Extends forces.rs's `sub_quantum_accelerations_act_on_average` (2D,
/// from rest, 0.127 quantum per step on the uniform path at 8 bits, 0.33 on
/// the field path at 16 bits) to 3D, to the potential path (eq. 6's central
/// differences of a linear potential), to the paths forces.rs left out at
/// each width (field at 8 bits, uniform at 16), to a hundredth of a quantum
/// per step, and to a deceleration through zero: particles start at +10
/// quanta along x, alone in their (y, z) row, and feel -0.01 quantum per
/// step for 2000 steps. Expected: mean stored v_x = 10 - 20 = -10 quanta
/// within 5 standard errors (sample variance across the independent
/// particles); the band excludes +10, where rounding to nearest would
/// leave them.
#[test]
fn hundredth_of_a_quantum_per_step_acts_on_average() {
    const STEPS: u64 = 2000;
    const ROWS: u32 = 16;
    for q in QUANTS {
        for path in ["uniform", "field", "potential"] {
            let what = format!("{q:?} {path}");
            let s = scale(q) as f32;
            let a = -0.01 / s; // cells per step^2
            let mut desc = Description::new_3d(512, 4 * ROWS, 4 * ROWS);
            desc.boundary[0] = [Boundary::Wall; 2];
            desc.quantization = q;
            desc.seed = 17;
            desc.drift = Drift::Calibrated;
            match path {
                "uniform" => {
                    desc.forces.uniform = true;
                    desc.gravity = [a, 0.0, 0.0];
                }
                "field" => desc.forces.field = true,
                _ => desc.forces.potential = true,
            }
            let mut mem = memory(&desc);
            let world = World::init(&desc, &mut mem).unwrap();
            match path {
                "field" => {
                    let f: Vec<f32> = cells(&desc).flat_map(|_| [a, 0.0, 0.0]).collect();
                    world.set_force_field(&f).unwrap();
                }
                "potential" => {
                    // F = -dU/dx = a (mass 1): U = -a x, exact differences.
                    let u: Vec<f32> = cells(&desc).map(|p| -a * p[0] as f32).collect();
                    world.set_potential(&u).unwrap();
                }
                _ => {}
            }
            let v0 = 10.0 / s;
            for j in 0..ROWS * ROWS {
                world.add_particle([252 + j % 8, 4 * (j % ROWS), 4 * (j / ROWS)], [v0, 0.0, 0.0]).unwrap();
            }
            world.step(STEPS);
            assert_eq!(world.stats().collisions, 0, "{what}");
            let v: Vec<f64> = world.particles().map(|p| quanta(p.velocity[0], q) as f64).collect();
            assert_eq!(v.len(), (ROWS * ROWS) as usize);
            // The walls at x = 0 and 511 stay out of reach (a wall would
            // flip a velocity): the mean path goes out 39 cells at 8 bits
            // and back, and rounding (variance 0.01 quantum^2 per step)
            // spreads it by about 40 cells.
            assert!(world.particles().all(|p| (1..511).contains(&p.pos[0])), "{what}");
            let (mean, se) = mean_and_se(&v);
            let want = 10.0 - 0.01 * STEPS as f64;
            assert!((mean - want).abs() <= Z * se, "{what}: mean {mean} quanta, expected {want} +- {}", Z * se);
            assert!((10.0 - want) > Z * se, "{what}: the band reaches +10");
        }
    }
}
