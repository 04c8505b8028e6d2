//! The float operations of the API and of a step's set-up, outside the
//! block rule (which computes in integers, M1c): on `[f32; 3]` (the third
//! component 0 in 2D) the dot product and normalisation (of obstacle
//! normals, M7), and a division and square root correctly rounded on every
//! target, for the conversions of M1c and the checks of a caller's values.

/// Whether the core has no floating-point unit (Arm without hard float):
/// there every operation on floats but a move is a library call, and the
/// functions below that say so take an integer form of their own (each
/// tested bit for bit against the operation, on every target).
pub(crate) const NO_FPU: bool = cfg!(all(target_arch = "arm", not(target_abi = "eabihf")));

#[inline]
pub(crate) fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    dot_of::<3>(a, b)
}

/// The dot product of the first `D` components, summed in the order
/// [`dot`] sums them: where the others are 0 (a 2D velocity), the same
/// value, without the arithmetic on zeros.
#[inline(always)]
pub(crate) fn dot_of<const D: usize>(a: [f32; 3], b: [f32; 3]) -> f32 {
    let mut sum = a[0] * b[0];
    for k in 1..D {
        sum += a[k] * b[k];
    }
    sum
}

/// The square root, correctly rounded as IEEE 754 asks and as
/// `libm::sqrtf` gives it. On Arm cores with a hard-float unit (the
/// `eabihf` targets: VFP, which has the instruction) one `vsqrt.f32`,
/// where libm is a software routine with a table of its own; elsewhere
/// libm's (an instruction too where libm has one).
#[inline(always)]
pub(crate) fn sqrt(x: f32) -> f32 {
    #[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
    {
        let root: u32;
        // Through s0, saved and restored around it: Rust names the FPU's
        // registers in `asm!` only for double-precision units, and the
        // Cortex-M4F's is single-precision.
        // SAFETY: the instructions touch s0 (restored), the stack (balanced)
        // and nothing else; hard-float code has the FPU on.
        unsafe {
            core::arch::asm!(
                "vpush {{s0}}",
                "vmov s0, {x}",
                "vsqrt.f32 s0, s0",
                "vmov {root}, s0",
                "vpop {{s0}}",
                x = in(reg) x.to_bits(),
                root = lateout(reg) root,
                options(pure, nomem, preserves_flags),
            )
        };
        f32::from_bits(root)
    }
    #[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
    if NO_FPU { bitwise_sqrt(x) } else { libm::sqrtf(x) }
}

/// The square root of a non-negative `x` digit by digit in integers,
/// correctly rounded: for Arm cores without a floating-point unit, where
/// libm's routine and its table are larger. `x` is never
/// negative or NaN here (squared lengths, uniform draws); for those it
/// gives NaN, for -0 and +infinity `x`. The tests hold it to libm bit for
/// bit. Hard-float Arm cores take the instruction instead.
#[cfg_attr(all(target_arch = "arm", target_abi = "eabihf"), allow(dead_code))]
fn bitwise_sqrt(x: f32) -> f32 {
    let bits = x.to_bits();
    if bits & 0x7fff_ffff == 0 || bits == 0x7f80_0000 {
        return x; // +-0, +infinity
    }
    if bits > 0x7f80_0000 {
        return f32::NAN; // negative or NaN
    }
    // x = m 2^(k - 23) with m of 24 significant bits ([`unpack`]); a
    // subnormal's top bit then brought to bit 23.
    let (mut m, f) = unpack(bits);
    let mut k = f - 127;
    while m < 0x80_0000 {
        m <<= 1;
        k -= 1;
    }
    if k & 1 != 0 {
        // An even exponent, so that it halves exactly.
        m <<= 1;
        k -= 1;
    }
    // sqrt(x) = sqrt(m 2^23) 2^(k/2 - 23): the root of n = m 2^23 (below
    // 2^48) to 24 bits, in 32-bit integers: two bits of n at a time, from
    // the top. With r the root of the part of n taken so far and rest that
    // part less r^2, two more bits make the part 4 times larger plus them,
    // its remainder for the root 2r 4 rest plus them, and for 2r + 1 less
    // (2r + 1)^2 - (2r)^2 = 4r + 1: the root gains a bit 1 where the
    // remainder holds that, else a 0. The remainder stays at most 2r,
    // below 2^25, and below 2^26 shifted. n's bits come from m placed at
    // the top of a word (its 25 bits are n's top 25; the 23 below are
    // zeros). The first two bits (m's top, at least 1) give the root's
    // first bit, 1, which then marks how many have been taken.
    let (mut rest, mut root, mut next) = ((m >> 23) - 1, 1u32, m << 9);
    while root < 1 << 23 {
        rest = rest << 2 | next >> 30;
        next <<= 2;
        // As in bitwise_div: borrow all ones where the remainder does not
        // hold 4r + 1 (both below 2^26, so the sign bit tells), else 0;
        // the root's next bit is 1 plus borrow, and 4r + 1 is added back
        // where it borrowed.
        let trial = root << 2 | 1;
        let less = rest.wrapping_sub(trial);
        let borrow = ((less as i32) >> 31) as u32;
        root = (root << 1 | 1).wrapping_add(borrow);
        rest = less.wrapping_add(trial & borrow);
    }
    // Nearest: up where n > (root + 1/2)^2 = root^2 + root + 1/4, that is
    // rest > root (never a tie). A root of 2^24 carries into the exponent.
    let root = root + u32::from(rest > root);
    f32::from_bits((((k / 2 + 127) as u32) << 23) + (root - 0x80_0000))
}

