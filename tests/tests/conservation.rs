//! Conservation in a closed periodic box without forces (M10): momentum,
//! kinetic energy with e = 1, and the energy the clamp (M5.5) removes.
//!
//! Everything is measured exactly, in quanta: a stored velocity component is
//! an integer X (v = X / SCALE, M1), so the momentum sum_i X_i and the
//! energy sum_i |X_i|^2 are exact integers. The only sources of change are:
//! - stochastic rounding (M1): a component computed as x (in quanta) is
//!   stored as X = x + eps with E[eps] = 0 and Var[eps] = f(1 - f) <= 1/4,
//!   f the fractional part of x; the rounding stream is the block's (M8),
//!   so the eps are independent across roundings;
//! - f32 arithmetic inside the block, bounded below;
//! - the clamp, whose removed energy the world reports.
//!
//! Without forces and obstacles a velocity changes only in a collision
//! (M5.2); an untouched velocity is an integer in quanta and is stored back
//! exactly. So each collision rounds at most 2 components per axis, 2 * dim
//! in all, and the bands below follow from counting collisions.

mod common;

use common::{memory, quanta, scale, Z};
use mpca::{Description, Quantization, World};

/// 2^-24, the unit roundoff of f32.
const U: f64 = 1.0 / 16_777_216.0;

/// The exact sums of one moment, in quanta. Masses are dyadic (0.5, 1, 2),
/// so m X and m X^2 are exact in f64, and so are their sums here.
#[derive(Clone, Debug, Default)]
struct Snap {
    /// sum m X per axis.
    momentum: [f64; 3],
    /// sum m |X|^2 over particles.
    energy: f64,
    /// Largest m |X|^2 of any particle.
    max_energy: f64,
    /// m^2 (2|X| + 3)^2 of every component, largest first.
    spread: Vec<f64>,
    /// Every particle's mass, sorted.
    masses: Vec<f32>,
}

fn snap(world: &World, q: Quantization, dim: usize) -> Snap {
    let mut s = Snap::default();
    for p in world.particles() {
        let m = f64::from(p.mass);
        let mut speed2 = 0.0;
        for k in 0..dim {
            let x = quanta(p.velocity[k], q) as f64;
            s.momentum[k] += m * x;
            speed2 += x * x;
            s.spread.push(m * m * (2.0 * x.abs() + 3.0).powi(2));
        }
        s.energy += m * speed2;
        s.max_energy = s.max_energy.max(m * speed2);
        s.masses.push(p.mass);
    }
    s.spread.sort_by(|a, b| b.total_cmp(a));
    s.masses.sort_by(|a, b| a.total_cmp(b));
    s
}

/// The f32 spacing at SCALE: the largest rounding step of a value in
/// [-SCALE, SCALE] is at most this.
fn ulp_at_scale(q: Quantization) -> f64 {
    let s = scale(q) as f32;
    f64::from(f32::from_bits(s.to_bits() + 1) - s)
}

/// A closed periodic box: `count` particles at distinct random cells of an
/// `n^dim` world, no forces, e = 1, velocities uniform in the disc or ball
/// of radius `max_speed`, masses drawn from `masses` (one mass: no
/// per-particle masses), run for `steps` steps.
struct Scene {
    dim: u32,
    q: Quantization,
    n: u32,
    count: usize,
    max_speed: f32,
    steps: u64,
    seed: u64,
    masses: &'static [f32],
}

/// What a run of a closed box measured, and the bands it implies.
#[derive(Debug)]
struct Outcome {
    start: Snap,
    end: Snap,
    collisions: u64,
    clamps: u64,
    /// Clamped energy in sum m |X|^2 units: 2 SCALE^2 times clamp_energy.
    clamped: f64,
    clamp_energy: f64,
    /// Per axis variance bound and deterministic slack of the momentum sum.
    momentum_var: f64,
    momentum_slack: f64,
    /// Bounds on the energy sum's rounding mean, variance and f32 slack.
    energy_bias: f64,
    energy_var: f64,
    energy_slack: f64,
}

