//! The step's integer arithmetic (M1c): working velocities in fine units,
//! the few operations that need more than 32 bits, the vortex's one 32-bit
//! division, the exact conversion of a float setting to an integer, and
//! the table of turns that the 2D collision reads. Every function here
//! gives the same integer on every target; none computes in floating
//! point.

/// The bound a stage saturates a working component to (M1c): at least
/// eight unit speeds at either width, far above anything but an absurd
/// force. Every stage after the first clamp (M5.5) reads velocities within
/// a unit speed, below `2^27`, so their differences and products with the
/// share, table and normal constants fit their operations.
pub(crate) const BOUND: i32 = 1 << 30;

/// `x` saturated to `[-BOUND, BOUND]`.
#[inline(always)]
pub(crate) fn sat(x: i64) -> i32 {
    x.clamp(-i64::from(BOUND), i64::from(BOUND)) as i32
}

/// `a b / 2^s` rounded to nearest, halves up (M1c `mulq`): a wide
/// product, a half added, an arithmetic shift. Rounded rather than cut,
/// so that a stage that multiplies (drag, a turn, a reflection) moves no
/// velocity a little the same way every time. Where it is used the result
/// fits an `i32`.
#[cfg_attr(feature = "small-step", inline(never))]
#[cfg_attr(not(feature = "small-step"), inline(always))]
pub(crate) fn mulq(a: i32, b: i32, s: u32) -> i32 {
    ((i64::from(a) * i64::from(b) + (1 << (s - 1))) >> s) as i32
}

/// A summed velocity `x` (64 bits a component) brought within the bound
/// with its direction kept (M1c): every component shifted right by the
/// same count, the fewest that make the largest fit. An enormous push
/// thus keeps its direction into the clamp (M5.5), where saturating each
/// component would turn it towards a diagonal.
#[inline]
pub(crate) fn fit(x: [i64; 3]) -> [i32; 3] {
    let m = x.iter().fold(0u64, |m, &c| m | c.unsigned_abs());
    let shift = (64 - m.leading_zeros()).saturating_sub(30);
    x.map(|c| (c >> shift) as i32)
}

/// The squared length of the first `D` components (M1c `sq`), exact.
#[inline(always)]
pub(crate) fn sq<const D: usize>(x: [i32; 3]) -> u64 {
    let mut s = 0u64;
    for k in 0..D {
        s += (i64::from(x[k]) * i64::from(x[k])) as u64;
    }
    s
}

/// `a / b` rounded down, `b > 0`: every division of the step goes through
/// here. On 32-bit Arm (no instruction divides 64 bits) by shifting and
/// subtracting, one quotient bit a round: a short loop in flash where the
/// runtime's routine is long; elsewhere the instruction.
#[inline]
pub(crate) fn udiv(a: u64, b: u64) -> u64 {
    if cfg!(target_arch = "arm") { shift_subtract(a, b) } else { a / b }
}

/// [`udiv`] by shift and subtract (tested against `/` on every target).
#[inline(never)]
fn shift_subtract(a: u64, b: u64) -> u64 {
    if a < b {
        return 0;
    }
    let shift = b.leading_zeros() - a.leading_zeros();
    let (mut rest, mut d, mut q) = (a, b << shift, 0u64);
    for _ in 0..=shift {
        q <<= 1;
        if rest >= d {
            rest -= d;
            q |= 1;
        }
        d >>= 1;
    }
    q
}

/// `floor(sqrt(n))` (M1c `isqrt`).
#[inline]
pub(crate) fn isqrt(n: u64) -> u64 {
    isqrt_from(n, 1 << ((64 - n.leading_zeros()).div_ceil(2)))
}

