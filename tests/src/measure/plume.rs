//! M5.1c: how turbulence breaks up a rising plume. The plume of
//! [`scenes::plume`] with and without turbulence, measured by the plume's
//! width (the standard deviation of the particles' x) in bands of height,
//! and by how long a particle's sideways velocity keeps its sign.

use mpca::World;

use super::run_steps;
use crate::scenes::{self, Scene};

/// The height bands, in cells from the floor, whose widths are measured.
pub const BANDS: [(u32, u32); 4] = [(8, 24), (40, 56), (72, 88), (104, 120)];

/// What a run of the plume shows, averaged over the snapshots of its last
/// half.
#[derive(Clone, Debug)]
pub struct Plume {
    /// The plume's width in each of [`BANDS`], in cells.
    pub width: [f64; 4],
    /// The root-mean-square sideways velocity of the particles above the
    /// vent, cells per step.
    pub sideways: f64,
    /// Clamps per particle-step over the whole run.
    pub clamps: f64,
    /// Particles in the world at the end.
    pub particles: u64,
}

/// Runs `scene` (a [`scenes::plume`]) for its steps and measures the last
/// half, every 20 steps; the seconds spent stepping.
pub fn measure(scene: &Scene) -> (Plume, f64) {
    let mut mem = Vec::new();
    let w = scenes::build(scene, &mut mem).expect("the plume builds");
    let mut sums = [(0.0f64, 0.0f64, 0.0f64); 4];
    let (mut side, mut side_n) = (0.0f64, 0.0f64);
    let mut particle_steps = 0u64;
    let half = scene.steps / 2;
    let seconds = run_steps(w, scene.steps, |w, step| {
        particle_steps += w.particle_count();
        if step > half && step % 20 == 0 {
            add_bands(w, &mut sums);
            for p in w.particles().filter(|p| p.pos[1] >= 8) {
                side += f64::from(p.velocity[0]).powi(2);
                side_n += 1.0;
            }
        }
    });
    let width = sums.map(|(n, sx, sxx)| if n > 1.0 { (sxx / n - (sx / n).powi(2)).max(0.0).sqrt() } else { f64::NAN });
    let plume = Plume {
        width,
        sideways: (side / side_n.max(1.0)).sqrt(),
        clamps: w.stats().clamps as f64 / particle_steps.max(1) as f64,
        particles: w.particle_count(),
    };
    (plume, seconds)
}

/// Adds the count, sum of x and sum of x² of the particles in each band.
fn add_bands(w: &World, sums: &mut [(f64, f64, f64); 4]) {
    for p in w.particles() {
        for (b, &(lo, hi)) in BANDS.iter().enumerate() {
            if (lo..hi).contains(&p.pos[1]) {
                let x = f64::from(p.pos[0]) + 0.5;
                sums[b].0 += 1.0;
                sums[b].1 += x;
                sums[b].2 += x * x;
            }
        }
    }
}
