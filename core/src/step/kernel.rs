//! The local map of M5 on one block: the step's inner loop.
//!
//! One routine for 2D and 3D reads a block from what the sweep hands it (its
//! occupancy bits, the block row's addresses), keeps the velocities nothing
//! changed as the stored integers (in quanta), decides the moves of M5.3 by
//! comparing 16 random bits with a table entry of the stored component,
//! assigns moves in 2D with one look-up in a table of every block state's
//! optimal assignments, and writes back only what changed: a block where
//! nothing moved and no velocity changed writes nothing. A velocity the
//! force or a collision changes is kept as an `i32` in fine units (M1c),
//! clamped after each stage (M5.5) and rounded back to stored quanta once,
//! after the collision stage (M1); a reflection (M5.4) rounds the velocity
//! it reflects again.
//! The move decisions of M5.3 therefore always read integers.
//!
//! [`Kernel::lean`] is the same routine for the common case, blocks of a
//! plain world (one mass, no lifetimes, at most a uniform force) away from
//! the faces and without an obstacle, without the code for what such a
//! block cannot hold; [`Kernel::lean_2d`] is the 2D 8-bit case of it, which
//! reads a block's velocities as one word of byte lanes. [`Kernel::general`]
//! handles everything. All three draw the same numbers in the same order,
//! so they give the same world bit for bit, and the tests hold them to it.
//!
//! Beside this file: what the routines work with (`block.rs`), the lanes
//! routine (`lanes.rs`), and the stages named after their rules: the clamp
//! (M5.5, `clamp.rs`), the reflection (M5.4, `reflection.rs`) and the
//! contacts (M5.7, `contacts.rs`).
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
//!    2D, at the first such particle one 64-bit output (a byte per cell and
//!    axis), then in cell and axis order 8 bits per axis whose byte ties
//!    with its threshold's ([`Kernel::decide`]); after a reflection, the
//!    reflected velocity's rounding;
//! 4. M5.6, the tie-break of the assignment, where there is a choice;
//! 5. M1 after M5.7's contacts (when on), per particle in cell order whose
//!    velocity a contact changed, its rounding.
//!
//! M5.1 draws nothing.

use crate::api::desc::Collisions;
use crate::rules::assign::{assign_moves, optimal_moves_2d, pick_move, Method, MoveProblem, PLACE_2D};
use crate::rules::collision::{collide_limited, collide_pair, difference, energy_neutral, pick_pair, shares, turned, HALVES};
use crate::rules::fixed::{csqrt, fit, mulq, sat, sq};
use crate::rules::faces::{resolve, Beyond};
use crate::rules::quant::Quant;
use crate::rules::rng::Stream;
use crate::step::block::{cells_of, each_occupied, ints, Block, Class, Shared, Writable};
use crate::step::clamp::clamp_counted;
use crate::step::contacts::contacts;
use crate::step::partition::{cells_at, BlockRow, BlockSink, Index};
use crate::step::reflection::{reflect_off, Wanted};
use crate::storage::layout::{mark, put_bit};
use crate::storage::world::Counters;





/// The block routine, specialised once per step (M9) on the stored velocity
/// type `Q` and the dimension `D` (with `CELLS = 2^D` cells a block).
/// Summed forces, obstacles, per-particle masses and lifetimes are per-step
/// switches: each costs a predictable branch per block or per particle in
/// the general routine, and sends every block there when it is on
/// ([`Shared::plain`]), so the lean routines never test them.
pub(crate) struct Kernel<'a, Q, const D: usize, const CELLS: usize> {
    pub shared: &'a Shared<'a>,
    pub planes: Writable<'a, Q, D>,
    pub counters: Counters,
}

/// A row of blocks as [`Kernel::visit`] sees it, worked out once a row.
#[derive(Clone, Copy)]
pub(crate) struct RowPlan {
    /// The blocks with x0 below it go to a lean routine
    /// ([`Kernel::lean_2d`] for 2D 8-bit worlds, [`Kernel::lean`] for the
    /// others), where the world lets them (0 where it does not), and the
    /// others to [`Kernel::general`]: in a row of blocks away from the y
    /// and z faces, every block up to the one that wraps round x.
    lean_below: usize,
    /// The world has obstacles: a block's own are read before it is lean.
    obstacles: bool,
}

