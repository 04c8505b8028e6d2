//! The local map of M5 on one block: the step's inner loop.
//!
//! One routine for 2D and 3D reads a block from what the sweep hands it (its
//! occupancy bits, the block row's addresses), keeps the velocities nothing
//! changed as the stored integers (in quanta), decides the moves of M5.3 by
//! comparing 16 random bits with a table entry of the stored component,
//! assigns moves in 2D with one look-up in a table of every block state's
//! optimal assignments, and writes back only what changed: a block where
//! nothing moved and no velocity changed writes nothing. A velocity the
//! force or a collision changes is kept in `f32` quanta, clamped after each
//! stage (M5.5) and rounded back to an integer once, after the collision
//! stage (M1); a reflection (M5.4) rounds the velocity it reflects again.
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

use crate::api::desc::{Boundary, Collisions, Description};
use crate::rules::assign::{assign_moves, bits, optimal_moves_2d, pick_move, Bits, Method, MoveProblem, PLACE_2D};
use crate::rules::collision::{collide_limited, collide_pair, energy_neutral, pick_pair, random_unit, shares};
use crate::rules::force::{Flow, ForceTerms};
use crate::rules::obstacle::{reflect, surface_at, Surface};
use crate::rules::quant::Quant;
use crate::rules::rng::{StepKey, Stream};
use crate::rules::vector::{dot, dot_of, normalise};
use crate::rules::faces::{resolve, Beyond, Coords};
use crate::step::partition::{cells_at, BlockRow, BlockSink, Index, Partition};
use crate::storage::cells::Cells;
use crate::storage::layout::{mark, put_bit, row_words, test_bit};
use crate::storage::world::{Counters, ENERGY_SCALE};

/// The description as a step's blocks read it: with `small-step` where it
/// lies in the world's header (no copy to set up: less flash, a load more
/// for each field a block reads), otherwise a copy beside the other
/// shared data, which the lean routines read without that load.
#[cfg(feature = "small-step")]
pub(crate) type StepDescription<'a> = &'a Description;
#[cfg(not(feature = "small-step"))]
pub(crate) type StepDescription<'a> = Description;

/// What every block of a step reads and none writes.
pub(crate) struct Shared<'a> {
    pub desc: StepDescription<'a>,
    pub n: [usize; 3],
    pub part: Partition,
    pub key: StepKey,
    pub obstacle: &'a [u64],
    pub surface: &'a [Surface],
    pub mass_table: &'a [f32],
    pub terms: ForceTerms<'a>,
    /// The uniform force's velocity change per step in quanta, where it
    /// changes anything (the general force path includes it in `terms`).
    pub push: Option<[f32; 3]>,
    /// `dt * SCALE`: turns an acceleration into quanta per step.
    pub dt_q: f32,
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
    fn tops(&self) -> &'static [u8; 256] {
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

/// `sqrt(D)` quanta for D = 2, 3: the most stochastic rounding can add to a
/// speed.
const ROUNDING_MARGIN: [f32; 2] = [core::f32::consts::SQRT_2, 1.732_050_8];

