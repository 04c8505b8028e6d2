//! External forces (M5.1, eqs. 4-6) and the unbiased storage that lets an
//! acceleration below one quantum per step act on average (M1).

mod common;

use common::{mean_and_se, memory, scale, Z};
use mpca::{Boundary, Description, Quantization, Vortex, World};

/// The cells of one coordinate axis used as probes: 4i and 4i + 3. At
/// offset 0 they lie in different blocks ((4i, 4i+1) and (4i+2, 4i+3)), so
/// probes never share a block, and a probe stays in its block during the
/// step: the block's probe coordinate recovers where it started.
fn probes(n: u32) -> Vec<u32> {
    (0..n / 4).flat_map(|i| [4 * i, 4 * i + 3]).collect()
}

fn probe_origin(x: u32) -> u32 {
    let block = x / 2;
    if block & 1 == 0 {
        2 * block
    } else {
        2 * block + 1
    }
}

/// Eq. 6 by central differences on the grid, one-sided at a face that is
/// not periodic (force.rs; M4 says nothing of the potential beyond a face).
fn gradient(u: &[f32], n: [u32; 2], pos: [u32; 2], periodic: bool) -> [f64; 2] {
    let at = |x: u32, y: u32| f64::from(u[(x + n[0] * y) as usize]);
    let mut g = [0.0; 2];
    for k in 0..2 {
        let step = |p: [u32; 2], d: i64| -> Option<[u32; 2]> {
            let v = i64::from(p[k]) + d;
            let w = if (0..i64::from(n[k])).contains(&v) {
                v as u32
            } else if periodic {
                v.rem_euclid(i64::from(n[k])) as u32
            } else {
                return None;
            };
            let mut q = p;
            q[k] = w;
            Some(q)
        };
        let here = at(pos[0], pos[1]);
        g[k] = match (step(pos, -1), step(pos, 1)) {
            (Some(lo), Some(hi)) => 0.5 * (at(hi[0], hi[1]) - at(lo[0], lo[1])),
            (None, Some(hi)) => at(hi[0], hi[1]) - here,
            (Some(lo), None) => here - at(lo[0], lo[1]),
            (None, None) => 0.0,
        };
    }
    g
}

/// The Rankine vortex force of `Vortex`'s documentation at a cell centre:
/// tangential (counter-clockwise for positive circulation), magnitude
/// G/(2 pi) r/R^2 inside the core and G/(2 pi r) outside.
fn vortex_force(v: &Vortex, pos: [u32; 2]) -> [f64; 2] {
    let dx = f64::from(pos[0]) + 0.5 - f64::from(v.centre[0]);
    let dy = f64::from(pos[1]) + 0.5 - f64::from(v.centre[1]);
    let r = (dx * dx + dy * dy).sqrt();
    let (g, big_r) = (f64::from(v.circulation), f64::from(v.core_radius));
    let magnitude =
        if r < big_r { g / std::f64::consts::TAU * r / (big_r * big_r) } else { g / (std::f64::consts::TAU * r) };
    if r == 0.0 {
        [0.0, 0.0]
    } else {
        [-dy / r * magnitude, dx / r * magnitude]
    }
}

