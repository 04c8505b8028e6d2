//! The speed clamp (M5.5): a velocity longer than the limit is scaled back
//! to it, its direction kept, and the clamp and the kinetic energy it
//! removed are counted, since they are error of the model (M10).

use crate::rules::fixed::{count_times, shorten, sq};
use crate::rules::class::Class;
use crate::storage::world::Counters;

/// M5.5: clamps `x` (in fine units) to the speed limit `unit` (fine units
/// to a unit speed), counting the clamp and the kinetic energy it removed
/// for a particle of class `class`. Only the test is inlined: a clamp is
/// rare, and its code would otherwise be copied into every stage of every
/// block routine. With `small-step` not even the test (one copy serves
/// every stage: less flash, a call per test).
#[cfg_attr(feature = "small-step", inline(never))]
#[cfg_attr(not(feature = "small-step"), inline(always))]
pub(crate) fn clamp_counted<const D: usize>(x: &mut [i32; 3], unit: i32, class: &Class, counters: &mut Counters) {
    // On a small Arm core a square is a library call (the M0 has no wider
    // multiply): components within 11/16 (2D) or 9/16 (3D) of the limit
    // leave the velocity within it, which 32-bit compares show. (Inlined
    // into every stage of the larger builds, the test costs more flash
    // than it saves time.)
    if cfg!(all(target_arch = "arm", feature = "small-step")) {
        let within = (unit >> 4) * if D == 2 { 11 } else { 9 };
        if x[..D].iter().all(|c| c.unsigned_abs() <= within as u32) {
            return;
        }
    }
    let s2 = sq::<D>(*x);
    let limit = (unit as u64) * (unit as u64);
    if s2 <= limit {
        return;
    }
    // By value through the call: a velocity whose address never escapes
    // stays in registers.
    *x = clamp_and_count::<D>(*x, s2, unit, class.energy, counters);
}

/// The rest of [`clamp_counted`]: the clamp ([`shorten`]), counted, and
/// the energy it removed, `m (s2 - unit^2) / 2` in the counter's units
/// (`energy` a fine unit squared).
#[cold]
#[inline(never)]
fn clamp_and_count<const D: usize>(x: [i32; 3], s2: u64, unit: i32, energy: f32, counters: &mut Counters) -> [i32; 3] {
    counters.clamps += 1;
    let removed = count_times(s2 - (unit as u64) * (unit as u64), energy);
    counters.clamp_energy = counters.clamp_energy.saturating_add(removed);
    shorten(x, s2, unit, D)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rules::rng::block_stream;

    #[test]
    fn the_clamp_keeps_the_direction_and_never_lengthens() {
        // Expect: for random velocities up to the saturation bound, in 2D
        // and 3D, a clamped velocity is at most the limit long, within two
        // fine units per component (the rounded-up length and the floor) of
        // the limit along the same direction, and one below the limit is
        // left as it is.
        let mut rng = block_stream(31, 0, 0);
        let unit = 127 << 16;
        let class = Class { push: 0.0, relative: 1 << 24, energy: 1.0, swirl: Default::default(), spare: 0 };
        for i in 0..crate::sized(20_000, 500) {
            let big = (rng.bits(27) as i32) >> (rng.bits(4) % 6);
            let mut x0 = [0, 1, 2].map(|_| (rng.bits(27) as i32 - (1 << 26)) % (big + 1));
            if i % 2 == 0 {
                x0[2] = 0;
            }
            let mut x = x0;
            let mut counters = Counters::default();
            if i % 2 == 0 {
                clamp_counted::<2>(&mut x, unit, &class, &mut counters);
            } else {
                clamp_counted::<3>(&mut x, unit, &class, &mut counters);
            }
            let d = 2 + i % 2;
            let len0 = (0..d).map(|k| f64::from(x0[k]).powi(2)).sum::<f64>().sqrt();
            if len0 <= f64::from(unit) {
                assert_eq!(x, x0);
                continue;
            }
            assert_eq!(counters.clamps, 1);
            assert!(sq::<3>(x) <= (unit as u64).pow(2), "{x0:?} -> {x:?}");
            for k in 0..d {
                let want = f64::from(x0[k]) * f64::from(unit) / len0;
                assert!((f64::from(x[k]) - want).abs() <= 2.0, "{x0:?} -> {x:?}");
            }
        }
    }
}
