//! The speed limit (M1): a velocity a caller hands in is at most 1 cell
//! per step long, and an emitter's velocity plus its spread at most 1 (M6).
//! Both are decided exactly for the `f32` values given, as the rule states
//! them, not for their squares rounded: in `f32`, 0.6² + 0.8² and
//! 1 + (2·10⁻⁴)² round to 1, though both exceed it. Every check of a
//! speed limit (a wind cell, a wind field, the description's wind, an
//! emitter, an image holding them) goes through [`slow`] or [`too_fast`].
//! A particle's velocity is held to what a world can store (edit.rs,
//! `storable`), decided in integers.

use crate::api::checks::size;
use crate::rules::fixed::parts;

/// Whether `u` (1 to 3 finite components, as every caller has checked)
/// has `|u| <= 1`, exactly: integers decide ([`too_fast`] with no spread),
/// after the `f32` sum of the squares where that is far enough from 1 to
/// decide ([`far_from_one`]). Out of line: one copy for every caller.
#[inline(never)]
pub(crate) fn slow(u: &[f32]) -> bool {
    let mut v = [0.0f32; 3];
    for (to, &c) in v.iter_mut().zip(u) {
        *to = c;
    }
    #[cfg(feature = "fields")]
    if let Some(slow) = far_from_one(&v) {
        return slow;
    }
    !too_fast(v, 0.0)
}

/// `|v| <= 1` where the `f32` sum of the squares decides it, else None.
/// Each square and each of the two additions rounds by at most 2^-24 of
/// its value, so the rounded sum of three non-negative terms lies within
/// 2^-22 of the exact one (relative; a square too small for `f32` loses
/// less than 2^-149), well inside the margin of 2^-20 taken here. For the
/// wind plane, checked once a cell (feature `fields`), where the integers'
/// sum costs some twenty times as much; firmware without it keeps the
/// smaller code.
#[cfg(feature = "fields")]
fn far_from_one(v: &[f32; 3]) -> Option<bool> {
    const MARGIN: f32 = 1.0 / (1u32 << 20) as f32;
    let rounded = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    if rounded < 1.0 - MARGIN {
        Some(true)
    } else if rounded > 1.0 + MARGIN {
        Some(false)
    } else {
        None
    }
}

/// Whether `|v| + spread > 1`, decided exactly, for finite `v` and
/// `spread >= 0` (M6). In `f32` the sum would round 0.5 + 0.50000006 down
/// to 1; in `f64`, as this was checked before, it still rounds a sum above
/// 1 by less than about 1e-16 down to 1 (`[1, 2^-149, 0]` passed), and it
/// cost a firmware double-precision soft float. Integers
/// decide it instead, without error:
///
/// - `spread >= 1`: over 1 exactly when `spread > 1` or `v != 0`;
/// - a component over 1 in size: over 1;
/// - otherwise `spread < 1`, and `|v| + spread > 1` exactly when
///   `|v|^2 > (1 - spread)^2` (both sides of `|v| > 1 - spread` are not
///   negative), that is `|v|^2 + 2 spread > 1 + spread^2`. Every `f32` is
///   an integer multiple of 2^-149, so every term here is one of 2^-298;
///   components and spread are at most 1, so each side is below 5: in
///   units of 2^-298 both are integers below 2^301, which [`Wide`] adds
///   without loss and compares exactly.
pub(crate) fn too_fast(v: [f32; 3], spread: f32) -> bool {
    // Sizes compared as integers (the values are finite, the spread not
    // negative: every caller checked).
    if size(spread) >= size(1.0) {
        return size(spread) > size(1.0) || v.iter().any(|&c| size(c) != 0);
    }
    if v.iter().any(|&c| size(c) > size(1.0)) {
        return true;
    }
    let (mut left, mut right) = (Wide::default(), Wide::default());
    for &c in &v {
        left.add_square(c);
    }
    let (_, m, e) = parts(spread);
    left.add(m, e + 1);
    right.add(1, 0);
    right.add_square(spread);
    left.above(&right)
}