/// Runs a closed box, accumulating the bands step by step.
fn closed_box(sc: &Scene) -> Outcome {
    let (dim, q, n) = (sc.dim, sc.q, sc.n);
    let mut desc = if dim == 2 { Description::new_2d(n, n) } else { Description::new_3d(n, n, n) };
    desc.quantization = q;
    desc.restitution = 1.0;
    desc.seed = sc.seed;
    desc.mass = sc.masses[0];
    desc.per_particle_mass = sc.masses.len() > 1;
    desc.mass_classes = sc.masses.len() as u16;
    let mut mem = memory(&desc);
    let world = World::init(&desc, &mut mem).unwrap();
    let mut rng = common::test_rng(sc.seed);
    let nz = if dim == 3 { n } else { 1 };
    let mut placed = 0;
    while placed < sc.count {
        let pos = [rng.below(n), rng.below(n), rng.below(nz)];
        let m = sc.masses[rng.below(sc.masses.len() as u32) as usize];
        if world.add_particle_with_mass(pos, rng.velocity(dim, sc.max_speed), m).is_ok() {
            placed += 1;
        }
    }
    let d = dim as usize;
    let s2 = scale(q) * scale(q);
    let m_max = f64::from(sc.masses.iter().fold(0.0f32, |a, &b| a.max(b)));
    let equal = sc.masses.len() == 1;
    let start = snap(world, q, d);
    let mut before = start.clone();
    let mut out = Outcome {
        start: start.clone(),
        end: start,
        collisions: 0,
        clamps: 0,
        clamped: 0.0,
        clamp_energy: 0.0,
        momentum_var: 0.0,
        momentum_slack: 0.0,
        energy_bias: 0.0,
        energy_var: 0.0,
        energy_slack: 0.0,
    };
    for _ in 0..sc.steps {
        let last = world.stats();
        world.step(1);
        let now = world.stats();
        let after = snap(world, q, d);
        let c = (now.collisions - last.collisions) as f64;
        let k = (now.clamps - last.clamps) as f64;
        // Momentum, per axis: at most 2 roundings per collision, each
        // adding m eps, of variance <= m^2/4. Deterministic part, equal
        // masses: eqs. 7-8 compute V0 exactly (half-integers) and the same
        // t = e sb |rel| R_k for both particles, so a + b = 2 V0 up to the
        // two roundings of V0 +- t, together at most one f32 spacing at
        // SCALE. Unequal masses: the shares ma/(ma+mb), mb/(ma+mb), V0, t
        // and V0 +- t each carry an f32 rounding (2^-24 relative) of a value
        // at most 2 SCALE in quanta: at most 16 2^-24 SCALE (ma + mb) in all.
        // And the draw of `chance` is 24-bit, biasing each rounding by at
        // most 2^-24.
        out.momentum_var += 2.0 * c * m_max * m_max / 4.0;
        let arithmetic = if equal { m_max * ulp_at_scale(q) } else { 32.0 * U * scale(q) * m_max };
        out.momentum_slack += c * (arithmetic + 2.0 * U * m_max);
        // Energy: a rounding changes m x^2 by m (2 x eps + eps^2), of mean
        // m f(1 - f) in [0, m/4] and variance <= m^2 E[eps^2] (2|x| + 1)^2
        // <= m^2 (2|x| + 1)^2 / 4. The stored X is floor(x) or ceil(x), so
        // |x| <= |X| + 1 for the component's value X after the step. A
        // step rounds each component at most once, and at most 2 dim c of
        // them, so its variance is at most the sum of the 2 dim c largest
        // m^2 (2|X| + 3)^2 / 4 over the components after the step.
        let roundings = 2 * d * (now.collisions - last.collisions) as usize;
        out.energy_bias += roundings as f64 * m_max / 4.0;
        out.energy_var += after.spread.iter().take(roundings).sum::<f64>() / 4.0;
        // f32 slack: a collision's outputs carry a handful of f32 roundings
        // (|rel| by a dot product and a square root, R by sincos, the mass
        // shares, V0 +- t), together at most 16 2^-24 of the pair's energy
        // (32 with unequal masses), itself at most twice the largest
        // particle energy before or after the step. A clamp rescales through
        // 1/SCALE, a dot product, a square root and back, and reports
        // m (|u|^2 - 1)/2 from the same dot product: at most
        // 32 2^-24 m SCALE^2 (|u|^2 <= 4 after a collision).
        let pair = 2.0 * before.max_energy.max(after.max_energy);
        let share = if equal { 16.0 } else { 32.0 };
        out.energy_slack += c * share * U * pair + k * 32.0 * U * m_max * s2;
        before = after;
    }
    let s = world.stats();
    out.end = before;
    out.collisions = s.collisions;
    out.clamps = s.clamps;
    out.clamp_energy = s.clamp_energy;
    out.clamped = 2.0 * s.clamp_energy * s2;

    // The reported momentum and energy are f64 sums of f32 velocities, each
    // within 2 * 2^-24 (relative) of X / SCALE: they match the exact sums.
    let count = s.particles as f64;
    for k in 0..3 {
        let exact = out.end.momentum[k] / scale(q);
        assert!(
            (s.momentum[k] - exact).abs() <= count * m_max * 2.0 * U,
            "reported momentum {k}: {} vs {exact}",
            s.momentum[k]
        );
    }
    let exact = 0.5 * out.end.energy / s2;
    assert!((s.kinetic_energy - exact).abs() <= count * m_max * f64::from(dim) * 4.0 * U, "reported energy");
    assert_eq!(s.particles, count as u64);
    out
}

