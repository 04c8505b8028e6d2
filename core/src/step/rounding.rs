//! M1 after a stage: the velocities a stage of M5 changed, kept in fine
//! units (M1c) until they are rounded back to stored quanta, in cell
//! order, each rounding drawing from the block's stream.

use core::mem::MaybeUninit;

use crate::step::block::{Shared, Widths};
use crate::rules::rng::Stream;
use crate::step::block::{cells_of, Stored};

/// The velocities the stages since the last rounding changed: `x[c]` for
/// each cell `c` of `pending`, in fine units. The others are never
/// written nor read, so nothing is cleared for a block.
pub(crate) struct Changes<const CELLS: usize> {
    x: [MaybeUninit<[i32; 3]>; CELLS],
    pending: u8,
}

impl<const CELLS: usize> Changes<CELLS> {
    #[inline(always)]
    pub(crate) fn new() -> Self {
        Changes { x: [MaybeUninit::uninit(); CELLS], pending: 0 }
    }

    /// The velocity of the particle in cell `c`, in fine units of
    /// `2^-fine` quanta: the changed one, or `b`'s stored one. Out of line
    /// with `small-step`: one copy for every stage (less flash, a call a
    /// read).
    #[cfg_attr(feature = "small-step", inline(never))]
    #[cfg_attr(not(feature = "small-step"), inline(always))]
    pub(crate) fn velocity<const D: usize>(&self, b: &impl Stored<D>, c: usize, fine: u32) -> [i32; 3] {
        if self.pending >> c & 1 != 0 {
            // SAFETY: cell c is pending, so `set` wrote its entry.
            return unsafe { self.x[c].assume_init() };
        }
        b.fine(c, fine)
    }

    /// Makes `x` the velocity of the particle in cell `c`, to be rounded.
    /// Out of line with `small-step`, as [`Changes::velocity`] is.
    #[cfg_attr(feature = "small-step", inline(never))]
    #[cfg_attr(not(feature = "small-step"), inline(always))]
    pub(crate) fn set(&mut self, c: usize, x: [i32; 3]) {
        self.x[c].write(x);
        self.pending |= 1 << c;
    }

    /// M1: rounds every changed velocity into `b`, stored at width `W`
    /// (of the step `sh`), one 64-bit output of the stream each (32 bits
    /// in 2D), in cell order. Out of line with `small-step`: one copy for
    /// every stage.
    #[cfg_attr(feature = "small-step", inline(never))]
    #[cfg_attr(not(feature = "small-step"), inline(always))]
    pub(crate) fn round<W: Widths, const D: usize>(&self, b: &mut impl Stored<D>, sh: &Shared<'_>, rng: &mut Stream) {
        let width = W::width(sh);
        for c in cells_of(self.pending) {
            // SAFETY: cell c is pending, so `set` wrote its entry.
            b.put(c, width.round::<D>(unsafe { self.x[c].assume_init() }, rng));
        }
    }
}

/// [`Changes::round`] out of line, after the stages that seldom change a
/// velocity: a reflection (M5.4) and contacts (M5.7).
#[inline(never)]
pub(crate) fn round_apart<W: Widths, const D: usize, const CELLS: usize>(changes: &Changes<CELLS>, b: &mut impl Stored<D>, sh: &Shared<'_>, rng: &mut Stream) {
    changes.round::<W, D>(b, sh, rng);
}

/// M1 for one velocity `x` (fine units): the particle in cell `c` after
/// its reflection (M5.4), which is rare, through [`round_apart`] (out of
/// line; one copy serves this and the contacts).
#[inline(always)]
pub(crate) fn round_one<W: Widths, const D: usize, const CELLS: usize>(b: &mut impl Stored<D>, c: usize, x: [i32; 3], sh: &Shared<'_>, rng: &mut Stream) {
    let mut changes = Changes::<CELLS>::new();
    changes.set(c, x);
    round_apart::<W, D, CELLS>(&changes, b, sh, rng);
}
