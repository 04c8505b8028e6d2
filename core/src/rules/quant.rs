//! Quantized velocity storage (M1). A component `v` in `[-1, 1]` is stored as
//! an integer near `v * SCALE`, rounded stochastically when it comes from the
//! step, so the stored value is right on average: an acceleration below one
//! quantum per step still acts, by raising the chance of rounding up.
//!
//! The step works in quanta: a velocity nothing changed is an integer and
//! stays one, and M5.3's move decision is an integer comparison of 16 random
//! bits against a threshold of the stored component ([`Quant::move_limit`]).

use crate::api::desc::Drift;
use crate::rules::rng::Stream;

/// Dispatches on the world's velocity storage type.
macro_rules! with_quant {
    ($q:expr, $t:ident => $body:expr) => {
        match $q {
            $crate::api::desc::Quantization::Bits8 => {
                type $t = i8;
                $body
            }
            #[cfg(feature = "q16")]
            $crate::api::desc::Quantization::Bits16 => {
                type $t = i16;
                $body
            }
            #[cfg(not(feature = "q16"))]
            $crate::api::desc::Quantization::Bits16 => unreachable!("refused by Description::check"),
        }
    };
}
pub(crate) use with_quant;

/// Fine units to a unit speed (M1c's `W`) of a world of `quantization`.
pub(crate) fn unit_of(quantization: crate::api::desc::Quantization) -> i32 {
    with_quant!(quantization, Q => Q::UNIT)
}

/// A stored velocity component type.
pub(crate) trait Quant: Copy + Default + Send + crate::storage::plain::Plain + 'static {
    /// Stored steps per unit speed.
    const SCALE: f32;
    fn from_int(q: i32) -> Self;
    fn to_int(self) -> i32;

    /// Whether a 2D block row's two velocities fit one 32-bit word of byte
    /// lanes ([`Quant::lanes_2d`]): 8-bit storage.
    const LANES: bool;
    /// A 2D block row's two stored velocities as byte lanes, lane `2c + k`
    /// holding cell `c`'s component `k` (where [`Quant::LANES`]; 0
    /// otherwise).
    fn lanes_2d<const D: usize>(pair: [[Self; D]; 2]) -> u32;
    /// The inverse of [`Quant::lanes_2d`] (where [`Quant::LANES`]).
    fn pair_from_lanes<const D: usize>(lanes: u32) -> [[Self; D]; 2];

    #[inline]
    fn get(self) -> f32 {
        self.to_int() as f32 * (1.0 / Self::SCALE)
    }

    /// Fine units a quantum (M1c's `F`): `2^FINE` of them make one.
    const FINE: u32;
    /// Fine units to a unit speed (M1c's `W`, `SCALE 2^FINE`).
    const UNIT: i32;

    /// M5.3: the largest 16 random bits `r` that say "move" for a stored
    /// component `q` (in quanta, not 0; its sign ignored) under `drift`:
    /// `r <= limit` for `round(p 2^16)` of the `2^16` values of `r`, with `p`
    /// the drift rule's probability. `table` is [`move_table_8`]'s table for
    /// `drift`, which 8-bit storage reads.
    fn move_limit(table: &[u16; 256], drift: Drift, q: i32) -> u32;
}

/// A stored velocity width as values rather than a type (M1, M1c): what
/// the step's pipeline with every part reads from the step's data, so that
/// one copy of it serves both widths. [`Width::of`] a type folds to
/// constants wherever the type is known at compile time.
#[derive(Clone, Copy)]
pub(crate) struct Width {
    /// [`Quant::FINE`].
    pub fine: u32,
    /// [`Quant::UNIT`].
    pub unit: i32,
    /// `2^fine - 1`: the random bits of a rounding.
    low: u32,
    /// 16-bit storage; read through [`Width::wide`].
    wide: bool,
}

impl Width {
    /// The width of `Q`.
    #[inline(always)]
    pub(crate) const fn of<Q: Quant>() -> Width {
        Width { fine: Q::FINE, unit: Q::UNIT, low: (1 << Q::FINE) - 1, wide: core::mem::size_of::<Q>() > 1 }
    }

