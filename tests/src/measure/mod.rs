//! The measurements of docs/model.md M10: error against run time, per scene,
//! assignment method (M5.6), drift rule (M5.3) and velocity quantization
//! (M1). Each submodule measures one kind of error on purpose-built scenes
//! (or the paper's, `scenes`) and returns plain numbers; the report program
//! (`src/bin/report.rs`) turns them into tables, JSON and a plot.
//!
//! Every run is seeded, so the error figures of a setting are the same bits
//! on every run; only the run times vary, and those are the median (with the
//! spread) of several runs.

pub mod additions;
pub mod assignment;
pub mod conservation;
pub mod cooling;
pub mod drift;
pub mod plume;
pub mod scenes;
pub mod walls;

use std::time::Instant;

use mpca::{Description, Drift, Method, Quantization, World};

pub use crate::setup::{cells, SetupRng};

/// Wall-clock times of repeated runs of one setting, in seconds.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Timing {
    /// One entry per run, in run order.
    pub seconds: Vec<f64>,
}

impl Timing {
    fn sorted(&self) -> Vec<f64> {
        let mut s = self.seconds.clone();
        s.sort_by(f64::total_cmp);
        s
    }

    /// The median run (the mean of the middle two for an even count).
    pub fn median(&self) -> f64 {
        let s = self.sorted();
        match s.len() {
            0 => f64::NAN,
            n if n % 2 == 1 => s[n / 2],
            n => 0.5 * (s[n / 2 - 1] + s[n / 2]),
        }
    }

    /// The fastest run.
    pub fn min(&self) -> f64 {
        self.sorted().first().copied().unwrap_or(f64::NAN)
    }

    /// The slowest run.
    pub fn max(&self) -> f64 {
        self.sorted().last().copied().unwrap_or(f64::NAN)
    }

    /// Adds the times of `other`, run by run (both must have as many runs):
    /// the time of two parts of one setting measured separately.
    pub fn plus(&self, other: &Timing) -> Timing {
        Timing { seconds: self.seconds.iter().zip(&other.seconds).map(|(a, b)| a + b).collect() }
    }
}

/// Runs `f` `runs` times (at least once). `f` returns its result and the
/// seconds of the part that is timed (so setup and checks can stay outside
/// the clock). The first run's result is kept: every run is seeded, so they
/// all give the same one.
pub fn repeat<T>(runs: usize, mut f: impl FnMut() -> (T, f64)) -> (T, Timing) {
    let (first, s) = f();
    let mut timing = Timing { seconds: vec![s] };
    for _ in 1..runs.max(1) {
        timing.seconds.push(f().1);
    }
    (first, timing)
}

/// Seconds that `f` takes.
pub fn clock(f: impl FnOnce()) -> f64 {
    let start = Instant::now();
    f();
    start.elapsed().as_secs_f64()
}

/// Steps `world` `steps` times, calling `after` after each step outside the
/// clock; returns the seconds spent stepping.
pub fn run_steps(world: &mut World, steps: u64, mut after: impl FnMut(&World, u64)) -> f64 {
    let mut seconds = 0.0;
    for t in 0..steps {
        seconds += clock(|| world.step(1));
        after(world, t + 1);
    }
    seconds
}

/// One choice of the three switches M10 reports on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Setting {
    /// Move assignment (M5.6).
    pub method: Method,
    /// Move probability rule (M5.3).
    pub drift: Drift,
    /// Stored bits per velocity component (M1).
    pub quant: Quantization,
}

impl Setting {
    /// The description defaults: exact-fast, the paper's drift, 8 bits.
    pub const DEFAULT: Setting = Setting { method: Method::ExactFast, drift: Drift::Paper, quant: Quantization::Bits8 };

    /// Every combination, methods outermost.
    pub fn all() -> Vec<Setting> {
        let mut v = vec![];
        for method in METHODS {
            for drift in DRIFTS {
                for quant in QUANTS {
                    v.push(Setting { method, drift, quant });
                }
            }
        }
        v
    }

    /// Writes the three switches into `desc`.
    pub fn apply(self, desc: &mut Description) {
        desc.method = self.method;
        desc.drift = self.drift;
        desc.quantization = self.quant;
    }

