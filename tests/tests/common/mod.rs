//! Helpers shared by the integration tests: memory for a world, a setup
//! stream independent of the world's own streams (M8), exact quantized
//! velocities, and the 5-standard-deviation band of the statistical tests.
#![allow(dead_code)]

use mpca::{Cell, Description, Particle, Quantization, World};
use rand_core::Rng;
use rand_pcg::Pcg32;

/// Half-width of every statistical band, in standard deviations. A correct
/// implementation fails one such check with probability about 6e-7.
pub const Z: f64 = 5.0;

/// Zeroed memory of exactly `world_bytes(desc)` bytes.
pub fn memory(desc: &Description) -> Vec<u8> {
    vec![0u8; mpca::world_bytes(desc).expect("valid description")]
}

/// Stored steps per unit speed of a quantization (M1).
pub fn scale(q: Quantization) -> f64 {
    match q {
        Quantization::Bits8 => 127.0,
        Quantization::Bits16 => 32767.0,
    }
}

/// A stored velocity component in quanta: the integer the world holds. The
/// world reports `q as f32 * (1 / SCALE)`, whose relative error (2^-24) is far
/// below half a quantum for |q| <= 32767, so rounding recovers `q` exactly.
pub fn quanta(v: f32, q: Quantization) -> i64 {
    let s = scale(q);
    let x = (f64::from(v) * s).round();
    debug_assert!((f64::from(v) * s - x).abs() < 1e-2, "{v} is not a stored value");
    x as i64
}

/// The particle at `pos`, which must hold one.
pub fn particle(world: &World, pos: [u32; 3]) -> Particle {
    match world.cell(pos) {
        Ok(Cell::Particle(p)) => p,
        other => panic!("no particle at {pos:?}: {other:?}"),
    }
}

/// The setup stream of the tests: separate from every stream of the world.
pub struct TestRng(Pcg32);

impl TestRng {
    pub fn new(seed: u64) -> Self {
        TestRng(Pcg32::new(seed ^ 0x07e5_75e7_u64, 0x51))
    }

    /// Uniform in [0, 1) with 24 random bits.
    pub fn unit(&mut self) -> f32 {
        (self.0.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    /// Uniform in 0..n (the bias of the multiply-shift, below 2^-32 n, is
    /// irrelevant for test setup).
    pub fn below(&mut self, n: u32) -> u32 {
        ((u64::from(self.0.next_u32()) * u64::from(n)) >> 32) as u32
    }

    /// A velocity uniform in the disc (2D) or ball (3D) of radius `r`, by
    /// rejection from the cube.
    pub fn velocity(&mut self, dim: u32, r: f32) -> [f32; 3] {
        loop {
            let mut v = [0.0f32; 3];
            for c in v.iter_mut().take(dim as usize) {
                *c = r * (2.0 * self.unit() - 1.0);
            }
            if v.iter().map(|c| c * c).sum::<f32>() <= r * r {
                return v;
            }
        }
    }
}

/// Cells of a world, `x` fastest, as positions (`z = 0` in 2D).
pub fn cells(desc: &Description) -> impl Iterator<Item = [u32; 3]> {
    let nz = if desc.dim == 3 { desc.size[2] } else { 1 };
    let [nx, ny, _] = desc.size;
    (0..nz).flat_map(move |z| (0..ny).flat_map(move |y| (0..nx).map(move |x| [x, y, z])))
}

/// Mean and standard error of the mean of `xs` (sample variance, n - 1).
pub fn mean_and_se(xs: &[f64]) -> (f64, f64) {
    let n = xs.len() as f64;
    let mean = xs.iter().sum::<f64>() / n;
    let var = xs.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// Asserts a binomial count: `|observed - n p| <= Z sqrt(n p (1 - p))`. With
/// `p` 0 or 1 the band is empty and the count must be exact.
pub fn assert_binomial(observed: u64, n: u64, p: f64, what: &str) {
    let (n, obs) = (n as f64, observed as f64);
    let mean = n * p;
    let sd = (n * p * (1.0 - p)).sqrt();
    assert!(
        (obs - mean).abs() <= Z * sd,
        "{what}: observed {observed}, expected {mean:.1} +- {:.1} (5 sd, n = {n}, p = {p})",
        Z * sd
    );
}