    /// The width of a world of `quantization`: read by the pipeline with
    /// every part (which `small-step` instantiates per width instead) and
    /// by edits, each of them one copy of its code for both widths.
    pub(crate) fn of_quantization(quantization: crate::api::desc::Quantization) -> Width {
        with_quant!(quantization, Q => Width::of::<Q>())
    }

    /// Stored steps per unit speed ([`Quant::SCALE`]).
    #[inline(always)]
    pub(crate) fn scale(self) -> i32 {
        self.unit >> self.fine
    }

    /// `v` (clamped to `[-1, 1]`) in quanta, rounded to nearest, halves
    /// away from zero so that `v` and `-v` store opposite values: for
    /// velocities a caller sets, which need no stream.
    #[inline(always)]
    pub(crate) fn nearest(self, v: f32) -> i32 {
        let scale = self.scale();
        (libm::roundf(v.clamp(-1.0, 1.0) * scale as f32) as i32).clamp(-scale, scale)
    }

    /// 16-bit storage: never in a build without the feature `q16`, where
    /// this folds to false.
    #[inline(always)]
    pub(crate) fn wide(self) -> bool {
        cfg!(feature = "q16") && self.wide
    }

    /// Stochastic rounding of `x`, a working component in fine units
    /// within a unit speed (every stage that changes a velocity ends with
    /// the clamp, M5.5), with the low [`Quant::FINE`] of 16 random bits `r`
    /// (M1c): `(x + r) >> FINE`. Its mean is `x / 2^FINE` exactly, and a
    /// whole number of quanta comes back as it is.
    #[inline(always)]
    pub(crate) fn stochastic(self, x: i32, r: u32) -> i32 {
        debug_assert!((-self.unit..=self.unit).contains(&x));
        (x + (r & self.low) as i32) >> self.fine
    }

    /// M1: every component of `x` (in fine units) rounded stochastically,
    /// 16 bits of the stream a component: 32 bits in 2D, a whole 64-bit
    /// output in 3D.
    #[inline(always)]
    pub(crate) fn round<const D: usize>(self, x: [i32; 3], rng: &mut Stream) -> [i32; D] {
        let r = if D == 2 { u64::from(rng.bits(32)) } else { rng.next_u64() };
        let mut out = [0; D];
        for k in 0..D {
            out[k] = self.stochastic(x[k], (r >> (16 * k)) as u32);
        }
        out
    }

    /// [`Quant::move_limit`] of this width's type.
    #[inline(always)]
    pub(crate) fn move_limit(self, table: &[u16; 256], drift: Drift, q: i32) -> u32 {
        #[cfg(feature = "q16")]
        if self.wide() {
            return i16::move_limit(table, drift, q);
        }
        i8::move_limit(table, drift, q)
    }
}

/// `round(p 2^16)` for `p = a/S` (paper) and `p = 2a/(S + a)`
/// (calibrated), `a` in quanta of `1/S`, in integers so the thresholds are
/// exact and the same on every target.
const fn threshold(calibrated: bool, a: u32, scale: u32) -> u32 {
    let (num, den) = if calibrated { (2 * a as u64, (scale + a) as u64) } else { (a as u64, scale as u64) };
    (((num << 17) + den) / (2 * den)) as u32
}

/// Per stored byte `q` (as `u8`), one less than the threshold of `|q|`:
/// every `q != 0` has a threshold of at least 1 (516 at `|q| = 1`), so
/// "below the threshold" is "at most the entry", and `|q| = 127` (p = 1)
/// always moves with entry 65535.
const fn move_table(calibrated: bool) -> [u16; 256] {
    let mut t = [0; 256];
    let mut b = 1;
    while b < 256 {
        let q = b as u8 as i8 as i32;
        let a = if q < 0 { -q } else { q };
        t[b] = (threshold(calibrated, if a > 127 { 127 } else { a } as u32, 127) - 1) as u16;
        b += 1;
    }
    t
}

static PAPER_8: [u16; 256] = move_table(false);
static CALIBRATED_8: [u16; 256] = move_table(true);

/// The high bytes of a move table's entries: what M5.3 compares a random
/// byte with first for 8-bit velocities, without the shift.
#[cfg(not(feature = "small-step"))]
const fn tops(table: &[u16; 256]) -> [u8; 256] {
    let mut t = [0; 256];
    let mut b = 0;
    while b < 256 {
        t[b] = (table[b] >> 8) as u8;
        b += 1;
    }
    t
}

