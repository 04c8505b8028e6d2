//! Drift error (M10): the measured mean velocity of free particles against
//! the requested one, under `Drift::Paper` and `Drift::Calibrated` (M5.3),
//! over a range of speeds and directions, in 2D and 3D.
//!
//! Free flight: each particle is alone in its own small periodic world
//! (8 cells per axis, its own seed), so nothing but the move rule acts on
//! it. A particle never moves against the sign of a velocity component
//! (no collision, force or wall changes it), so reading its cell every 7
//! steps unwraps the periodic axes without ambiguity.
//!
//! Along each axis the expected mean speed is `p/(2-p)` of the stored
//! component (statistics.rs derives it), which is `|v|` under the
//! calibrated rule; starting cells of both parities keep the finite-run
//! bias of that chain (under one cell over the run) small against the noise.

use mpca::{Drift, Quantization, World};

use super::{cube, free_speed, mean_and_se, memory, move_probability, repeat, Timing};

/// Requested speeds.
pub const SPEEDS: [f32; 5] = [0.1, 0.3, 0.5, 0.7, 0.9];

/// Requested directions (unit vectors): axis-aligned, diagonal and oblique,
/// with both signs.
pub fn directions(dim: u32) -> Vec<[f64; 3]> {
    let raw: Vec<[f64; 3]> = if dim == 2 {
        [0.0f64, 30.0, 45.0, 100.0, 200.0, 300.0]
            .iter()
            .map(|deg| {
                let a = deg.to_radians();
                [a.cos(), a.sin(), 0.0]
            })
            .collect()
    } else {
        vec![[1.0, 0.0, 0.0], [0.0, -1.0, 1.0], [1.0, 1.0, 1.0], [0.3, -0.5, 0.8], [-0.7, 0.2, -0.4]]
    };
    raw.into_iter()
        .map(|v| {
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            v.map(|c| c / n)
        })
        .collect()
}

/// Size of the run.
#[derive(Clone, Copy, Debug)]
pub struct DriftConfig {
    /// Particles per (speed, direction).
    pub particles: usize,
    /// Steps each particle flies.
    pub steps: u64,
    /// Timed runs.
    pub runs: usize,
}