/// A number below 2^301 in units of 2^-298 (every `f32` square is a whole
/// number of them), in little-endian 32-bit limbs; see [`too_fast`].
///
/// Aligned to 8 bytes: its zeroing is then the library's one aligned
/// clear (`__aeabi_memclr8` on Arm), not a copy of its own for 4 bytes.
#[derive(Default)]
#[repr(align(8))]
struct Wide([u32; 10]);

impl Wide {
    /// Adds `m 2^e`, `m` below 2^48 and `e` from -298 up; the sums
    /// [`too_fast`] makes stay below 2^301 units.
    fn add(&mut self, m: u64, e: i32) {
        let at = (e + 298) as u32;
        // In pieces of 32 bits, each shifted by less than a limb, so a
        // piece and its carries fit a u64.
        for (piece, at) in [(m as u32, at), ((m >> 32) as u32, at + 32)] {
            let mut carry = u64::from(piece) << (at % 32);
            for limb in self.0.iter_mut().skip((at / 32) as usize) {
                if carry == 0 {
                    break;
                }
                let sum = u64::from(*limb) + carry;
                *limb = sum as u32;
                carry = sum >> 32;
            }
        }
    }

    /// Adds `x^2`.
    fn add_square(&mut self, x: f32) {
        let (_, m, e) = parts(x);
        self.add(m * m, 2 * e);
    }

    /// Whether `self > other`.
    fn above(&self, other: &Wide) -> bool {
        self.0.iter().rev().cmp(other.0.iter().rev()) == core::cmp::Ordering::Greater
    }
}

#[cfg(test)]
mod tests {
    extern crate std;

    use super::*;
    use crate::rng::block_stream;

    /// The check this replaced: `f64` throughout, exact but for the last
    /// roundings.
    fn in_f64(v: [f32; 3], spread: f32) -> (bool, f64) {
        let speed = v.iter().map(|&c| f64::from(c) * f64::from(c)).sum::<f64>().sqrt();
        (speed + f64::from(spread) > 1.0, speed + f64::from(spread))
    }

    fn up(x: f32) -> f32 {
        f32::from_bits(x.to_bits() + 1)
    }

    fn down(x: f32) -> f32 {
        f32::from_bits(x.to_bits() - 1)
    }

    #[test]
    fn speed_and_spread_of_exactly_one_pass_and_one_unit_more_fails() {
        // Expect: |v| + spread exactly 1 passes, in 1, 2 and 3 components
        // (3-4-5 and 1-2-2 triangles scaled by powers of 2, so exact in
        // f32), and the next f32 up of the spread or of a component fails;
        // as does the least possible excess, a subnormal spread on a unit
        // speed, or a subnormal component beside a unit one (2^-298 over
        // 1 in the square), which the f64 check took for 1. Spread 1 or
        // more passes only with no speed, and over 1 never. 0.6 + 0.4 in
        // f32 is over 1.
        let tiny = f32::from_bits(1);
        let exact: [([f32; 3], f32); 8] = [
            ([0.5, 0.0, 0.0], 0.5),
            ([0.0, 0.75, 0.0], 0.25),
            ([0.375, -0.5, 0.0], 0.375),
            ([0.25, 0.5, -0.5], 0.25),
            ([1.0, 0.0, 0.0], 0.0),
            ([0.0, -1.0, 0.0], 0.0),
            ([0.0, 0.0, 0.0], 1.0),
            ([0.0, 0.0, 1.0], -0.0),
        ];
        for (v, spread) in exact {
            assert!(!too_fast(v, spread), "{v:?} {spread}");
            assert!(too_fast(v, if spread == 0.0 { tiny } else { up(spread) }), "{v:?} {spread}");
            for k in 0..3 {
                let mut w = v;
                w[k] = if w[k] == 0.0 { tiny } else { w[k].signum() * up(w[k].abs()) };
                assert!(too_fast(w, spread), "{w:?} {spread}");
            }
        }
        assert!(too_fast([1.0, tiny, 0.0], 0.0));
        assert!(!in_f64([1.0, tiny, 0.0], 0.0).0, "the f64 check rounded it to 1");
        assert!(!too_fast([down(1.0), 0.0, 0.0], tiny));
        assert!(!too_fast([tiny, tiny, tiny], down(1.0)));
        assert!(too_fast([0.0, 0.0, 0.0], up(1.0)));
        assert!(too_fast([f32::MAX, 0.0, 0.0], 0.0));
        assert!(too_fast([0.0, -f32::MAX, 0.0], f32::MAX));
        assert!(too_fast([0.8, 0.7, 0.0], 0.0));
        assert!(too_fast([0.6, 0.0, 0.0], 0.4), "0.6 and 0.4 as f32 sum to 1 + 3e-8");
        assert!(in_f64([0.6, 0.0, 0.0], 0.4).0);
        assert!(!too_fast([0.0, 0.6, 0.0], 0.2), "the smoke scenes' emitter");
    }