#[cfg(not(feature = "small-step"))]
static PAPER_TOPS_8: [u8; 256] = tops(&move_table(false));
#[cfg(not(feature = "small-step"))]
static CALIBRATED_TOPS_8: [u8; 256] = tops(&move_table(true));

/// The 8-bit move table of a drift rule.
pub(crate) fn move_table_8(drift: Drift) -> &'static [u16; 256] {
    match drift {
        Drift::Paper => &PAPER_8,
        Drift::Calibrated => &CALIBRATED_8,
    }
}

/// The high bytes of [`move_table_8`]'s entries for a drift rule.
#[cfg(not(feature = "small-step"))]
pub(crate) fn move_tops_8(drift: Drift) -> &'static [u8; 256] {
    match drift {
        Drift::Paper => &PAPER_TOPS_8,
        Drift::Calibrated => &CALIBRATED_TOPS_8,
    }
}

impl Quant for i8 {
    const SCALE: f32 = 127.0;
    const FINE: u32 = 16;
    const UNIT: i32 = 127 << 16;
    const LANES: bool = true;
    #[inline(always)]
    fn lanes_2d<const D: usize>(pair: [[Self; D]; 2]) -> u32 {
        u32::from_le_bytes([pair[0][0] as u8, pair[0][1] as u8, pair[1][0] as u8, pair[1][1] as u8])
    }
    #[inline(always)]
    fn pair_from_lanes<const D: usize>(lanes: u32) -> [[Self; D]; 2] {
        let b = lanes.to_le_bytes().map(|b| b as i8);
        let mut pair = [[0; D]; 2];
        (pair[0][0], pair[0][1], pair[1][0], pair[1][1]) = (b[0], b[1], b[2], b[3]);
        pair
    }
    #[inline]
    fn from_int(q: i32) -> Self {
        q.clamp(-127, 127) as i8
    }
    #[inline]
    fn to_int(self) -> i32 {
        i32::from(self)
    }
    #[inline]
    fn move_limit(table: &[u16; 256], _: Drift, q: i32) -> u32 {
        u32::from(table[usize::from(q as u8)])
    }
}

