//! What a block routine works with: the data every block of a step reads,
//! the planes the step writes, and one block's particles as the stages of
//! M5 see them.

use crate::api::desc::Description;
use crate::rules::assign::{bits, Bits};
use crate::rules::force::{Flow, ForceTerms};
use crate::rules::obstacle::Surface;
use crate::rules::quant::Quant;
use crate::rules::rng::{StepKey, Stream};
use crate::step::partition::Partition;
use crate::storage::cells::Cells;

/// The description as a step's blocks read it: with `small-step` where it
/// lies in the world's header (no copy to set up: less flash, a load more
/// for each field a block reads), otherwise a copy beside the other
/// shared data, which the lean routines read without that load.
#[cfg(feature = "small-step")]
pub(crate) type StepDescription<'a> = &'a Description;
#[cfg(not(feature = "small-step"))]
pub(crate) type StepDescription<'a> = Description;

/// A mass class as a step's blocks read it, converted from its mass once a
/// step (M1c). Laid out without padding: the classes of a world of masses
/// lie in its memory ([`mass_plane`](crate::storage::layout::mass_plane)).
#[derive(Clone, Copy, Default)]
#[repr(C)]
pub(crate) struct Class {
    /// M1c's `K = quot(dt, m)`: the velocity, in unit speeds, a unit of
    /// force adds in a step. A force's push is its exact product with this
    /// and `W`, rounded.
    pub push: f32,
    /// M1c's `M`: the mass relative to the largest in use, `2^24` for that
    /// one (at least 1), from which a collision takes the shares.
    pub relative: u32,
    /// Units of the clamp's energy counter a fine unit squared of speed
    /// removed is worth: `m 2^31 / W^2` (M5.5, M10), by [`quot`](crate::rules::fixed::quot).
    pub energy: f32,
    /// Unused: brings `swirl` to its alignment.
    pub spare: u32,
    /// The vortex's strength as a push for this class (M1c's `Γ'`), 0
    /// without a vortex.
    pub swirl: i64,
}

impl Shared<'_> {
    /// The class of mass index `i`: the first where the index names none
    /// (no index an API call writes does; an image's are checked).
    #[inline(always)]
    pub(crate) fn class(&self, i: u8) -> Class {
        match self.classes.get(usize::from(i)) {
            Some(c) => *c,
            None => self.one,
        }
    }
}

/// What every block of a step reads and none writes.
pub(crate) struct Shared<'a> {
    pub desc: StepDescription<'a>,
    pub n: [usize; 3],
    pub part: Partition,
    pub key: StepKey,
    pub obstacle: &'a [u64],
    pub surface: &'a [Surface],
    /// The mass classes in use in a world of masses, converted for this
    /// step (M1c); none in a world of one mass, which reads `one`.
    pub classes: &'a [Class],
    /// The class of every particle of a world of one mass (class 0 in a
    /// world of masses), where the lean routines read it without a bounds
    /// check.
    pub one: Class,
    pub terms: ForceTerms<'a>,
    /// The uniform force's velocity change per step in fine units (M1c's
    /// `G`), where it changes anything (the general force path includes it
    /// in `terms`).
    pub push: Option<[i64; 3]>,
    /// `push` where every component is below `2^29`, so that a velocity
    /// and the push add up within the bound in 32 bits: what the lean
    /// routines add (a world whose push is larger is not plain).
    pub lean_push: Option<[i32; 3]>,
    /// M5.2's restitution in Q16 (M1c's `E`).
    pub restitution: i32,
    /// M5.1b flow drag, where its rate is not 0.
    pub drag: Option<Flow<'a>>,
    /// The 8-bit move table of the drift rule (M5.3).
    pub moves: &'static [u16; 256],
    /// The high bytes of `moves`' entries, which the lanes routine reads
    /// ([`Shared::tops`]; not built with `small-step`, which never calls
    /// that routine).
    #[cfg(not(feature = "small-step"))]
    pub tops: &'static [u8; 256],
    /// Forces other than a uniform one (fields, potentials, the vortex,
    /// drag) are summed per particle, in [`Kernel::general`].
    pub summed: bool,
    /// One mass, no lifetimes, no summed force: blocks away from the faces
    /// and without an obstacle go through [`Kernel::lean`] (or
    /// [`Kernel::lean_2d`]).
    pub plain: bool,
    /// `plain` without contacts (M5.7): what [`Kernel::lean_2d`] needs of
    /// the step, tested once a block.
    pub lanes: bool,
}

impl Shared<'_> {
    /// The high bytes of the move table's entries, for the lanes routine.
    #[inline(always)]
    pub(crate) fn tops(&self) -> &'static [u8; 256] {
        #[cfg(not(feature = "small-step"))]
        return self.tops;
        // `visit` sends every block to the general routine with
        // `small-step`: the lanes routine, and this, never run.
        #[cfg(feature = "small-step")]
        unreachable!("small-step has no lanes routine")
    }
}