/// `a / b`, correctly rounded as IEEE 754 asks. On Arm cores without a
/// floating-point unit [`bitwise_div`], smaller than the
/// Rust runtime's `__divsf3` it replaces; elsewhere the division itself
/// (an instruction, or the runtime's routine where the core has none).
#[inline(always)]
pub(crate) fn div(a: f32, b: f32) -> f32 {
    if NO_FPU { bitwise_div(a, b) } else { a / b }
}

/// A finite, non-negative `f32`'s bits as `(m, f)` with the value
/// `m 2^(f - 150)`: `f` its exponent field, `m` its 23 bits with the
/// implicit top one at bit 23 (the bits less the field, plus 1); a
/// subnormal (field 0) is its bits, scaled as field 1. For the integer
/// forms of the square root and the division.
#[inline(always)]
fn unpack(bits: u32) -> (u32, i32) {
    let f = (bits >> 23).max(1);
    (bits - ((f - 1) << 23), f as i32)
}

/// `a / b` by long division of the significands in 32-bit integers,
/// correctly rounded (to nearest, ties to even): for Arm cores without a
/// floating-point unit, where the runtime's `__divsf3` takes some 530
/// bytes and multiplies in 64 bits (itself a library call there).
///
/// Every IEEE case comes out as the division gives it: a NaN operand comes
/// back quieted (the first one where both are NaN, as x86-64 and the
/// runtime's routine pick), `0 / 0` and `inf / inf` are `f32::NAN`,
/// `x / 0` and `inf / x` signed infinities, `0 / x` and `x / inf` signed
/// zeros; subnormal operands and results, and overflow to infinity, are
/// rounded as any other. The tests hold it to the division bit for bit.
fn bitwise_div(a: f32, b: f32) -> f32 {
    const INF: u32 = 0x7f80_0000;
    let (x, y) = (a.to_bits(), b.to_bits());
    let sign = (x ^ y) & 0x8000_0000;
    let (ax, ay) = (x & 0x7fff_ffff, y & 0x7fff_ffff);
    if ax > INF || ay > INF {
        // A NaN operand, quieted: the first where both are.
        return f32::from_bits(if ax > INF { x } else { y } | 0x40_0000);
    }
    if ax == INF || ay == 0 {
        // inf / inf and 0 / 0 are NaN; x / 0 and inf / x infinite.
        return if ax == ay { f32::NAN } else { f32::from_bits(sign | INF) };
    }
    if ax == 0 || ay == INF {
        return f32::from_bits(sign); // 0 / x, x / inf
    }
    if y == 1.0f32.to_bits() {
        // x / 1 is x, exactly: the divisor of most calls (a mass of 1),
        // without the 26 steps of the long division.
        return a;
    }
    // Each operand as m 2^(f - 150) ([`unpack`]).
    let (mut ma, fa) = unpack(ax);
    let (mut mb, fb) = unpack(ay);
    // The quotient of the significands brought to [1, 2), that is mb <= ma
    // < 2 mb, doubling the smaller (a subnormal's may take 23 doublings),
    // with e the result's biased exponent: ma stays below 2^25, mb below
    // 2^24.
    let mut e = fa - fb + 127;
    while ma < mb {
        ma <<= 1;
        e -= 1;
    }
    while ma >= mb << 1 {
        mb <<= 1;
        e += 1;
    }
    if e >= 255 {
        return f32::from_bits(sign | INF);
    }
    // 26 bits of ma / mb (in [2^25, 2^26)): the 24 of the significand, a
    // rounding bit and one more, a bit at a time, the first (always 1)
    // marking how many have been taken; the remainder stays below mb,
    // under 2^24. A remainder left over sets the lowest bit (sticky): the
    // quotient was not exact.
    let (mut q, mut rest) = (1u32, ma - mb);
    while q < 1 << 25 {
        // The remainder doubled, less mb; borrow all ones where that went
        // below zero (the doubled remainder under mb: both are below 2^25,
        // so the sign bit tells), else 0. The quotient's next bit is 1
        // plus borrow, and mb is added back where it borrowed. Without a
        // branch: fewer instructions a bit on the M0.
        let less = (rest << 1).wrapping_sub(mb);
        let borrow = ((less as i32) >> 31) as u32;
        q = (q << 1 | 1).wrapping_add(borrow);
        rest = less.wrapping_add(mb & borrow);
    }
    q |= u32::from(rest != 0);
    // Below the normal range: the significand shifted right to the
    // subnormals' fixed exponent (field 0, scaled as field 1), a bit at a
    // time, each bit shifted out kept in the lowest (sticky) bit.
    while e < 1 {
        q = q >> 1 | q & 1;
        e += 1;
    }
    // To nearest, ties to even: adding 1, and 1 more where the last kept
    // bit is odd, carries into it exactly where the two bits below are 11,
    // or 10 after an odd bit.
    let q = (q + 1 + (q >> 2 & 1)) >> 2;
    // The significand's top bit adds 1 to the exponent field e - 1, and a
    // rounding that carries to 2^24 one more (up to infinity's field 255);
    // a subnormal has no top bit and stays at field 0, or reaches the
    // smallest normal number when it rounds up to 2^23.
    f32::from_bits(sign | ((((e - 1) as u32) << 23) + q))
}

