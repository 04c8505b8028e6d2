//! The local map of M5 on one block: the step's inner loop, written once
//! as one pipeline ([`Kernel::local_map`]).
//!
//! The pipeline reads a block from what the sweep hands it (its occupancy
//! bits, the block row's addresses), keeps the velocities nothing changed
//! as the stored integers (in quanta), decides the moves of M5.3 by
//! comparing 16 random bits with a table entry of the stored component,
//! assigns moves in 2D with one look-up in a table of every block state's
//! optimal assignments, and writes back only what changed: a block where
//! nothing moved and no velocity changed writes nothing. A velocity the
//! force or a collision changes is kept as an `i32` in fine units (M1c),
//! clamped after each stage (M5.5) and rounded back to stored quanta once,
//! after the collision stage (M1); a reflection (M5.4) rounds the velocity
//! it reflects again. The move decisions of M5.3 therefore always read
//! integers.
//!
//! What varies between blocks is a parameter of the pipeline, chosen once
//! a step and once a row ([`RowPlan`]), never a second copy of a stage:
//! - the parts it has code for ([`Parts`]): [`Every`] part, switched on
//!   and off by the description at run time (the faces, obstacles, masses,
//!   lifetimes, summed forces, drag, contacts), or a plain world's block
//!   away from the faces and obstacles ([`Plain`], and [`Bare`] without
//!   contacts), whose cells are unrolled (not for 16-bit 3D worlds, whose
//!   blocks all take [`Every`]: the C library's size budget);
//! - the block's representation ([`Plane`]): per-cell arrays ([`Block`]),
//!   or, for the plain 2D block of an 8-bit world, one word of byte lanes
//!   ([`Lanes`]), whose rarer stages run out of line;
//! - the stored velocity width ([`Widths`]): the plain instantiations take
//!   the world's as a type, which folds at compile time; the one with
//!   [`Every`] part reads it from the step's data ([`AnyWidth`]), so that
//!   one copy serves both widths: the width shows only in its loads and
//!   writes of the velocity plane, the fine units and the clamp's limit
//!   (M1c, M5.5), the rounding (M1) and the move limits (M5.3);
//! - the firmware's size-before-speed choices (feature `small-step`):
//!   every block takes [`Every`] with cells in loops, at the world's width
//!   as a type, and the helpers that every stage calls stay out of line.
//!
//! The stages live in files named after their rules: the force and drag
//! (M5.1, M5.1b, `force.rs`), the collision (M5.2, `collision.rs`), the
//! rounding (M1, `rounding.rs`), the desired move (M5.3, `moves.rs`), the
//! reflection (M5.4, `reflection.rs`), the clamp (M5.5, `clamp.rs`), the
//! assignment (M5.6, `assign.rs`) and the contacts (M5.7, `contacts.rs`).
//!
//! Every draw of a block comes from its stream (M8), in this order:
//! 1. M5.2, if the block holds two particles or more, the pair (16 bits);
//!    if both cells of the pair hold one and their velocities differ, the
//!    unit vector `R` (32 or 48 bits a try);
//! 2. M1, per particle in cell order whose velocity the force or the
//!    collision changed, its rounding (16 bits a component: 32 bits in 2D,
//!    a 64-bit output in 3D);
//! 3. M5.3 and M5.4: in 3D, per particle in cell order that could move
//!    inside the block along some axis, 16 bits per axis (32, then 16); in
//!    2D, where some particle could, one 64-bit output (a byte per cell and
//!    axis), then in cell and axis order 8 bits per axis whose byte ties
//!    with its threshold's ([`Kernel::crosses`]); after a reflection, the
//!    reflected velocity's rounding;
//! 4. M5.6, the tie-break of the assignment, where there is a choice;
//! 5. M1 after M5.7's contacts (when on), per particle in cell order whose
//!    velocity a contact changed, its rounding.
//!
//! M5.1 draws nothing.

use crate::api::desc::Identity;
use crate::rules::collision::pick_pair;
use crate::rules::faces::{resolve, Beyond};
use core::marker::PhantomData;