    /// "exact-fast, paper, 8-bit".
    pub fn label(self) -> String {
        format!("{}, {}, {}", method_name(self.method), drift_name(self.drift), quant_name(self.quant))
    }
}

/// The three assignment methods, in the order the report lists them.
pub const METHODS: [Method; 3] = [Method::Exhaustive, Method::ExactFast, Method::Greedy];
/// The two drift rules.
pub const DRIFTS: [Drift; 2] = [Drift::Paper, Drift::Calibrated];
/// The two quantizations.
pub const QUANTS: [Quantization; 2] = [Quantization::Bits8, Quantization::Bits16];

/// The name the report uses for a method.
pub fn method_name(m: Method) -> &'static str {
    match m {
        Method::Exhaustive => "exhaustive",
        Method::ExactFast => "exact-fast",
        Method::Greedy => "greedy",
    }
}

/// The name the report uses for a drift rule.
pub fn drift_name(d: Drift) -> &'static str {
    match d {
        Drift::Paper => "paper",
        Drift::Calibrated => "calibrated",
    }
}

/// The name the report uses for a quantization.
pub fn quant_name(q: Quantization) -> &'static str {
    match q {
        Quantization::Bits8 => "8-bit",
        Quantization::Bits16 => "16-bit",
    }
}

/// Stored steps per unit speed (M1): 127 or 32767.
pub fn scale(q: Quantization) -> f64 {
    match q {
        Quantization::Bits8 => 127.0,
        Quantization::Bits16 => 32767.0,
    }
}

/// Zeroed memory of exactly `world_bytes(desc)` bytes.
pub fn memory(desc: &Description) -> Vec<u8> {
    vec![0u8; mpca::world_bytes(desc).expect("a valid description")]
}

/// A `dim`-dimensional cube of side `n`.
pub fn cube(dim: u32, n: u32) -> Description {
    if dim == 2 { Description::new_2d(n, n) } else { Description::new_3d(n, n, n) }
}


/// Places about `density` of the free cells of `world` with particles of
/// velocity uniform in the ball of radius `max_speed`; returns how many.
pub fn scatter(world: &mut World, density: f32, max_speed: f32, rng: &mut SetupRng) -> u64 {
    let desc = *world.description();
    let mut placed = 0;
    for pos in cells(&desc) {
        if rng.unit() < density {
            let v = rng.velocity(desc.dim, max_speed);
            if world.add_particle(pos, v).is_ok() {
                placed += 1;
            }
        }
    }
    placed
}

/// Mean and standard error of the mean (sample variance, n - 1).
pub fn mean_and_se(xs: &[f64]) -> (f64, f64) {
    let n = xs.len() as f64;
    let mean = xs.iter().sum::<f64>() / n;
    if xs.len() < 2 {
        return (mean, f64::NAN);
    }
    let var = xs.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// The probability of wanting a move along an axis of speed `v` (M5.3).
pub fn move_probability(drift: Drift, v: f64) -> f64 {
    match drift {
        Drift::Paper => v,
        Drift::Calibrated => 2.0 * v / (1.0 + v),
    }
}

/// The mean speed of a free particle along an axis where it wants a move
/// with probability `p`: `p / (2 - p)` (M5.3; derived in
/// tests/tests/statistics.rs).
pub fn free_speed(p: f64) -> f64 {
    p / (2.0 - p)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_and_spread() {
        let t = Timing { seconds: vec![3.0, 1.0, 2.0, 10.0] };
        assert_eq!((t.median(), t.min(), t.max()), (2.5, 1.0, 10.0));
        let t = Timing { seconds: vec![3.0, 1.0, 2.0] };
        assert_eq!(t.median(), 2.0);
    }

    #[test]
    fn calibrated_rule_drifts_at_the_requested_speed() {
        for v in [0.0, 0.1, 0.5, 0.9, 1.0] {
            assert!((free_speed(move_probability(Drift::Calibrated, v)) - v).abs() < 1e-12);
        }
        assert!((free_speed(move_probability(Drift::Paper, 0.5)) - 1.0 / 3.0).abs() < 1e-12);
    }
}