/// Slow particles (|v| <= 0.3), so no speed ever nears 1 and no clamp
/// fires: one mass, 2D and 3D, 8 and 16 bits.
fn slow_boxes() -> Vec<(String, Outcome)> {
    let mut v = vec![];
    for q in [Quantization::Bits8, Quantization::Bits16] {
        let two = Scene { dim: 2, q, n: 64, count: 1000, max_speed: 0.3, steps: 300, seed: 21, masses: &[1.0] };
        v.push((format!("2D {q:?}"), closed_box(&two)));
        let three = Scene { dim: 3, n: 24, count: 2000, steps: 200, seed: 22, ..two };
        v.push((format!("3D {q:?}"), closed_box(&three)));
    }
    v
}

/// As `slow_boxes`, with per-particle masses 0.5, 1 and 2 (M9), which
/// exercise the mass shares of eqs. 7-8.
///
/// Speeds start below 0.15, not 0.3: collisions share the energy out
/// evenly (equipartition), so the light particles end up faster than the
/// rest, and at 0.3 a particle of mass 0.5 has mean square speed about
/// 0.105 and exceeds 1 (a clamp) with probability about e^(-1/0.105) ~ 7e-5
/// per collision it leaves: a couple of clamps in 20,000 collisions, which
/// the no-clamp bands below cannot allow for. At 0.15 the mean square speed
/// is a quarter of that and the chance about e^-38 per collision.
fn mixed_boxes() -> Vec<(String, Outcome)> {
    let mut v = vec![];
    for q in [Quantization::Bits8, Quantization::Bits16] {
        let masses: &[f32] = &[1.0, 0.5, 2.0];
        let two = Scene { dim: 2, q, n: 64, count: 1000, max_speed: 0.15, steps: 300, seed: 23, masses };
        v.push((format!("2D {q:?} mixed masses"), closed_box(&two)));
        let three = Scene { dim: 3, n: 24, count: 2000, steps: 200, seed: 24, ..two };
        v.push((format!("3D {q:?} mixed masses"), closed_box(&three)));
    }
    v
}

/// M10 momentum: in a closed periodic box without forces, e = 1, the total
/// momentum changes only by rounding noise. Expected per axis, in quanta:
/// |P_end - P_start| <= 5 sqrt(sum 2 c m^2/4) + sum c (f32 slack + 2^-23 m),
/// c the collisions of each step (derivation in `closed_box`); no clamp
/// (deterministic under the fixed seeds) and enough collisions to matter.
/// With one mass and with masses 0.5, 1 and 2.
#[test]
fn momentum_is_conserved_in_a_closed_box() {
    for (name, o) in slow_boxes().into_iter().chain(mixed_boxes()) {
        assert_eq!(o.clamps, 0, "{name}: a clamp fired ({} clamps, {} collisions)", o.clamps, o.collisions);
        assert_eq!(o.clamp_energy, 0.0, "{name}: clamped energy without a clamp");
        assert!(o.collisions > 5000, "{name}: only {} collisions", o.collisions);
        let band = Z * o.momentum_var.sqrt() + o.momentum_slack;
        for k in 0..3 {
            let drift = o.end.momentum[k] - o.start.momentum[k];
            assert!(drift.abs() <= band, "{name} axis {k}: momentum moved {drift} quanta, band {band:.2}");
        }
    }
}

/// M5.6: velocities and masses travel with their particles unchanged.
/// Expected: in the mixed-mass boxes the multiset of masses after the run is
/// the one before.
#[test]
fn masses_travel_with_their_particles() {
    for (name, o) in mixed_boxes() {
        assert_eq!(o.start.masses, o.end.masses, "{name}");
        assert!(o.start.masses.contains(&0.5) && o.start.masses.contains(&2.0));
    }
}

/// M10 kinetic energy with e = 1: eqs. 7-8 keep the energy of a pair, so
/// sum m |X|^2 changes only by rounding: a mean in [0, m roundings/4] and a
/// variance bounded in `closed_box`. Expected:
/// -5 sd - slack <= E_end - E_start <= m roundings/4 + 5 sd + slack, in
/// m quanta^2. Relative to the energy, the 16-bit band is about 2^8 times
/// tighter than the 8-bit one (the noise is linear in |x|, the energy
/// quadratic).
#[test]
fn kinetic_energy_is_conserved_with_e_1() {
    for (name, o) in slow_boxes().into_iter().chain(mixed_boxes()) {
        assert_eq!(o.clamps, 0, "{name}: a clamp fired ({} clamps, {} collisions)", o.clamps, o.collisions);
        let change = o.end.energy - o.start.energy;
        let sd = o.energy_var.sqrt();
        let (lo, hi) = (-Z * sd - o.energy_slack, o.energy_bias + Z * sd + o.energy_slack);
        assert!(
            (lo..=hi).contains(&change),
            "{name}: energy moved {change} quanta^2 of {}, band [{lo:.0}, {hi:.0}]",
            o.start.energy
        );
    }
}

