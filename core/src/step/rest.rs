//! Resting contact (M5.7b): a particle that rests on a full support takes
//! no push from the uniform force and loses its velocity into the support
//! along it, so a pool or a pile comes exactly to rest. Draws nothing.

use crate::api::desc::Description;
use crate::rules::fixed::mulq;
use crate::step::block::{cells_of, Stored};
use crate::step::rounding::Changes;

/// The support of a step: the axis and side the uniform push `G` points
/// to (M5.7b), worked out once a step.
#[derive(Clone, Copy)]
pub(crate) struct Support {
    /// The axis of the largest `|G_k|`, the lowest on a tie.
    axis: usize,
    /// Whether `G` points to the axis' high side.
    up: bool,
    /// The block's cells on the side `G` points to: its lower half.
    lower: u8,
    /// `T`: the fastest approach along the axis that is a resting contact
    /// and not an impact (fine units).
    slow: i32,
}

/// What a block's particles rest on: whether its support holds, what a
/// particle coming into it fast does, and which of its particles rest.
#[derive(Clone, Copy)]
pub(crate) struct Resting {
    /// Every cell of the lower half is a wall, an obstacle or a particle.
    pub held: bool,
    /// What a particle of the upper half coming into a held support faster
    /// than `T` does.
    pub fast: Fast,
    /// The particles that rest.
    pub cells: u8,
}

/// What a fast particle does at a held support (M5.7b).
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Fast {
    /// Walls and obstacles alone: left to M5.4.
    Leave,
    /// Particles with room above: it reflects off them as off a floor.
    Reflect,
    /// A full block: it stops, as a slow one does.
    Stop,
}

/// M5.7b's support as every step reads it (M1c), for a second
/// implementation (`mpca::port`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RestConstants {
    /// The support axis: that of the largest `|G_k|`, the lowest on a tie.
    pub axis: u32,
    /// Whether `G` points to the axis' high side.
    pub up: bool,
    /// The block's cells on the side `G` points to (its lower half), a bit
    /// a cell.
    pub lower: u32,
    /// `T`: the fastest approach along the axis that is a resting contact
    /// (fine units).
    pub slow: i32,
}

impl Resting {
    /// A block where nothing rests: a world without M5.7b.
    pub(crate) const NONE: Resting = Resting { held: false, fast: Fast::Leave, cells: 0 };
}

impl Support {
    /// The support of a step whose uniform push is `g` (fine units of
    /// `2^-fine` quanta) in a world of description `d`; none where resting
    /// contact is off or the push is zero.
    pub(crate) fn of(d: &Description, g: [i64; 3], fine: u32) -> Option<Support> {
        if !d.has_rest() {
            return None;
        }
        let dim = d.dim as usize;
        let mut axis = 0;
        for k in 1..dim {
            if g[k].unsigned_abs() > g[axis].unsigned_abs() {
                axis = k;
            }
        }
        if g[axis] == 0 {
            return None;
        }
        let up = g[axis] > 0;
        let mut lower = 0u8;
        for c in 0..1usize << dim {
            lower |= u8::from((c >> axis & 1 == 1) == up) << c;
        }
        // Two pushes and a quantum of rounding: a particle that started at
        // rest, after its lower-half step and its upper-half one.
        let slow = (2 * g[axis].unsigned_abs().min(1 << 40) + (1 << fine)).min(i32::MAX as u64) as i32;
        Some(Support { axis, up, lower, slow })
    }

    /// The support as a second implementation reads it.
    pub(crate) fn constants(&self) -> RestConstants {
        RestConstants { axis: self.axis as u32, up: self.up, lower: u32::from(self.lower), slow: self.slow }
    }

    /// Which particles of the block `b` rest, and whether its support
    /// holds: every cell of its lower half `blocked` (a wall or an
    /// obstacle) or holding a particle. A still particle of the upper half
    /// rests where no particle of the lower half falls away from it.
    #[inline(always)]
    pub(crate) fn read<const D: usize>(&self, b: &impl Stored<D>, blocked: u8) -> Resting {
        let occ = b.occ();
        let (mut still, mut falling) = (0u8, 0u8);
        for c in cells_of(occ) {
            let q = b.stored(c);
            still |= u8::from(q.iter().all(|&q| q == 0)) << c;
            falling |= u8::from(self.into(q[self.axis]) > 0) << c;
        }
        let held = self.lower & !(blocked | occ) == 0;
        let upper = !self.lower & (u8::MAX >> (8 - (1 << D)));
        let fast = if self.lower & occ == 0 {
            Fast::Leave
        } else if upper & !(occ | blocked) != 0 {
            Fast::Reflect
        } else {
            Fast::Stop
        };
        // A still particle of the lower half rests on what lies below the
        // block, checked when it last lay in an upper half.
        let on = held && self.lower & falling == 0;
        Resting { held, fast, cells: still & if on { u8::MAX } else { self.lower } }
    }

    /// The component `x` along the axis, signed to be positive into the
    /// support.
    #[inline(always)]
    fn into(&self, x: i32) -> i32 {
        if self.up { x } else { -x }
    }

    /// Step 2 of M5.7b where the support holds (`resting.held`): every
    /// particle of the upper half coming into the support faster than the
    /// support's slowest cell moves away from it (walls and obstacles: 0;
    /// never below 0) loses the difference if it comes slowly or the
    /// block is full, reflects off it with restitution `e` (Q16) if it
    /// comes fast with room above, and is left to M5.4 against walls and
    /// obstacles alone.
    #[inline(always)]
    pub(crate) fn settle<const D: usize, const CELLS: usize>(&self, b: &impl Stored<D>, changes: &mut Changes<CELLS>, fine: u32, resting: Resting, e: i32) {
        let mut floor = i32::MAX;
        for c in cells_of(self.lower) {
            let away = if b.occ() >> c & 1 != 0 { self.into(changes.velocity(b, c, fine)[self.axis]) } else { 0 };
            floor = floor.min(away.max(0));
        }
        for c in cells_of(b.occ() & !self.lower) {
            let mut x = changes.velocity(b, c, fine);
            let closing = self.into(x[self.axis]) - floor;
            let after = if closing.unsigned_abs() <= self.slow as u32 {
                // A resting contact: at the support's speed, and what little
                // it slides across it is taken too.
                for k in 0..D {
                    if k != self.axis && x[k].unsigned_abs() <= self.slow as u32 {
                        x[k] = 0;
                    }
                }
                floor
            } else if closing < 0 || resting.fast == Fast::Leave {
                continue;
            } else if resting.fast == Fast::Reflect {
                floor - mulq(closing, e, 16)
            } else {
                floor
            };
            x[self.axis] = self.into(after);
            changes.set(c, x);
        }
    }
}