use crate::rules::rng::Stream;
use crate::step::assign::{stored_speed2, FIELDS, IDENTITY};
#[cfg(not(feature = "small-step"))]
use crate::step::block::AnyWidth;
use crate::step::block::{cells_of, each_occupied, Bare, Block, Carried, Every, Kernel, Parts, Plain, Shared, Site, Stored, Typed, Velocity, Widths};
#[cfg(feature = "identity")]
use crate::step::identity::carry;
use crate::step::contacts::contacts;
use crate::step::rest::Resting;
use crate::step::lanes::Lanes;
use crate::step::partition::{cells_at, BlockRow, BlockSink, Index};
use crate::step::rounding::{round_apart, Changes};
use crate::storage::layout::{mark, put_bit};

/// A representation of a block's velocities ([`Stored`]) with its writes
/// of the velocity plane of width `W`.
pub(crate) trait Plane<W, const D: usize>: Stored<D> {
    /// The stages that most blocks of a step skip (the force and
    /// collision, the assignment and write back) run out of line: the
    /// sweep's loop keeps its registers.
    const APART: bool;
    /// Writes cell `c`'s stored velocity to cell `at` of the plane.
    fn write(&self, velocity: &Velocity<'_, D>, sh: &Shared<'_>, c: usize, at: usize);
    /// Writes the velocities that changed (`dirty`) back to their own
    /// cells, where no particle moved.
    fn write_in_place(&self, velocity: &Velocity<'_, D>, sh: &Shared<'_>, site: &Site<'_>);
}

impl<W: Widths, const D: usize, const CELLS: usize> Plane<W, D> for Block<D, CELLS> {
    const APART: bool = false;

    #[inline(always)]
    fn write(&self, velocity: &Velocity<'_, D>, sh: &Shared<'_>, c: usize, at: usize) {
        W::store(velocity, sh, at, &self.v[c]);
    }

    #[inline(always)]
    fn write_in_place(&self, velocity: &Velocity<'_, D>, sh: &Shared<'_>, site: &Site<'_>) {
        for c in cells_of(self.dirty) {
            W::store(velocity, sh, site.cell(c), &self.v[c]);
        }
    }
}

impl<Q: Typed, const D: usize> Plane<Q, D> for Lanes {
    const APART: bool = true;

    #[inline(always)]
    fn write(&self, velocity: &Velocity<'_, D>, _: &Shared<'_>, c: usize, at: usize) {
        Q::plane(velocity).set(at, self.to_plane::<Q, D>(c));
    }

    #[inline(always)]
    fn write_in_place(&self, velocity: &Velocity<'_, D>, _: &Shared<'_>, site: &Site<'_>) {
        // SAFETY: a lanes block is loaded only where the row plan's bound
        // holds for its x0 (`visit`).
        unsafe { self.write_rows(Q::plane(velocity), site.row, site.xs[0]) }
    }
}

/// What the sweep hands the blocks of a world of stored type `Q` to: the
/// pipeline, whose plain instantiations take `Q`'s width at compile time,
/// and whose one with every part reads the step's ([`AnyWidth`]).
pub(crate) struct Sink<'a, Q, const D: usize, const CELLS: usize> {
    pub kernel: Kernel<'a, D, CELLS>,
    stored: PhantomData<Q>,
}

impl<'a, Q, const D: usize, const CELLS: usize> Sink<'a, Q, D, CELLS> {
    /// The sink of a world of `Q` for `kernel`.
    #[inline(always)]
    pub(crate) fn new(kernel: Kernel<'a, D, CELLS>) -> Self {
        Sink { kernel, stored: PhantomData }
    }
}

/// A row of blocks as [`Kernel::visit`] sees it, worked out once a row.
#[derive(Clone, Copy)]
pub(crate) struct RowPlan {
    /// The blocks with x0 below it take a plain instantiation
    /// ([`Lanes`] for 2D 8-bit worlds, [`Block`] for the others), where
    /// the world lets them (0 where it does not), and the others [`Every`]
    /// part: in a row of blocks away from the y and z faces, every block
    /// up to the one that wraps round x.
    lean_below: usize,
    /// The world has obstacles: a block's own are read before it is plain.
    obstacles: bool,
}