/// `floor(sqrt(n))` by Newton's iteration from `guess` (any positive
/// value; the nearer the root, the fewer rounds): one round from any guess
/// lands at or above the root's floor, and the rounds after it decrease to
/// it, which they have reached once the square is at most `n`. A caller
/// that knows the root is near a value (the clamp, M5.5: near the unit
/// speed) passes it. On 32-bit Arm, whose cores divide 64 bits only by
/// shifting and subtracting (each round of Newton's a long division), digit
/// by digit instead, without the guess.
#[inline(never)]
pub(crate) fn isqrt_from(n: u64, guess: u64) -> u64 {
    if cfg!(target_arch = "arm") {
        return isqrt_by_digits(n);
    }
    if n < 2 {
        return n;
    }
    // From 4 up the first sum cannot overflow.
    let guess = guess.max(4);
    let mut x = (guess + udiv(n, guess)) / 2;
    while x.checked_mul(x).is_none_or(|s| s > n) {
        x = (x + udiv(n, x)) / 2;
    }
    x
}

/// `floor(sqrt(n))` digit by digit, one result bit a round from the
/// highest power of four at most `n`: 64-bit shifts, adds and compares, no
/// division (tested against Newton's iteration).
fn isqrt_by_digits(n: u64) -> u64 {
    if n == 0 {
        return 0;
    }
    let (mut rest, mut root, mut bit) = (n, 0u64, 1u64 << ((63 - n.leading_zeros()) & !1));
    while bit != 0 {
        if rest >= root + bit {
            rest -= root + bit;
            root = (root >> 1) + bit;
        } else {
            root >>= 1;
        }
        bit >>= 2;
    }
    root
}

/// `sqrt(n)` rounded to the nearest integer: where a length multiplies a
/// direction (the 3D collision, contacts), rounding down would shorten
/// every result a little, the same way, and cool the gas.
#[inline]
pub(crate) fn rsqrt(n: u64) -> u64 {
    let r = isqrt(n);
    // sqrt(n) >= r + 1/2 exactly when n >= r^2 + r + 1/4, that is n > r^2 + r.
    r + u64::from(n - r * r > r)
}

/// `ceil(sqrt(n))`, from `guess` as [`isqrt_from`] takes it: the clamp
/// (M5.5) divides by it, so that what it scales is never longer than the
/// limit.
#[inline]
pub(crate) fn csqrt(n: u64, guess: u64) -> u64 {
    let r = isqrt_from(n, guess);
    r + u64::from(r * r < n)
}

/// M5.5 in fine units (M1c): `x`, of squared length `s2` above `unit^2`,
/// scaled back: each component's magnitude times the factor
/// `floor(2^32 unit / L)`, shifted down by 32 and rounded down, with `L`
/// the length rounded up, so the result is never longer than `unit`.
pub(crate) fn shorten(mut x: [i32; 3], s2: u64, unit: i32, dim: usize) -> [i32; 3] {
    // L > unit, so the factor is below 2^32, and a component (at most
    // 2^30) times it fits 64 bits; L is below 2^31 (three such components).
    let length = csqrt(s2, unit as u64);
    let factor = if cfg!(target_arch = "arm") { u64::from(fraction(unit as u32, length as u32)) } else { udiv((unit as u64) << 32, length) };
    for c in x.iter_mut().take(dim) {
        let scaled = ((u64::from(c.unsigned_abs()) * factor) >> 32) as i32;
        *c = if *c < 0 { -scaled } else { scaled };
    }
    x
}

/// `floor(a / n)` where the quotient is below `2^16` and `n` below `2^17`:
/// the vortex's one division (M1c). On 32-bit Arm by shifting and
/// subtracting, as [`udiv`] does, in 16 rounds with no test for their
/// number, where the runtime's general routine is long (Armv6-M has no
/// divide instruction); elsewhere the instruction.
#[inline]
pub(crate) fn quotient16(a: u32, n: u32) -> u32 {
    if cfg!(target_arch = "arm") { quotient16_by_rounds(a, n) } else { a / n }
}

