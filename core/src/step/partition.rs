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

use core::ops::Range;

use crate::api::desc::Boundary;
use crate::storage::cells::Cells;
use crate::storage::layout::Layout;
use crate::step::Route;


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
    /// Summary words per row: one bit per occupancy word.
    pub summary_words: usize,
}

/// One row of blocks of a step's partition: the blocks that share their y
/// (and z) cells. Block row `r` of a block (its cells `2r` and `2r + 1`,
/// `r = dy + 2 dz`) lies in the domain row whose first bit-plane word is
/// `word[r]` and whose first cell is `cell[r]`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BlockRow {
    pub word: [usize; 4],
    pub cell: [usize; 4],
    /// The domain row `y + ny z` of block row `r`, its index in the row
    /// flags.
    pub line: [usize; 4],
    /// The block cells beyond a y or z face (a half block on a face that is
    /// not periodic), as a mask over the block's cells; their `word` and
    /// `cell` are 0 and mean nothing.
    pub outside: u8,
    /// The y and z of the blocks' lowest corner.
    pub origin: [isize; 2],
    /// The index (M8) of the row's block 0.
    pub index: u64,
}

/// What the sweep reads to find the occupied blocks, and the summaries it
/// keeps exact for the rows it sweeps.
#[derive(Clone, Copy)]
pub(crate) struct Index<'a> {
    /// The occupancy plane.
    pub occupancy: Cells<'a, u64>,
    /// A byte per domain row: 0 where the row holds no particle for sure.
    pub rows: Cells<'a, u8>,
    /// Per domain row, one bit per occupancy word: 0 where the word holds
    /// no particle for sure.
    pub words: Cells<'a, u64>,
}

/// What the sweep hands each occupied block to; `'a` is the borrow of the
/// planes.
pub(crate) trait BlockSink<'a> {
    /// Cells of a block: 4 in 2D, 8 in 3D.
    const CELLS: usize;
    /// The dimension, from `CELLS`: a constant, so that the sweep's loops
    /// over a row's layers unroll and its cell masks fold.
    const DIM: usize = if Self::CELLS == 8 { 3 } else { 2 };
    /// The planes the sweep reads and the summaries it keeps, read between
    /// visits.
    fn index(&self) -> Index<'a>;
    /// What the sink decides once for a row of blocks, handed back to each
    /// visit of that row.
    type Plan: Copy;
    /// The plan of `row`: made once before its blocks are visited (the
    /// small sweep makes it at each block, where it is a constant).
    fn plan(&self, row: &BlockRow) -> Self::Plan;
    /// Processes block `bx` of `row`, whose lowest corner has x `x0` and
    /// whose cells holding a particle are the set bits of `occ` (bit `c` for
    /// cell `c`, never a cell beyond a face).
    fn visit(&mut self, row: &BlockRow, plan: Self::Plan, x0: isize, bx: usize, occ: u8);
}

