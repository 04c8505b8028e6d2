//! Conservation (M10) in a closed periodic box without forces, e = 1:
//! momentum drift per step, kinetic energy drift, and the clamps (M5.5)
//! with the energy they remove.
//!
//! Two regimes: "slow" (speeds start uniform in the ball of radius 0.3, so
//! a speed past 1, which needs a collision to hand one particle nearly all
//! of a pair's energy several times over, is practically never reached: no
//! clamp fires and only rounding moves the sums) and "fast" (radius 1:
//! collisions overshoot and the clamp removes energy and changes momentum).
//!
//! What rounding alone predicts (tests/tests/conservation.rs derives the
//! bounds): without forces a velocity changes only in a collision, which
//! rounds 2 components per axis; each rounding adds `eps` (in quanta) with
//! mean 0 and variance `f(1-f)`, `f` the fractional part, which is 1/6 on
//! average for a fraction uniform in [0, 1) (a collision's random direction
//! makes it so). After `c` collisions, then, with `S` = SCALE:
//! - momentum, per axis: mean 0, standard deviation `sqrt(2c/6) m / S`;
//! - energy `m |v|^2 / 2`: a rounding adds `m (2 x eps + eps^2) / (2 S^2)`
//!   (`x` the component in quanta), of mean `m / (12 S^2)`, so `2 dim c`
//!   roundings add `2 dim c m / (12 S^2)` on average (the bias), with
//!   variance `m^2 x^2 / (6 S^4)` each; a component's mean square is
//!   `2 T / (m dim)` in speed (`T` the kinetic energy per particle), so the
//!   standard deviation is `sqrt(2 c m T / 3) / S`.

use mpca::{Method, Quantization, World};

use super::{cube, memory, repeat, scale, scatter, SetupRng, Timing};

/// Size of the run.
#[derive(Clone, Copy, Debug)]
pub struct BoxConfig {
    /// Steps.
    pub steps: u64,
    /// Timed runs.
    pub runs: usize,
}

/// One closed box.
#[derive(Clone, Debug)]
pub struct BoxResult {
    /// 2 or 3.
    pub dim: u32,
    /// Storage.
    pub quant: Quantization,
    /// Assignment.
    pub method: Method,
    /// "slow" or "fast".
    pub regime: &'static str,
    /// Particles.
    pub particles: u64,
    /// Steps.
    pub steps: u64,
    /// Collisions in all.
    pub collisions: u64,
    /// Momentum at the end minus at the start, per axis.
    pub momentum_change: [f64; 3],
    /// What rounding predicts for the standard deviation of each axis's
    /// change: `sqrt(c/3) m / SCALE`.
    pub momentum_sigma: f64,
    /// Kinetic energy at the start.
    pub energy_start: f64,
    /// Kinetic energy at the end.
    pub energy_end: f64,
    /// Mean energy gain rounding predicts: `2 dim c m / (12 SCALE^2)`.
    pub energy_rounding_gain: f64,
    /// Its standard deviation: `sqrt(2 c m T / 3) / SCALE`.
    pub energy_sigma: f64,
    /// Clamps (M5.5).
    pub clamps: u64,
    /// Energy they removed.
    pub clamp_energy: f64,
    /// Step times.
    pub timing: Timing,
    /// Bytes per cell.
    pub bytes_per_cell: f64,
}

