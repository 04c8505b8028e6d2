//! The random streams of M8.
//!
//! Every random draw of a step comes from a stream determined only by
//! `(world seed, step number, block index)`, or for emitters by
//! `(seed, step, emitter index)` in a domain of their own. Processing the
//! blocks in any order, on any thread or target, therefore draws the same
//! numbers.
//!
//! The generator is counter-based: SplitMix64's output function applied to
//! a counter. For a step, a key `k` and an odd increment `g` are derived
//! from the seed and the step number (SplitMix64's own seed and gamma
//! derivation, done once per step); output `i` of block `b` is
//! `mix(k + g (b 2^16 + i + 1))`. Within a step every draw of every block
//! therefore goes through the bijection `mix` from a distinct counter, and
//! a block needs no state seeded beyond one multiply: that is what makes
//! this the documented equivalent of seeding a PCG per block that M8 allows
//! (seeding PCG32 cost about 75 instructions per block, a quarter of the
//! lean kernel's budget). A block has room for 2^16 outputs; its rejection
//! loops need a handful.
//!
//! Draws take as many bits as they need from the current 64-bit output
//! ([`Stream::bits`]): a move decision 16 a component, a pair choice or a
//! tie-break 16 (32 above 2^16), so a typical 2D block uses one output; a
//! stochastic rounding takes a whole output (16 bits a component).

/// Domain tags keep the block streams and the emitter streams apart even
/// where a block index equals an emitter index.
const DOMAIN_BLOCK: u64 = 0x6d70_6361_626c_6b00; // "mpcablk"
const DOMAIN_EMITTER: u64 = 0x6d70_6361_656d_6900; // "mpcaemi"
/// The push-outs of M13's body moves.
#[cfg(feature = "obstacles")]
const DOMAIN_BODY: u64 = 0x6d70_6361_6264_7900; // "mpcabdy"

/// Block `b` owns counters `b 2^16 + 1 ..= b 2^16 + 2^16`.
const BLOCK_WINDOW: u32 = 16;
/// Emitter `e` owns `2^32` counters: selection sampling over a large region
/// draws once per cell.
const EMITTER_WINDOW: u32 = 32;

/// SplitMix64's output function: a bijection on u64 whose every output bit
/// depends on every input bit.
#[inline]
pub(crate) const fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// SplitMix64's increment derivation: odd, and with enough bit changes
/// between neighbouring bits that successive counters differ in many bits.
#[inline]
const fn increment(z: u64) -> u64 {
    let g = mix(z) | 1;
    if (g ^ (g >> 1)).count_ones() < 24 { g ^ 0xaaaa_aaaa_aaaa_aaaa } else { g }
}

/// The key and increment of one step in one domain: everything a block's
/// stream needs that does not depend on the block, computed once per step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StepKey {
    key: u64,
    gamma: u64,
    /// `gamma 2^window`: the step from one block's (emitter's) counters to
    /// the next one's.
    stride: u64,
}

impl StepKey {
    fn derive(seed: u64, step: u64, domain: u64, window: u32) -> StepKey {
        let a = mix(seed ^ domain);
        let key = mix(a ^ step.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        let gamma = increment(key ^ 0xa076_1d64_78bd_642f);
        StepKey { key, gamma, stride: gamma << window }
    }

    /// The block streams of `step`.
    pub fn blocks(seed: u64, step: u64) -> StepKey {
        StepKey::derive(seed, step, DOMAIN_BLOCK, BLOCK_WINDOW)
    }

    /// The emitter streams of `step`.
    pub fn emitters(seed: u64, step: u64) -> StepKey {
        StepKey::derive(seed, step, DOMAIN_EMITTER, EMITTER_WINDOW)
    }

    /// The push-out streams of the body moves before `step` (M13): one
    /// per cell and redraw, each needing one output.
    #[cfg(feature = "obstacles")]
    pub(crate) fn bodies(seed: u64, step: u64) -> StepKey {
        StepKey::derive(seed, step, DOMAIN_BODY, 1)
    }

    /// The stream of block (or emitter) `index`.
    #[inline]
    pub fn stream(&self, index: u64) -> Stream {
        Stream { counter: self.key.wrapping_add(self.stride.wrapping_mul(index)), gamma: self.gamma, pool: 0, left: 0 }
    }
}

/// One block's (or emitter's) random stream.
#[derive(Clone, Debug)]
pub struct Stream {
    counter: u64,
    gamma: u64,
    /// Bits of the current output not yet handed out, lowest first.
    pool: u64,
    left: u32,
}

impl Stream {
    /// The next 64-bit output.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.counter = self.counter.wrapping_add(self.gamma);
        mix(self.counter)
    }

