//! What the stability tests (tests/tests/stability_*.rs, issue #5) share:
//! two checks, and a world with every part on (`busy_desc`).
//!
//! Every case states what it expects. Two checks recur:
//! - `check_sane`: the particle count is exact; every stored velocity
//!   component lies in [-1, 1] and the stored speed is at most
//!   `1 + sqrt(dim)/SCALE` (the documented rounding excess, README "Speed
//!   limit"), checked exactly in quanta; masses are finite and positive;
//!   the statistics' momentum, kinetic energy and clamped energy are finite.
//! - `Book`: the momentum change over steps in which no clamp fired (a clamp
//!   scales a velocity and so changes momentum; M5.5), against the band that
//!   rounding allows (derived in tests/tests/conservation.rs): per collision
//!   and axis two roundings, each adding `m eps` with `Var[eps] <= 1/4`, and
//!   the f32 arithmetic of eqs. 7-8 and the 24-bit draw as a deterministic
//!   slack; the band is 5 standard deviations plus the slack.
#![allow(dead_code)]

use crate::common::{cells, quanta, scale, TestRng, Z};
use mpca::{Boundary, Description, Emitter, Quantization, Stats, Vortex, World};

/// 2^-24, the unit roundoff of f32.
pub const U: f64 = 1.0 / 16_777_216.0;

pub const QUANTS: [Quantization; 2] = [Quantization::Bits8, Quantization::Bits16];

pub fn cube(dim: u32, n: u32) -> Description {
    if dim == 2 { Description::new_2d(n, n) } else { Description::new_3d(n, n, n) }
}

pub fn stored(v: [f32; 3], q: Quantization) -> [i64; 3] {
    v.map(|c| quanta(c, q))
}

/// The checks every world must pass after every step (module doc).
pub fn check_sane(world: &World, expected: u64, what: &str) {
    let d = world.description();
    let (dim, q) = (d.dim as usize, d.quantization);
    let s = scale(q);
    let limit = s + (dim as f64).sqrt();
    let mut n = 0u64;
    for p in world.particles() {
        n += 1;
        for (k, c) in p.velocity.iter().enumerate() {
            assert!(c.is_finite() && (-1.0..=1.0).contains(c), "{what}: component {k} = {c} at {:?}", p.pos);
        }
        if dim == 2 {
            assert_eq!(p.velocity[2], 0.0, "{what}: 2D velocity with a z component");
        }
        let x = stored(p.velocity, q);
        let speed = ((x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) as f64).sqrt();
        assert!(speed <= limit, "{what}: stored speed {speed} quanta > {limit} at {:?}", p.pos);
        assert!(p.mass.is_finite() && p.mass > 0.0, "{what}: mass {}", p.mass);
    }
    assert_eq!(n, expected, "{what}: particles found");
    assert_eq!(world.particle_count(), expected, "{what}: particle count");
    let st = world.stats();
    assert_eq!(st.particles, expected, "{what}: stats particles");
    assert!(st.momentum.iter().all(|c| c.is_finite()), "{what}: momentum {:?}", st.momentum);
    assert!(st.kinetic_energy.is_finite(), "{what}: energy {}", st.kinetic_energy);
    assert!(st.clamp_energy.is_finite() && st.clamp_energy >= 0.0, "{what}: clamped energy {}", st.clamp_energy);
}

/// Places particles on about `density` of the free cells with velocities
/// uniform in the ball of radius `speed`, masses drawn from `masses` (the
/// world must accept them); returns how many.
pub fn scatter(world: &mut World, density: f32, speed: f32, masses: &[f32], rng: &mut TestRng) -> u64 {
    let desc = *world.description();
    let mut n = 0;
    for pos in cells(&desc) {
        if rng.unit() < density {
            let m = masses[rng.below(masses.len() as u32) as usize];
            if world.add_particle_with_mass(pos, rng.velocity(desc.dim, speed), m).is_ok() {
                n += 1;
            }
        }
    }
    n
}

