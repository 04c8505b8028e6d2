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
    if crate::api::speed::too_fast(e.velocity, e.spread) {
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
}