/// The bits of a block in a bit plane, bit `c` for cell `c` (x `xs[c & 1]`
/// in the block row `c >> 1` whose words start at `row.word`): one read per
/// block row where its two cells share a word.
#[inline(always)]
fn read_block<const CELLS: usize>(plane: &[u64], row: &BlockRow, xs: [usize; 2]) -> u8 {
    let mut bits = 0u8;
    if xs[1] == xs[0] + 1 && xs[0] & 63 != 63 {
        let (w, s) = (xs[0] >> 6, xs[0] & 63);
        for r in 0..CELLS / 2 {
            bits |= ((plane[row.word[r] + w] >> s) as u8 & 3) << (2 * r);
        }
    } else {
        for c in 0..CELLS {
            let b = xs[c & 1] + 64 * row.word[c >> 1];
            bits |= ((plane[b >> 6] >> (b & 63)) as u8 & 1) << c;
        }
    }
    bits
}

impl<const D: usize, const CELLS: usize> Kernel<'_, D, CELLS> {
    /// Every cell of the block.
    pub(crate) const EVERY_CELL: u8 = {
        assert!(CELLS == 1 << D && (D == 2 || D == 3));
        (u8::MAX as usize >> (8 - CELLS)) as u8
    };

    /// The local map of M5 on the block at `site` with the stored
    /// velocities `b`, drawing from the stream of block `index` (M8): the
    /// one place where the stages and their draws are put in order.
    #[inline(always)]
    fn local_map<W: Widths, P: Parts, R: Plane<W, D>>(&mut self, site: &Site<'_>, index: u64, mut b: R) {
        let carried = self.carried::<P>(site, b.occ());
        let mut rng = self.shared.key.stream(index);
        // M5.2's pair, the block's first draw: nothing before the collision
        // draws.
        let pair = pick_pair::<D>(b.occ(), &mut rng);
        // M5.1 force, M5.1b drag, M5.2 collision, then M1 for what they
        // changed. With `small-step` every block goes through them: the
        // tests would take more flash than they save.
        if cfg!(feature = "small-step") || pair.is_some() || self.pushes::<P>() {
            if R::APART {
                b = self.change_apart::<W, P, R>(site.row, site.xs[0], b, pair, &mut rng);
            } else {
                self.change::<W, P, R>(site, &mut b, &carried, pair, &mut rng);
            }
        }
        // M5.3 desired move, M5.4 reflection: the axes each particle wants
        // to cross, `D` bits a cell.
        let want = self.desire::<W, P, R>(site, &mut b, &carried, &mut rng);
        self.counters.processed += 1;
        // Plain blocks only: for the others `finish` serves this case too
        // (less code; with `small-step`, less flash).
        if !P::ALL && want == 0 {
            // M5.6 leaves every particle in place without a draw, and M5.7
            // has no refused particle: only changed velocities to write.
            if b.dirty() != 0 {
                b.write_in_place(&self.planes.velocity, self.shared, site);
            }
            return;
        }
        // M5.6 move, M5.7 contacts, and the block written back.
        if R::APART {
            self.finish_apart::<W, P, R>(site.row, site.xs[0], b, want, &mut rng);
        } else {
            self.finish::<W, P, R>(site, &mut b, &carried, want, &mut rng);
        }
    }

    /// The mass indices and lifetimes of the block's particles, where the
    /// parts are on.
    #[inline(always)]
    fn carried<P: Parts>(&self, site: &Site<'_>, occ: u8) -> Carried<CELLS> {
        // Guarded: an empty loop over the cells is not left out by itself.
        if !P::ALL {
            return Carried::none();
        }
        let desc = &self.shared.rules;
        let mut carried = Carried::new(desc.has_masses(), desc.lifetimes);
        for c in cells_of(occ) {
            if carried.masses() {
                carried.mass_index[c] = self.planes.mass_index.get(site.cell(c));
            }
            if carried.lifetimes {
                carried.life[c] = self.planes.life.get(site.cell(c));
            }
        }
        carried
    }

    /// M5.1, M5.1b, M5.2 on the block (the collision on `pair`, when both
    /// its cells hold a particle), then M1 for what they changed.
    #[inline(always)]
    fn change<W: Widths, P: Parts, R: Plane<W, D>>(&mut self, site: &Site<'_>, b: &mut R, carried: &Carried<CELLS>, pair: Option<(usize, usize)>, rng: &mut Stream) {
        let sh = self.shared;
        let w = W::width(sh);
        let class = |c: usize| carried.class(sh, c);
        // A lanes block where only the collision changes anything (most
        // of a 2D gas's): its two results rounded in cell order (a < c in
        // every pair), as [`Changes::round`] would, without keeping them.
        // (The caller had a pair.) Lanes alone: a second copy of the
        // collision in every instantiation would cost more code than it
        // saves time elsewhere.
        if R::APART && !self.pushes::<P>() {
            let Some((a, c)) = pair else { return };
            if let Some((xa, xc)) = self.collide_two::<W>(b.fine(a, w.fine), b.fine(c, w.fine), (class(a), class(c)), !carried.masses(), rng) {
                b.put(a, w.round::<D>(xa, rng));
                b.put(c, w.round::<D>(xc, rng));
            }
            return;
        }
        let mut changes = Changes::<CELLS>::new();
        // M5.7b: what the block's particles rest on (nothing without it;
        // no code for it in a build without the collision rules).
        let support = if P::ALL && cfg!(feature = "collision-rules") { sh.rest } else { None };
        let resting = support.map_or(Resting::NONE, |s| s.read(&*b, site.blocked));
        self.force::<W, P>(site, b, &mut changes, carried, resting.cells);
        if P::ALL {
            self.drag::<W>(site, b, &mut changes, carried);
        }
        if let (Some(s), true) = (support, resting.held) {
            s.settle::<D, CELLS>(&*b, &mut changes, w.fine, resting, sh.restitution);
        }
        if let Some((a, c)) = pair {
            let (va, vc) = (changes.velocity(b, a, w.fine), changes.velocity(b, c, w.fine));
            if let Some((xa, xc)) = self.collide_two::<W>(va, vc, (class(a), class(c)), !carried.masses(), rng) {
                changes.set(a, xa);
                changes.set(c, xc);
            }
        }
        changes.round::<W, D>(b, sh, rng);
    }

    /// [`Kernel::change`] out of line, for a plain block (`!P::ALL`) at
    /// x `x0` of `row`: its site and what its particles carry are
    /// rebuilt here, since they hold nothing but those, and the block goes
    /// by value: passed by reference, each would be written to memory for
    /// every block.
    #[inline(never)]
    fn change_apart<W: Widths, P: Parts, R: Plane<W, D>>(&mut self, row: &BlockRow, x0: usize, mut b: R, pair: Option<(usize, usize)>, rng: &mut Stream) -> R {
        debug_assert!(!P::ALL);
        self.change::<W, P, R>(&Site::plain(row, x0), &mut b, &Carried::none(), pair, rng);
        b
    }

    /// M5.6 for the particles that want to cross the axes `want` (`D` bits
    /// a cell), M5.7 and M1 for what the contacts changed, then the block
    /// written back: each particle's velocity in its new cell, or the
    /// particle gone through an open face (M4) or at the end of its
    /// lifetime (M6), and the occupancy.
    #[inline(always)]
    fn finish<W: Widths, P: Parts, R: Plane<W, D>>(&mut self, site: &Site<'_>, b: &mut R, carried: &Carried<CELLS>, want: u32, rng: &mut Stream) {
        let sh = self.shared;
        let w = W::width(sh);
        let occ = b.occ();
        let targets = self.assign(occ, |c| stored_speed2(b.stored(c)), site.blocked, want, rng);
        if P::CONTACTS && sh.rules.has_contacts() && want != 0 {
            let mut changes = Changes::<CELLS>::new();
            // A copy: a reference would keep `carried` in memory, and its
            // switches from folding.
            let mass_index = carried.masses().then_some(carried.mass_index);
            contacts::<D, CELLS>(sh, &*b, &mut changes, want, targets, mass_index, w.unit, w.fine, &mut self.counters);
            round_apart::<W, D, CELLS>(&changes, b, sh, rng);
        }
        // Nothing to write where nobody moves and no velocity changed. Not
        // tested with `small-step`: the write back below changes nothing
        // then, and the test takes flash.
        // M6b: a plain world has no ids, ages or tags (not read for its
        // blocks).
        let on = if P::ALL { sh.rules.identity_planes() } else { Identity::NONE };
        if !cfg!(feature = "small-step") && (targets ^ IDENTITY) & FIELDS[usize::from(occ)] == 0 && b.dirty() == 0 && !carried.lifetimes && !on.ages() {
            return;
        }
        let mut after = 0u8;
        each_occupied!(!P::ALL && (!w.wide() || D == 2), CELLS, occ, c => {
            let t = (targets >> (4 * c) & 7) as usize;
            if P::ALL && site.open >> t & 1 != 0 {
                self.counters.exited += 1; // M4 open face
            } else if carried.lifetimes && carried.life[c] == 1 {
                self.counters.expired += 1; // M6 lifetime
            } else {
                after |= 1 << t;
                let to = site.cell(t);
                if t != c || b.dirty() >> c & 1 != 0 {
                    b.write(&self.planes.velocity, sh, c, to);
                }
                if carried.masses() && t != c {
                    self.planes.mass_index.set(to, carried.mass_index[c]);
                }
                if carried.lifetimes {
                    self.planes.life.set(to, carried.life[c].saturating_sub(1));
                }
            }
        });
        #[cfg(feature = "identity")]
        if P::ALL && on.any() {
            carry(sh.identity, site, occ, after, targets, on);
        }
        self.occupy(site, occ, after);
    }

    /// [`Kernel::finish`] out of line, for a plain block, as
    /// [`Kernel::change_apart`].
    #[inline(never)]
    fn finish_apart<W: Widths, P: Parts, R: Plane<W, D>>(&mut self, row: &BlockRow, x0: usize, mut b: R, want: u32, rng: &mut Stream) {
        debug_assert!(!P::ALL);
        self.finish::<W, P, R>(&Site::plain(row, x0), &mut b, &Carried::none(), want, rng);
    }

    /// Sets and clears the block's occupancy bits from `before` to `after`:
    /// a block row's two bits in one word where they share it, flagging a
    /// row that held none of the block's particles (the sweep may have
    /// passed it as empty: M3).
    #[inline(always)]
    pub(crate) fn occupy(&mut self, site: &Site<'_>, before: u8, after: u8) {
        let (xs, row) = (site.xs, site.row);
        let occupancy = self.planes.occupancy;
        let summary = self.shared.part.summary_words;
        // 2D: most blocks are lanes, whose rows share a word. Not with
        // `small-step`: the bit by bit loop below serves every block.
        if D == 2 && !cfg!(feature = "small-step") && xs[1] == xs[0] + 1 && xs[0] & 63 != 63 {
            let shift = xs[0] & 63;
            for r in 0..CELLS / 2 {
                let (old, new) = (u64::from(before >> (2 * r) & 3), u64::from(after >> (2 * r) & 3));
                if old != new {
                    let at = row.word[r] + (xs[0] >> 6);
                    occupancy.set(at, occupancy.get(at) & !(3 << shift) | new << shift);
                    if old == 0 {
                        mark(self.planes.rows, self.planes.words, summary, row.line[r], xs[0]);
                    }
                }
            }
            return;
        }
        let bit = |c: usize| (if c & 1 == 0 { xs[0] } else { xs[1] }) + 64 * row.word[c >> 1];
        for c in cells_of(before & !after) {
            put_bit(occupancy, bit(c), false);
        }
        for c in cells_of(after & !before) {
            put_bit(occupancy, bit(c), true);
            mark(self.planes.rows, self.planes.words, summary, row.line[c >> 1], xs[c & 1]);
        }
    }

    /// Where block `x0` of `row` lies: its cells, those beyond a face and
    /// those blocked (M3, M4).
    #[inline(always)]
    fn site<'r>(&self, row: &'r BlockRow, x0: isize) -> Site<'r> {
        let sh = self.shared;
        let (xs, x_out) = sh.part.axis_pair(0, x0);
        let mut site = Site { row, x0, xs, wall: 0, open: 0, blocked: 0 };
        let mut outside = row.outside;
        if x_out != 0 {
            let low = if x_out & 1 != 0 { const { cells_at(0, 0, D) } } else { 0 };
            outside |= low | if x_out & 2 != 0 { const { cells_at(0, 1, D) } } else { 0 };
        }
        for c in cells_of(outside & Self::EVERY_CELL) {
            match resolve(sh.n, &sh.rules.boundary, site.at(c)) {
                Beyond::Wall(_) => site.wall |= 1 << c,
                _ => site.open |= 1 << c,
            }
        }
        site.blocked = site.wall | if sh.rules.has_obstacles() { read_block::<CELLS>(sh.obstacle, row, xs) & !outside & Self::EVERY_CELL } else { 0 };
        site
    }

    /// The pipeline with [`Every`] part, for any block, of width `W`.
    #[inline(never)]
    fn general<W: Widths>(&mut self, row: &BlockRow, x0: isize, bx: usize, occ: u8) {
        let site = self.site(row, x0);
        let b = W::load(&self.planes.velocity, self.shared, row, site.xs, occ);
        self.local_map::<W, Every, Block<D, CELLS>>(&site, row.index + bx as u64, b);
    }
}