    /// `|v|^2 > (1 - spread)^2` in u128 units of 2^-108, for `v` and
    /// `spread < 1` whose last bits are 2^-54 or more (else None): another
    /// way to the exact answer, for a narrower range.
    fn in_u128(v: [f32; 3], spread: f32) -> Option<bool> {
        let fixed = |x: f32| {
            let (_, m, e) = parts(x);
            (e >= -54).then(|| u128::from(m) << (e + 54))
        };
        if spread >= 1.0 {
            return None;
        }
        let mut square = 0;
        for &c in &v {
            square += fixed(c)?.pow(2);
        }
        Some(square > ((1u128 << 54) - fixed(spread)?).pow(2))
    }

    #[test]
    fn speed_check_agrees_with_f64_wherever_that_is_not_within_its_rounding() {
        // Expect: on 400,000 random emitters near the limit (a random
        // velocity of up to 3 components with exponents from -1 to -30,
        // and a spread from a few units below 1 - |v| to a few above), the
        // exact check gives the f64 check's answer wherever the f64 sum is
        // further than 2^-45 from 1 (its error is about 2^-52), and the
        // answer of a u128 computation wherever every value's last bit is
        // 2^-54 or more; some land on each side.
        let mut rng = block_stream(12, 0, 0);
        let (mut over, mut under, mut in_range) = (0, 0, 0);
        for _ in 0..crate::sized(400_000, 200) {
            let mut v = [0.0f32; 3];
            for c in v.iter_mut().take(1 + rng.below(3) as usize) {
                let scale = f32::from_bits((126 - rng.below(30)) << 23);
                *c = (rng.unit() * 2.0 - 1.0) * scale;
            }
            let speed = v.iter().map(|&c| f64::from(c) * f64::from(c)).sum::<f64>().sqrt();
            if speed >= 1.0 {
                continue;
            }
            let mut spread = (1.0 - speed) as f32;
            for _ in 0..rng.below(8) {
                spread = up(spread);
            }
            for _ in 0..rng.below(8) {
                spread = if spread > 0.0 { down(spread) } else { spread };
            }
            let (f64_says, sum) = in_f64(v, spread);
            let says = too_fast(v, spread);
            if (sum - 1.0).abs() > 2f64.powi(-45) {
                assert_eq!(says, f64_says, "{v:?} {spread}");
            }
            if let Some(exact) = in_u128(v, spread) {
                assert_eq!(says, exact, "{v:?} {spread}");
                in_range += 1;
            }
            if says { over += 1 } else { under += 1 }
        }
        assert!(over > 0 && under > 0 && in_range > 0, "{over} {under} {in_range}");
    }

    /// The check `slow` replaced: the squares summed in `f32`.
    fn in_f32(u: &[f32]) -> bool {
        u.iter().map(|c| c * c).sum::<f32>() <= 1.0
    }

