//! Cooling of a granular gas with e < 1 against Haff's law (M10):
//! `T(t) = T0 / (1 + t/tau)^2`, with `T` the mean kinetic energy per
//! particle.
//!
//! Haff's law makes `1/sqrt(T)` linear in `t`: `1/sqrt(T) = a + b t` with
//! `a = 1/sqrt(T0)` and `b = a/tau`. Both are fitted by ordinary least
//! squares, so `tau = a/b`; the residual is the root mean square of
//! `T/T_fit - 1` over the fitted steps. The law describes the homogeneous
//! cooling state, before clusters form and, here, before the temperature
//! nears the velocity quantum; so the fit covers the first decade of
//! cooling, from step 0 to the first step where `T < T0/10` (the window).
//!
//! For comparison the same window is fitted by an exponential,
//! `ln T = c - t/tau_e`. M5.2 picks a pair whatever the particles' speeds,
//! so the collision frequency does not grow with `sqrt(T)` as Haff's law
//! assumes; for uncorrelated velocities each collision of equal masses
//! removes `(1 - e^2) T` on average (the relative energy `m |v_a - v_b|^2/4`
//! scaled by `1 - e^2`, with `<|v_a - v_b|^2> = 4T/m`), so the mean-field
//! cooling is exponential at the rate `(1 - e^2)` times the collisions per
//! particle-step, which the run also reports.

use mpca::{Description, World};

use super::{cube, memory, repeat, scatter, Setting, SetupRng, Timing};

/// Least squares `y = a + b x`; returns `(a, b)`.
pub fn line_fit(points: &[(f64, f64)]) -> (f64, f64) {
    let n = points.len() as f64;
    let (sx, sy) = points.iter().fold((0.0, 0.0), |(sx, sy), &(x, y)| (sx + x, sy + y));
    let (mx, my) = (sx / n, sy / n);
    let (mut sxx, mut sxy) = (0.0, 0.0);
    for &(x, y) in points {
        sxx += (x - mx) * (x - mx);
        sxy += (x - mx) * (y - my);
    }
    let b = sxy / sxx;
    (my - b * mx, b)
}

/// Haff's law fitted to a cooling curve.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HaffFit {
    /// Fitted `tau`, in steps.
    pub tau: f64,
    /// Fitted `T0`.
    pub t0: f64,
    /// RMS of `T/T_fit - 1`.
    pub residual: f64,
    /// The exponential fit's time constant, in steps.
    pub tau_exp: f64,
    /// RMS of `T/T_exp - 1` for the exponential fit.
    pub residual_exp: f64,
    /// Steps fitted (the window).
    pub points: usize,
}

/// Fits Haff's law (and an exponential) to `series[t] = T(t)`, `t` in
/// steps from 0, over the window of the first decade of cooling.
pub fn fit_haff(series: &[f64]) -> HaffFit {
    let end = window(series);
    let pts: Vec<(f64, f64)> = series[..end].iter().enumerate().map(|(i, &t)| (i as f64, t)).collect();
    let (a, b) = line_fit(&pts.iter().map(|&(x, t)| (x, 1.0 / t.sqrt())).collect::<Vec<_>>());
    let rms = |model: &dyn Fn(f64) -> f64| {
        (pts.iter().map(|&(x, t)| (t / model(x) - 1.0).powi(2)).sum::<f64>() / pts.len() as f64).sqrt()
    };
    let residual = rms(&|x| 1.0 / (a + b * x).powi(2));
    let (c, d) = line_fit(&pts.iter().map(|&(x, t)| (x, t.ln())).collect::<Vec<_>>());
    let residual_exp = rms(&|x| (c + d * x).exp());
    HaffFit { tau: a / b, t0: 1.0 / (a * a), residual, tau_exp: -1.0 / d, residual_exp, points: pts.len() }
}

/// The steps fitted: up to the first with `T < T0/10` (inclusive), or
/// every step if the gas never cools that far; only positive temperatures.
pub fn window(series: &[f64]) -> usize {
    let t0 = series[0];
    let positive = series.iter().position(|&t| t <= 0.0).unwrap_or(series.len());
    series[..positive].iter().position(|&t| t < t0 / 10.0).map_or(positive, |i| i + 1)
}