impl<'a, Q: Typed, const D: usize, const CELLS: usize> BlockSink<'a> for Sink<'a, Q, D, CELLS> {
    const CELLS: usize = CELLS;

    fn index(&self) -> Index<'a> {
        let planes = &self.kernel.planes;
        Index { occupancy: planes.occupancy, rows: planes.rows, words: planes.words }
    }

    type Plan = RowPlan;

    /// What is the same for every block of `row` in the choice of
    /// instantiation, so that the choice is one compare a block.
    #[inline(always)]
    fn plan(&self, row: &BlockRow) -> RowPlan {
        // With `small-step` no block is plain (`visit`).
        if cfg!(feature = "small-step") {
            return RowPlan { lean_below: 0, obstacles: false };
        }
        let sh = self.kernel.shared;
        // 2D, 8 bits: lanes or every part (worlds with contacts among
        // them), never plain cells, which are then left out. Every
        // x0 < n - 1 reads cells x0 and x0 + 1 of both domain rows, which
        // lie in the velocity plane (checked here, once a row: lanes are
        // read unchecked).
        // 3D, 16 bits: every part, never plain cells either: the room the
        // C library's budget keeps for new rules (the README measures what
        // it costs such worlds).
        let lean = if D == 2 && Q::LANES {
            sh.lanes && row.cell[0].max(row.cell[1]) <= Q::plane(&self.kernel.planes.velocity).len().saturating_sub(sh.n[0])
        } else {
            sh.plain && (D == 2 || Q::LANES)
        };
        let lean = lean && row.outside == 0;
        RowPlan { lean_below: if lean { sh.n[0] - 1 } else { 0 }, obstacles: sh.rules.has_obstacles() }
    }

    #[inline(always)]
    fn visit(&mut self, row: &BlockRow, plan: RowPlan, x0: isize, bx: usize, occ: u8) {
        // With `small-step` every part alone (the plain instantiations left
        // out of the build).
        if cfg!(feature = "small-step") {
            return self.every(row, x0, bx, occ);
        }
        // The half block's x0 = -1 is usize::MAX here, and the block that
        // wraps round a periodic x axis has x0 = n - 1: both fail the test
        // (a plain block's row holds two neighbouring cells).
        let x = x0 as usize;
        let k = &mut self.kernel;
        // A world with obstacles: only blocks without one are plain.
        if x < plan.lean_below && (!plan.obstacles || read_block::<CELLS>(k.shared.obstacle, row, [x, x + 1]) == 0) {
            let site = Site::plain(row, x);
            let index = row.index + bx as u64;
            if D == 2 && Q::LANES {
                // SAFETY: x < lean_below: `plan` checked the row's cells.
                let b = unsafe { Lanes::load(Q::plane(&k.planes.velocity), row, x, occ) };
                return k.local_map::<Q, Bare, Lanes>(&site, index, b);
            }
            let b = Q::load(&k.planes.velocity, k.shared, row, site.xs, occ);
            return k.local_map::<Q, Plain, Block<D, CELLS>>(&site, index, b);
        }
        self.every(row, x0, bx, occ);
    }
}