/// M5.2b's limit on a squared speed in fine units (M1c): a unit speed
/// `unit` less `sqrt(D)` quanta (`2^fine` fine units each) rounded up,
/// the most stochastic rounding can add to a speed, squared.
#[inline]
fn speed_limit2<const D: usize>(unit: i32, fine: u32) -> u64 {
    let limit = unit as u64 - csqrt((D as u64) << (2 * fine), 1 << fine);
    limit * limit
}

/// M5.1's sum `x + dv` of a velocity within a unit speed and a push (fine
/// units), fitted to the bound with its direction kept (M1c).
#[inline(always)]
pub(crate) fn pushed(x: [i32; 3], dv: [i64; 3]) -> [i32; 3] {
    fit([0, 1, 2].map(|k| i64::from(x[k]) + dv[k]))
}

/// [`pushed`] for a push whose components are below `2^29`
/// ([`Shared::lean_push`]): the sum is within the bound already, so it is
/// the same value taken in 32 bits.
#[inline(always)]
pub(crate) fn pushed_small(x: [i32; 3], dv: [i32; 3]) -> [i32; 3] {
    [x[0] + dv[0], x[1] + dv[1], x[2] + dv[2]]
}

/// The squared length of a stored velocity, exact: what greedy ranks by
/// (M5.6). It fits: `3 * 32767^2` is below `2^32`.
#[inline(always)]
pub(crate) fn stored_speed2<const D: usize>(q: [i32; D]) -> u32 {
    let mut s = 0u32;
    for k in 0..D {
        s += (q[k] * q[k]) as u32;
    }
    s
}

/// Per 2D blocked mask, the part of the table key its cells contribute
/// (digit 1 each, M5.6); twice it for an occupancy mask (digit 2 + m).
pub(crate) const BLOCKED_KEY_2D: [u16; 16] = {
    let mut t = [0; 16];
    let mut mask = 0;
    while mask < 16 {
        let mut c = 0;
        while c < 4 {
            if mask >> c & 1 != 0 {
                t[mask] += PLACE_2D[c];
            }
            c += 1;
        }
        mask += 1;
    }
    t
};

/// `field` shifted to cell `c`'s place (`width` bits a cell) for each cell
/// `c` set in `mask`, together: the per-mask tables below.
pub(crate) const fn per_cell(mask: usize, width: u32, field: u64) -> u64 {
    let mut out = 0;
    let mut c = 0;
    while c < 8 {
        if mask >> c & 1 != 0 {
            out |= field << (width * c);
        }
        c += 1;
    }
    out
}

/// Targets of a block's cells, 4 bits a cell (cell `c` goes to
/// `targets >> 4c & 7`): per occupancy mask the bits that belong to
/// occupied cells, and the targets that leave every particle in place.
pub(crate) const FIELDS: [u32; 256] = {
    let mut t = [0; 256];
    let mut mask = 0;
    while mask < 256 {
        t[mask] = per_cell(mask, 4, 0xf) as u32;
        mask += 1;
    }
    t
};
pub(crate) const IDENTITY: u32 = 0x7654_3210;

/// A 2D table move's 2-bit targets (one byte) spread to 4 bits a cell.
pub(crate) const SPREAD_2D: [u32; 256] = {
    let mut t = [0; 256];
    let mut b = 0;
    while b < 256 {
        let mut c = 0;
        while c < 4 {
            t[b] |= ((b as u32 >> (2 * c)) & 3) << (4 * c);
            c += 1;
        }
        b += 1;
    }
    t
};

/// Per 2D wish byte (bits `2c, 2c + 1`: the axes cell `c` wants to cross),
/// the part `m` of the key digit `2 + m` of each particle that wants
/// `c ^ m`; the part 2 is twice [`BLOCKED_KEY_2D`] of the occupied cells.
pub(crate) const KEY_2D_WANTS: [u16; 256] = {
    let mut t = [0; 256];
    let mut w = 0;
    while w < 256 {
        let mut c = 0;
        while c < 4 {
            t[w] += PLACE_2D[c] * ((w >> (2 * c)) & 3) as u16;
            c += 1;
        }
        w += 1;
    }
    t
};










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