/// The block cells with offset `d` along axis `k`, for blocks of `2^dim`
/// cells: bit `c` set where `(c >> k) & 1 == d`.
pub(crate) const fn cells_at(k: usize, d: usize, dim: usize) -> u8 {
    let mut mask = 0u8;
    let mut c = 0;
    while c < 1 << dim {
        if (c >> k) & 1 == d {
            mask |= 1 << c;
        }
        c += 1;
    }
    mask
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
        Partition { offset, axes: [axis(0), axis(1), axis(2)], dim, row_words: layout.row_words, summary_words: layout.summary_words }
    }

    /// Blocks in the grid, occupied or not. Multiplied in machine words:
    /// an axis has no more blocks than cells (`n / 2 + 1 <= n`), and the
    /// cells fit a `u32` (`Layout::of`), so the product does too.
    pub fn total_blocks(&self) -> u64 {
        self.axes.iter().map(|a| a.blocks).product::<usize>() as u64
    }

    /// The coordinates of cell `c` of a block of `row` whose x coordinates
    /// are `xs`: `[xs[0], y, z]` with y and z of the row's cell `c`.
    /// Meaningful for cells inside the domain only.
    #[inline]
    pub fn cell_coords(&self, row: &BlockRow, xs: [usize; 3], c: usize) -> [usize; 3] {
        let y = self.axis_pair(1, row.origin[0]).0[(c >> 1) & 1];
        let z = self.axis_pair(2, row.origin[1]).0[(c >> 2) & 1];
        [xs[0], y, z]
    }

    /// The coordinates of a block's two cells along axis `k`, for the block
    /// starting at `origin`, and a mask of those beyond a face (bit `d` for
    /// cell `origin + d`; its coordinate is then 0 and means nothing). Only
    /// a block at offset 1 on a face that is not periodic has one; on a
    /// periodic axis the last block wraps round to cell 0.
    #[inline]
    pub fn axis_pair(&self, k: usize, origin: isize) -> ([usize; 2], u8) {
        let a = &self.axes[k];
        if origin < 0 {
            ([0, 0], 0b01)
        } else if origin as usize + 1 < a.n {
            ([origin as usize, origin as usize + 1], 0)
        } else if a.periodic {
            ([a.n - 1, 0], 0)
        } else {
            ([a.n - 1, 0], 0b10)
        }
    }

    /// The rows of blocks of the step, numbered `by + cy bz`.
    pub fn block_rows(&self) -> usize {
        self.axes[1].blocks * self.axes[2].blocks
    }

    /// Task `i` of `count` of a parallel step (M11): a band of consecutive
    /// rows of blocks, the bands of `0..count` covering every row once.
    /// Rows of blocks share no domain row, so tasks share no element of any
    /// plane the step writes (see [`Cells`]).
    #[cfg(target_has_atomic = "8")]
    pub fn band(&self, i: usize, count: usize) -> Range<usize> {
        let total = self.block_rows();
        let edge = |i: usize| (i as u64 * total as u64 / count as u64) as usize;
        edge(i)..edge(i + 1)
    }

    /// Visits every block holding a particle in the rows of blocks of
    /// `band` (all of them: `0..block_rows()`), forward (x fastest) or, on
    /// the route `R` that says so, in exactly the reverse order. Blocks are independent (M3), so both orders
    /// leave the same world; the tests check it.
    ///
    /// Rows of blocks whose domain rows are all flagged empty are skipped,
    /// four at a time where eight rows of flags read as one word are zero;
    /// a row of blocks that is swept leaves its rows' flags exact.
    ///
    /// On a route that does not skip, every row and word is swept, whatever
    /// the summaries say (the tests' reference).
    ///
    /// The flags and summaries of rows outside the band are neither read
    /// nor written, so bands can be swept at the same time (M11).
    pub fn sweep_band<'a, S: BlockSink<'a>, R: Route>(&self, sink: &mut S, band: Range<usize>) {
        let (reverse, skip) = (R::REVERSE, R::SKIP);
        if cfg!(feature = "small-step") {
            return self.sweep_band_small(sink, band, reverse);
        }
        let idx = sink.index();
        let [ax, ay, az] = self.axes;
        let dim = S::DIM;
        debug_assert_eq!(dim, self.dim);
        let layers = dim - 1;
        let total = band.len();
        let mut j = 0;
        while j < total {
            let i = if reverse { band.end - 1 - j } else { band.start + j };
            let (by, bz) = (i % ay.blocks, i / ay.blocks);
            let origin = [ay.first + 2 * by as isize, az.first + 2 * bz as isize];
            let (ys, y_out) = self.axis_pair(1, origin[0]);
            let (zs, z_out) = self.axis_pair(2, origin[1]);
            // The row's domain rows and their flags first; the addresses
            // only for a row of blocks that is swept.
            let (mut line, mut outside, mut flagged) = ([0; 4], 0u8, false);
            for dz in 0..layers {
                for dy in 0..2 {
                    if (y_out >> dy | z_out >> dz) & 1 != 0 {
                        // The masks as constants (no call at opt-level z).
                        let y = if dy == 0 { const { cells_at(1, 0, S::DIM) } } else { const { cells_at(1, 1, S::DIM) } };
                        let z = if dz == 0 { const { cells_at(2, 0, S::DIM) } } else { const { cells_at(2, 1, S::DIM) } };
                        outside |= y & z;
                        continue;
                    }
                    let l = ys[dy] + ay.n * zs[dz];
                    line[dy + 2 * dz] = l;
                    flagged |= idx.rows.get(l) != 0;
                }
            }
            if flagged || !skip {
                j += 1;
                let (words, cells) = (line.map(|l| l * self.row_words), line.map(|l| l * ax.n));
                let row = BlockRow { word: words, cell: cells, line, outside, origin, index: (i * ax.blocks) as u64 };
                self.sweep_row(sink, idx, &row, reverse, skip);
                continue;
            }
            // An empty row of blocks: skip it, and the empty ones after it
            // four at a time where their flags say so. Rows of blocks from
            // i to the band's edge, i included.
            let room = if reverse { i - band.start + 1 } else { band.end - i };
            j += match layers {
                1 => self.empty_run_2d(idx.rows, [by, bz], reverse, room),
                _ => self.empty_run::<2>(idx.rows, [by, bz], reverse, room),
            }
            .max(1);
        }
    }

    /// [`Partition::sweep_band`] with `small-step`: the rows of blocks in
    /// the band, and in each the blocks holding a particle, found from the
    /// set bits of the OR of the row's domain rows, a word at a time, and
    /// visited in the same order. The row flags and summary words are
    /// neither read nor kept: only the sweep without `small-step` reads
    /// them, to skip what they say is empty, and the blocks and the edits
    /// only ever set them. Much less code; a word read for every word of
    /// every row.
    fn sweep_band_small<'a, S: BlockSink<'a>>(&self, sink: &mut S, band: Range<usize>, reverse: bool) {
        let occupancy = sink.index().occupancy;
        // By reference: a copy of the axes is a memcpy call at opt-level z.
        let [ax, ay, az] = &self.axes;
        // Offset 1 on a periodic x axis: the last block holds cells n - 1
        // and 0; bit 0 of a row is that block's, not block 0's.
        let wraps = ax.first == 1;
        let last = ax.blocks - 1;
        for j in 0..band.len() {
            let i = if reverse { band.end - 1 - j } else { band.start + j };
            // In 2D one layer of rows of blocks: no division.
            let (by, bz) = if S::DIM == 2 { (i, 0) } else { (i % ay.blocks, i / ay.blocks) };
            let origin = [ay.first + 2 * by as isize, az.first + 2 * bz as isize];
            let (ys, y_out) = self.axis_pair(1, origin[0]);
            let (zs, z_out) = self.axis_pair(2, origin[1]);
            let mut row = BlockRow { word: [0; 4], cell: [0; 4], line: [0; 4], outside: 0, origin, index: (i * ax.blocks) as u64 };
            // Block row r holds cells 2r and 2r + 1, at y offset r & 1 and
            // z offset r >> 1.
            for r in 0..S::CELLS / 2 {
                if (y_out >> (r & 1) | z_out >> (r >> 1)) & 1 != 0 {
                    row.outside |= 3 << (2 * r);
                    continue;
                }
                let l = ys[r & 1] + ay.n * zs[r >> 1];
                (row.line[r], row.word[r], row.cell[r]) = (l, l * self.row_words, l * ax.n);
            }
            // Block bx, if it holds a particle: its occupancy read a cell
            // at a time, now (the blocks before it changed only their own
            // cells).
            let mut visit = |bx: usize| {
                let x0 = ax.first + 2 * bx as isize;
                let (xs, x_out) = self.axis_pair(0, x0);
                let mut occ = 0u8;
                for c in 0..S::CELLS {
                    if (row.outside | x_out << (c & !1)) >> c & 1 == 0 {
                        let (x, word) = (xs[c & 1], row.word[c >> 1]);
                        occ |= ((occupancy.get(word + (x >> 6)) >> (x & 63)) as u8 & 1) << c;
                    }
                }
                if occ != 0 {
                    // The plan at each block: with `small-step` it is a
                    // constant, and nothing is kept for the row.
                    sink.visit(&row, sink.plan(&row), x0, bx, occ);
                }
            };
            // The blocks of the set bits, each once: `next` is the first
            // block not passed yet (forward) or the last (reverse, from
            // one past the end).
            let mut next = if reverse { ax.blocks } else { 0 };
            if reverse && wraps {
                visit(last);
                next = last;
            }
            for jw in 0..self.row_words {
                let w = if reverse { self.row_words - 1 - jw } else { jw };
                let mut m = 0u64;
                for r in 0..S::CELLS / 2 {
                    if row.outside >> (2 * r) & 1 == 0 {
                        m |= occupancy.get(row.word[r] + w);
                    }
                }
                while m != 0 {
                    let b = if reverse { 63 - m.leading_zeros() } else { m.trailing_zeros() } as usize;
                    m &= !(1u64 << b);
                    let x = 64 * w + b;
                    if wraps && x == 0 {
                        continue;
                    }
                    let bx = ((x as isize - ax.first) >> 1) as usize;
                    if (!reverse && bx >= next) || (reverse && bx < next) {
                        visit(bx);
                        next = if reverse { bx } else { bx + 1 };
                    }
                }
            }
            if !reverse && wraps && next <= last {
                visit(last);
            }
        }
    }

    /// How many rows of blocks from (`by`, `bz`) on (back from it in
    /// reverse), all in one layer of blocks, away from the faces and among
    /// the `room` rows of blocks left in the band, hold no particle for
    /// sure: a multiple of four, their rows read eight flags at a time, at
    /// most 32; rows of blocks hold `LAYERS` layers of cells (1 in 2D, 2
    /// in 3D).
    #[inline(always)]
    fn empty_run<const LAYERS: usize>(&self, rows: Cells<'_, u8>, [by, bz]: [usize; 2], reverse: bool, room: usize) -> usize {
        let [_, ay, az] = self.axes;
        let (zs, z_out) = self.axis_pair(2, az.first + 2 * bz as isize);
        let mut run = 0;
        while run < 32 && run + 4 <= room {
            // The four rows of blocks from `low` to `low + 3`.
            let low = if reverse { by.checked_sub(run + 3) } else { Some(by + run).filter(|&b| b + 4 <= ay.blocks) };
            let Some(low) = low else { break };
            let y = ay.first + 2 * low as isize;
            if y < 0 || y as usize + 8 > ay.n {
                break;
            }
            let empty = (0..LAYERS).all(|dz| {
                let at = zs[dz] * ay.n + y as usize;
                z_out >> dz & 1 != 0 || rows.window::<8>(at) == [0; 8]
            });
            if !empty {
                break;
            }
            run += 4;
        }
        run
    }

    /// [`Partition::empty_run`] in 2D, out of line: one copy for both
    /// velocity widths. In 3D it stays inline, where most rows of a world
    /// are empty and a call for each run of them would cost a scene such as
    /// water a measurable share of its blocks' instructions.
    #[inline(never)]
    fn empty_run_2d(&self, rows: Cells<'_, u8>, at: [usize; 2], reverse: bool, room: usize) -> usize {
        self.empty_run::<1>(rows, at, reverse, room)
    }

    /// Word `w` of each domain row of a row of blocks (0 for a row beyond
    /// a face), block row `r` in element `r`.
    #[inline]
    fn words<const ROWS: usize>(occ: Cells<'_, u64>, row: &BlockRow, w: usize) -> [u64; ROWS] {
        let mut m = [0; ROWS];
        for (r, m) in m.iter_mut().enumerate() {
            if row.outside >> (2 * r) & 1 == 0 {
                *m = occ.get(row.word[r] + w);
            }
        }
        m
    }

    fn sweep_row<'a, S: BlockSink<'a>>(&self, sink: &mut S, idx: Index<'a>, row: &BlockRow, reverse: bool, skip: bool) {
        match S::CELLS {
            4 => self.sweep_row_of::<S, 2>(sink, idx, row, reverse, skip),
            _ => self.sweep_row_of::<S, 4>(sink, idx, row, reverse, skip),
        }
    }

    /// Visits the occupied blocks of one row of blocks, whose blocks have
    /// `ROWS` rows of two cells. Each word of the row's domain rows is read
    /// once: the blocks' occupancy comes from the words the sweep holds.
    /// Blocks only change their own cells, so a word read before a block
    /// was visited still holds the right bits for every later block.
    #[inline(always)]
    fn sweep_row_of<'a, S: BlockSink<'a>, const ROWS: usize>(&self, sink: &mut S, idx: Index<'a>, row: &BlockRow, reverse: bool, skip: bool) {
        let ax = self.axes[0];
        let words = self.row_words;
        let sw = self.summary_words;
        let inside = |r: usize| row.outside >> (2 * r) & 1 == 0;
        // The block's cells 2r, 2r + 1 from bits b, b + 1 of row word r.
        let block = |m: &[u64; ROWS], b: usize| {
            let mut bits = 0u8;
            for r in 0..ROWS {
                bits |= ((m[r] >> b) as u8 & 3) << (2 * r);
            }
            bits
        };
        // Summary word k of the row's domain rows, OR-ed.
        let summary = |idx: &Index<'_>, k: usize| (0..ROWS).filter(|&r| inside(r)).fold(0, |s, r| s | idx.words.get(row.line[r] * sw + k));
        // Offset 1, not periodic: the half block (-1, 0) has block index 0,
        // its cell 1 in bit 0 of each row, and the pairs after it start at
        // index 1.
        let half = self.offset == 1 && !ax.periodic;
        let plan = sink.plan(row);
        let half_block = |sink: &mut S| {
            let first = Self::words::<ROWS>(idx.occupancy, row, 0).map(|m| (m & 1) << 1);
            let bits = block(&first, 0);
            if bits != 0 {
                sink.visit(row, plan, -1, 0, bits);
            }
        };
        // The rows' flags start cleared; they are set again below for every
        // row a word with a particle is seen in, and by the blocks for every
        // row a particle moves into.
        for r in (0..ROWS).filter(|&r| inside(r)) {
            idx.rows.set(row.line[r], 0);
        }
        let mut seen = [0u64; ROWS];
        if half && !reverse {
            half_block(sink);
        }
        // Cell nx (one past the end) is cell 0 when periodic: read it before
        // any block of the row is visited (only the wrapping block holds it).
        let wrap = if self.offset == 1 && ax.periodic {
            Self::words::<ROWS>(idx.occupancy, row, 0).map(|m| m & 1)
        } else {
            [0; ROWS]
        };
        let last = (ax.n - 1) / 64;
        for jk in 0..sw {
            let k = if reverse { sw - 1 - jk } else { jk };
            // The words to sweep: those that may hold a particle, and at
            // offset 1 those before them (the pair 64w + 63, 64w + 64 lies
            // across two words, and the last word's pair wraps to cell 0).
            let mut todo = summary(&idx, k);
            if !skip {
                // Every word of the row.
                let count = (words - 64 * k).min(64);
                todo = u64::MAX >> (64 - count);
            }
            if self.offset == 1 {
                let next = if k + 1 < sw { summary(&idx, k + 1) & 1 } else { 0 };
                todo |= todo >> 1 | next << 63;
                if last >> 6 == k && wrap.iter().any(|&b| b != 0) {
                    todo |= 1 << (last & 63);
                }
            }
            while todo != 0 {
                let b = if reverse { 63 - todo.leading_zeros() } else { todo.trailing_zeros() } as usize;
                todo &= !(1u64 << b);
                let w = 64 * k + b;
                let mut m = Self::words::<ROWS>(idx.occupancy, row, w);
                for r in (0..ROWS).filter(|&r| inside(r)) {
                    seen[r] |= m[r];
                    if m[r] == 0 {
                        // Swept and empty: the summary says so from now on.
                        let at = row.line[r] * sw + k;
                        idx.words.set(at, idx.words.get(at) & !(1u64 << b));
                    }
                }
                if self.offset == 1 {
                    // Pairs (2i+1, 2i+2): shift so bit b is cell 64 w + b + 1.
                    let next = if w + 1 < words { Self::words::<ROWS>(idx.occupancy, row, w + 1) } else { [0; ROWS] };
                    for r in 0..ROWS {
                        m[r] = m[r] >> 1 | next[r] << 63;
                        if w == last {
                            m[r] |= wrap[r] << ((ax.n - 1) % 64);
                        }
                    }
                }
                let any = m.iter().fold(0, |a, &x| a | x);
                // Pair (2i, 2i+1) of the (shifted) words: bit 2i of the fold.
                let mut bits = (any | any >> 1) & EVEN;
                while bits != 0 {
                    let b = if reverse { 63 - bits.leading_zeros() } else { bits.trailing_zeros() } as usize;
                    bits &= !(1u64 << b);
                    let pair = 32 * w + b / 2;
                    let occ = block(&m, b);
                    // At offset 1 the pair starts one cell on, and after a
                    // half block its index is one more (`half` implies
                    // offset 1). One call for both offsets: the block
                    // routines are inlined here, and a call in each branch
                    // copied them twice into libmpca.so.
                    sink.visit(row, plan, (2 * pair + self.offset) as isize, pair + usize::from(half), occ);
                }
            }
        }
        if half && reverse {
            half_block(sink);
        }
        for r in (0..ROWS).filter(|&r| inside(r) && seen[r] != 0) {
            idx.rows.set(row.line[r], 1);
        }
    }
}