/// [`quotient16`] by shift and subtract (tested against `/`).
fn quotient16_by_rounds(a: u32, n: u32) -> u32 {
    long_division(a, n << 15, 16)
}

/// `floor(2^32 a / b)` for `a < b` below `2^31`: the clamp's factor where
/// 64-bit division is shift and subtract (tested against it).
fn fraction(a: u32, b: u32) -> u32 {
    long_division(a << 1, b, 32)
}

/// `floor(rest 2^(rounds - 1) / d)` for `rest < 2d` and `d` at most
/// `2^31`, one quotient bit a round: the remainder stays below `2d`, so
/// in 32 bits. The shift and subtract of [`quotient16`] and of the
/// clamp's factor.
fn long_division(mut rest: u32, d: u32, rounds: u32) -> u32 {
    let mut q = 0;
    for _ in 0..rounds {
        q <<= 1;
        if rest >= d {
            rest -= d;
            q |= 1;
        }
        rest <<= 1;
    }
    q
}

/// `x` clamped to `unit` ([`shorten`] where it is longer), uncounted.
pub(crate) fn clamp_to<const D: usize>(x: [i32; 3], unit: i32) -> [i32; 3] {
    let s2 = sq::<D>(x);
    if s2 > (unit as u64) * (unit as u64) { shorten(x, s2, unit, D) } else { x }
}

/// `a / b` rounded to the nearest integer, halves up, for `a >= 0`,
/// `b > 0` (M1c `divr`).
#[inline]
pub(crate) fn divr(a: u64, b: u64) -> u64 {
    udiv(a + b / 2, b)
}

/// `|x| = m 2^e` of a finite float (`m` below `2^24`), and its sign.
#[inline]
pub(crate) fn parts(x: f32) -> (bool, u64, i32) {
    let bits = x.to_bits();
    let exponent = (bits >> 23 & 0xff) as i32;
    let fraction = u64::from(bits & 0x7f_ffff);
    let (m, e) = if exponent == 0 { (fraction, -149) } else { (fraction | 1 << 23, exponent - 150) };
    (bits >> 31 != 0, m, e)
}

/// The most [`scaled`] returns: the few terms of a push (M5.1), each at
/// most this or twice it (a difference of potentials), add up within 64
/// bits without a test.
pub(crate) const SCALED_MAX: u64 = 1 << 59;

/// `a b 2^shift` rounded to the nearest integer, halves away from zero,
/// saturated to `±2^59` (M1c's `conv`): [`scaled_by`] with `c = 1`.
#[inline]
pub(crate) fn scaled(a: f32, b: f32, shift: i32) -> i64 {
    scaled_by(a, b, 1, shift)
}

/// `a b c 2^shift` for a whole `c` below `2^15`, rounded to the nearest
/// integer, halves away from zero, saturated to `±2^59` (M1c's `conv`):
/// the exact product of the two significands and `c` (below `2^63`)
/// shifted, so no rounding but the last. NaN gives 0, an infinity (or an
/// infinite product) saturates.
#[inline(never)]
pub(crate) fn scaled_by(a: f32, b: f32, c: u32, shift: i32) -> i64 {
    let nan = |x: f32| x.to_bits() & 0x7fff_ffff > 0x7f80_0000;
    if nan(a) || nan(b) {
        return 0;
    }
    let (sa, ma, ea) = parts(a);
    let (sb, mb, eb) = parts(b);
    let p = ma * mb * u64::from(c);
    let e = ea + eb + shift;
    let magnitude = if p == 0 {
        0
    } else if e >= 0 {
        if e >= 59 || p > SCALED_MAX >> e { SCALED_MAX } else { p << e }
    } else if e < -63 {
        // p < 2^63: the product is below a half.
        0
    } else {
        ((p >> (-e - 1)) + 1) >> 1
    };
    let magnitude = magnitude.min(SCALED_MAX) as i64;
    if sa != sb { -magnitude } else { magnitude }
}