/// M5.6 by `method` (not 2D exact-fast, which [`Kernel::assign`] takes to
/// the table) for the particles of the cells of `occ`, which want to cross
/// the axes `want` of their cell, into the cells `free`; `speed2` gives a
/// cell's squared speed (for greedy). Where each particle goes, as
/// [`Kernel::assign`] returns it, adding to `displaced` those not placed in
/// their desired cell.
#[inline(always)]
fn solve_block<const D: usize, const CELLS: usize>(
    method: Method,
    (occ, free): (u8, u8),
    want: &[u8; CELLS],
    speed2: impl Fn(usize) -> u32,
    rng: &mut Stream,
    displaced: &mut u64,
) -> u32 {
    let mut problem = MoveProblem { free, count: occ.count_ones() as usize, ..MoveProblem::default() };
    for (i, c) in cells_of(occ).enumerate() {
        problem.current[i] = c as u8;
        problem.desired[i] = c as u8 ^ want[c];
        if method == Method::Greedy {
            problem.speed2[i] = speed2(c);
        }
    }
    let moves = assign_moves::<D>(method, &problem, rng);
    let mut targets = 0u32;
    for i in 0..problem.count {
        targets |= u32::from(moves.target[i]) << (4 * problem.current[i]);
        *displaced += u64::from(moves.target[i] != problem.desired[i]);
    }
    targets
}

/// [`solve_block`] in 2D, out of line, with the squared speeds by cell.
#[inline(never)]
fn solve_block_2d(method: Method, cells: (u8, u8), want: &[u8; 4], speeds: &[u32; 4], rng: &mut Stream, displaced: &mut u64) -> u32 {
    solve_block::<2, 4>(method, cells, want, |c| speeds[c], rng, displaced)
}