    /// `|u|^2 <= 1` exactly, for components whose last bits are 2^-54 or
    /// more (else None): `in_u128` with no spread.
    fn slow_in_u128(u: &[f32]) -> Option<bool> {
        let mut square = 0u128;
        for &c in u.iter().filter(|&&c| c != 0.0) {
            let (_, m, e) = parts(c);
            square += (u128::from(m) << (e >= -54).then_some(e + 54)?).pow(2);
        }
        Some(square <= 1 << 108)
    }

    #[test]
    fn speeds_of_one_pass_and_one_unit_more_fails() {
        // Expect: the unit vectors f32 holds exactly (along an axis, either
        // sign, 1 to 3 components) pass and one unit in the last place more
        // fails, as does the least excess: a subnormal beside a unit
        // component. One unit less passes. The cases, (0.6, 0.8)
        // and (1, 2e-4), are over 1 by about 2e-8 and fail, though their
        // squares summed in f32 round to 1.
        let tiny = f32::from_bits(1);
        for dim in 1..=3 {
            for axis in 0..dim {
                for sign in [1.0f32, -1.0] {
                    let mut u = [0.0f32; 3];
                    u[axis] = sign;
                    assert!(slow(&u[..dim]), "{u:?}");
                    u[axis] = sign * up(1.0);
                    assert!(!slow(&u[..dim]), "{u:?}");
                    u[axis] = sign * down(1.0);
                    assert!(slow(&u[..dim]), "{u:?}");
                    u[axis] = sign;
                    for other in (0..dim).filter(|&k| k != axis) {
                        let mut w = u;
                        w[other] = tiny;
                        assert!(!slow(&w[..dim]), "{w:?}");
                        assert!(in_f32(&w[..dim]), "f32 took it for 1");
                        w[axis] = sign * down(1.0);
                        assert!(slow(&w[..dim]), "{w:?}");
                    }
                }
            }
        }
        for u in [[0.6f32, 0.8], [0.8, -0.6], [1.0, 2e-4], [-2e-4, 1.0]] {
            assert!(!slow(&u), "{u:?}");
            assert!(in_f32(&u), "{u:?}: the f32 check passed it");
        }
        assert!(slow(&[0.6, down(0.8)]) && slow(&[down(0.6), 0.8]));
        assert!(!slow(&[-f32::MAX, 0.0, 0.0]) && !slow(&[0.0, f32::MAX]));
        assert!(slow(&[0.0]) && slow(&[-0.0, 0.0, 0.0]));
    }

    #[test]
    fn speeds_at_the_limit_in_every_direction_pass_and_one_unit_more_fails() {
        // Expect: for 10,000 random vectors in 2D and 3D, each component
        // in turn made as large as the exact rule allows with the others
        // held (found with the u128 reference): the vector passes, and one
        // unit in the last place more of that component, of either sign,
        // fails. Some of those the f32 sum passed.
        let mut rng = block_stream(25, 0, 0);
        let mut f32_wrong = 0;
        for round in 0..crate::sized(10_000, 50) {
            let dim = 2 + round % 2;
            let mut u = [0.0f32; 3];
            for c in u.iter_mut().take(dim) {
                *c = (rng.unit() * 2.0 - 1.0) * 0.55;
            }
            for k in 0..dim {
                let with = |x: f32| {
                    let mut w = u;
                    w[k] = x;
                    w
                };
                let passes = |x: f32| slow_in_u128(&with(x)[..dim]) == Some(true);
                let rest = 1.0 - (0..dim).filter(|&j| j != k).map(|j| f64::from(u[j]).powi(2)).sum::<f64>();
                let mut x = rest.sqrt() as f32;
                while !passes(x) {
                    x = down(x);
                }
                while passes(up(x)) {
                    x = up(x);
                }
                for sign in [1.0f32, -1.0] {
                    assert!(slow(&with(sign * x)[..dim]), "{:?}", with(sign * x));
                    let over = with(sign * up(x));
                    assert!(!slow(&over[..dim]), "{over:?}");
                    f32_wrong += usize::from(in_f32(&over[..dim]));
                }
            }
        }
        assert!(f32_wrong > 0);
    }
}