/// M5.1: v <- v + dt (g + (F_field - grad U + F_vortex) / m), evaluated at
/// the particle's cell before it moves. Particles at rest on probe cells of
/// a 2D world with every term on, masses 1 and 2, dt = 0.5, 16-bit storage;
/// after one step each stored velocity must be the computed dt a, to within
/// the one quantum of its stochastic rounding (plus 1e-6 for the f32
/// arithmetic on values below 1). Periodic and walled worlds (the potential's
/// differences wrap, or turn one-sided at the faces).
#[test]
fn forces_give_the_specified_velocity_change() {
    for faces in [Boundary::Periodic, Boundary::Wall] {
        let n = 32u32;
        let mut desc = Description::new_2d(n, n).with_boundary(faces);
        desc.quantization = Quantization::Bits16;
        desc.per_particle_mass = true;
        desc.mass_classes = 2;
        desc.dt = 0.5;
        desc.forces.uniform = true;
        desc.gravity = [0.001, -0.002, 0.0];
        desc.forces.field = true;
        desc.forces.potential = true;
        desc.forces.vortex = true;
        desc.vortex = Vortex { centre: [13.0, 17.5], core_radius: 5.0, circulation: 0.4 };
        desc.seed = 91;
        let mut mem = memory(&desc);
        let world = World::init(&desc, &mut mem).unwrap();
        let mut rng = common::test_rng(91);
        let cells = (n * n) as usize;
        let field: Vec<f32> = (0..2 * cells).map(|_| 0.02 * (rng.unit() - 0.5)).collect();
        let potential: Vec<f32> = (0..cells)
            .map(|i| {
                let (x, y) = ((i as u32 % n) as f32, (i as u32 / n) as f32);
                0.003 * x + 0.0001 * y * y + 0.001 * (0.7 * x).sin()
            })
            .collect();
        world.set_force_field(&field).unwrap();
        world.set_potential(&potential).unwrap();
        let mut count = 0;
        for &y in &probes(n) {
            for &x in &probes(n) {
                let m = if (x + y) % 3 == 0 { 2.0 } else { 1.0 };
                world.add_particle_with_mass([x, y, 0], [0.0; 3], m).unwrap();
                count += 1;
            }
        }
        world.step(1);
        assert_eq!(world.particles().count(), count);
        let tolerance = 1.0 / scale(desc.quantization) + 1e-6;
        for p in world.particles() {
            let pos = [probe_origin(p.pos[0]), probe_origin(p.pos[1])];
            let cell = (pos[0] + n * pos[1]) as usize;
            let grad = gradient(&potential, [n, n], pos, faces == Boundary::Periodic);
            let swirl = vortex_force(&desc.vortex, pos);
            let m = f64::from(p.mass);
            for k in 0..2 {
                let force = f64::from(field[2 * cell + k]) - grad[k] + swirl[k];
                let want = f64::from(desc.dt) * (f64::from(desc.gravity[k]) + force / m);
                let got = f64::from(p.velocity[k]);
                assert!(
                    (got - want).abs() <= tolerance,
                    "{faces:?} cell {pos:?} axis {k} m {m}: v = {got}, dt a = {want}"
                );
            }
        }
    }
}

/// M1: storage rounds stochastically and without bias, so an acceleration
/// of a fraction of a quantum per step still acts. Free particles at rest
/// (one per row, rows 4 apart, pushed along x only, so they never meet) get
/// g dt = 0.001 per step, 0.127 of an 8-bit quantum (round-to-nearest would
/// leave them at rest forever); and, in a 16-bit world, a per-cell force of
/// 2e-5 on particles of mass 2, a = 1e-5, 0.33 of a quantum per step.
/// Expected after T steps: the mean stored velocity is a T dt (each step's
/// rounding is unbiased given the past, so the expectation adds up),
/// within 5 standard errors from the sample variance across particles.
#[test]
fn sub_quantum_accelerations_act_on_average() {
    const PARTICLES: u32 = 400;
    const STEPS: u64 = 300;
    for q in [Quantization::Bits8, Quantization::Bits16] {
        let mut desc = Description::new_2d(64, 4 * PARTICLES);
        desc.quantization = q;
        desc.seed = 92;
        let accel = if q == Quantization::Bits8 {
            desc.forces.uniform = true;
            desc.gravity = [0.001, 0.0, 0.0];
            0.001
        } else {
            desc.forces.field = true;
            desc.per_particle_mass = true;
            desc.mass_classes = 1;
            desc.mass = 2.0;
            1e-5
        };
        let mut mem = memory(&desc);
        let world = World::init(&desc, &mut mem).unwrap();
        if q == Quantization::Bits16 {
            let cells = (64 * 4 * PARTICLES) as usize;
            let field: Vec<f32> = (0..2 * cells).map(|i| if i % 2 == 0 { 2e-5 } else { 0.0 }).collect();
            world.set_force_field(&field).unwrap();
        }
        for i in 0..PARTICLES {
            world.add_particle([(5 * i) % 64, 4 * i, 0], [0.0; 3]).unwrap();
        }
        world.step(STEPS);
        assert_eq!(world.stats().collisions, 0);
        let v: Vec<f64> = world.particles().map(|p| f64::from(p.velocity[0])).collect();
        assert_eq!(v.len(), PARTICLES as usize);
        let (mean, se) = mean_and_se(&v);
        let want = accel * STEPS as f64;
        assert!((mean - want).abs() <= Z * se, "{q:?}: mean v {mean}, expected {want} +- {}", Z * se);
        // The band excludes 0, the mean round-to-nearest would give.
        assert!(want > Z * se, "{q:?}: the band reaches 0");
    }
}
