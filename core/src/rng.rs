//! The per-block random streams of M8.
//!
//! Every random draw of a step comes from a PCG32 stream whose state and
//! increment are derived only from `(world seed, step number, block index)`
//! (or, for emitters, `(seed, step, emitter index)` in a separate domain).
//! No stream outlives the block that made it, so processing blocks in any
//! order, on any thread or target, draws the same numbers.

use rand_core::Rng;
use rand_pcg::Pcg32;

/// The generator behind every stream.
pub type Stream = Pcg32;

/// Domain tags keep the block streams and the emitter streams apart even
/// where a block index equals an emitter index.
const DOMAIN_BLOCK: u64 = 0x6d70_6361_626c_6b00; // "mpcablk"
const DOMAIN_EMITTER: u64 = 0x6d70_6361_656d_6900; // "mpcaemi"

/// SplitMix64's output function: a bijection on u64 whose every output bit
/// depends on every input bit, so neighbouring counters give unrelated seeds.
#[inline]
const fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

#[inline]
fn derive(seed: u64, step: u64, index: u64, domain: u64) -> Stream {
    let a = mix(seed ^ domain);
    let b = mix(a ^ step.wrapping_mul(0x9e37_79b9_7f4a_7c15));
    let state = mix(b ^ index.wrapping_mul(0xd1b5_4a32_d192_ed03));
    // A second, independent derivation picks the increment, so two blocks
    // never share a stream even if their states collided.
    let stream = mix(state ^ 0xa076_1d64_78bd_642f);
    Pcg32::new(state, stream)
}

/// The stream of block `block` (its index in the step's block grid) at `step`.
#[inline]
pub fn block_stream(seed: u64, step: u64, block: u64) -> Stream {
    derive(seed, step, block, DOMAIN_BLOCK)
}

/// The stream of emitter `emitter` at `step`.
#[inline]
pub fn emitter_stream(seed: u64, step: u64, emitter: u64) -> Stream {
    derive(seed, step, emitter, DOMAIN_EMITTER)
}

/// A uniform integer in `0..n` without modulo bias (Lemire's multiply and
/// reject). `n` must be at least 1.
#[inline]
pub fn below<R: Rng + ?Sized>(rng: &mut R, n: u32) -> u32 {
    debug_assert!(n > 0);
    let mut m = u64::from(rng.next_u32()) * u64::from(n);
    if (m as u32) < n {
        let threshold = n.wrapping_neg() % n;
        while (m as u32) < threshold {
            m = u64::from(rng.next_u32()) * u64::from(n);
        }
    }
    (m >> 32) as u32
}

/// A uniform `f32` in `[0, 1)` with 24 random bits.
#[inline]
pub fn unit<R: Rng + ?Sized>(rng: &mut R) -> f32 {
    (rng.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// True with probability `p` (`p` in `[0, 1]`; 1 is always true).
#[inline]
pub fn chance<R: Rng + ?Sized>(rng: &mut R, p: f32) -> bool {
    unit(rng) < p
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_depend_on_every_input() {
        let base = block_stream(1, 2, 3).next_u64();
        assert_ne!(base, block_stream(0, 2, 3).next_u64());
        assert_ne!(base, block_stream(1, 3, 3).next_u64());
        assert_ne!(base, block_stream(1, 2, 4).next_u64());
        assert_ne!(base, emitter_stream(1, 2, 3).next_u64());
        assert_eq!(base, block_stream(1, 2, 3).next_u64());
    }

    #[test]
    fn below_is_uniform() {
        // 60,000 draws in 6 bins: each count is binomial(60000, 1/6), sd ~91;
        // a 5 sd band fails by chance with probability ~1e-6 per bin.
        let mut rng = block_stream(7, 0, 0);
        let mut bins = [0u32; 6];
        for _ in 0..60_000 {
            bins[below(&mut rng, 6) as usize] += 1;
        }
        let sd = (60_000.0f64 * (1.0 / 6.0) * (5.0 / 6.0)).sqrt();
        for b in bins {
            assert!((f64::from(b) - 10_000.0).abs() < 5.0 * sd, "{bins:?}");
        }
    }

    #[test]
    fn unit_stays_below_one() {
        let mut rng = block_stream(0, 0, 0);
        for _ in 0..100_000 {
            let u = unit(&mut rng);
            assert!((0.0..1.0).contains(&u));
        }
    }
}