/// The magnitude of a finite float as `(m, e)`, `|x| = m 2^e` with `m`
/// below `2^24`: what [`quot`] takes.
#[inline]
pub(crate) fn magnitude(x: f32) -> (u32, i32) {
    let (_, m, e) = parts(x);
    (m as u32, e)
}

/// The quotient `2^shift a / b` of `a = am 2^ae` and `b = bm 2^be`
/// (`am`, `bm` below `2^24`, `bm` not 0) as a float made from integers
/// alone (M1c's `quot`): both significands normalised to 24 bits, the 26
/// bits `q = floor(am 2^25 / bm)` by long division, `q` rounded to 24
/// significant bits, halves up. 0 where `am` is 0 or the quotient lies
/// below the normal floats, infinity above them.
pub(crate) fn quot((am, ae): (u32, i32), (bm, be): (u32, i32), shift: i32) -> f32 {
    if am == 0 {
        return 0.0;
    }
    let (la, lb) = (am.leading_zeros() - 8, bm.leading_zeros() - 8);
    let (a, b) = (am << la, bm << lb);
    // a / b lies between 1/2 and 2: its bits from 2^0 down to 2^-25.
    let (mut rest, mut q) = (a, 0u32);
    for _ in 0..26 {
        q <<= 1;
        if rest >= b {
            rest -= b;
            q |= 1;
        }
        rest <<= 1;
    }
    let z = 8 - q.leading_zeros() as i32;
    let mut m = (q + (1 << (z - 1))) >> z;
    let mut e = ae - la as i32 - be + lb as i32 - 25 + z + shift;
    if m >> 24 != 0 {
        // Rounded up to 2^24.
        m >>= 1;
        e += 1;
    }
    match e + 150 {
        ..=0 => 0.0,
        255.. => f32::INFINITY,
        biased => f32::from_bits((biased as u32) << 23 | (m & 0x7f_ffff)),
    }
}

/// A unit speed of `unit = W = S 2^F` fine units (M1c) as `(S, F)`: `S`
/// is odd (127 or 32767), so `F` is the count of trailing zeros.
#[inline]
pub(crate) fn unit_scale(unit: i32) -> (u32, i32) {
    let fine = unit.trailing_zeros();
    ((unit >> fine) as u32, fine as i32)
}

/// The speed `a` (in unit speeds) in fine units of a world whose unit
/// speed is `(s, fine)` ([`unit_scale`]): `conv(a, W, 0)` ([`scaled_by`]),
/// saturated to a working component's bound.
#[inline]
pub(crate) fn to_fine(a: f32, (s, fine): (u32, i32)) -> i32 {
    sat(scaled_by(a, 1.0, s, fine))
}

/// `floor(n g)` for a count `n` and a float factor `g >= 0` (finite), to a
/// few parts in 2^16: `n` is cut to its top 40 bits first, so the product
/// fits 64. For a counter of error (the clamp's energy, M10), not for the
/// world.
pub(crate) fn count_times(n: u64, g: f32) -> u64 {
    let (negative, m, e) = parts(g);
    if negative || n == 0 || m == 0 {
        return 0;
    }
    let cut = (64 - n.leading_zeros()).saturating_sub(40) as i32;
    let p = (n >> cut) * m;
    let e = e + cut;
    if e >= 0 {
        if e >= 64 || p > u64::MAX >> e { u64::MAX } else { p << e }
    } else if e <= -64 {
        0
    } else {
        p >> -e
    }
}

/// Turns of the 2D collision (M5.2): 1,024 angles.
pub(crate) const TURNS: u32 = 1024;