#[cfg(feature = "q16")]
impl Quant for i16 {
    const SCALE: f32 = 32767.0;
    const FINE: u32 = 12;
    const UNIT: i32 = 32767 << 12;
    const LANES: bool = false;
    fn lanes_2d<const D: usize>(_: [[Self; D]; 2]) -> u32 {
        0
    }
    fn pair_from_lanes<const D: usize>(_: u32) -> [[Self; D]; 2] {
        [[0; D]; 2]
    }
    #[inline]
    fn from_int(q: i32) -> Self {
        q.clamp(-32767, 32767) as i16
    }
    #[inline]
    fn to_int(self) -> i32 {
        i32::from(self)
    }
    #[inline]
    fn move_limit(_: &[u16; 256], drift: Drift, q: i32) -> u32 {
        // 32,768 thresholds would not fit a table: the 8-bit table's
        // formula, computed for the one component.
        threshold(drift == Drift::Calibrated, q.unsigned_abs().min(32767), 32767).saturating_sub(1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rules::rng::block_stream;

    fn mean_of<Q: Quant>(x: i32, n: u32) -> f64 {
        let mut rng = block_stream(3, 0, 0);
        (0..n).map(|_| f64::from(Width::of::<Q>().stochastic(x, rng.bits(16)))).sum::<f64>() / f64::from(n)
    }

    /// `x` quanta in fine units of `Q`, to nearest.
    fn fine<Q: Quant>(x: f64) -> i32 {
        (x * f64::from(1u32 << Q::FINE)).round() as i32
    }

    #[test]
    fn rounding_up_happens_for_the_fraction_of_draws() {
        // Expect: over all 2^16 values of r, x = lo + phi (phi fine units
        // above lo quanta) rounds up for exactly phi 2^(16 - F) of them,
        // for both signs and widths. Under Miri every 64th r: the values
        // of r that round up are the top phi of each 2^F, which the sample
        // meets every 64th of, so it counts them / 64 to within 63 in each
        // of the 2^(16 - F) periods (exact where every r is drawn).
        let stride = crate::sized(1, 64);
        fn check<Q: Quant>(stride: usize) {
            for x in [10.3f64, -9.7, 0.3, -0.7, 0.0, 126.99, -126.01] {
                let x = fine::<Q>(x);
                let lo = x >> Q::FINE;
                let phi = x - (lo << Q::FINE);
                let ups = (0..1u32 << 16).step_by(stride).filter(|&r| Width::of::<Q>().stochastic(x, r) == lo + 1).count();
                let want = (phi as usize) << (16 - Q::FINE);
                assert!((ups * stride).abs_diff(want) <= (stride - 1) << (16 - Q::FINE), "{x}: {ups}");
            }
        }
        check::<i8>(stride);
        #[cfg(feature = "q16")]
        check::<i16>(stride);
    }

    #[test]
    fn stochastic_rounding_is_unbiased() {
        // x sits 0.3 quanta above a grid point (and below one, negative);
        // each draw is the lower point plus a Bernoulli(0.3) quantum, sd of
        // the mean = sqrt(.21/n) quanta.
        let n = crate::sized(100_000, 4_000) as u32;
        let sd = (0.21f64 / f64::from(n)).sqrt();
        for want in [10.3f64, -9.7, 0.3, -0.7] {
            let mean = mean_of::<i8>(fine::<i8>(want), n);
            assert!((mean - want).abs() < 5.0 * sd, "{want}: {mean}");
        }
    }

    #[test]
    fn integers_in_quanta_stay_put() {
        for q in -127..=127 {
            for r in [0, 1, 0x7fff, 0xffff] {
                assert_eq!(Width::of::<i8>().stochastic(q << 16, r), q);
            }
        }
        assert_eq!(Width::of::<i8>().stochastic(i8::UNIT, 0xffff), 127);
        assert_eq!(Width::of::<i8>().stochastic(-i8::UNIT, 0xffff), -127);
        #[cfg(feature = "q16")]
        assert_eq!(Width::of::<i16>().stochastic(-32767 << 12, 0), -32767);
    }

    #[test]
    fn nearest_round_trips_every_stored_value() {
        for q in -127..=127 {
            assert_eq!(Width::of::<i8>().nearest(i8::from_int(q).get()), q);
        }
    }

    #[test]
    fn move_decisions_follow_the_rounded_probabilities() {
        // Expect: for every stored value but 0, exactly round(p 2^16) of the
        // 2^16 values of r say "move" (within 0.5 of p 2^16; for 16-bit
        // storage within 0.51, the f32 rounding of a/32767), all of them at
        // full speed, for both widths and rules. Under Miri every 8th value
        // and every 64th r: a move is r below a threshold, so the sample
        // counts the threshold / 64, rounded up, and the bands widen by 64.
        let (every, stride) = (crate::sized(1, 8), crate::sized(1, 64));
        let slack = (stride - 1) as f64;
        let moves = |f: &dyn Fn(u32) -> bool| (0..1u32 << 16).step_by(stride).filter(|&r| f(r)).count() as f64 * stride as f64;
        for drift in [Drift::Paper, Drift::Calibrated] {
            let p = |a: f64| if drift == Drift::Paper { a } else { 2.0 * a / (1.0 + a) };
            let table = move_table_8(drift);
            for q in (-127..=127).step_by(every).filter(|&q| q != 0) {
                let want = p(f64::from(q).abs() / 127.0) * 65536.0;
                let got = moves(&|r| r <= i8::move_limit(table, drift, q));
                assert!((got - want).abs() <= 0.5 + slack, "{drift:?} {q}: {got} vs {want}");
            }
            assert_eq!(moves(&|r| r <= i8::move_limit(table, drift, -127)), 65536.0);
            #[cfg(feature = "q16")]
            for q in [-32767, -20000, -1, 1, 777, 32767] {
                let want = p(f64::from(q).abs() / 32767.0) * 65536.0;
                let got = moves(&|r| r <= i16::move_limit(table, drift, q));
                assert!((got - want).abs() <= 0.51 + slack, "{drift:?} {q}: {got} vs {want}");
            }
        }
    }
}