    /// `n` fresh random bits (`1 <= n <= 32`), the lowest of what is left of
    /// the current output; an output with fewer than `n` bits left is
    /// dropped for the next.
    #[inline]
    pub fn bits(&mut self, n: u32) -> u32 {
        debug_assert!((1..=32).contains(&n));
        if self.left < n {
            self.pool = self.next_u64();
            self.left = 64;
        }
        let r = self.pool as u32 & (u32::MAX >> (32 - n));
        self.pool >>= n;
        self.left -= n;
        r
    }

    /// A uniform integer in `0..n` without bias (Lemire's multiply and
    /// reject), from 16 bits per try where `n <= 2^16`, else 32. `n >= 1`.
    #[inline]
    pub fn below(&mut self, n: u32) -> u32 {
        debug_assert!(n > 0);
        let width = if n <= 1 << 16 { 16 } else { 32 };
        let mut m = u64::from(self.bits(width)) * u64::from(n);
        let low = |m: u64| m & (u64::MAX >> (64 - width));
        if low(m) < u64::from(n) {
            // 2^width mod n: the low products below it are over-represented.
            // In 32 bits (2^width - n fits): no 64-bit division, which small
            // cores call a library routine for.
            let span = if width == 16 { 1u32 << 16 } else { 0 };
            let threshold = u64::from(remainder(span.wrapping_sub(n), n));
            while low(m) < threshold {
                m = u64::from(self.bits(width)) * u64::from(n);
            }
        }
        (m >> width) as u32
    }

    /// A uniform `f32` in `[0, 1)` on a grid of `2^-24`.
    #[inline]
    pub fn unit(&mut self) -> f32 {
        crate::rules::vector::small_to_f32(self.bits(24)) * (1.0 / 16_777_216.0)
    }

    /// True with probability `p` (to within `2^-24`; `p >= 1` always true).
    #[inline]
    pub fn chance(&mut self, p: f32) -> bool {
        self.unit() < p
    }
}

/// The stream as a generator of the `rand_core` ecosystem (its `Rng`, the
/// infallible `TryRng`), so that users and tests can draw from a world's
/// streams with the ecosystem's tools (`rand`'s distributions, say).
/// `next_u32` takes 32 bits as [`Stream::bits`] does, so two of them use
/// one output; `next_u64` and `fill_bytes` take whole outputs, least
/// significant byte first.
///
/// ```
/// use rand_core::Rng;
///
/// // The stream block 5 of a world seeded 42 draws from at step 0.
/// let mut stream = mpca::rng::block_stream(42, 0, 5);
/// let mut bytes = [0u8; 16];
/// stream.fill_bytes(&mut bytes);
/// let again = mpca::rng::block_stream(42, 0, 5).next_u64();
/// assert_eq!(bytes[..8], again.to_le_bytes());
/// ```
impl rand_core::TryRng for Stream {
    type Error = core::convert::Infallible;

    #[inline]
    fn try_next_u32(&mut self) -> Result<u32, Self::Error> {
        Ok(self.bits(32))
    }

    #[inline]
    fn try_next_u64(&mut self) -> Result<u64, Self::Error> {
        Ok(Stream::next_u64(self))
    }

    #[inline]
    fn try_fill_bytes(&mut self, dst: &mut [u8]) -> Result<(), Self::Error> {
        rand_core::utils::fill_bytes_via_next_word(dst, || self.try_next_u64())
    }
}

/// `a % n` (`n >= 1`) by shifts and subtractions, a bit at a time: the
/// rejection threshold of [`Stream::below`], which a draw needs once in
/// thousands, without the division routine that small cores (Cortex-M0)
/// would otherwise link for it: with `small-step` (firmware) only, since
/// hosts divide in one instruction.
fn remainder(a: u32, n: u32) -> u32 {
    if !cfg!(feature = "small-step") {
        return a % n;
    }
    // r < n before each step; doubled plus a bit it is below 2n, which
    // may pass 2^32 (the bit shifted out): then it is n or more.
    let mut r = 0u32;
    for i in (0..32).rev() {
        let carry = r >> 31;
        r = r << 1 | (a >> i & 1);
        if carry != 0 || r >= n {
            r = r.wrapping_sub(n);
        }
    }
    r
}

/// The stream of block `block` (its index in the step's block grid) at `step`.
pub fn block_stream(seed: u64, step: u64, block: u64) -> Stream {
    StepKey::blocks(seed, step).stream(block)
}

