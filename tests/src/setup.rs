//! What tests, the report and the benchmark share to set scenes up: the
//! cells of a world, and a random stream for placing particles that is
//! separate from every stream of a world (M8).

use mpca::Description;
use rand_core::Rng;
use rand_pcg::Pcg32;

/// Cells of a description, `x` fastest (`z = 0` in 2D).
pub fn cells(desc: &Description) -> impl Iterator<Item = [u32; 3]> {
    let nz = if desc.dim == 3 { desc.size[2] } else { 1 };
    let [nx, ny, _] = desc.size;
    (0..nz).flat_map(move |z| (0..ny).flat_map(move |y| (0..nx).map(move |x| [x, y, z])))
}

/// The stream that places particles: separate from every stream of a world
/// (M8), so setting a scene up draws nothing the world will draw.
pub struct SetupRng(Pcg32);

impl SetupRng {
    /// A stream for `seed`.
    pub fn new(seed: u64) -> Self {
        Self::with_stream(seed ^ 0x6d65_6173_7572_6500, 0x2f)
    }

    /// A PCG32 stream of the given state and stream number, for callers
    /// that keep streams of their own apart from the report's.
    pub fn with_stream(state: u64, stream: u64) -> Self {
        SetupRng(Pcg32::new(state, stream))
    }

    /// Uniform in `[0, 1)` with 24 random bits.
    pub fn unit(&mut self) -> f32 {
        (self.0.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    /// Uniform in `0..n` (multiply-shift; its bias, below `n / 2^32`, does
    /// not matter for placing particles).
    pub fn below(&mut self, n: u32) -> u32 {
        ((u64::from(self.0.next_u32()) * u64::from(n)) >> 32) as u32
    }

    /// A velocity uniform in the disc (2D) or ball (3D) of radius `r`, by
    /// rejection from the cube around it.
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