/// One requested velocity and what was measured for it.
#[derive(Clone, Debug)]
pub struct DriftGroup {
    /// The velocity handed to `add_particle`.
    pub requested: [f64; 3],
    /// The velocity stored (rounded to the nearest quantum, M1).
    pub stored: [f64; 3],
    /// Mean displacement per step over the group.
    pub measured: [f64; 3],
    /// Standard error of `measured` per axis (sample variance over the
    /// group's independent particles).
    pub se: [f64; 3],
    /// `p/(2-p)` of the stored component per axis, with its sign.
    pub predicted: [f64; 3],
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn diff(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

impl DriftGroup {
    /// Requested speed.
    pub fn speed(&self) -> f64 {
        norm(self.requested)
    }

    /// `|measured - requested| / |requested|`.
    pub fn relative_error(&self) -> f64 {
        norm(diff(self.measured, self.requested)) / self.speed()
    }

    /// `|se| / |requested|`: the noise level of `relative_error`.
    pub fn relative_noise(&self) -> f64 {
        norm(self.se) / self.speed()
    }

    /// `|predicted - requested| / |requested|`: the error the rule implies.
    pub fn predicted_error(&self) -> f64 {
        norm(diff(self.predicted, self.requested)) / self.speed()
    }

    /// Largest `|measured - predicted| / se` over the axes that move.
    pub fn worst_z(&self) -> f64 {
        (0..3).filter(|&k| self.se[k] > 0.0).map(|k| (self.measured[k] - self.predicted[k]).abs() / self.se[k]).fold(0.0, f64::max)
    }
}

/// The drift error of one (dimension, rule, quantization).
#[derive(Clone, Debug)]
pub struct DriftResult {
    /// 2 or 3.
    pub dim: u32,
    /// The rule.
    pub drift: Drift,
    /// The storage.
    pub quant: Quantization,
    /// One per (speed, direction).
    pub groups: Vec<DriftGroup>,
    /// Particle-steps per run.
    pub particle_steps: u64,
    /// Run times (stepping and reading positions).
    pub timing: Timing,
    /// Bytes per cell of the worlds.
    pub bytes_per_cell: f64,
}

impl DriftResult {
    fn mean(&self, f: impl Fn(&DriftGroup) -> f64) -> f64 {
        self.groups.iter().map(f).sum::<f64>() / self.groups.len() as f64
    }

    /// Mean over the groups of `|measured - requested| / |requested|`.
    pub fn mean_relative_error(&self) -> f64 {
        self.mean(DriftGroup::relative_error)
    }

    /// Largest relative error of any group.
    pub fn max_relative_error(&self) -> f64 {
        self.groups.iter().map(DriftGroup::relative_error).fold(0.0, f64::max)
    }

    /// Mean relative noise level (standard error over speed).
    pub fn mean_relative_noise(&self) -> f64 {
        self.mean(DriftGroup::relative_noise)
    }

    /// Mean relative error the rule predicts (`p/(2-p)` against `|v|`).
    pub fn mean_predicted_error(&self) -> f64 {
        self.mean(DriftGroup::predicted_error)
    }

    /// Largest deviation from the prediction in standard errors.
    pub fn worst_z(&self) -> f64 {
        self.groups.iter().map(DriftGroup::worst_z).fold(0.0, f64::max)
    }

    /// Median run time per particle-step, in nanoseconds.
    pub fn ns_per_particle_step(&self) -> f64 {
        self.timing.median() * 1e9 / self.particle_steps as f64
    }
}

/// Flies the groups of one setting.
pub fn measure(dim: u32, drift: Drift, quant: Quantization, cfg: DriftConfig) -> DriftResult {
    const N: u32 = 8;
    const CHUNK: u64 = N as u64 - 1;
    let mut desc = cube(dim, N);
    desc.drift = drift;
    desc.quantization = quant;
    let mut mem = memory(&desc);
    let dirs = directions(dim);
    let d = dim as usize;
    let mut bytes_per_cell = 0.0;
    let (groups, timing) = repeat(cfg.runs, || {
        let mut groups = vec![];
        let mut seconds = 0.0;
        let mut seed = 1u64 << 40 | u64::from(dim) << 32;
        for &speed in &SPEEDS {
            for dir in &dirs {
                let requested = dir.map(|c| f64::from((c * f64::from(speed)) as f32));
                let v = requested.map(|c| c as f32);
                let mut per_particle: [Vec<f64>; 3] = [vec![], vec![], vec![]];
                let mut stored = [0.0; 3];
                for i in 0..cfg.particles {
                    seed += 1;
                    desc.seed = seed;
                    let world: &mut World = World::init(&desc, &mut mem).expect("fits");
                    bytes_per_cell = world.bytes_per_cell();
                    // Starting cells of both parities on every axis.
                    let start = [0, 1, 2].map(|k| ((i as u32) >> k & 1) + 2 * (k as u32));
                    let start = if dim == 2 { [start[0], start[1], 0] } else { start };
                    world.add_particle(start, v).expect("free cell, |v| <= 1");
                    let p = world.particles().next().expect("one particle");
                    stored = p.velocity.map(f64::from);
                    let mut at = p.pos;
                    let mut moved = [0i64; 3];
                    let mut left = cfg.steps;
                    while left > 0 {
                        let n = left.min(CHUNK);
                        seconds += super::clock(|| world.step(n));
                        left -= n;
                        let now = world.particles().next().expect("the particle stays").pos;
                        for k in 0..d {
                            let fwd = (i64::from(now[k]) - i64::from(at[k])).rem_euclid(i64::from(N));
                            moved[k] += if stored[k] > 0.0 {
                                fwd
                            } else if stored[k] < 0.0 {
                                -((i64::from(N) - fwd) % i64::from(N))
                            } else {
                                assert_eq!(fwd, 0, "a particle moved along an axis where it has no speed");
                                0
                            };
                        }
                        at = now;
                    }
                    for k in 0..3 {
                        per_particle[k].push(moved[k] as f64 / cfg.steps as f64);
                    }
                }
                let mut measured = [0.0; 3];
                let mut se = [0.0; 3];
                let mut predicted = [0.0; 3];
                for k in 0..3 {
                    (measured[k], se[k]) = mean_and_se(&per_particle[k]);
                    predicted[k] = stored[k].signum() * free_speed(move_probability(drift, stored[k].abs()));
                    if stored[k] == 0.0 {
                        (se[k], predicted[k]) = (0.0, 0.0);
                    }
                }
                groups.push(DriftGroup { requested, stored, measured, se, predicted });
            }
        }
        (groups, seconds)
    });
    let particle_steps = (groups.len() * cfg.particles) as u64 * cfg.steps;
    DriftResult { dim, drift, quant, groups, particle_steps, timing, bytes_per_cell }
}