/// M5.5 / M10: fast particles (|v| up to 1) collide into speeds above 1,
/// which the clamp scales back, counting the clamps and the energy removed.
/// Expected: clamps fire (deterministic under the seed), clamp_energy > 0
/// exactly when clamps > 0 (and both 0 in the slow boxes), and the energy
/// balance E_end + clamped = E_start holds within the rounding band, so in
/// particular E_end <= E_start + band: a clamp never adds energy.
#[test]
fn clamps_remove_exactly_the_reported_energy() {
    for (name, o) in slow_boxes() {
        assert_eq!((o.clamps, o.clamp_energy), (0, 0.0), "{name}");
    }
    for q in [Quantization::Bits8, Quantization::Bits16] {
        for dim in [2u32, 3] {
            let (n, count) = if dim == 2 { (64, 1200) } else { (24, 2000) };
            let sc = Scene { dim, q, n, count, max_speed: 1.0, steps: 100, seed: 30 + u64::from(dim), masses: &[1.0] };
            let o = closed_box(&sc);
            let name = format!("{dim}D {q:?} fast");
            assert!(o.clamps > 0, "{name}: no clamp fired");
            assert!(o.clamp_energy > 0.0, "{name}: {} clamps but no clamped energy", o.clamps);
            let change = o.end.energy - o.start.energy;
            let sd = o.energy_var.sqrt();
            let (lo, hi) = (-Z * sd - o.energy_slack, o.energy_bias + Z * sd + o.energy_slack);
            assert!(change <= hi, "{name}: energy grew by {change} quanta^2, band {hi:.0}");
            let balance = change + o.clamped;
            assert!(
                (lo..=hi).contains(&balance),
                "{name}: E_end - E_start + clamped = {balance:.0} quanta^2 (clamped {:.0}), band [{lo:.0}, {hi:.0}]",
                o.clamped
            );
        }
    }
}

/// M1 says |v| <= 1, and the clamp (M5.5) restores it before storage; but
/// storage rounds each component (to nearest for a velocity a caller sets,
/// stochastically in a step), which can carry a unit vector a fraction of a
/// quantum past 1: (0.6, 0.8) is stored as (76, 102)/127, |v| = 1.0016.
/// Expected: every stored speed is within one quantum per axis of 1, i.e.
/// |X| <= SCALE + sqrt(dim) in quanta, before and after steps full of clamps.
#[test]
fn stored_speeds_stay_within_a_quantum_of_one() {
    for q in [Quantization::Bits8, Quantization::Bits16] {
        let mut desc = Description::new_2d(16, 16);
        desc.quantization = q;
        let mut mem = memory(&desc);
        let world = World::init(&desc, &mut mem).unwrap();
        world.add_particle([0, 0, 0], [0.6, 0.8, 0.0]).unwrap();
        let p = common::particle(world, [0, 0, 0]);
        let speed = (f64::from(p.velocity[0]).powi(2) + f64::from(p.velocity[1]).powi(2)).sqrt();
        assert!(speed <= 1.0 + 2f64.sqrt() / scale(q), "{q:?}: stored speed {speed}");
    }
    for dim in [2u32, 3] {
        let q = Quantization::Bits8;
        let n = if dim == 2 { 64 } else { 24 };
        let mut desc = if dim == 2 { Description::new_2d(n, n) } else { Description::new_3d(n, n, n) };
        desc.seed = 33;
        let mut mem = memory(&desc);
        let world = World::init(&desc, &mut mem).unwrap();
        let mut rng = common::test_rng(33);
        for pos in common::cells(&desc) {
            if rng.unit() < 0.4 {
                world.add_particle(pos, rng.velocity(dim, 1.0)).unwrap();
            }
        }
        let limit = scale(q) + f64::from(dim).sqrt();
        for _ in 0..50 {
            world.step(1);
            let s = snap(world, q, dim as usize);
            assert!(s.max_energy.sqrt() <= limit, "{dim}D: stored speed {} quanta", s.max_energy.sqrt());
        }
        assert!(world.stats().clamps > 0);
    }
}