impl<Q: Quant, const D: usize, const CELLS: usize> Kernel<'_, Q, D, CELLS> {
    const ALL: u8 = {
        assert!(CELLS == 1 << D && (D == 2 || D == 3));
        (u8::MAX as usize >> (8 - CELLS)) as u8
    };

    /// The block's particles: their stored velocities, read a block row (two
    /// neighbouring cells) at a time where the row does not wrap.
    #[inline(always)]
    fn load(&self, row: &BlockRow, xs: [usize; 2], occ: u8) -> Block<D, CELLS> {
        let mut b = Block { occ, v: [[0; D]; CELLS], pending: 0, x: [[0; 3]; CELLS], dirty: 0 };
        let velocity = self.planes.velocity;
        // With `small-step` a cell at a time always: one loop, less flash.
        if !cfg!(feature = "small-step") && xs[1] == xs[0] + 1 {
            for r in 0..CELLS / 2 {
                if occ >> (2 * r) & 3 != 0 {
                    let at = xs[0] + row.cell[r];
                    let pair = velocity.pair(at);
                    b.v[2 * r] = ints(pair[0]);
                    b.v[2 * r + 1] = ints(pair[1]);
                }
            }
        } else {
            for c in cells_of(occ) {
                b.v[c] = ints(velocity.get(xs[c & 1] + row.cell[c >> 1]));
            }
        }
        b
    }

    /// M5.1 for the particle in cell `c` of class `class`, whose velocity
    /// with its push (eqs. 4-5, [`pushed`]) is `x`: the clamp.
    #[inline(always)]
    fn push(&mut self, b: &mut Block<D, CELLS>, c: usize, mut x: [i32; 3], class: &Class) {
        clamp_counted::<D>(&mut x, Q::UNIT, class, &mut self.counters);
        b.set(c, x);
    }

    /// M5.2: one of the block's pairs, uniformly; if both its cells hold a
    /// particle, [`Kernel::collide_two`]. `class` gives a cell's mass
    /// class; `equal` says every mass is the same.
    #[inline(always)]
    fn collide(&mut self, b: &mut Block<D, CELLS>, rng: &mut Stream, class: impl Fn(usize) -> Class, equal: bool) {
        if let Some((a, c)) = pick_pair::<D>(b.occ, rng) {
            if let Some((xa, xc)) = self.collide_two(b.velocity(a, Q::FINE), b.velocity(c, Q::FINE), (class(a), class(c)), equal, rng) {
                b.set(a, xa);
                b.set(c, xc);
            }
        }
    }

    /// M5.2 on two particles of classes `(ca, cc)` with velocities `va`,
    /// `vc` in fine units: eqs. 7-8 with `R` uniform (or M5.2b), M1b when
    /// on, then the clamp of both; counts the collision. `None` where the
    /// collision changes neither velocity, whatever `R`: two equal
    /// velocities within the speed limit (eqs. 7-8 give both the
    /// centre-of-mass velocity, which is theirs), so a pair at rest draws
    /// nothing for it.
    #[inline(always)]
    pub(crate) fn collide_two(&mut self, va: [i32; 3], vc: [i32; 3], (ca, cc): (Class, Class), equal: bool, rng: &mut Stream) -> Option<([i32; 3], [i32; 3])> {
        self.counters.collisions += 1;
        // Component by component: an array comparison is a `memcmp` call
        // on small cores.
        if (va[0] ^ vc[0]) | (va[1] ^ vc[1]) | (va[2] ^ vc[2]) == 0 && sq::<D>(va) <= (Q::UNIT as u64) * (Q::UNIT as u64) {
            return None;
        }
        let masses = (!equal).then_some((ca.relative, cc.relative));
        let s = if equal { HALVES } else { shares(ca.relative, cc.relative) };
        let e = self.shared.restitution;
        let (mut xa, mut xc) = match self.shared.desc.collision_rule() {
            Collisions::Paper => collide_pair::<D>(va, vc, s, e, turned::<D>(difference::<D>(va, vc), rng), masses),
            // Below the limit by sqrt(D) quanta, so that rounding (less than a
            // quantum per component) cannot store a speed above 1 either.
            Collisions::SpeedLimited => collide_limited(va, vc, s, e, speed_limit2::<D>(Q::UNIT, Q::FINE), masses, rng, D),
        };
        if self.shared.desc.has_energy_neutral() {
            (xa, xc) = energy_neutral(xa, xc, s, Q::FINE, masses);
        }
        clamp_counted::<D>(&mut xa, Q::UNIT, &ca, &mut self.counters);
        clamp_counted::<D>(&mut xc, Q::UNIT, &cc, &mut self.counters);
        Some((xa, xc))
    }

    /// M5.3: the axes the particle in cell `c` wants to cross, from its
    /// stored (rounded) velocity `q`. Only a move that stays inside the block
    /// can be wanted: towards +k from the low side of the block, towards -k
    /// from the high.
    ///
    /// In 2D, `bytes` is one 64-bit output of the stream, drawn by the
    /// block's first particle that wants to cross an axis: byte `2c + k`
    /// holds the high 8 of the 16 random bits for cell `c`'s axis `k`, and
    /// the low 8 come from the stream only where the high 8 alone cannot
    /// decide (they equal the limit's high 8: one case in 256). The decision
    /// is that of 16 uniform bits, drawn without bookkeeping for most axes.
    /// In 3D, 16 bits an axis come from the stream (48 a particle).
    #[inline(always)]
    fn decide(&self, q: [i32; D], c: usize, bytes: &mut Option<u64>, rng: &mut Stream) -> u8 {
        let mut inward = 0u8;
        for k in 0..D {
            let low = (c >> k) & 1 == 0;
            inward |= u8::from(if low { q[k] > 0 } else { q[k] < 0 }) << k;
        }
        if inward == 0 {
            return 0;
        }
        let (table, drift) = (self.shared.moves, self.shared.desc.drift);
        let mut m = 0u8;
        if D == 2 {
            let bytes = *bytes.get_or_insert_with(|| rng.next_u64());
            for k in 0..D {
                if inward >> k & 1 != 0 {
                    let limit = Q::move_limit(table, drift, q[k]);
                    let (high, top) = ((bytes >> (8 * (2 * c + k))) as u8 as u32, limit >> 8);
                    let moves = high < top || high == top && rng.bits(8) <= limit & 0xff;
                    m |= u8::from(moves) << k;
                }
            }
            return m;
        }
        let r = u64::from(rng.bits(32)) | u64::from(rng.bits(16)) << 32;
        for k in 0..D {
            m |= u8::from((r >> (16 * k)) as u32 & 0xffff <= Q::move_limit(table, drift, q[k])) << k;
        }
        m & inward
    }

    /// M5.6: where each particle goes, `targets >> 4c & 7` for the particle
    /// in cell `c`, counting those not placed in their desired cell. `want`
    /// holds the axes each wants to cross (a desired cell is never blocked:
    /// M5.4 has turned such a wish into staying); `speed2` gives a cell's
    /// squared speed (for greedy); `key` is the 2D table key.
    #[inline(always)]
    pub(crate) fn assign(&mut self, occ: u8, speed2: impl Fn(usize) -> u32, blocked: u8, want: &[u8; CELLS], key: usize, rng: &mut Stream) -> u32 {
        // Where nobody wants to move, or the block holds one particle, the
        // optimum is unique (everyone stays; the particle takes the free cell
        // it wants) and no method draws for it: take it directly.
        if *want == [0; CELLS] {
            return IDENTITY;
        }
        if occ & (occ - 1) == 0 {
            let c = occ.trailing_zeros() as usize;
            return IDENTITY ^ u32::from(want[c]) << (4 * c);
        }
        let method = self.shared.desc.assignment();
        if D == 2 && method == Method::ExactFast {
            let packed = pick_move(optimal_moves_2d(key), rng);
            self.counters.displaced += u64::from(packed >> 12);
            // 2 bits a cell in the table; 4 here, as in 3D.
            return SPREAD_2D[usize::from(packed as u8)];
        }
        let cells = (occ, !blocked & Self::ALL);
        let displaced = &mut self.counters.displaced;
        // In 2D, a method other than exact-fast is a description's choice
        // that no scene of the paper makes: one copy, out of line, serves
        // every 2D routine. In 3D every assignment comes here.
        if D == 2 {
            let (mut speeds, mut want4) = ([0u32; 4], [0u8; 4]);
            for c in cells_of(occ) {
                want4[c] = want[c];
                if method == Method::Greedy {
                    speeds[c] = speed2(c);
                }
            }
            return solve_block_2d(method, cells, &want4, &speeds, rng, displaced);
        }
        solve_block::<D, CELLS>(method, cells, want, speed2, rng, displaced)
    }

    /// Writes the velocity of the particle of cell `c` to cell `to` of the
    /// planes.
    #[inline(always)]
    fn store(&mut self, b: &Block<D, CELLS>, c: usize, to: usize) {
        self.planes.velocity.set(to, b.v[c].map(Q::from_int));
    }

    /// Sets and clears the block's occupancy bits from `before` to `after`.
    #[inline(always)]
    pub(crate) fn occupy(&mut self, row: &BlockRow, xs: [usize; 2], before: u8, after: u8) {
        let bit = |c: usize| xs[c & 1] + 64 * row.word[c >> 1];
        for c in cells_of(before & !after) {
            put_bit(self.planes.occupancy, bit(c), false);
        }
        for c in cells_of(after & !before) {
            put_bit(self.planes.occupancy, bit(c), true);
            mark(self.planes.rows, self.planes.words, self.shared.part.summary_words, row.line[c >> 1], xs[c & 1]);
        }
    }

    /// The local map of M5 on a block of a plain world (one mass, no
    /// lifetimes, no force but a uniform one) away from the faces and
    /// without an obstacle: [`Kernel::general`] without what such a block
    /// cannot have. Cell `c`
    /// has x `xs[c & 1]` in block row `c >> 1`; the two are neighbours (the
    /// block that wraps round a periodic axis goes to the general routine).
    #[inline(always)]
    fn lean(&mut self, row: &BlockRow, xs: [usize; 2], index: u64, occ: u8) {
        let sh = self.shared;
        let class = &sh.one;
        let mut b = self.load(row, xs, occ);
        let mut rng = sh.key.stream(index);
        let mut bytes = None;
        if let Some(dv) = sh.lean_push {
            for c in cells_of(occ) {
                let x = pushed_small(b.velocity(c, Q::FINE), dv);
                self.push(&mut b, c, x, class);
            }
        }
        self.collide(&mut b, &mut rng, |_| *class, true);
        b.round::<Q>(&mut rng);
        let mut want = [0u8; CELLS];
        let (mut key, mut wanted) = (0, 0u8);
        // 8-bit velocities and 2D: the cells unrolled, so that what depends
        // on a cell folds at compile time. 16-bit 3D: a loop (here and in
        // the write back), which keeps a copy of M5.3 for each of eight
        // cells out of the library.
        each_occupied!(Q::LANES || D == 2, CELLS, occ, c => {
            want[c] = self.decide(b.v[c], c, &mut bytes, &mut rng);
            wanted |= want[c];
            if D == 2 {
                key += usize::from(PLACE_2D[c & 3]) * usize::from(2 + want[c]);
            }
        });
        let targets = self.assign(occ, |c| stored_speed2(b.v[c]), 0, &want, key, &mut rng);
        if sh.desc.has_contacts() && wanted != 0 {
            contacts(sh, &mut b, &want, targets, &[0; CELLS], Q::UNIT, Q::FINE, &mut self.counters);
            b.round_apart::<Q>(&mut rng);
        }
        self.counters.processed += 1;
        if (targets ^ IDENTITY) & FIELDS[usize::from(occ)] == 0 && b.dirty == 0 {
            return;
        }
        let cell = |c: usize| xs[c & 1] + row.cell[c >> 1];
        let mut after = 0u8;
        each_occupied!(Q::LANES || D == 2, CELLS, occ, c => {
            let t = (targets >> (4 * c) & 7) as usize;
            after |= 1 << t;
            if t != c || b.dirty >> c & 1 != 0 {
                self.store(&b, c, cell(t));
            }
        });
        self.occupy(row, xs, occ, after);
    }

    /// The local map of M5 on any block: the half blocks on faces that are
    /// not periodic, blocks with obstacles, per-particle masses, lifetimes
    /// or forces other than a uniform one.
    #[inline(never)]
    fn general(&mut self, row: &BlockRow, x0: isize, bx: usize, occ: u8) {
        let sh = self.shared;
        let desc = &sh.desc;

        // M3, M4: the block's cells. Cell c lies at x xs[c & 1] of block row
        // c >> 1 (y, then z).
        let (xs, x_out) = sh.part.axis_pair(0, x0);
        let cell = |c: usize| xs[c & 1] + row.cell[c >> 1];
        let at = |c: usize| [x0 + (c & 1) as isize, row.origin[0] + ((c >> 1) & 1) as isize, row.origin[1] + ((c >> 2) & 1) as isize];
        let mut outside = row.outside;
        if x_out != 0 {
            let low = if x_out & 1 != 0 { const { cells_at(0, 0, D) } } else { 0 };
            outside |= low | if x_out & 2 != 0 { const { cells_at(0, 1, D) } } else { 0 };
        }
        // The cells beyond a face are wall or open (their sites mean
        // nothing).
        let (mut wall, mut open) = (0u8, 0u8);
        for c in cells_of(outside & Self::ALL) {
            match resolve(sh.n, &desc.boundary, at(c)) {
                Beyond::Wall(_) => wall |= 1 << c,
                _ => open |= 1 << c,
            }
        }
        let blocked = wall | if desc.has_obstacles() { read_block::<CELLS>(sh.obstacle, row, xs) & !outside & Self::ALL } else { 0 };

        let mut b = self.load(row, xs, occ);
        let mut mass_index = [0u8; CELLS];
        let mut life = [0u16; CELLS];
        for c in cells_of(occ) {
            if desc.has_masses() {
                mass_index[c] = self.planes.mass_index.get(cell(c));
            }
            if desc.lifetimes {
                life[c] = self.planes.life.get(cell(c));
            }
        }
        // A cell's mass class: the world's one where particles carry none
        // (no array read, so no bounds check, in a build without masses).
        let class_of = |c: usize| if desc.has_masses() { sh.class(mass_index[c]) } else { sh.one };
        let mut rng = sh.key.stream(row.index + bx as u64);
        let mut bytes = None;

        // M5.1 external force: v <- v + dt F / m (eqs. 4-5), in fine units.
        for c in cells_of(occ) {
            let dv = if sh.summed {
                let pos = sh.part.cell_coords(row, [xs[c & 1], 0, 0], c);
                sh.terms.push(pos, cell(c), &class_of(c))
            } else {
                sh.push.unwrap_or_default()
            };
            // A force that changes nothing is no step 1: a zero-valued part
            // gives the same world as a world without it (M9). Component by
            // component: an array comparison is a `memcmp` call on small
            // cores.
            if dv[0] | dv[1] | dv[2] != 0 {
                let x = pushed(b.velocity(c, Q::FINE), dv);
                self.push(&mut b, c, x, &class_of(c));
            }
        }

        // M5.1b flow drag: v <- (v + a u) / (1 + a), u the flow at the cell
        // (none without the feature `fields`: `Layout::of`), as the weighted
        // mean `C v + (1 - C) u` with `C` in Q16 (M1c).
        let drag = if cfg!(feature = "fields") { sh.drag.as_ref() } else { None };
        if let Some(flow) = drag {
            let keep = flow.keep;
            for c in cells_of(occ) {
                let u = flow.at(sh.part.cell_coords(row, [xs[c & 1], 0, 0], c), cell(c));
                let mut x = b.velocity(c, Q::FINE);
                for k in 0..D {
                    x[k] = sat(i64::from(mulq(x[k], keep, 16)) + i64::from(mulq(u[k], (1 << 16) - keep, 16)));
                }
                clamp_counted::<D>(&mut x, Q::UNIT, &class_of(c), &mut self.counters);
                b.set(c, x);
            }
        }

        // M5.2 collision, then M1 for what the force, the drag and the
        // collision changed.
        self.collide(&mut b, &mut rng, class_of, !desc.has_masses());
        b.round::<Q>(&mut rng);

        // M5.3 desired move, M5.4 obstacle reflection: `want[c]` holds the
        // axes the particle in cell c wants to cross.
        let mut want = [0u8; CELLS];
        let mut wanted = 0u8;
        let mut key = if D == 2 { usize::from(BLOCKED_KEY_2D[usize::from(blocked & 15)]) } else { 0 };
        for c in cells_of(occ) {
            let mut m = self.decide(b.v[c], c, &mut bytes, &mut rng);
            let t = c ^ usize::from(m);
            if m != 0 && blocked >> t & 1 != 0 {
                let to = Wanted { cell: t, site: cell(t), at: at(t), wall: wall >> t & 1 != 0 };
                // M5.4, its new velocity rounded at once (M1).
                if let Some(x) = reflect_off(sh, b.velocity(c, Q::FINE), c, to, &class_of(c), Q::UNIT, &mut self.counters, D) {
                    b.set(c, x);
                    b.round_apart::<Q>(&mut rng);
                }
                m = 0;
            }
            want[c] = m;
            wanted |= m;
            if D == 2 {
                key += usize::from(PLACE_2D[c & 3]) * usize::from(2 + m);
            }
        }

        // M5.6 move.
        let targets = self.assign(occ, |c| stored_speed2(b.v[c]), blocked, &want, key, &mut rng);

        // M5.7 contacts, then M1 for what they changed.
        if desc.has_contacts() && wanted != 0 {
            contacts(sh, &mut b, &want, targets, &mass_index, Q::UNIT, Q::FINE, &mut self.counters);
            b.round_apart::<Q>(&mut rng);
        }

        // Write back what changed.
        self.counters.processed += 1;
        if (targets ^ IDENTITY) & FIELDS[usize::from(occ)] == 0 && b.dirty == 0 && !desc.lifetimes {
            return;
        }
        let mut after = 0u8;
        for c in cells_of(occ) {
            let t = (targets >> (4 * c) & 7) as usize;
            // A lifetime is 0 (none) in worlds without lifetimes.
            if open >> t & 1 != 0 {
                self.counters.exited += 1; // M4 open face
            } else if life[c] == 1 {
                self.counters.expired += 1; // M6 lifetime
            } else {
                after |= 1 << t;
                let to = cell(t);
                if t != c || b.dirty >> c & 1 != 0 {
                    self.store(&b, c, to);
                }
                if desc.has_masses() && t != c {
                    self.planes.mass_index.set(to, mass_index[c]);
                }
                if desc.lifetimes {
                    self.planes.life.set(to, life[c].saturating_sub(1));
                }
            }
        }
        self.occupy(row, xs, occ, after);
    }
}

