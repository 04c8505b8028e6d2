//! The speed clamp (M5.5): a velocity longer than the limit is scaled back
//! to it, its direction kept, and the clamp and the kinetic energy it
//! removed are counted, since they are error of the model (M10).

use crate::storage::world::{Counters, ENERGY_SCALE};

/// M5.5: clamps `x` (in quanta) to the speed limit `scale`, counting the
/// clamp and the kinetic energy it removed for mass `m`. Only the test is
/// inlined: a clamp is rare, and its code would otherwise be copied into
/// every stage of every block routine.
#[cfg(not(feature = "small-step"))]
#[inline(always)]
pub(crate) fn clamp_counted<const D: usize>(x: &mut [f32; 3], scale: f32, m: f32, counters: &mut Counters) {
    let s2 = crate::rules::vector::dot_of::<D>(*x, *x);
    if s2 <= scale * scale {
        return;
    }
    // By value through the call: a velocity whose address never escapes
    // stays in registers.
    *x = clamp_and_count(*x, s2, scale, m, counters);
}

/// [`clamp_counted`] with `small-step`: not even the test inlined, and
/// the clamp the one of [`crate::rules::vector::clamp`], which emitters use too
/// (one copy serves every stage: less flash, a call per test). Its squared
/// length sums all three components, the same number in 2D, where the
/// third is 0.
#[cfg(feature = "small-step")]
#[inline(never)]
pub(crate) fn clamp_counted<const D: usize>(x: &mut [f32; 3], scale: f32, m: f32, counters: &mut Counters) {
    if let Some(s2) = crate::rules::vector::clamp(x, scale) {
        count_clamp(s2, scale, m, counters);
    }
}

/// The rest of [`clamp_counted`]: the clamp, and its count, from the
/// squared speed `s2` it had (in quanta).
#[cfg(not(feature = "small-step"))]
#[cold]
#[inline(never)]
fn clamp_and_count(x: [f32; 3], s2: f32, scale: f32, m: f32, counters: &mut Counters) -> [f32; 3] {
    let (x, s2) = crate::rules::vector::clamp_long(x, s2, scale);
    count_clamp(s2, scale, m, counters);
    x
}

/// Counts a clamp (M5.5) of a particle of mass `m` whose squared speed was
/// `s2` quanta (infinite where it overflowed), `scale` quanta to a unit
/// speed, and the kinetic energy it removed.
#[inline(always)]
fn count_clamp(s2: f32, scale: f32, m: f32, counters: &mut Counters) {
    let s2 = crate::rules::vector::div(s2, scale * scale);
    counters.clamps += 1;
    // f32 and a saturating cast: no f64 or 128-bit arithmetic, which small
    // cores emulate; f32's 24 bits are far finer than the statistic needs.
    let fixed = crate::rules::vector::saturating_u64(0.5 * m * (s2 - 1.0) * ENERGY_SCALE as f32);
    counters.clamp_energy = counters.clamp_energy.saturating_add(fixed);
}