/// Size of the run.
#[derive(Clone, Copy, Debug)]
pub struct CoolingConfig {
    /// Side of the periodic box.
    pub n: u32,
    /// Steps.
    pub steps: u64,
    /// Timed runs.
    pub runs: usize,
}

/// One cooling run.
#[derive(Clone, Debug)]
pub struct CoolingResult {
    /// 2 or 3.
    pub dim: u32,
    /// The switches.
    pub setting: Setting,
    /// Restitution.
    pub restitution: f32,
    /// Particles.
    pub particles: u64,
    /// `T(t)` at every step from 0.
    pub series: Vec<f64>,
    /// The fits.
    pub fit: HaffFit,
    /// Clamps during the run.
    pub clamps: u64,
    /// Collisions per particle-step over the fit's window.
    pub collision_rate: f64,
    /// Step times.
    pub timing: Timing,
    /// Bytes per cell.
    pub bytes_per_cell: f64,
}

impl CoolingResult {
    /// `T` at the end over `T` at the start.
    pub fn cooled_to(&self) -> f64 {
        self.series[self.series.len() - 1] / self.series[0]
    }

    /// The mean-field cooling rate per step, `(1 - e^2)` times the
    /// collisions per particle-step: `1/tau_e` if velocities stayed
    /// uncorrelated.
    pub fn mean_field_rate(&self) -> f64 {
        let e = f64::from(self.restitution);
        (1.0 - e * e) * self.collision_rate
    }
}

/// The gas: density 0.3, restitution `e`, speeds uniform in the unit ball
/// scaled to 0.5, periodic box, no force.
pub fn gas(dim: u32, n: u32, setting: Setting, e: f32) -> Description {
    let mut desc = cube(dim, n);
    setting.apply(&mut desc);
    desc.restitution = e;
    desc.seed = 60 + u64::from(dim);
    desc
}

/// Runs one cooling gas of restitution `e` and fits it.
pub fn measure(dim: u32, setting: Setting, e: f32, cfg: CoolingConfig) -> CoolingResult {
    let desc = gas(dim, cfg.n, setting, e);
    let mut mem = memory(&desc);
    let ((series, collisions, particles, clamps, bytes_per_cell), timing) = repeat(cfg.runs, || {
        let world: &mut World = World::init(&desc, &mut mem).expect("fits");
        let mut rng = SetupRng::new(desc.seed);
        let particles = scatter(world, 0.3, 0.5, &mut rng);
        let mut series = vec![world.stats().kinetic_energy / particles as f64];
        let mut collisions = vec![0u64];
        let seconds = super::run_steps(world, cfg.steps, |w, _| {
            let s = w.stats();
            series.push(s.kinetic_energy / particles as f64);
            collisions.push(s.collisions);
        });
        ((series, collisions, particles, world.stats().clamps, world.bytes_per_cell()), seconds)
    });
    let fit = fit_haff(&series);
    let steps = fit.points.saturating_sub(1).max(1);
    let collision_rate = collisions[steps] as f64 / (particles as f64 * steps as f64);
    CoolingResult { dim, setting, restitution: desc.restitution, particles, series, fit, clamps, collision_rate, timing, bytes_per_cell }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn haff_fit_recovers_an_exact_law() {
        // Cools to T0/10 at t = 40 (sqrt(10) - 1) = 86.5: 88 points fitted.
        let series: Vec<f64> = (0..200).map(|t| 0.3 / (1.0 + t as f64 / 40.0).powi(2)).collect();
        let fit = fit_haff(&series);
        assert!((fit.tau - 40.0).abs() < 1e-9 && (fit.t0 - 0.3).abs() < 1e-12, "{fit:?}");
        assert!(fit.residual < 1e-12 && fit.residual_exp > 0.05 && fit.points == 88, "{fit:?}");
    }

    #[test]
    fn exponential_fit_recovers_an_exponential() {
        // Cools to T0/10 at t = 50 ln 10 = 115.1: 117 points fitted.
        let series: Vec<f64> = (0..200).map(|t| 0.3 * (-(t as f64) / 50.0).exp()).collect();
        let fit = fit_haff(&series);
        assert!((fit.tau_exp - 50.0).abs() < 1e-9 && fit.residual_exp < 1e-12 && fit.points == 117, "{fit:?}");
    }
}