/// Per 2D blocked mask, the part of the table key its cells contribute
/// (digit 1 each, M5.6); twice it for an occupancy mask (digit 2 + m).
const BLOCKED_KEY_2D: [u16; 16] = {
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
const fn per_cell(mask: usize, width: u32, field: u64) -> u64 {
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
const FIELDS: [u32; 256] = {
    let mut t = [0; 256];
    let mut mask = 0;
    while mask < 256 {
        t[mask] = per_cell(mask, 4, 0xf) as u32;
        mask += 1;
    }
    t
};
const IDENTITY: u32 = 0x7654_3210;

/// A 2D table move's 2-bit targets (one byte) spread to 4 bits a cell.
const SPREAD_2D: [u32; 256] = {
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
const KEY_2D_WANTS: [u16; 256] = {
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

/// Per 2D occupancy mask, `0xffff` in the two byte lanes of each occupied
/// cell.
const LANES_2D: [u64; 16] = {
    let mut t = [0; 16];
    let mut mask = 0;
    while mask < 16 {
        t[mask] = per_cell(mask, 16, 0xffff);
        mask += 1;
    }
    t
};

/// The high bit of each byte lane `2c + k` where cell `c` lies on the high
/// side of axis `k` (its inward direction is negative).
const HIGH_SIDE_2D: u64 = {
    let mut m = 0u64;
    let mut i = 0;
    while i < 8 {
        let (c, k) = (i / 2, i % 2);
        if (c >> k) & 1 != 0 {
            m |= 0x80 << (8 * i);
        }
        i += 1;
    }
    m
};

/// M5.3's first test for a whole 2D block of 8-bit velocities in byte
/// lanes (lane `2c + k`: cell `c`'s component `k`): bit `2c + k` set where
/// cell `c` is occupied and its component `k` points inward (positive on
/// the block's low side of the axis, negative on the high side).
#[inline(always)]
fn inward_lanes(lanes: u64, occ: u8) -> u8 {
    const HIGH: u64 = 0x8080_8080_8080_8080;
    const LOW: u64 = 0x7f7f_7f7f_7f7f_7f7f;
    // The high bit of each lane: set where the lane is not 0.
    let nonzero = (((lanes & LOW) + LOW) | lanes) & HIGH;
    let inward = nonzero & !(lanes ^ HIGH_SIDE_2D) & LANES_2D[usize::from(occ & 15)];
    // Gather the eight high bits into one byte.
    ((inward >> 7).wrapping_mul(0x0102_0408_1020_4080) >> 56) as u8
}

/// Cell `c`'s velocity from a 2D block's byte lanes, in quanta.
#[inline(always)]
fn lane_quanta(lanes: u64, c: usize) -> [f32; 3] {
    let [x, y] = lane_ints(lanes, c);
    [f32::from(x), f32::from(y), 0.0]
}

/// Cell `c`'s stored velocity in byte lanes, as integers: bytes `2c` and
/// `2c + 1` of the word, one indexed load each where `c` is not a
/// constant (a shift by `16 c` and masks take more instructions and
/// registers).
#[inline(always)]
fn lane_ints(lanes: u64, c: usize) -> [i8; 2] {
    let bytes = lanes.to_le_bytes();
    [bytes[2 * c] as i8, bytes[2 * c + 1] as i8]
}

/// `lanes` with cell `c`'s two lanes replaced by the stored components
/// `q` (in range: each lane is the value's low byte), one indexed store
/// each.
#[inline(always)]
fn with_lane_ints(lanes: u64, c: usize, q: [i32; 2]) -> u64 {
    let mut bytes = lanes.to_le_bytes();
    for (k, q) in q.into_iter().enumerate() {
        debug_assert!((-127..=127).contains(&q));
        bytes[2 * c + k] = q as u8;
    }
    u64::from_le_bytes(bytes)
}

/// Cell `c`'s two byte lanes, in the low 16 bits.
#[inline(always)]
fn cell_lanes(lanes: u64, c: usize) -> u32 {
    u32::from((lanes >> (16 * c)) as u16)
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

/// The cells of a block mask (its set bits), lowest first.
#[inline]
pub(crate) fn cells_of(mask: u8) -> Bits {
    bits(mask)
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

/// A unit normal from cell `to` back towards cell `from` of the same block.
pub(crate) fn back_normal<const D: usize>(from: usize, to: usize) -> [f32; 3] {
    let mut n = [0.0f32; 3];
    for k in 0..D {
        n[k] = ((from >> k) & 1) as f32 - ((to >> k) & 1) as f32;
    }
    normalise(n).unwrap_or([0.0; 3])
}

/// M5.5: clamps `x` (in quanta) to the speed limit `scale`, counting the
/// clamp and the kinetic energy it removed for mass `m`. Only the test is
/// inlined: a clamp is rare, and its code would otherwise be copied into
/// every stage of every block routine.
#[cfg(not(feature = "small-step"))]
#[inline(always)]
fn clamp_counted<const D: usize>(x: &mut [f32; 3], scale: f32, m: f32, counters: &mut Counters) {
    let s2 = dot_of::<D>(*x, *x);
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
fn clamp_counted<const D: usize>(x: &mut [f32; 3], scale: f32, m: f32, counters: &mut Counters) {
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

/// A blocked cell a particle wants (M5.4): its number in the block, its
/// dense index in the planes (meaningless beyond a face), its coordinates
/// (possibly beyond a face) and whether it lies beyond a wall.
#[derive(Clone, Copy)]
struct Wanted {
    cell: usize,
    site: usize,
    at: Coords,
    wall: bool,
}

/// M5.4: the particle in cell `c` of mass `m`, with velocity `x` (in
/// quanta, `scale` to a unit speed), wants the blocked cell `to`: its
/// velocity reflected off that cell's surface (eq. 9) and clamped, or `None`
/// where the surface says the particle is already leaving and it keeps its
/// velocity. Either way the caller keeps the particle in its cell this step.
/// Rare, so kept out of the block routine's straight line, and the same
/// code for both velocity widths.
#[cold]
#[inline(never)]
fn reflect_off<const D: usize>(sh: &Shared<'_>, x: [f32; 3], c: usize, to: Wanted, m: f32, scale: f32, counters: &mut Counters) -> Option<[f32; 3]> {
    let t = to.cell;
    let mut surface = None;
    if to.wall {
        if let Beyond::Wall(n) = resolve(sh.n, &sh.desc.boundary, to.at) {
            surface = Some((n, sh.desc.wall_restitution));
        }
    }
    // A build without obstacles has no surface entry and no obstacle
    // cell (here and below), and no code to look either up.
    let table: &[Surface] = if cfg!(feature = "obstacles") { sh.surface } else { &[] };
    let (n, e) = surface.unwrap_or_else(|| match surface_at(table, to.site as u32) {
        // Component by component: a copy of the array through the
        // reference is a `memmove` call at opt-level z, the only one in a
        // firmware build.
        Some(s) => ([s.normal[0], s.normal[1], s.normal[2]], s.restitution),
        // Unreachable for obstacles added through the API (every cell
        // next to a free one has an entry): the direction back to the
        // particle.
        None if cfg!(feature = "obstacles") => (back_normal::<D>(c, t), sh.desc.wall_restitution),
        // Unreachable without obstacles: only cells beyond a wall are
        // blocked then, and `resolve` gave their surface above. A normal
        // of 0 would reflect nothing; the build holds no code for the
        // direction back.
        None => ([0.0; 3], sh.desc.wall_restitution),
    });
    // Without obstacles only cells beyond a wall face are blocked, and a
    // particle asks for one only moving towards it (M5.3: every axis it
    // crosses points out of the domain), so N.v < 0: a build without
    // obstacles leaves out the case below (the tests check the claim).
    let n = if !cfg!(feature = "obstacles") || dot(x, n) < 0.0 {
        n
    } else {
        // The particle already leaves the surface (N.v >= 0), yet asks
        // for one of its cells: a stair of a surface tilted against the
        // grid. Where N faces the particle's cell, the particle is on
        // the free side of that surface: it keeps its velocity and only
        // this move is refused, unless no cell along one axis of its
        // velocity is free, which would leave it stuck (a concave
        // corner where shapes overlap). Otherwise, or where N does not
        // face the particle (a half-space seen across a periodic seam, a
        // mask corner), it would press on the obstacle for ever: reflect
        // off the face it came through. M5.4.
        let mut at = to.at;
        for (k, a) in at.iter_mut().enumerate().take(D) {
            *a += ((c >> k) & 1) as isize - ((t >> k) & 1) as isize;
        }
        let back = back_normal::<D>(c, t);
        if dot(n, back) > 0.0 && axis_move_free(if cfg!(feature = "obstacles") { sh.obstacle } else { &[] }, sh.n, &sh.desc.boundary, at, x, D) {
            return None;
        }
        back
    };
    let mut x = reflect(x, n, e); // eq. 9
    clamp_counted::<D>(&mut x, scale, m, counters);
    Some(x)
}

/// M5.4: whether the particle at `at` (raw coordinates, resolved across the
/// faces `boundary` of a domain of `n` cells per axis) with velocity `v`
/// has a cell to go to along a single axis `k` of its velocity (towards
/// `sign(v_k)`, `v_k != 0`, one of the first `dim` axes) that is neither an
/// obstacle (bit plane `obstacle`) nor beyond a wall. Such a particle can
/// always move on later, so refusing it one move leaves it never stuck.
pub(crate) fn axis_move_free(obstacle: &[u64], n: [usize; 3], boundary: &[[Boundary; 2]; 3], at: Coords, v: [f32; 3], dim: usize) -> bool {
    (0..dim).any(|k| {
        if v[k] == 0.0 {
            return false;
        }
        let mut to = at;
        to[k] += if v[k] > 0.0 { 1 } else { -1 };
        match resolve(n, boundary, to) {
            Beyond::Wall(_) => false,
            Beyond::Open => true,
            Beyond::Inside(p) => !test_bit(obstacle, (p[1] + n[1] * p[2]) * row_words(n[0]) * 64 + p[0]),
        }
    })
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
    speed2: impl Fn(usize) -> f32,
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
fn solve_block_2d(method: Method, cells: (u8, u8), want: &[u8; 4], speeds: &[f32; 4], rng: &mut Stream, displaced: &mut u64) -> u32 {
    solve_block::<2, 4>(method, cells, want, |c| speeds[c], rng, displaced)
}

/// M5.7: every particle refused the cell it wanted (`want`, by the
/// assignment's `targets`) meets the particle that holds that cell, in the
/// order of the refused particles' cells: eqs. 7-8 with `R` from the wanted
/// cell back towards the refused particle's, if it was closing in, then the
/// clamp to `scale` quanta. `mass` holds each cell's mass, by the cell the
/// particle started in. Out of line, one copy for both velocity widths:
/// only worlds with contacts come here, and they pay one call a block.
#[inline(never)]
fn contacts<const D: usize, const CELLS: usize>(
    sh: &Shared<'_>,
    b: &mut Block<D, CELLS>,
    want: &[u8; CELLS],
    targets: u32,
    mass: &[f32; CELLS],
    scale: f32,
    counters: &mut Counters,
) {
    let equal = !sh.desc.has_masses();
    for a in cells_of(b.occ) {
        let wanted = a ^ usize::from(want[a]);
        if want[a] == 0 || (targets >> (4 * a) & 7) as usize == wanted {
            continue;
        }
        // The particle placed in the wanted cell, if any.
        let Some(h) = cells_of(b.occ).find(|&h| (targets >> (4 * h) & 7) as usize == wanted) else { continue };
        let r = back_normal::<D>(a, wanted);
        let (xa, xh) = (b.velocity(a), b.velocity(h));
        if dot([xa[0] - xh[0], xa[1] - xh[1], xa[2] - xh[2]], r) >= 0.0 {
            continue;
        }
        let (ma, mh) = (mass[a], mass[h]);
        let s = if equal { (0.5, 0.5) } else { shares(ma, mh) };
        let (mut ya, mut yh) = collide_pair::<D>(xa, xh, s, sh.desc.restitution, r);
        if sh.desc.has_energy_neutral() {
            (ya, yh) = energy_neutral::<D>(ya, yh, s);
        }
        clamp_counted::<D>(&mut ya, scale, ma, counters);
        clamp_counted::<D>(&mut yh, scale, mh, counters);
        b.set(a, ya);
        b.set(h, yh);
    }
}

/// Stored components as integers (quanta), component by component: an
/// array's `map` is a call at opt-level z.
#[inline(always)]
fn ints<Q: Quant, const D: usize>(q: [Q; D]) -> [i32; D] {
    let mut v = [0; D];
    for k in 0..D {
        v[k] = q[k].to_int();
    }
    v
}

/// A block's particles as the stages of M5 see them.
struct Block<const D: usize, const CELLS: usize> {
    /// Cells holding a particle.
    occ: u8,
    /// Velocities as stored, in quanta; what an empty cell holds is never
    /// read.
    v: [[i32; D]; CELLS],
    /// Cells whose velocity a stage changed and that await their rounding:
    /// the velocity is `x[c]`, in quanta.
    pending: u8,
    x: [[f32; 3]; CELLS],
    /// Cells whose velocity differs from what the plane holds.
    dirty: u8,
}

impl<const D: usize, const CELLS: usize> Block<D, CELLS> {
    /// The velocity of the particle in cell `c`, in quanta. Out of line
    /// with `small-step`: one copy for every stage (less flash, a call a
    /// read).
    #[cfg_attr(feature = "small-step", inline(never))]
    #[cfg_attr(not(feature = "small-step"), inline(always))]
    fn velocity(&self, c: usize) -> [f32; 3] {
        if self.pending >> c & 1 != 0 {
            return self.x[c];
        }
        let mut x = [0.0; 3];
        for k in 0..D {
            x[k] = self.v[c][k] as f32;
        }
        x
    }

    /// Makes `x` the velocity of the particle in cell `c`, to be rounded.
    /// Out of line with `small-step`, as [`Block::velocity`] is.
    #[cfg_attr(feature = "small-step", inline(never))]
    #[cfg_attr(not(feature = "small-step"), inline(always))]
    fn set(&mut self, c: usize, x: [f32; 3]) {
        self.x[c] = x;
        self.pending |= 1 << c;
    }

    /// M1: rounds every pending velocity back to storage, one 64-bit output
    /// of the stream each, in cell order. Out of line with `small-step`:
    /// one copy for every stage.
    #[cfg_attr(feature = "small-step", inline(never))]
    #[cfg_attr(not(feature = "small-step"), inline(always))]
    fn round<Q: Quant>(&mut self, rng: &mut Stream) {
        for c in cells_of(self.pending) {
            self.v[c] = Q::round::<D>(self.x[c], rng);
        }
        self.dirty |= self.pending;
        self.pending = 0;
    }

    /// [`Block::round`] out of line, after the stages that seldom change a
    /// velocity: a reflection (M5.4) and contacts (M5.7).
    #[inline(never)]
    fn round_apart<Q: Quant>(&mut self, rng: &mut Stream) {
        self.round::<Q>(rng);
    }
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
        let mut b = Block { occ, v: [[0; D]; CELLS], pending: 0, x: [[0.0; 3]; CELLS], dirty: 0 };
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

    /// M5.1 for the particle in cell `c` of mass `m`: `v <- v + dv` (dv in
    /// quanta, eqs. 4-5), then the clamp.
    #[inline(always)]
    fn push(&mut self, b: &mut Block<D, CELLS>, c: usize, dv: [f32; 3], m: f32) {
        let mut x = b.velocity(c);
        for k in 0..D {
            x[k] += dv[k];
        }
        clamp_counted::<D>(&mut x, Q::SCALE, m, &mut self.counters);
        b.set(c, x);
    }

    /// M5.2: one of the block's pairs, uniformly; if both its cells hold a
    /// particle, [`Kernel::collide_two`]. `mass` gives a cell's mass;
    /// `equal` says every mass is the same.
    #[inline(always)]
    fn collide(&mut self, b: &mut Block<D, CELLS>, rng: &mut Stream, mass: impl Fn(usize) -> f32, equal: bool) {
        if let Some((a, c)) = pick_pair::<D>(b.occ, rng) {
            if let Some((xa, xc)) = self.collide_two(b.velocity(a), b.velocity(c), (mass(a), mass(c)), equal, rng) {
                b.set(a, xa);
                b.set(c, xc);
            }
        }
    }

    /// M5.2 on two particles of masses `(ma, mc)` with velocities `va`, `vc`
    /// in quanta: eqs. 7-8 with `R` uniform (or M5.2b), M1b when on, then
    /// the clamp of both; counts the collision. `None` where the collision
    /// changes neither velocity, whatever `R`: two equal velocities within the
    /// speed limit (eqs. 7-8 give both the centre-of-mass velocity, which is
    /// theirs), so a pair at rest draws nothing for it.
    #[inline(always)]
    fn collide_two(&mut self, va: [f32; 3], vc: [f32; 3], (ma, mc): (f32, f32), equal: bool, rng: &mut Stream) -> Option<([f32; 3], [f32; 3])> {
        self.counters.collisions += 1;
        if va == vc && dot_of::<D>(va, va) <= Q::SCALE * Q::SCALE {
            return None;
        }
        let s = if equal { (0.5, 0.5) } else { shares(ma, mc) };
        let e = self.shared.desc.restitution;
        let (mut xa, mut xc) = match self.shared.desc.collision_rule() {
            Collisions::Paper => collide_pair::<D>(va, vc, s, e, random_unit::<D>(rng)),
            // Below the limit by sqrt(D) quanta, so that rounding (less than a
            // quantum per component) cannot store a speed above 1 either.
            Collisions::SpeedLimited => collide_limited::<D>(va, vc, s, e, Q::SCALE - ROUNDING_MARGIN[D - 2], rng),
        };
        if self.shared.desc.has_energy_neutral() {
            (xa, xc) = energy_neutral::<D>(xa, xc, s);
        }
        clamp_counted::<D>(&mut xa, Q::SCALE, ma, &mut self.counters);
        clamp_counted::<D>(&mut xc, Q::SCALE, mc, &mut self.counters);
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
    fn assign(&mut self, occ: u8, speed2: impl Fn(usize) -> f32, blocked: u8, want: &[u8; CELLS], key: usize, rng: &mut Stream) -> u32 {
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
            let (mut speeds, mut want4) = ([0.0f32; 4], [0u8; 4]);
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
    fn occupy(&mut self, row: &BlockRow, xs: [usize; 2], before: u8, after: u8) {
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
        let mass = sh.desc.mass;
        let mut b = self.load(row, xs, occ);
        let mut rng = sh.key.stream(index);
        let mut bytes = None;
        if let Some(dv) = sh.push {
            for c in cells_of(occ) {
                self.push(&mut b, c, dv, mass);
            }
        }
        self.collide(&mut b, &mut rng, |_| mass, true);
        b.round::<Q>(&mut rng);
        let mut want = [0u8; CELLS];
        let (mut key, mut wanted) = (0, 0u8);
        each_cell!(CELLS, c => {
            if occ >> c & 1 != 0 {
                want[c] = self.decide(b.v[c], c, &mut bytes, &mut rng);
                wanted |= want[c];
                if D == 2 {
                    key += usize::from(PLACE_2D[c & 3]) * usize::from(2 + want[c]);
                }
            }
        });
        let targets = self.assign(occ, |c| { let x = b.velocity(c); dot(x, x) }, 0, &want, key, &mut rng);
        if sh.desc.has_contacts() && wanted != 0 {
            contacts(sh, &mut b, &want, targets, &[mass; CELLS], Q::SCALE, &mut self.counters);
            b.round_apart::<Q>(&mut rng);
        }
        self.counters.processed += 1;
        if (targets ^ IDENTITY) & FIELDS[usize::from(occ)] == 0 && b.dirty == 0 {
            return;
        }
        let cell = |c: usize| xs[c & 1] + row.cell[c >> 1];
        let mut after = 0u8;
        each_cell!(CELLS, c => {
            if occ >> c & 1 != 0 {
                let t = (targets >> (4 * c) & 7) as usize;
                after |= 1 << t;
                if t != c || b.dirty >> c & 1 != 0 {
                    self.store(&b, c, cell(t));
                }
            }
        });
        self.occupy(row, xs, occ, after);
    }

    /// M5.1 (a uniform force) and M5.2 (on `pair`, when both its cells hold
    /// a particle) on a block of byte lanes ([`Kernel::lean_2d`]), then M1:
    /// the lanes after rounding, and the cells whose velocity changed. Out
    /// of line: most blocks of most steps need neither.
    #[inline(never)]
    fn change_lanes(&mut self, mut lanes: u64, occ: u8, pair: Option<(usize, usize)>, rng: &mut Stream) -> (u64, u8) {
        let mass = self.shared.desc.mass;
        // Cell c's lanes replaced by the rounding of x (M1).
        let round_into = |lanes: u64, c: usize, x: [f32; 3], rng: &mut Stream| {
            with_lane_ints(lanes, c, Q::round::<2>(x, rng).map(|q| Q::from_int(q).to_int()))
        };
        if self.shared.push.is_none() {
            // The collision alone: its two results rounded in cell order
            // (a < c in every pair), as the loop below would.
            let Some((a, c)) = pair else { return (lanes, 0) };
            debug_assert!(a < c);
            let Some((xa, xc)) = self.collide_two(lane_quanta(lanes, a), lane_quanta(lanes, c), (mass, mass), true, rng) else {
                return (lanes, 0);
            };
            // The four components together: 32 bits for a, then 32 for c.
            let r = [rng.bits(32), rng.bits(32)];
            let x = [xa[0], xa[1], xc[0], xc[1]];
            let q: [i32; 4] = core::array::from_fn(|i| Q::stochastic(x[i], r[i / 2] >> (16 * (i & 1))));
            // 8-bit rounding stays within the stored range (+-127).
            lanes = with_lane_ints(with_lane_ints(lanes, a, [q[0], q[1]]), c, [q[2], q[3]]);
            return (lanes, 1 << a | 1 << c);
        }
        let mut x = [[0.0f32; 3]; CELLS];
        let mut pending = 0u8;
        if let Some(dv) = self.shared.push {
            for c in cells_of(occ) {
                let mut y = lane_quanta(lanes, c);
                y[0] += dv[0];
                y[1] += dv[1];
                clamp_counted::<D>(&mut y, Q::SCALE, mass, &mut self.counters);
                x[c] = y;
            }
            pending = occ;
        }
        if let Some((a, c)) = pair {
            let get = |c: usize| if pending >> c & 1 != 0 { x[c] } else { lane_quanta(lanes, c) };
            if let Some(pair) = self.collide_two(get(a), get(c), (mass, mass), true, rng) {
                (x[a], x[c]) = pair;
                pending |= 1 << a | 1 << c;
            }
        }
        for c in cells_of(pending) {
            lanes = round_into(lanes, c, x[c], rng);
        }
        (lanes, pending)
    }

    /// [`Kernel::lean`] for a 2D block of an 8-bit world whose two cells of
    /// each row are neighbours (no wrap: `x0 + 1 < nx`), in a world without
    /// contacts. The block's stored velocities are read as one 64-bit word
    /// of byte lanes, lane `2c + k` holding cell `c`'s component `k` (two
    /// 32-bit reads, one a block row): which particles want to cross an
    /// axis inward is a handful of word operations for the whole block, and
    /// only those axes read the move table. A velocity a stage changes is
    /// rounded back into its lanes. The draws are those of
    /// [`Kernel::general`], in the same order, so the world is the same bit
    /// for bit.
    #[inline(always)]
    fn lean_2d(&mut self, row: &BlockRow, x0: usize, index: u64, occ: u8) {
        let sh = self.shared;
        let velocity = self.planes.velocity;
        // Both block rows, occupied or not: the lanes of an empty cell are
        // never read as a velocity (every use is masked by `occ`), and a
        // row written back whole writes them back as they were.
        let mut lanes = 0u64;
        for r in 0..2 {
            // SAFETY: x0 < RowPlan::lean_below, so x0 + 1 + row.cell[r] is
            // below the plane's length (`plan`).
            let pair = unsafe { velocity.pair_unchecked(x0 + row.cell[r]) };
            lanes |= u64::from(Q::lanes_2d(pair)) << (32 * r);
        }
        let mut rng = sh.key.stream(index);
        let pair = pick_pair::<D>(occ, &mut rng);
        let mut pending = 0u8;
        if sh.push.is_some() || pair.is_some() {
            (lanes, pending) = self.change_lanes(lanes, occ, pair, &mut rng);
        }

        // M5.3: the lanes that point inward, then a move table entry for
        // each of those only ([`Kernel::decide`]'s draws).
        let mut want = 0u8;
        let inward = inward_lanes(lanes, occ);
        if inward != 0 {
            // Lane i's random byte and stored component as byte i of an
            // array: one indexed load each, where a shift of the word by
            // 8i took three instructions.
            let bytes = rng.next_u64().to_le_bytes();
            let stored = lanes.to_le_bytes();
            let (table, tops) = (sh.moves, sh.tops());
            let mut todo = u32::from(inward);
            while todo != 0 {
                let i = todo.trailing_zeros() as usize;
                todo &= todo - 1;
                let v = usize::from(stored[i]);
                let (high, top) = (bytes[i], tops[v]);
                if high < top || high == top && rng.bits(8) <= u32::from(table[v]) & 0xff {
                    want |= 1 << i;
                }
            }
        }

        self.counters.processed += 1;
        if want != 0 {
            self.finish_2d(row, x0, occ, lanes, want, pending, &mut rng);
        } else if pending != 0 {
            self.write_rows(row, x0, lanes, pending);
        }
    }

    /// The block rows of a lanes block holding a velocity that changed
    /// (`pending`), written back whole from `lanes` (the row's other cell
    /// as it was read), where no particle moved.
    #[inline(always)]
    fn write_rows(&mut self, row: &BlockRow, x0: usize, lanes: u64, pending: u8) {
        for r in 0..2 {
            if pending >> (2 * r) & 3 != 0 {
                // SAFETY: as for the read in `lean_2d`: x0 < lean_below.
                unsafe { self.planes.velocity.set_pair_unchecked(x0 + row.cell[r], Q::pair_from_lanes((lanes >> (32 * r)) as u32)) };
            }
        }
    }

    /// The rest of [`Kernel::lean_2d`] for a block where a particle wants
    /// to move: M5.6, then the moved velocities and those that changed
    /// (`pending`) and the occupancy written back. Out of line: in a
    /// cooling gas most blocks need none of it, and the sweep's loop keeps
    /// its registers.
    #[inline(never)]
    #[allow(clippy::too_many_arguments)]
    fn finish_2d(&mut self, row: &BlockRow, x0: usize, occ: u8, lanes: u64, want: u8, pending: u8, rng: &mut Stream) {
        let sh = self.shared;
        let velocity = self.planes.velocity;
        // M5.6.
        let wants = [want & 3, want >> 2 & 3, want >> 4 & 3, want >> 6];
        let mut per_cell = [0u8; CELLS];
        per_cell[..4].copy_from_slice(&wants);
        let key = 2 * usize::from(BLOCKED_KEY_2D[usize::from(occ)]) + usize::from(KEY_2D_WANTS[usize::from(want)]);
        let targets = self.assign(occ, |c| { let x = lane_quanta(lanes, c); dot(x, x) }, 0, &per_cell, key, rng);
        if (targets ^ IDENTITY) & FIELDS[usize::from(occ)] == 0 {
            return self.write_rows(row, x0, lanes, pending);
        }
        let mut after = 0u8;
        each_cell!(CELLS, c => {
            if occ >> c & 1 != 0 {
                let t = (targets >> (4 * c) & 7) as usize;
                after |= 1 << t;
                if t != c || pending >> c & 1 != 0 {
                    // Cell c's two lanes, as the first cell of a pair.
                    let [stored, _] = Q::pair_from_lanes(cell_lanes(lanes, c));
                    velocity.set(x0 + (t & 1) + row.cell[t >> 1], stored);
                }
            }
        });
        if x0 & 63 == 63 {
            // The block's cells lie in two occupancy words (rare).
            return self.occupy(row, [x0, x0 + 1], occ, after);
        }
        let shift = x0 & 63;
        for r in 0..2 {
            let (old, new) = (u64::from(occ >> (2 * r) & 3), u64::from(after >> (2 * r) & 3));
            if old != new {
                let at = row.word[r] + (x0 >> 6);
                let w = self.planes.occupancy.get(at);
                self.planes.occupancy.set(at, w & !(3 << shift) | new << shift);
                // A row that held no particle of the block may have been
                // swept as empty: flag it again (M3).
                if old == 0 {
                    mark(self.planes.rows, self.planes.words, sh.part.summary_words, row.line[r], x0);
                }
            }
        }
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
        let mut mass = [desc.mass; CELLS];
        let mut mass_index = [0u8; CELLS];
        let mut life = [0u16; CELLS];
        for c in cells_of(occ) {
            if desc.has_masses() {
                mass_index[c] = self.planes.mass_index.get(cell(c));
                mass[c] = sh.mass_table[usize::from(mass_index[c])];
            }
            if desc.lifetimes {
                life[c] = self.planes.life.get(cell(c));
            }
        }
        // A cell's mass: the world's one where particles carry none (no
        // array read, so no bounds check, in a build without masses).
        let mass_of = |c: usize| if desc.has_masses() { mass[c] } else { desc.mass };
        let mut rng = sh.key.stream(row.index + bx as u64);
        let mut bytes = None;

        // M5.1 external force: v <- v + dt F / m (eqs. 4-5).
        for c in cells_of(occ) {
            let dv = if sh.summed {
                let pos = sh.part.cell_coords(row, [xs[c & 1], 0, 0], c);
                // dt = 0 changes nothing, even under an infinite force
                // (0 * inf would be NaN).
                let mut a = sh.terms.accel(pos, cell(c), mass_of(c));
                // Component by component: an array's map is a call at
                // opt-level z.
                for a in &mut a {
                    *a = if sh.dt_q == 0.0 { 0.0 } else { *a * sh.dt_q };
                }
                a
            } else {
                sh.push.unwrap_or_default()
            };
            // A force that changes nothing is no step 1: a zero-valued part
            // gives the same world as a world without it (M9).
            if crate::rules::vector::nonzero(dv) {
                self.push(&mut b, c, dv, mass_of(c));
            }
        }

        // M5.1b flow drag: v <- (v + a u) / (1 + a), u the flow at the cell
        // (none without the feature `fields`: `Layout::of`).
        let drag = if cfg!(feature = "fields") { sh.drag.as_ref() } else { None };
        if let Some(flow) = drag {
            let a = flow.rate;
            for c in cells_of(occ) {
                let u = flow.at(sh.part.cell_coords(row, [xs[c & 1], 0, 0], c), cell(c));
                let mut x = b.velocity(c);
                for k in 0..D {
                    x[k] = crate::rules::vector::div(x[k] + a * u[k], 1.0 + a);
                }
                clamp_counted::<D>(&mut x, Q::SCALE, mass_of(c), &mut self.counters);
                b.set(c, x);
            }
        }

        // M5.2 collision, then M1 for what the force, the drag and the
        // collision changed.
        self.collide(&mut b, &mut rng, mass_of, !desc.has_masses());
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
                if let Some(x) = reflect_off::<D>(sh, b.velocity(c), c, to, mass_of(c), Q::SCALE, &mut self.counters) {
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
        let targets = self.assign(occ, |c| { let x = b.velocity(c); dot(x, x) }, blocked, &want, key, &mut rng);

        // M5.7 contacts, then M1 for what they changed.
        if desc.has_contacts() && wanted != 0 {
            contacts(sh, &mut b, &want, targets, &mass, Q::SCALE, &mut self.counters);
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
    use crate::rules::assign::digit;
    use crate::rules::rng::block_stream;
    use crate::{Description, World};

    #[test]
    fn the_lanes_routine_gives_the_general_ones_world_at_the_row_ends() {
        // Expect: a crowded periodic 8 x 6 world of 8-bit velocities
        // (every block of a row but the wrapping one goes through the
        // lanes routine, whose reads and writes are unchecked under the
        // row plan's bound: under Miri they are checked here) steps to the
        // same world, bit for bit, as through the general routine alone,
        // at both offsets; its particles collide, move and stay put.
        let desc = Description::new_2d(8, 6);
        let mut rng = block_stream(8, 6, 0);
        let (mut a, mut b) = ([0u64; 512], [0u64; 512]);
        let bytes = |m: &mut [u64; 512]| {
            // SAFETY: the array's 4,096 bytes, borrowed once each.
            unsafe { core::slice::from_raw_parts_mut(m.as_mut_ptr().cast::<u8>(), 4096) }
        };
        let lean = World::init(&desc, bytes(&mut a)).unwrap();
        let general = World::init(&desc, bytes(&mut b)).unwrap();
        for y in 0..6 {
            for x in 0..8 {
                if rng.bits(2) != 0 {
                    let v = [rng.unit() - 0.5, rng.unit() - 0.5, 0.0];
                    lean.add_particle([x, y, 0], v).unwrap();
                    general.add_particle([x, y, 0], v).unwrap();
                }
            }
        }
        let (particles, start) = (lean.stats().particles, lean.state_hash());
        for _ in 0..6 {
            lean.step(1);
            general.step_reference();
            assert_eq!(lean.state_hash(), general.state_hash());
        }
        let stats = lean.stats();
        assert_eq!(stats.particles, particles);
        assert!(stats.collisions > 0 && lean.state_hash() != start, "{stats:?}");
    }

    #[test]
    fn inward_lanes_match_the_rule_lane_by_lane() {
        // Expect: bit 2c + k set exactly where cell c is occupied and its
        // component k is positive on the low side of axis k, negative on
        // the high side; for random lanes (every byte value) and every mask.
        let mut rng = block_stream(1, 2, 3);
        for round in 0..crate::sized(20_000, 600) {
            let lanes = if round < 256 { 0x0101_0101_0101_0101 * round as u64 } else { rng.next_u64() };
            for occ in 0..16u8 {
                let mut want = 0u8;
                for c in 0..4 {
                    for k in 0..2 {
                        let q = (lanes >> (8 * (2 * c + k))) as u8 as i8;
                        let inward = if (c >> k) & 1 == 0 { q > 0 } else { q < 0 };
                        if occ >> c & 1 != 0 && inward {
                            want |= 1 << (2 * c + k);
                        }
                    }
                }
                assert_eq!(inward_lanes(lanes, occ), want, "{lanes:#018x} {occ:#06b}");
            }
        }
    }

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
                                let mut v = [0.0f32; 3];
                                for k in 0..dim {
                                    v[k] = if wish >> k & 1 != 0 {
                                        if c >> k & 1 == 0 { 1.0 } else { -1.0 }
                                    } else {
                                        (signs / 3usize.pow(k as u32) % 3) as f32 - 1.0
                                    };
                                }
                                assert!(dot(v, normal) < 0.0, "{dim}D faces {faces:#b} corner {corner} cell {c} wish {wish:#b} v {v:?} N {normal:?}");
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