/// The planes a step writes; `velocity` holds a cell's `D` components
/// together. Copies go to the tasks of a parallel step, which write
/// disjoint elements ([`Cells`]).
#[derive(Clone, Copy)]
pub(crate) struct Writable<'a, Q, const D: usize> {
    pub occupancy: Cells<'a, u64>,
    pub rows: Cells<'a, u8>,
    pub words: Cells<'a, u64>,
    pub velocity: Cells<'a, [Q; D]>,
    pub mass_index: Cells<'a, u8>,
    pub life: Cells<'a, u16>,
}

/// A block's particles as the stages of M5 see them.
pub(crate) struct Block<const D: usize, const CELLS: usize> {
    /// Cells holding a particle.
    pub(crate) occ: u8,
    /// Velocities as stored, in quanta; what an empty cell holds is never
    /// read.
    pub(crate) v: [[i32; D]; CELLS],
    /// Cells whose velocity a stage changed and that await their rounding:
    /// the velocity is `x[c]`, in fine units (M1c).
    pub(crate) pending: u8,
    pub(crate) x: [[i32; 3]; CELLS],
    /// Cells whose velocity differs from what the plane holds.
    pub(crate) dirty: u8,
}

impl<const D: usize, const CELLS: usize> Block<D, CELLS> {
    /// The velocity of the particle in cell `c`, in fine units of
    /// `2^-fine` quanta (M1c). Out of line with `small-step`: one copy for
    /// every stage (less flash, a call a read).
    #[cfg_attr(feature = "small-step", inline(never))]
    #[cfg_attr(not(feature = "small-step"), inline(always))]
    pub(crate) fn velocity(&self, c: usize, fine: u32) -> [i32; 3] {
        if self.pending >> c & 1 != 0 {
            return self.x[c];
        }
        let mut x = [0; 3];
        for k in 0..D {
            x[k] = self.v[c][k] << fine;
        }
        x
    }

    /// Makes `x` the velocity of the particle in cell `c`, to be rounded.
    /// Out of line with `small-step`, as [`Block::velocity`] is.
    #[cfg_attr(feature = "small-step", inline(never))]
    #[cfg_attr(not(feature = "small-step"), inline(always))]
    pub(crate) fn set(&mut self, c: usize, x: [i32; 3]) {
        self.x[c] = x;
        self.pending |= 1 << c;
    }

    /// M1: rounds every pending velocity back to storage, one 64-bit output
    /// of the stream each, in cell order. Out of line with `small-step`:
    /// one copy for every stage.
    #[cfg_attr(feature = "small-step", inline(never))]
    #[cfg_attr(not(feature = "small-step"), inline(always))]
    pub(crate) fn round<Q: Quant>(&mut self, rng: &mut Stream) {
        for c in cells_of(self.pending) {
            self.v[c] = Q::round::<D>(self.x[c], rng);
        }
        self.dirty |= self.pending;
        self.pending = 0;
    }

    /// [`Block::round`] out of line, after the stages that seldom change a
    /// velocity: a reflection (M5.4) and contacts (M5.7).
    #[inline(never)]
    pub(crate) fn round_apart<Q: Quant>(&mut self, rng: &mut Stream) {
        self.round::<Q>(rng);
    }
}

/// Stored components as integers (quanta), component by component: an
/// array's `map` is a call at opt-level z.
#[inline(always)]
pub(crate) fn ints<Q: Quant, const D: usize>(q: [Q; D]) -> [i32; D] {
    let mut v = [0; D];
    for k in 0..D {
        v[k] = q[k].to_int();
    }
    v
}

/// The cells of a block mask (its set bits), lowest first.
#[inline]
pub(crate) fn cells_of(mask: u8) -> Bits {
    bits(mask)
}

/// Runs `$body` once for each cell of a block of `$cells` cells, with `$c`
/// bound to the cell's number as a constant: every index, side and table
/// entry derived from the cell folds at compile time, where a loop over the
/// cells would be left rolled.
macro_rules! each_cell {
    ($cells:expr, $c:ident => $body:block) => {{
        { let $c: usize = 0; $body }
        { let $c: usize = 1; $body }
        { let $c: usize = 2; $body }
        { let $c: usize = 3; $body }
        if $cells > 4 {
            { let $c: usize = 4; $body }
            { let $c: usize = 5; $body }
            { let $c: usize = 6; $body }
            { let $c: usize = 7; $body }
        }
    }};
}
pub(crate) use each_cell;

/// Runs `$body` for each cell `$c` set in `$occ` (of a block of `$cells`
/// cells): unrolled as [`each_cell`] where `$unroll`, else a loop over the
/// set cells, which is a little slower and far smaller.
macro_rules! each_occupied {
    ($unroll:expr, $cells:expr, $occ:expr, $c:ident => $body:block) => {{
        if $unroll {
            $crate::step::block::each_cell!($cells, $c => {
                if $occ >> $c & 1 != 0 $body
            });
        } else {
            for $c in $crate::step::block::cells_of($occ) $body
        }
    }};
}
pub(crate) use each_occupied;
