//! Emitters (M6). Each step, before the blocks are processed, every emitter
//! places `floor(rate)` particles plus one more with probability
//! `rate - floor(rate)` (a Bernoulli sum: the mean is exactly `rate`, the
//! variance at most 1/4), in empty non-obstacle cells of its region chosen
//! uniformly (selection sampling over the region). What does not fit is
//! counted as shortfall. Draws come from the emitter's own stream
//! `(seed, step, emitter index)` (M8).

use core::ffi::CStr;

use crate::{Error, ErrorKind};
use crate::api::checks::{finite, negative};
use crate::rules::fixed::{clamp_to, mulq, parts, sq, to_fine, unit_scale};
use crate::rules::rng::Stream;

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
    /// Initial velocity, in cells per step.
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
    /// The mass index of its particles in the low byte, and in the next
    /// the tag they carry where the world has tags (M6b): the word an
    /// image holds (M12).
    pub class: u32,
    /// What the emitter asked for and what it placed over its life (M6):
    /// see [`EmitterStats`].
    pub stats: EmitterStats,
}

/// What one emitter asked for and what it placed, counted from when it was
/// added (saturating). The difference is its part of the world's
/// shortfall: particles its region had no free cell for, or no id was left
/// for (M6b).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(C)]
pub struct EmitterStats {
    /// Particles asked for: each step the whole part of its rate, and one
    /// more where the step's draw falls below the fraction.
    pub requested: u64,
    /// Particles placed.
    pub delivered: u64,
}

impl Slot {
    #[inline(always)]
    pub(crate) fn mass_index(&self) -> u8 {
        self.class as u8
    }

    #[inline(always)]
    pub(crate) fn tag(&self) -> u8 {
        (self.class >> 8) as u8
    }
}

/// `e` as a world of `dim` dimensions, `n` cells per axis and, if
/// `lifetimes`, an age plane stores it (2D drops the third axis), or why
/// such a world refuses it. Shared by [`World::add_emitter`] and the
/// snapshot loader (M12), which holds a stored emitter to the same rules.
/// `e` is changed in place, refused or not (no copy of it in or out, each
/// a `memcpy` call on a small core): callers check a copy of their own.
pub(crate) fn checked(e: &mut Emitter, dim: usize, n: [usize; 3], lifetimes: bool) -> Result<(), Error> {
    // Every float is checked as given, before 2D drops the third axis.
    finite(&[e.rate, e.velocity[0], e.velocity[1], e.velocity[2], e.spread], c"emitter.rate, velocity or spread")?;
    if dim == 2 {
        e.min[2] = 0;
        e.max[2] = 1;
        e.velocity[2] = 0.0;
    }
    if negative(e.rate) || negative(e.spread) || (0..3).any(|k| e.min[k] >= e.max[k] || e.max[k] as usize > n[k]) {
        return Err(Error::computed(ErrorKind::BadEmitter, || bad_field(e)));
    }
    if crate::api::speed::too_fast(e.velocity, e.spread) {
        return Err(Error::new(ErrorKind::SpeedRange, c"emitter.velocity and spread"));
    }
    if e.lifetime > u32::from(u16::MAX) {
        return Err(Error::new(ErrorKind::LifetimeRange, c"emitter.lifetime"));
    }
    if e.lifetime > 0 && !lifetimes {
        return Err(Error::new(ErrorKind::NotEnabled, c"emitter.lifetime (desc.lifetimes is off)"));
    }
    Ok(())
}

/// The field [`checked`] refuses with `BadEmitter`. Apart, and asked only
/// once the one test failed, so the test stays one.
#[cold]
#[inline(never)]
fn bad_field(e: &Emitter) -> &'static CStr {
    if negative(e.rate) {
        c"emitter.rate is negative"
    } else if negative(e.spread) {
        c"emitter.spread is negative"
    } else if (0..3).any(|k| e.min[k] >= e.max[k]) {
        c"emitter.min is not below max"
    } else {
        c"emitter.max is past the world"
    }
}