impl BoxResult {
    /// `|Delta P| / steps`.
    pub fn momentum_drift_per_step(&self) -> f64 {
        let p = self.momentum_change;
        (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() / self.steps as f64
    }

    /// Largest `|Delta P_k| / sigma` over the axes: about 1 (below 3 or so
    /// for 3 axes) when the drift is rounding noise. Clamps change momentum
    /// too, so this is `None` when one fired.
    pub fn momentum_z(&self) -> Option<f64> {
        (self.clamps == 0).then(|| self.momentum_change.iter().map(|c| c.abs() / self.momentum_sigma).fold(0.0, f64::max))
    }

    /// `(E_end + clamped - E_start - bias) / sigma`: the energy change that
    /// rounding does not explain, in its standard deviations.
    pub fn energy_z(&self) -> f64 {
        (self.energy_end + self.clamp_energy - self.energy_start - self.energy_rounding_gain) / self.energy_sigma
    }

    /// `(E_end - E_start) / E_start / steps`.
    pub fn energy_drift_per_step(&self) -> f64 {
        (self.energy_end - self.energy_start) / self.energy_start / self.steps as f64
    }

    /// The standard deviation of [`BoxResult::energy_drift_per_step`] that
    /// rounding noise alone gives: a drift below it is not measured.
    pub fn energy_noise_per_step(&self) -> f64 {
        self.energy_sigma / self.energy_start / self.steps as f64
    }

    /// `(E_end + clamped - E_start) / E_start / steps`: the drift with the
    /// clamps' removal put back, which rounding alone explains.
    pub fn energy_drift_without_clamps(&self) -> f64 {
        (self.energy_end + self.clamp_energy - self.energy_start) / self.energy_start / self.steps as f64
    }

    /// What rounding predicts for `energy_drift_without_clamps`.
    pub fn predicted_energy_drift(&self) -> f64 {
        self.energy_rounding_gain / self.energy_start / self.steps as f64
    }

    /// Clamps per particle-step.
    pub fn clamps_per_particle_step(&self) -> f64 {
        self.clamps as f64 / (self.particles * self.steps) as f64
    }

    /// Clamped energy per step relative to the starting energy.
    pub fn clamp_energy_per_step(&self) -> f64 {
        self.clamp_energy / self.energy_start / self.steps as f64
    }

    /// Median step time in milliseconds.
    pub fn ms_per_step(&self) -> f64 {
        self.timing.median() * 1e3 / self.steps as f64
    }
}

/// Runs one box: 2D 64 x 64 with 1000 particles, or 3D 24^3 with 2000.
pub fn measure(dim: u32, quant: Quantization, method: Method, regime: &'static str, cfg: BoxConfig) -> BoxResult {
    let (n, count) = if dim == 2 { (64, 1000) } else { (24, 2000) };
    let max_speed = if regime == "slow" { 0.3 } else { 1.0 };
    let mut desc = cube(dim, n);
    desc.quantization = quant;
    desc.method = method;
    desc.restitution = 1.0;
    desc.seed = 70 + u64::from(dim);
    let mut mem = memory(&desc);
    let (out, timing) = repeat(cfg.runs, || {
        let world: &mut World = World::init(&desc, &mut mem).expect("fits");
        let mut rng = SetupRng::new(desc.seed);
        let cells = f64::from(n).powi(dim as i32);
        scatter(world, (count as f64 / cells) as f32, max_speed, &mut rng);
        let start = world.stats();
        let seconds = super::clock(|| world.step(cfg.steps));
        let end = world.stats();
        let c = end.collisions as f64;
        let m = f64::from(desc.mass);
        let s = scale(quant);
        let out = BoxResult {
            dim,
            quant,
            method,
            regime,
            particles: end.particles,
            steps: cfg.steps,
            collisions: end.collisions,
            momentum_change: [0, 1, 2].map(|k| end.momentum[k] - start.momentum[k]),
            momentum_sigma: (c / 3.0).sqrt() * m / s,
            energy_start: start.kinetic_energy,
            energy_end: end.kinetic_energy,
            energy_rounding_gain: 2.0 * f64::from(dim) * c * m / (12.0 * s * s),
            energy_sigma: (2.0 * c * m * start.kinetic_energy / start.particles as f64 / 3.0).sqrt() / s,
            clamps: end.clamps,
            clamp_energy: end.clamp_energy,
            timing: Timing::default(),
            bytes_per_cell: world.bytes_per_cell(),
        };
        assert_eq!(end.particles, start.particles, "a closed box keeps its particles");
        (out, seconds)
    });
    BoxResult { timing, ..out }
}