// ------------------------------------------------------------- momentum book

/// Exact sums of one moment, in quanta.
pub struct Snap {
    momentum: [f64; 3],
}

pub fn snap(world: &World) -> Snap {
    let q = world.description().quantization;
    let mut momentum = [0.0; 3];
    for p in world.particles() {
        let x = stored(p.velocity, q);
        for k in 0..3 {
            momentum[k] += f64::from(p.mass) * x[k] as f64;
        }
    }
    Snap { momentum }
}

/// The momentum change over clamp-free steps and its band (module doc).
pub struct Book {
    pub m_max: f64,
    pub s: f64,
    pub prev: Snap,
    pub prev_stats: Stats,
    pub drift: [f64; 3],
    pub var: f64,
    pub slack: f64,
    pub collisions: u64,
}

impl Book {
    pub fn new(world: &World, m_max: f64) -> Book {
        let s = scale(world.description().quantization);
        Book { m_max, s, prev: snap(world), prev_stats: world.stats(), drift: [0.0; 3], var: 0.0, slack: 0.0, collisions: 0 }
    }

    /// Call after every step.
    pub fn step(&mut self, world: &World) {
        let now = snap(world);
        let st = world.stats();
        let c = st.collisions - self.prev_stats.collisions;
        if st.clamps == self.prev_stats.clamps {
            for k in 0..3 {
                self.drift[k] += now.momentum[k] - self.prev.momentum[k];
            }
            let c = c as f64;
            self.var += c * 2.0 * self.m_max * self.m_max / 4.0;
            // Unequal masses: ~16 f32 roundings of values up to 2 SCALE in
            // quanta, over (ma + mb) <= 2 m_max; the 24-bit draw biases
            // each of the two roundings by at most 2^-24.
            self.slack += c * (32.0 * U * self.s * self.m_max + 2.0 * U * self.m_max);
            self.collisions += st.collisions - self.prev_stats.collisions;
        }
        self.prev = now;
        self.prev_stats = st;
    }

    pub fn check(&self, what: &str) {
        let band = Z * self.var.sqrt() + self.slack;
        for k in 0..3 {
            assert!(
                self.drift[k].abs() <= band,
                "{what}: momentum moved {} quanta along axis {k} in clamp-free steps, band {band}",
                self.drift[k]
            );
        }
    }
}

// ------------------------------------------------------------- a busy world

/// A description with every part on.
pub fn busy_desc(dim: u32) -> Description {
    let mut desc = cube(dim, 8).with_boundary(Boundary::Wall);
    desc.per_particle_mass = true;
    desc.mass_classes = 4;
    desc.obstacles = true;
    desc.surface_capacity = 512;
    desc.forces = mpca::Forces { uniform: true, field: true, potential: true, vortex: true };
    desc.gravity = [0.0, -0.01, 0.0];
    desc.vortex = Vortex { centre: [4.0, 4.0], core_radius: 1.0, circulation: 0.5 };
    desc.lifetimes = true;
    desc.emitter_capacity = 8;
    desc.seed = 12;
    desc
}

/// Fills a `busy_desc` world: particles of two masses, an obstacle, an
/// emitter; a few steps taken.
pub fn make_busy(w: &mut World) {
    w.add_particle([1, 1, 0], [0.3, 0.1, 0.0]).unwrap();
    w.add_particle_with_mass([2, 5, 0], [-0.2, 0.1, 0.0], 2.0).unwrap();
    w.add_obstacle([6, 1, 0], [0.0, 1.0, 0.0], 1.0).unwrap();
    let e = Emitter { min: [0, 6, 0], max: [2, 8, 1], rate: 0.5, velocity: [0.1, 0.0, 0.0], mass: 1.0, lifetime: 30, ..Emitter::default() };
    w.add_emitter(e).unwrap();
    w.step(5);
}