/// M6: how many particles a step asks of an emitter of rate `rate` (not
/// negative, finite: [`checked`]), from the bits of the float: the whole
/// part (saturating) and the fraction's threshold, `ceil(f 2^24)` for the
/// fraction `f = rate - floor(rate)`. A uniform 24-bit draw below the
/// threshold is the trial of one more particle, with probability `f` to
/// within `2^-24`: the float comparison `u 2^-24 < f`, exactly, without
/// a float operation.
pub(crate) fn split_rate(rate: f32) -> (u64, u32) {
    let (_, m, e) = parts(rate);
    if e >= 0 {
        // No fraction; a whole part of 2^64 or more saturates.
        let whole = if e > 40 { u64::MAX } else { m << e };
        return (whole, 0);
    }
    // With a fraction the whole part is below the mantissa's 2^24, and
    // so is all that follows: 32 bits (on a small core 64-bit shifts are
    // library calls).
    let (m, point) = (m as u32, (-e) as u32);
    let whole = m.checked_shr(point).unwrap_or(0);
    let fraction = m - (whole << point.min(31));
    // The fraction's bits at 2^24, rounded up.
    let threshold = if point <= 24 {
        fraction << (24 - point)
    } else {
        let cut = point - 24;
        let kept = fraction.checked_shr(cut).unwrap_or(0);
        kept + u32::from(kept.checked_shl(cut).unwrap_or(0) != fraction)
    };
    (u64::from(whole), threshold)
}

/// M6: an emitted particle's velocity in fine units of a world of `unit`
/// fine units to a unit speed (M1c): the emitter's velocity converted,
/// plus a point uniform in the disc (2D) or ball (3D) of radius `spread`,
/// drawn by rejection in a square (cube) of side `2^16` around 0 (32 bits a
/// try in 2D, 48 in 3D), then the clamp to a unit speed, uncounted (the
/// speeds were checked: only the conversions can leave a hair over).
pub(crate) fn spread_velocity(e: &Emitter, dim: usize, unit: i32, rng: &mut Stream) -> [i32; 3] {
    let scale = unit_scale(unit);
    let mut x = [0, 1, 2].map(|k| if k < dim { to_fine(e.velocity[k], scale) } else { 0 });
    let radius = to_fine(e.spread, scale);
    if radius > 0 {
        // A build without 3D has only 2D worlds.
        let three = dim == 3 && cfg!(feature = "dim3");
        let p = loop {
            let xy = rng.bits(32);
            let z = if three { rng.bits(16) as i32 - (1 << 15) } else { 0 };
            let p = [(xy & 0xffff) as i32 - (1 << 15), (xy >> 16) as i32 - (1 << 15), z];
            if sq::<3>(p) <= 1 << 30 {
                break p;
            }
        };
        for k in 0..3 {
            x[k] += mulq(p[k], radius, 15);
        }
    }
    clamp_to::<3>(x, unit)
}

#[cfg(test)]
mod tests {
    extern crate std;

    use super::*;
    use crate::rules::rng::block_stream;

    #[test]
    fn the_rate_split_is_the_float_draw() {
        // Expect: the whole part is the saturating cast of floor(rate),
        // and for every 24-bit draw u (the edges of the threshold and
        // random ones) u < threshold exactly where u 2^-24 < rate -
        // floor(rate) in f64 (exact for these values): for 0, every
        // power of two's neighbours, and random rates of every size.
        let mut rng = block_stream(9, 9, 9);
        let check = |x: f32, u: u32| {
            let (whole, threshold) = split_rate(x);
            let floor = libm::floor(f64::from(x));
            assert_eq!(whole, floor as u64, "{x:e}");
            for u in [u, threshold.saturating_sub(1), threshold, threshold + 1, (1 << 24) - 1] {
                let u = u & 0xff_ffff;
                let want = f64::from(u) / 16_777_216.0 < f64::from(x) - floor;
                assert_eq!(u < threshold, want, "{x:e} {u}");
            }
        };
        check(0.0, 0);
        for e in 0..255u32 {
            let x = f32::from_bits(e << 23);
            for k in 0..3 {
                check(f32::from_bits(x.to_bits() + k), rng.bits(24));
                check(f32::from_bits((x.to_bits() + k).saturating_sub(3)), rng.bits(24));
            }
        }
        for _ in 0..crate::sized(100_000, 1_000) {
            let x = f32::from_bits(rng.bits(31));
            if x.is_finite() {
                check(x, rng.bits(24));
            }
        }
    }
}
