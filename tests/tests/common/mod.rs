//! Helpers shared by the integration tests: memory for a world, a setup
//! stream independent of the world's own streams (M8), exact quantized
//! velocities, and the 5-standard-deviation band of the statistical tests.
#![allow(dead_code)]

use mpca::{Cell, Description, Particle, Quantization, World};

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

/// The cells of a world, shared with the report.
#[allow(unused_imports)]
pub use mpca_tests::setup::cells;

/// The tests' setup stream: the report's generator with the tests' own
/// stream constants, which the tests' fixed seeds were chosen with.
pub type TestRng = mpca_tests::setup::SetupRng;

/// The tests' setup stream for `seed`.
pub fn test_rng(seed: u64) -> TestRng {
    TestRng::with_stream(seed ^ 0x07e5_75e7_u64, 0x51)
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

/// A setter of one float of a description.
pub type Setter = fn(&mut Description, f32);

/// Every float a description holds, by name, the circulation also with the
/// vortex switched on (M1: each must be finite).
pub fn description_floats() -> [(&'static str, Setter); 12] {
    [
        ("mass", |d, v| d.mass = v),
        ("restitution", |d, v| d.restitution = v),
        ("wall_restitution", |d, v| d.wall_restitution = v),
        ("dt", |d, v| d.dt = v),
        ("gravity x", |d, v| d.gravity[0] = v),
        ("gravity y", |d, v| d.gravity[1] = v),
        ("gravity z", |d, v| d.gravity[2] = v),
        ("vortex centre x", |d, v| d.vortex.centre[0] = v),
        ("vortex centre y", |d, v| d.vortex.centre[1] = v),
        ("vortex core radius", |d, v| d.vortex.core_radius = v),
        ("vortex circulation", |d, v| d.vortex.circulation = v),
        ("vortex circulation, vortex on", |d, v| {
            d.forces.vortex = true;
            d.vortex.circulation = v;
        }),
    ]
}

/// CRC-32 (zlib's), one bit at a time: written apart from the library's
/// table-driven one, so the two check each other.
pub fn crc32(bytes: &[u8]) -> u32 {
    let mut r = u32::MAX;
    for &b in bytes {
        r ^= u32::from(b);
        for _ in 0..8 {
            r = (r >> 1) ^ (0xedb8_8320 & (r & 1).wrapping_neg());
        }
    }
    !r
}

/// Writes a fresh checksum over a changed world image (M12).
pub fn reseal(image: &mut [u8]) {
    let n = image.len() - 4;
    let crc = crc32(&image[..n]);
    image[n..].copy_from_slice(&crc.to_le_bytes());
}