impl<Q: Typed, const D: usize, const CELLS: usize> Sink<'_, Q, D, CELLS> {
    /// The pipeline with every part for block `x0` of `row`: one copy for
    /// both widths, which reads the step's ([`AnyWidth`]). With
    /// `small-step`, `Q`'s own: a firmware build holds one width, and
    /// every block comes here.
    #[inline(always)]
    fn every(&mut self, row: &BlockRow, x0: isize, bx: usize, occ: u8) {
        #[cfg(not(feature = "small-step"))]
        self.kernel.general::<AnyWidth>(row, x0, bx, occ);
        #[cfg(feature = "small-step")]
        self.kernel.general::<Q>(row, x0, bx, occ);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::api::desc::Boundary;
    use crate::rules::faces::Coords;

    #[test]
    fn a_wall_is_only_asked_for_against_its_normal() {
        // Expect: where only walls block (no obstacles), a particle whose
        // wish (M5.3: an axis of the block it crosses towards the block's
        // other half, its velocity component pointing that way) lands
        // beyond a wall moves against the wall's normal, N.v < 0: for
        // every block across the faces of a 2D and a 3D box, every mix of
        // wall and open faces, every cell inside the box, every wish and
        // every sign of the components it does not cross. reflect_off
        // leaves out N.v >= 0 without obstacles on this.
        for dim in [2usize, 3] {
            let n = [4usize, 4, if dim == 3 { 4 } else { 1 }];
            let cells = 1usize << dim;
            for faces in 0..1u32 << (2 * dim) {
                let mut boundary = [[Boundary::Wall; 2]; 3];
                for k in 0..dim {
                    for side in 0..2 {
                        if faces >> (2 * k + side) & 1 != 0 {
                            boundary[k][side] = Boundary::Open;
                        }
                    }
                }
                // The block's lowest corner: -1 (across the low face) or
                // n - 1 (across the high one) on each axis.
                for corner in 0..cells {
                    let origin: Coords = core::array::from_fn(|k| if k >= dim { 0 } else if corner >> k & 1 == 0 { -1 } else { n[k] as isize - 1 });
                    let at = |c: usize| -> Coords { core::array::from_fn(|k| if k >= dim { 0 } else { origin[k] + (c >> k & 1) as isize }) };
                    for c in 0..cells {
                        if !matches!(resolve(n, &boundary, at(c)), Beyond::Inside(_)) {
                            continue;
                        }
                        for wish in 1..cells {
                            let Beyond::Wall(normal) = resolve(n, &boundary, at(c ^ wish)) else { continue };
                            for signs in 0..3usize.pow(dim as u32) {
                                let mut v = [0i32; 3];
                                for k in 0..dim {
                                    v[k] = if wish >> k & 1 != 0 {
                                        if c >> k & 1 == 0 { 1 } else { -1 }
                                    } else {
                                        (signs / 3usize.pow(k as u32) % 3) as i32 - 1
                                    };
                                }
                                let dot: i32 = (0..3).map(|k| v[k] * normal[k]).sum();
                                assert!(dot < 0, "{dim}D faces {faces:#b} corner {corner} cell {c} wish {wish:#b} v {v:?} N {normal:?}");
                            }
                        }
                    }
                }
            }
        }
    }
}