/// `x as f32` for an `x` below 2^31 (random bits, grid coordinates). On
/// Arm cores without an FPU through `i32`: the same value, as both
/// conversions round the same integer, but the signed one is the library
/// routine the step links anyway (`__aeabi_i2f`), where the unsigned one
/// would add another (`__aeabi_ui2f`). Elsewhere the cast itself.
#[inline(always)]
pub(crate) fn small_to_f32(x: u32) -> f32 {
    debug_assert!(x < 1 << 31);
    #[cfg(all(target_arch = "arm", not(target_abi = "eabihf")))]
    {
        let mut x = x as i32;
        // The optimiser turns a signed conversion of a value it knows to be
        // non-negative (masked bits) back into the unsigned one; an empty
        // `asm!` that it must assume changes `x` hides that knowledge.
        // SAFETY: no instructions: nothing is touched.
        unsafe { core::arch::asm!("/* {x} */", x = inout(reg) x, options(pure, nomem, nostack, preserves_flags)) };
        x as f32
    }
    #[cfg(not(all(target_arch = "arm", not(target_abi = "eabihf"))))]
    {
        x as f32
    }
}

/// `v / |v|`, or `None` where the length is zero or not finite.
pub(crate) fn normalise(v: [f32; 3]) -> Option<[f32; 3]> {
    let len = sqrt(dot(v, v));
    (len.is_finite() && len > 1e-6).then(|| [div(v[0], len), div(v[1], len), div(v[2], len)])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bitwise_sqrt_is_libms() {
        // Expect: libm's sqrtf bit for bit for every non-negative float
        // at the edges of each exponent and 300,000 random ones, and +0,
        // -0, infinity; NaN for negatives and NaN.
        let check = |x: f32| assert_eq!(bitwise_sqrt(x).to_bits(), libm::sqrtf(x).to_bits(), "{x:e} {:#x}", x.to_bits());
        for e in 0..255u32 {
            for k in 0..64 {
                check(f32::from_bits((e << 23) + k));
                check(f32::from_bits(((e << 23) | 0x7f_ffff) - k));
            }
        }
        let mut bits = 0x0bad_cafeu32;
        for _ in 0..crate::sized(300_000, 3_000) {
            bits = bits.wrapping_mul(0x9e37_79b9).wrapping_add(0x7f4a_7c15);
            check(f32::from_bits((bits & 0x7fff_ffff).min(f32::MAX.to_bits())));
        }
        check(f32::INFINITY);
        check(-0.0);
        assert!(bitwise_sqrt(-1.0).is_nan() && bitwise_sqrt(f32::NAN).is_nan() && bitwise_sqrt(-f32::MIN_POSITIVE).is_nan());
    }

    #[test]
    fn bitwise_div_is_the_division() {
        // Expect: the hardware's `a / b` bit for bit wherever it is a
        // number; where it is NaN, a NaN, and the one the runtime's
        // `__divsf3` (which `bitwise_div` replaces) gives: the first NaN
        // operand quieted, else `f32::NAN` (0 / 0, inf / inf). Operands:
        // every pair of special values, the edges of every exponent pair,
        // quotients at the underflow and overflow boundaries, random bits.
        let check = |a: f32, b: f32| {
            let (a, b) = (core::hint::black_box(a), core::hint::black_box(b));
            let (got, want) = (bitwise_div(a, b), a / b);
            if want.is_nan() {
                let runtime = match (a.is_nan(), b.is_nan()) {
                    (true, _) => a.to_bits() | 0x40_0000,
                    (false, true) => b.to_bits() | 0x40_0000,
                    _ => f32::NAN.to_bits(),
                };
                assert_eq!(got.to_bits(), runtime, "{a:e} / {b:e} ({:#x} / {:#x})", a.to_bits(), b.to_bits());
            } else {
                assert_eq!(got.to_bits(), want.to_bits(), "{a:e} / {b:e} ({:#x} / {:#x})", a.to_bits(), b.to_bits());
            }
        };
        let specials = [
            0.0,
            f32::INFINITY,
            f32::NAN,
            f32::from_bits(0x7f80_0001), // signalling
            f32::from_bits(0x7fa5_a5a5), // signalling, with a payload
            f32::from_bits(0x7fc1_2345), // quiet, with a payload
            f32::from_bits(1),           // the smallest subnormal
            f32::from_bits(0x7f_ffff),   // the largest
            f32::from_bits(0x40_0000),
            f32::MIN_POSITIVE,
            f32::MAX,
            1.0,
            1.5,
            3.0,
            f32::EPSILON,
            1.0 - f32::EPSILON / 2.0,
        ];
        for a in specials {
            for b in specials {
                for (sa, sb) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                    check(a.copysign(sa), b.copysign(sb));
                }
            }
        }
        // Both exponents' edges: every pair of exponent fields (0 the
        // subnormals, 255 infinity and NaN) with the smallest and largest
        // significands, and every 16th pair with a few more.
        let edges = [0u32, 1, 2, 0x40_0000, 0x7f_fffe, 0x7f_ffff];
        // (Every 17th field under Miri: 0, 17, ..., 255.)
        for ea in (0..256u32).step_by(crate::sized(1, 17)) {
            for eb in (0..256u32).step_by(crate::sized(1, 17)) {
                let some = if (ea ^ eb) % 16 == 0 { &edges[..] } else { &edges[..1] };
                for &ka in some.iter().chain(&edges[5..]) {
                    for &kb in some.iter().chain(&edges[5..]) {
                        check(f32::from_bits(ea << 23 | ka), f32::from_bits(0x8000_0000 | eb << 23 | kb));
                    }
                }
            }
        }
        let mut bits = 0x2545_f491u32;
        let mut next = || {
            bits ^= bits << 13;
            bits ^= bits >> 17;
            bits ^= bits << 5;
            bits
        };
        // Quotients next to the boundaries: a random divisor b and a
        // dividend r b for r about the smallest subnormal, the largest
        // subnormal, the smallest normal and the largest finite number (or
        // beyond it), each nudged by a few ulps.
        for _ in 0..crate::sized(20_000, 200) {
            let b = f32::from_bits(next() & 0x7fff_ffff).clamp(f32::from_bits(1), f32::MAX);
            for r in [f32::from_bits(1), f32::from_bits(3), f32::from_bits(0x7f_ffff), f32::MIN_POSITIVE, f32::MAX] {
                let a = (f64::from(r) * f64::from(b)) as f32;
                if a.is_finite() {
                    for k in 0..5u32 {
                        check(f32::from_bits((a.to_bits() + k).saturating_sub(2)), b);
                    }
                }
            }
        }
        // Random bit patterns: all signs, every exponent, NaNs included;
        // then both in the normal range of nearby exponents, so that most
        // quotients are ordinary numbers.
        for _ in 0..crate::sized(300_000, 3_000) {
            let (a, b) = (next(), next());
            check(f32::from_bits(a), f32::from_bits(b));
            check(f32::from_bits(a & 0x87ff_ffff | 0x3800_0000), f32::from_bits(b & 0x87ff_ffff | 0x3800_0000));
        }
    }

    #[test]
    fn small_to_f32_is_the_cast() {
        // Expect: below 2^31 the conversion through i32 (what the helper
        // does on cores without an FPU) and the helper both give `as f32`
        // bit for bit: every power of two's neighbours, where rounding
        // changes, and random values.
        let check = |x: u32| {
            let want = core::hint::black_box(x) as f32;
            assert_eq!((core::hint::black_box(x) as i32 as f32).to_bits(), want.to_bits(), "{x}");
            assert_eq!(small_to_f32(x).to_bits(), want.to_bits(), "{x}");
        };
        for p in 0..31 {
            for k in 0..64u32 {
                check((1u32 << p).saturating_sub(k) & 0x7fff_ffff);
                check(((1u32 << p) + k) & 0x7fff_ffff);
            }
        }
        check(0x7fff_ffff);
        let mut bits = 0x0f0f_1234u32;
        for _ in 0..crate::sized(200_000, 2_000) {
            bits = bits.wrapping_mul(0x9e37_79b9).wrapping_add(0x7f4a_7c15);
            check(bits >> 1);
        }
    }
}