/// The stream of emitter `emitter` at `step`.
pub fn emitter_stream(seed: u64, step: u64, emitter: u64) -> Stream {
    StepKey::emitters(seed, step).stream(emitter)
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
    fn neighbouring_blocks_never_share_a_counter() {
        // Block b's outputs come from counters b 2^16 + 1 ..= (b + 1) 2^16:
        // the last output of block 0's window is not block 1's first.
        let key = StepKey::blocks(9, 9);
        let mut a = key.stream(0);
        let mut last = 0;
        for _ in 0..1 << 16 {
            last = a.next_u64();
        }
        let mut b = key.stream(1);
        assert_eq!(a.next_u64(), b.next_u64(), "block 0's 2^16+1-th output is block 1's first");
        assert_ne!(last, key.stream(1).next_u64());
    }

    #[test]
    fn bits_hand_out_each_output_once() {
        // Four 16-bit draws are the four quarters of one output, lowest
        // first; a 24-bit draw with 16 bits left starts the next output.
        let mut s = block_stream(3, 4, 5);
        let mut t = s.clone();
        let whole = t.next_u64();
        for k in 0..4 {
            assert_eq!(u64::from(s.bits(16)), whole >> (16 * k) & 0xffff);
        }
        let mut s = block_stream(3, 4, 5);
        s.bits(16);
        s.bits(32);
        assert_eq!(u64::from(s.bits(24)), t.next_u64() & 0xff_ffff);
    }

    #[test]
    fn the_rand_core_generator_is_the_stream() {
        // Through rand_core's Rng: next_u64 is the stream's output, two
        // next_u32 are one output's halves, lowest first, and fill_bytes
        // lays outputs down little-endian, dropping the unused rest.
        use rand_core::Rng;
        let mut direct = block_stream(11, 12, 13);
        let mut rng = direct.clone();
        let first = direct.next_u64();
        assert_eq!(Rng::next_u64(&mut rng), first);
        let second = direct.next_u64();
        assert_eq!(u64::from(rng.next_u32()), second & 0xffff_ffff);
        assert_eq!(u64::from(rng.next_u32()), second >> 32);
        let mut bytes = [0u8; 11];
        rng.fill_bytes(&mut bytes);
        let (a, b) = (direct.next_u64().to_le_bytes(), direct.next_u64().to_le_bytes());
        assert_eq!(bytes[..8], a);
        assert_eq!(bytes[8..], b[..3]);
    }

    #[test]
    fn remainder_is_the_remainder() {
        // Expect: a % n for every edge of the u32 range and random pairs.
        let mut rng = block_stream(5, 6, 7);
        let edges = [1u32, 2, 3, 7, 1 << 16, (1 << 31) - 1, 1 << 31, (1 << 31) + 1, u32::MAX - 1, u32::MAX];
        for &n in &edges {
            for &a in edges.iter().chain(&[0]) {
                assert_eq!(remainder(a, n), a % n, "{a} % {n}");
            }
        }
        for _ in 0..crate::sized(10_000, 200) {
            let (a, n) = (rng.bits(32), rng.bits(32) >> rng.bits(5));
            let n = n.max(1);
            assert_eq!(remainder(a, n), a % n, "{a} % {n}");
        }
    }

    #[test]
    fn below_is_uniform() {
        // 60,000 draws (2,000 under Miri) in 6 bins and in 7 bins: each
        // count is binomial; a 5 sd band fails by chance with probability
        // ~6e-7 per bin.
        let draws = crate::sized(60_000, 2_000) as u32;
        for n in [6u32, 7, 100_003] {
            let bins = n.min(7) as usize;
            let mut rng = block_stream(7, 0, u64::from(n));
            let mut counts = [0u32; 7];
            for _ in 0..draws {
                let v = rng.below(n);
                assert!(v < n);
                counts[(u64::from(v) * bins as u64 / u64::from(n)) as usize] += 1;
            }
            let p = 1.0 / bins as f64;
            let sd = (f64::from(draws) * p * (1.0 - p)).sqrt();
            for &c in &counts[..bins] {
                // For n = 100,003 the 7 bins differ in size by one value in
                // 14,286: far inside the band.
                assert!((f64::from(c) - f64::from(draws) * p).abs() < 5.0 * sd, "{n}: {counts:?}");
            }
        }
    }

    #[test]
    fn unit_stays_below_one() {
        let mut rng = block_stream(0, 0, 0);
        for _ in 0..crate::sized(100_000, 2_000) {
            let u = rng.unit();
            assert!((0.0..1.0).contains(&u));
        }
    }
}
