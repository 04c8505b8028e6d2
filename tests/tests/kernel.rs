//! The step has two block routines: a lean one for blocks of plain worlds
//! (no obstacles, one mass, no lifetimes, at most a uniform force) away
//! from the faces, and one that handles every part. Both draw the same
//! numbers in the same order (M8), so a world stepped with every block
//! through the general routine (`World::step_reference`) must be the same
//! world, bit for bit, as one stepped normally: this test holds the lean
//! routine to the general one, step by step, on every plain setting.

mod common;

use mpca::{Boundary, Description, Drift, Method, Quantization, World};

/// A plain world: a gas at density `density` with speeds up to `speed`.
fn gas<'a>(desc: &Description, density: f32, speed: f32, seed: u64, memory: &'a mut Vec<u8>) -> &'a mut World {
    memory.clear();
    memory.resize(mpca::world_bytes(desc).unwrap(), 0);
    let world = World::init(desc, memory).unwrap();
    let mut rng = common::test_rng(seed);
    for pos in common::cells(desc).collect::<Vec<_>>() {
        if rng.unit() < density {
            world.add_particle(pos, rng.velocity(desc.dim, speed)).unwrap();
        }
    }
    world
}

/// Every plain setting: 2D and 3D; periodic, walled and open faces (whose
/// half blocks take the general routine in both runs); no force and
/// gravity; both widths, both drift rules, all three methods.
fn settings() -> Vec<Description> {
    let mut out = vec![];
    for dim in [2u32, 3] {
        for (i, faces) in [Boundary::Periodic, Boundary::Wall, Boundary::Open].into_iter().enumerate() {
            for variant in 0..4usize {
                let mut d = if dim == 2 { Description::new_2d(48, 40) } else { Description::new_3d(12, 10, 14) };
                d = d.with_boundary(faces);
                d.quantization = [Quantization::Bits8, Quantization::Bits16][variant % 2];
                d.drift = [Drift::Paper, Drift::Calibrated][variant / 2];
                d.method = [Method::ExactFast, Method::Greedy, Method::Exhaustive][(variant + i) % 3];
                d.restitution = [1.0, 0.6, 0.0][i];
                if variant % 2 == 1 {
                    d.forces.uniform = true;
                    d.gravity = [0.004, -0.03, 0.01];
                }
                d.seed = 900 + 10 * u64::from(dim) + (4 * i + variant) as u64;
                out.push(d);
            }
        }
    }
    out
}

#[test]
fn lean_routine_equals_the_general_one_bit_for_bit() {
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for (n, desc) in settings().iter().enumerate() {
        let what = format!("setting {n}: {}D {:?} {:?} {:?} {:?}", desc.dim, desc.boundary[0][0], desc.quantization, desc.drift, desc.method);
        let lean = gas(desc, 0.35, 0.9, n as u64, &mut a);
        let general = gas(desc, 0.35, 0.9, n as u64, &mut b);
        assert_eq!(lean.state_hash(), general.state_hash());
        for step in 0..40 {
            lean.step(1);
            general.step_reference();
            assert_eq!(lean.state_hash(), general.state_hash(), "{what}: worlds differ after step {step}");
            assert_eq!(lean.stats(), general.stats(), "{what}: stats differ after step {step}");
        }
        assert!(lean.stats().collisions > 100, "{what}: too few collisions to compare");
    }
}