impl<'a, Q: Quant, const D: usize, const CELLS: usize> BlockSink<'a> for Kernel<'a, Q, D, CELLS> {
    const CELLS: usize = CELLS;

    fn index(&self) -> Index<'a> {
        Index { occupancy: self.planes.occupancy, rows: self.planes.rows, words: self.planes.words }
    }

    type Plan = RowPlan;

    /// What is the same for every block of `row` in the choice of routine,
    /// so that the choice is one compare a block.
    #[inline(always)]
    fn plan(&self, row: &BlockRow) -> RowPlan {
        // With `small-step` no block is lean (`visit`).
        if cfg!(feature = "small-step") {
            return RowPlan { lean_below: 0, obstacles: false };
        }
        let sh = self.shared;
        // 2D, 8 bits: the lanes routine or the general one (worlds with
        // contacts among them), never `lean`, which is then left out. Every
        // x0 < n - 1 reads cells x0 and x0 + 1 of both domain rows, which
        // lie in the velocity plane (checked here, once a row: the lanes
        // routine reads them unchecked).
        let lean = if D == 2 && Q::LANES {
            sh.lanes && row.cell[0].max(row.cell[1]) <= self.planes.velocity.len().saturating_sub(sh.n[0])
        } else {
            sh.plain
        };
        let lean = lean && row.outside == 0;
        RowPlan { lean_below: if lean { sh.n[0] - 1 } else { 0 }, obstacles: sh.desc.has_obstacles() }
    }

    #[inline(always)]
    fn visit(&mut self, row: &BlockRow, plan: RowPlan, x0: isize, bx: usize, occ: u8) {
        // With `small-step` the general routine alone (the lean ones left
        // out of the build).
        if cfg!(feature = "small-step") {
            return self.general(row, x0, bx, occ);
        }
        // The half block's x0 = -1 is usize::MAX here, and the block that
        // wraps round a periodic x axis has x0 = n - 1: both fail the test
        // (the lean routines read a block row's two cells as neighbours).
        let x = x0 as usize;
        // A world with obstacles: only blocks without one are lean.
        if x < plan.lean_below && (!plan.obstacles || read_block::<CELLS>(self.shared.obstacle, row, [x, x + 1]) == 0) {
            let index = row.index + bx as u64;
            if D == 2 && Q::LANES {
                return self.lean_2d(row, x, index, occ);
            }
            return self.lean(row, [x, x + 1], index, occ);
        }
        self.general(row, x0, bx, occ);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::api::desc::Boundary;
    use crate::rules::faces::Coords;
    use crate::rules::assign::digit;

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

    #[test]
    fn split_keys_add_up_to_the_table_key() {
        // Expect: for every occupancy and every wish of the occupied cells,
        // the two look-ups give the key digit by digit (M5.6).
        for occ in 0..16usize {
            for want in 0..256usize {
                if (0..4).any(|c| occ >> c & 1 == 0 && (want >> (2 * c)) & 3 != 0) {
                    continue;
                }
                let mut key = 0;
                for c in 0..4 {
                    let particle = (occ >> c & 1 != 0).then_some((want >> (2 * c)) as u8 & 3);
                    key += PLACE_2D[c] * digit(true, particle);
                }
                assert_eq!(2 * BLOCKED_KEY_2D[occ] + KEY_2D_WANTS[want], key);
            }
        }
    }
}
