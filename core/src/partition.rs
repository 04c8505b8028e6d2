//! The Margolus partition (M3) and the boundaries it meets (M4).
//!
//! Step `t` uses offset `o = t mod 2` on every axis: the block holding cell
//! `x` starts at `2 floor((x - o) / 2) + o`. Along an axis of `n` cells,
//! blocks start at `first + 2 b` for `b` in `0..blocks`:
//! - offset 0: `first = 0`, `n / 2` blocks;
//! - offset 1, periodic: `first = 1`, `n / 2` blocks, the last wrapping
//!   around to cell 0;
//! - offset 1, not periodic: `first = -1`, `n / 2 + 1` blocks, the first and
//!   last half outside the domain.
//!
//! A block's index, which seeds its stream (M8), is `bx + cx (by + cy bz)`
//! with `c` the block counts.
//!
//! Blocks holding no particle are skipped (M3) a machine word at a time: the
//! occupancy rows of a row of blocks are OR-ed together, folded pairwise, and
//! only the set bits of the fold are visited.

use crate::desc::{Boundary, Layout};

/// One axis of a step's partition.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Axis {
    pub n: usize,
    pub first: isize,
    pub blocks: usize,
    pub periodic: bool,
}

/// The block grid of one step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Partition {
    pub offset: usize,
    pub axes: [Axis; 3],
    pub dim: usize,
    row_words: usize,
}

/// What the sweep hands each occupied block to.
pub(crate) trait BlockSink {
    /// The occupancy plane, read between visits.
    fn occupancy(&self) -> &[u64];
    /// Processes the block with lowest corner `origin` and index `index`.
    fn visit(&mut self, origin: [isize; 3], index: u64);
}

const EVEN: u64 = 0x5555_5555_5555_5555;

impl Partition {
    pub fn new(layout: &Layout, boundary: &[[Boundary; 2]; 3], dim: usize, step: u64) -> Partition {
        let offset = (step & 1) as usize;
        let axis = |k: usize| {
            let n = layout.n[k];
            let periodic = boundary[k][0] == Boundary::Periodic;
            if k >= dim {
                Axis { n: 1, first: 0, blocks: 1, periodic: true }
            } else if offset == 0 {
                Axis { n, first: 0, blocks: n / 2, periodic }
            } else if periodic {
                Axis { n, first: 1, blocks: n / 2, periodic }
            } else {
                Axis { n, first: -1, blocks: n / 2 + 1, periodic }
            }
        };
        Partition { offset, axes: [axis(0), axis(1), axis(2)], dim, row_words: layout.row_words }
    }

    /// Blocks in the grid, occupied or not.
    pub fn total_blocks(&self) -> u64 {
        self.axes.iter().map(|a| a.blocks as u64).product()
    }

    /// The in-domain cell coordinate `first + 2 b + d` along axis `k`
    /// (wrapped if periodic), or `None` outside the domain.
    #[inline]
    pub fn coord(&self, k: usize, origin: isize, d: usize) -> Option<usize> {
        let a = &self.axes[k];
        let c = origin + d as isize;
        if c >= 0 && (c as usize) < a.n {
            Some(c as usize)
        } else if a.periodic {
            Some(c.rem_euclid(a.n as isize) as usize)
        } else {
            None
        }
    }

    /// Visits every block holding a particle, forward (x fastest) or in
    /// exactly the reverse order. Blocks are independent (M3), so both orders
    /// leave the same world; the tests check it.
    pub fn sweep<S: BlockSink>(&self, sink: &mut S, reverse: bool) {
        let [ax, ay, az] = self.axes;
        let zs = if self.dim == 3 { 2 } else { 1 };
        for i in 0..ay.blocks * az.blocks {
            let i = if reverse { ay.blocks * az.blocks - 1 - i } else { i };
            let (by, bz) = (i % ay.blocks, i / ay.blocks);
            let (oy, oz) = (ay.first + 2 * by as isize, az.first + 2 * bz as isize);
            // The rows (y, z) of this row of blocks that lie in the domain.
            let mut rows = [0usize; 4];
            let mut nrows = 0;
            for dz in 0..zs {
                for dy in 0..2 {
                    if let (Some(y), Some(z)) = (self.coord(1, oy, dy), self.coord(2, oz, dz)) {
                        rows[nrows] = (y + ay.n * z) * self.row_words;
                        nrows += 1;
                    }
                }
            }
            let rows = &rows[..nrows];
            let row_index = (i * ax.blocks) as u64;
            self.sweep_row(sink, rows, [oy, oz], row_index, reverse);
        }
    }

    /// The OR of word `w` over the rows of a row of blocks.
    #[inline]
    fn word(occ: &[u64], rows: &[usize], w: usize) -> u64 {
        rows.iter().fold(0, |m, &r| m | occ[r + w])
    }

    fn sweep_row<S: BlockSink>(&self, sink: &mut S, rows: &[usize], oyz: [isize; 2], row_index: u64, reverse: bool) {
        let ax = self.axes[0];
        let words = self.row_words;
        // Offset 1, not periodic: the half block (-1, 0) has block index 0
        // and the pairs below start at index 1.
        let half = self.offset == 1 && !ax.periodic;
        let half_block = |sink: &mut S| {
            if Self::word(sink.occupancy(), rows, 0) & 1 != 0 {
                sink.visit([-1, oyz[0], oyz[1]], row_index);
            }
        };
        if half && !reverse {
            half_block(sink);
        }
        // Cell nx (one past the end) is cell 0 when periodic: read it before
        // any block of the row is visited (only the wrapping block holds it).
        let wrap = self.offset == 1 && ax.periodic && Self::word(sink.occupancy(), rows, 0) & 1 != 0;
        let last = (ax.n - 1) / 64;
        for j in 0..words {
            let w = if reverse { words - 1 - j } else { j };
            let occ = sink.occupancy();
            let m = Self::word(occ, rows, w);
            let fold = if self.offset == 0 {
                // Pairs (2i, 2i+1): bit 2i of the fold.
                (m | m >> 1) & EVEN
            } else {
                // Pairs (2i+1, 2i+2): shift so bit b is cell 64 w + b + 1.
                let next = if w + 1 < words { Self::word(occ, rows, w + 1) & 1 } else { 0 };
                let mut s = m >> 1 | next << 63;
                if w == last && wrap {
                    s |= 1 << ((ax.n - 1) % 64);
                }
                (s | s >> 1) & EVEN
            };
            let mut bits = fold;
            while bits != 0 {
                let b = if reverse { 63 - bits.leading_zeros() } else { bits.trailing_zeros() } as usize;
                bits &= !(1u64 << b);
                let pair = 32 * w + b / 2;
                let (x0, bx) = if self.offset == 0 {
                    (2 * pair as isize, pair)
                } else {
                    (2 * pair as isize + 1, pair + usize::from(half))
                };
                sink.visit([x0, oyz[0], oyz[1]], row_index + bx as u64);
            }
        }
        if half && reverse {
            half_block(sink);
        }
    }
}