/// `round(2^30 sin(2 pi j / 1024))` for `j` in `0..=256`: the quarter wave,
/// the rest by symmetry ([`turn`]). Computed at build time from a Taylor
/// series in `f64`, far finer than the last place of the entries.
static QUARTER_SINE: [i32; 257] = {
    let mut t = [0i32; 257];
    let mut j = 0;
    while j <= 256 {
        let x = core::f64::consts::TAU * j as f64 / 1024.0;
        // sin x = x - x^3/3! + x^5/5! - ..., to x^29/29! (below 1e-27 at
        // x = pi/2).
        let (mut term, mut sum, mut n) = (x, x, 1u32);
        while n < 29 {
            term = -term * x * x / ((n + 1) as f64 * (n + 2) as f64);
            sum += term;
            n += 2;
        }
        t[j] = (sum * 1_073_741_824.0 + 0.5) as i32;
        j += 1;
    }
    t
};

/// `(round(2^30 cos θ), round(2^30 sin θ))` for `θ = 2 pi j / 1024`, `j`
/// below 1,024.
#[inline]
pub(crate) fn turn(j: u32) -> (i32, i32) {
    let sine = |j: u32| {
        let (quadrant, i) = (j >> 8 & 3, (j & 255) as usize);
        let s = if quadrant & 1 == 0 { QUARTER_SINE[i] } else { QUARTER_SINE[256 - i] };
        if quadrant >= 2 { -s } else { s }
    };
    (sine(j + 256), sine(j))
}

