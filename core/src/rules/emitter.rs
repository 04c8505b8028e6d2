//! Emitters (M6). Each step, before the blocks are processed, every emitter
//! places `floor(rate)` particles plus one more with probability
//! `rate - floor(rate)` (a Bernoulli sum: the mean is exactly `rate`, the
//! variance at most 1/4), in empty non-obstacle cells of its region chosen
//! uniformly (selection sampling over the region). What does not fit is
//! counted as shortfall. Draws come from the emitter's own stream
//! `(seed, step, emitter index)` (M8).

use crate::Error;
use crate::api::checks::finite;
use crate::rules::collision::random_unit;
use crate::rules::rng::Stream;
use crate::rules::vector::clamp;

/// An emitter as the caller describes it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct Emitter {
    /// First cell of the region, inclusive.
    pub min: [u32; 3],
    /// Last cell of the region, exclusive (the third is 1 in 2D).
    pub max: [u32; 3],
    /// Mean particles per step, finite and not negative.
    pub rate: f32,
    /// Initial velocity.
    pub velocity: [f32; 3],
    /// Radius of a uniform random spread added to the velocity;
    /// `|velocity| + spread` must not exceed 1 (decided exactly).
    pub spread: f32,
    /// Mass of the emitted particles.
    pub mass: f32,
    /// Steps each particle lives, 0 for no limit; at most 65535, and only in
    /// worlds with `lifetimes`.
    pub lifetime: u32,
}

/// An emitter as the world stores it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub(crate) struct Slot {
    pub emitter: Emitter,
    pub mass_index: u32,
}

/// `e` as a world of `dim` dimensions, `n` cells per axis and, if
/// `lifetimes`, an age plane stores it (2D drops the third axis), or why
/// such a world refuses it. Shared by [`World::add_emitter`] and the
/// snapshot loader (M12), which holds a stored emitter to the same rules.
/// `e` is changed in place, refused or not (no copy of it in or out, each
/// a `memcpy` call on a small core): callers check a copy of their own.
pub(crate) fn checked(e: &mut Emitter, dim: usize, n: [usize; 3], lifetimes: bool) -> Result<(), Error> {
    // Every float is checked as given, before 2D drops the third axis.
    finite(&[e.rate, e.velocity[0], e.velocity[1], e.velocity[2], e.spread])?;
    if dim == 2 {
        e.min[2] = 0;
        e.max[2] = 1;
        e.velocity[2] = 0.0;
    }
    if e.rate < 0.0 || e.spread < 0.0 || (0..3).any(|k| e.min[k] >= e.max[k] || e.max[k] as usize > n[k]) {
        return Err(Error::BadEmitter);
    }
    if too_fast(e.velocity, e.spread) {
        return Err(Error::SpeedRange);
    }
    if e.lifetime > u32::from(u16::MAX) {
        return Err(Error::LifetimeRange);
    }
    if e.lifetime > 0 && !lifetimes {
        return Err(Error::NotEnabled);
    }
    Ok(())
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
fn too_fast(v: [f32; 3], spread: f32) -> bool {
    if spread >= 1.0 {
        return spread > 1.0 || v.iter().any(|&c| c != 0.0);
    }
    if v.iter().any(|c| c.abs() > 1.0) {
        return true;
    }
    let (mut left, mut right) = (Wide::default(), Wide::default());
    for &c in &v {
        left.add_square(c);
    }
    let (m, e) = parts(spread);
    left.add(m, e + 1);
    right.add(1, 0);
    right.add_square(spread);
    left.above(&right)
}

/// `x = m 2^e` (m below 2^24, e from -149 up) for a finite `x`, its sign
/// dropped.
fn parts(x: f32) -> (u64, i32) {
    let bits = x.to_bits() & 0x7fff_ffff;
    let (exponent, fraction) = ((bits >> 23) as i32, u64::from(bits & 0x7f_ffff));
    if exponent == 0 {
        (fraction, -149) // subnormal
    } else {
        (fraction | 1 << 23, exponent - 150)
    }
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
        let (m, e) = parts(x);
        self.add(m * m, 2 * e);
    }

    /// Whether `self > other`.
    fn above(&self, other: &Wide) -> bool {
        self.0.iter().rev().cmp(other.0.iter().rev()) == core::cmp::Ordering::Greater
    }
}


/// `floor(x)` for an `x` that is not negative (a rate: `checked`), by
/// clearing the bits of its fraction: a few instructions where `floorf`
/// is a library routine.
pub(crate) fn floor_rate(x: f32) -> f32 {
    let bits = x.to_bits();
    let exponent = (bits >> 23 & 0xff) as i32 - 127;
    if exponent < 0 {
        // Below 1: no whole part (the sign kept, as floor keeps -0).
        return f32::from_bits(bits & 0x8000_0000);
    }
    // 23 fraction bits, of which `exponent` lie above the point.
    let fraction = 0x7f_ffffu32.checked_shr(exponent as u32).unwrap_or(0);
    f32::from_bits(bits & !fraction)
}


/// The emitter's velocity plus a uniform point of the disc or ball of radius
/// `spread`.
pub(crate) fn spread_velocity(e: &Emitter, dim: usize, rng: &mut Stream) -> [f32; 3] {
    let mut v = e.velocity;
    if e.spread > 0.0 {
        // A build without 3D has only 2D worlds: the 3D branch (and cbrtf)
        // is not linked into it.
        let (dir, radius) = if dim == 2 || !cfg!(feature = "dim3") {
            (random_unit::<2>(rng), crate::rules::vector::sqrt(rng.unit()))
        } else {
            (random_unit::<3>(rng), libm::cbrtf(rng.unit()))
        };
        for k in 0..3 {
            v[k] += e.spread * radius * dir[k];
        }
    }
    // |velocity| + spread <= 1 was checked; rounding may still leave a hair
    // over 1, which is no clamp of the model's, so it is not counted.
    let _ = clamp(&mut v, 1.0);
    v
}

#[cfg(test)]
mod tests {
    extern crate std;

    use super::*;
    use crate::rules::rng::block_stream;

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
    fn floor_rate_is_floor_for_rates() {
        // Expect: floorf's value, bit for bit, for 0, -0, every power of
        // two's neighbours, infinity and random values of every size.
        let mut rng = block_stream(9, 9, 9);
        let check = |x: f32| assert_eq!(floor_rate(x).to_bits(), libm::floorf(x).to_bits(), "{x:e}");
        check(0.0);
        check(-0.0);
        check(f32::INFINITY);
        for e in 0..255u32 {
            let x = f32::from_bits(e << 23);
            for k in 0..3 {
                check(f32::from_bits(x.to_bits() + k));
                check(f32::from_bits((x.to_bits() + k).saturating_sub(3)));
            }
        }
        for _ in 0..crate::sized(100_000, 1_000) {
            check(f32::from_bits(rng.bits(31)));
        }
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
            let (m, e) = parts(x);
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
}