/// `round(2^30 / sqrt(2))` and `round(2^30 / sqrt(3))`: the components of a
/// unit diagonal in Q30 (M5.4, M5.7).
pub(crate) const DIAGONAL_Q30: [i32; 2] = [759_250_125, 619_925_131];

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::rules::rng::block_stream;

    #[test]
    fn shift_and_subtract_is_the_division() {
        // Expect: the quotient of `/` for random operands of every size,
        // and at the edges.
        let mut rng = block_stream(24, 0, 0);
        for _ in 0..crate::sized(100_000, 2_000) {
            let a = rng.next_u64() >> rng.bits(6);
            let b = (rng.next_u64() >> rng.bits(6)).max(1);
            assert_eq!(shift_subtract(a, b), a / b, "{a} / {b}");
            assert_eq!(udiv(a, b), a / b);
        }
        for (a, b) in [(0, 1), (u64::MAX, 1), (u64::MAX, u64::MAX), (u64::MAX - 1, u64::MAX), (1 << 63, 3)] {
            assert_eq!(shift_subtract(a, b), a / b, "{a} / {b}");
        }
    }

    #[test]
    fn isqrt_is_the_floor_of_the_root() {
        // Expect: r^2 <= n < (r + 1)^2, for small n, squares and their
        // neighbours, and random n of every size below 2^56.
        let check = |n: u64| {
            let r = isqrt(n);
            assert!(r * r <= n && (r + 1) * (r + 1) > n, "{n}: {r}");
            let near = rsqrt(n);
            assert!((near as f64 - (n as f64).sqrt()).abs() <= 0.5 + 1e-9, "{n}: {near}");
            let up = csqrt(n, 1 + n % 1000);
            assert_eq!(isqrt_from(n, 1 + n % 77), r);
            assert_eq!(isqrt_by_digits(n), r);
            assert!(up * up >= n && (up == 0 || (up - 1) * (up - 1) < n), "{n}: {up}");
        };
        for n in 0..10_000 {
            check(n);
        }
        for r in [1u64, 255, 65_535, 1 << 20, (1 << 28) - 1] {
            for n in [r * r - 1, r * r, r * r + r, r * r + r + 1] {
                check(n);
            }
        }
        let mut rng = block_stream(21, 0, 0);
        for _ in 0..crate::sized(100_000, 2_000) {
            check(rng.next_u64() >> (8 + rng.bits(6) % 48));
        }
    }

    #[test]
    fn fraction_is_the_quotient() {
        // Expect: floor(2^32 a / b) for a < b, at the ends of the range and
        // at random.
        let mut rng = block_stream(47, 0, 0);
        for _ in 0..crate::sized(100_000, 2_000) {
            let b = (rng.bits(31) >> rng.bits(5)).max(1);
            for a in [0, b - 1, rng.bits(32) % b] {
                assert_eq!(u64::from(fraction(a, b)), (u64::from(a) << 32) / u64::from(b), "{a} / {b}");
            }
        }
    }

    #[test]
    fn quotient16_by_rounds_divides() {
        // Expect: the quotient for every divisor from 2^14 to 2^16 (every
        // 97th under Miri), with dividends at both ends of their range (a
        // quotient below 2^16) and between.
        let mut rng = block_stream(43, 0, 0);
        for n in (1 << 14..=1 << 16).step_by(crate::sized(1, 97)) {
            let most = (u64::from(n) << 16).min(1 << 32) - 1;
            for a in [0, 1, n - 1, n, most as u32, rng.bits(32) % (most as u32), rng.bits(31) % (most as u32)] {
                assert_eq!(quotient16_by_rounds(a, n), a / n, "{a} / {n}");
            }
        }
    }

    #[test]
    fn scaled_is_the_rounded_exact_product() {
        // Expect: for random floats of every size and sign, the product
        // computed in f64 (exact: 48 significant bits) times 2^shift,
        // rounded half away from zero and saturated; NaN 0, infinities
        // saturated, a product below a half 0.
        let mut rng = block_stream(22, 0, 0);
        for _ in 0..crate::sized(100_000, 2_000) {
            let f = |rng: &mut crate::rules::rng::Stream| f32::from_bits(rng.bits(32) & 0x807f_ffff | (100 + rng.bits(7) % 60) << 23);
            let (a, b, shift) = (f(&mut rng), f(&mut rng), rng.bits(5) as i32 - 8);
            // 2^shift from its bits: exact, where Miri lets `powi` round.
            let exact = f64::from(a) * f64::from(b) * f64::from_bits(((1023 + shift) as u64) << 52);
            let want = exact.abs().round().min(SCALED_MAX as f64).copysign(exact) as i64;
            assert_eq!(scaled(a, b, shift), want, "{a:e} {b:e} {shift}");
        }
        assert_eq!(scaled(f32::NAN, 1.0, 0), 0);
        assert_eq!(scaled(f32::INFINITY, -1.0, 0), -(SCALED_MAX as i64));
        assert_eq!(scaled(f32::INFINITY, 0.0, 0), 0);
        assert_eq!(scaled(2.5, 1.0, 0), 3);
        assert_eq!(scaled(-2.5, 1.0, 0), -3);
        assert_eq!(scaled(1.0, 1.0, 30), 1 << 30);
        assert_eq!(to_fine(1e30, (1, 0)), BOUND);
    }

    #[test]
    fn mulq_rounds_to_nearest_and_fit_keeps_the_direction() {
        assert_eq!(mulq(3, 1 << 15, 16), 2); // 1.5 up
        assert_eq!(mulq(-3, 1 << 15, 16), -1); // -1.5 up
        assert_eq!(mulq(5, 1 << 14, 16), 1); // 1.25
        assert_eq!(mulq(-7, 1 << 14, 16), -2); // -1.75
        assert_eq!(fit([5, -7, 0]), [5, -7, 0]);
        let big = fit([3 << 40, -(4 << 40), 1 << 20]);
        assert!(big[1].unsigned_abs() < 1 << 30 && big[1].unsigned_abs() >= 1 << 29, "{big:?}");
        assert_eq!(i64::from(big[0]) * 4, -i64::from(big[1]) * 3);
    }

    #[test]
    fn quot_is_the_quotient_to_a_float_s_last_place() {
        // Expect: within one unit in the last place of the exact quotient
        // (the floor, then the rounding to 24 bits), for significands of
        // every length below 2^24 and exponents and shifts of either sign,
        // exact where the quotient is a power of two; 0 for a numerator of
        // 0, and beyond the floats' range 0 or infinity.
        let mut rng = block_stream(29, 0, 0);
        for _ in 0..crate::sized(20_000, 500) {
            let am = rng.bits(24) >> (rng.bits(5) % 24);
            let bm = (rng.bits(24) >> (rng.bits(5) % 24)).max(1);
            let (ae, be, shift) = (rng.bits(6) as i32 - 32, rng.bits(6) as i32 - 32, rng.bits(5) as i32 - 16);
            let exact = f64::from(am) / f64::from(bm) * 2f64.powi(ae - be + shift);
            let got = f64::from(quot((am, ae), (bm, be), shift));
            assert!((got - exact).abs() <= exact * 2f64.powi(-23), "{am} 2^{ae} / {bm} 2^{be}: {got:e} vs {exact:e}");
        }
        assert_eq!(quot((3 << 20, 0), (3, 4), 0), 65536.0);
        assert_eq!(quot((0, 0), (1, 0), 0), 0.0);
        assert_eq!(quot((1, -200), (1, 0), 0), 0.0);
        assert_eq!(quot((1, 200), (1, 0), 0), f32::INFINITY);
    }

    #[test]
    fn scaled_by_is_the_exact_product() {
        // Expect: round(a b c 2^s), halves away from zero, saturated at
        // 2^59, as computed in 128 bits from the significands, for random
        // finite a, b below 2^24, c below 2^15 and shifts of either sign.
        let mut rng = block_stream(30, 0, 0);
        for _ in 0..crate::sized(20_000, 500) {
            let a = f32::from_bits((rng.bits(31) % 0x4b80_0000) | (rng.bits(1) << 31));
            let b = f32::from_bits(rng.bits(31) % 0x4b80_0000);
            let c = rng.bits(15);
            let shift = rng.bits(6) as i32 - 32;
            let (sa, ma, ea) = parts(a);
            let (_, mb, eb) = parts(b);
            let p = i128::from(ma) * i128::from(mb) * i128::from(c);
            let e = ea + eb + shift;
            let want = if e >= 0 {
                if p == 0 { 0 } else { (p << e.min(60)).min(1 << 59) }
            } else if e < -100 {
                0
            } else {
                ((p >> (-e - 1)) + 1) >> 1
            }
            .min(1 << 59) as i64;
            let want = if sa { -want } else { want };
            assert_eq!(scaled_by(a, b, c, shift), want, "{a:e} {b:e} {c} {shift}");
        }
    }

    #[test]
    fn count_times_is_the_product_to_a_few_parts_in_2_16() {
        let mut rng = block_stream(23, 0, 0);
        for _ in 0..crate::sized(10_000, 500) {
            let n = rng.next_u64() >> rng.bits(6);
            let g = rng.unit() * 2f32.powi(rng.bits(6) as i32 - 40);
            let exact = (n as f64 * f64::from(g)).min(u64::MAX as f64);
            let got = count_times(n, g) as f64;
            assert!(got <= exact && got >= exact * (1.0 - 2f64.powi(-38)) - 1.0, "{n} {g:e}: {got} vs {exact}");
        }
    }

    #[test]
    fn the_turns_are_the_rounded_circle() {
        // Expect: every entry within half a unit (and 1e-6 for the series)
        // of 2^30 cos, 2^30 sin.
        for j in 0..TURNS {
            let (c, s) = turn(j);
            let t = core::f64::consts::TAU * f64::from(j) / f64::from(TURNS);
            let one = 1_073_741_824.0;
            assert!((f64::from(c) - one * t.cos()).abs() <= 0.5 + 1e-6, "{j}: cos {c}");
            assert!((f64::from(s) - one * t.sin()).abs() <= 0.5 + 1e-6, "{j}: sin {s}");
        }
        for (k, d) in DIAGONAL_Q30.iter().enumerate() {
            let want = (1_073_741_824.0 / ((k + 2) as f64).sqrt()).round();
            assert_eq!(f64::from(*d), want);
        }
    }
}
