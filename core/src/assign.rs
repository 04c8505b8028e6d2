//! The move assignment of M5.6: which cell of its block each particle ends in.
//!
//! ```
//! use mpca::assign::{assign_moves, cost, Method, MoveProblem};
//! use mpca::rng::block_stream;
//!
//! // A 2D block: particles in cells 1 and 2 both want the empty cell 0.
//! let mut problem = MoveProblem { free: 0b1111, count: 2, ..MoveProblem::default() };
//! problem.current[..2].copy_from_slice(&[1, 2]);
//! problem.desired[..2].copy_from_slice(&[0, 0]);
//! let mut rng = block_stream(7, 0, 0);
//! let moved = assign_moves::<2>(Method::ExactFast, &problem, &mut rng);
//! // One of them gets cell 0 and the other stays put; the stream picks which.
//! assert_eq!(cost(&problem, &moved), (1, 1));
//! ```
//!
//! Every particle of a block goes to a distinct free cell of the block. The
//! chosen assignment minimises, lexicographically, the summed distance to the
//! desired cells and then the summed distance to the current cells (so a
//! particle that gains nothing by moving stays); the block's stream (M8)
//! breaks the remaining ties. The distance between two local cells is the
//! number of axes on which they differ: local cell `c` has offset
//! `(c >> k) & 1` along axis `k`, so it is `popcount(a ^ b)`.
//!
//! Three methods, all selectable (docs/model.md M5.6):
//! - [`Method::Exhaustive`], the paper's: every permutation of the particles
//!   over the free cells, one optimal leaf kept by reservoir sampling. The
//!   reference for the others.
//! - [`Method::ExactFast`]: the same optimum, uniform over the optimal
//!   assignments. In 2D a table built at compile time holds every optimal
//!   assignment of each block state in which no particle wants a blocked
//!   cell (944 of the 1296, among them the 815 the step can meet); the
//!   others, which only a direct caller can pose, are solved when asked by
//!   the programme that builds the table. In 3D the common blocks
//!   are settled directly (every wish distinct and free; two particles
//!   after one cell); otherwise the Hungarian method finds an optimal
//!   assignment with prices that mark every pair an optimal assignment may
//!   use, the optimal assignments along those pairs are counted, and one
//!   draw picks among them.
//! - [`Method::Greedy`], the paper's 3D approximation: the particles, fastest
//!   first, each take their best untaken cell.

use crate::rules::rng::Stream;

/// How particles are assigned to the cells of their block (M5.6).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Method {
    /// Every permutation, the paper's method and the reference: 4! leaves in
    /// 2D, 8! = 40320 for a full 3D block.
    Exhaustive = 0,
    /// The exhaustive optimum at a small fraction of its cost: a compile-time
    /// table in 2D, the Hungarian method and a count of the optimal
    /// assignments in 3D.
    ExactFast = 1,
    /// The paper's 3D approximation: fastest particle first, each to its best
    /// untaken cell. Not always optimal.
    Greedy = 2,
}

/// The most cells a block has (3D).
pub const MAX_CELLS: usize = 8;

/// One block's assignment problem.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MoveProblem {
    /// Bit c set: local cell c may receive a particle. Bits of cells the
    /// block does not have (4 and up in 2D) are ignored.
    pub free: u8,
    /// Number of particles (<= number of free cells).
    pub count: usize,
    /// Local cell each particle is in now.
    pub current: [u8; MAX_CELLS],
    /// Local cell each particle wants.
    pub desired: [u8; MAX_CELLS],
    /// Squared speed of each particle, for greedy ranking.
    pub speed2: [f32; MAX_CELLS],
}

/// The local cell given to each particle, in the problem's particle order.
/// Entries from the problem's `count` on are 0.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Assignment {
    /// Target local cell of particle `i`.
    pub target: [u8; MAX_CELLS],
}

/// (cost1, cost2) of an assignment: summed distance to the desired cells,
/// summed distance to the current cells.
pub fn cost(problem: &MoveProblem, assignment: &Assignment) -> (u32, u32) {
    let count = problem.count.min(MAX_CELLS);
    let mut to_desired = 0;
    let mut to_current = 0;
    for i in 0..count {
        let target = assignment.target[i];
        to_desired += u32::from(dist(target, problem.desired[i]));
        to_current += u32::from(dist(target, problem.current[i]));
    }
    (to_desired, to_current)
}

/// Solve one block: D is 2 or 3.
///
/// Draws from `rng` only to break ties: exact-fast at most once, exhaustive
/// once per optimal leaf after the first, greedy once per particle that has
/// several equally good cells.
///
/// The preconditions (`count` at most the number of free cells, current
/// cells distinct, free and inside the block, desired cells inside the
/// block) are checked in debug builds only. A release build given a block
/// with more particles than free cells leaves every particle where it is.
///
/// Inlined: the step settles a 2D block's exact-fast assignment from the
/// table before it calls this, so where this is inlined into the step the
/// compiler sees that the 2D table's method is not called from there, and
/// a 2D-only firmware does not carry it (the fallback for keys the table
/// does not list is most of it).
#[inline(always)]
pub fn assign_moves<const D: usize>(method: Method, problem: &MoveProblem, rng: &mut Stream) -> Assignment {
    const { assert!(D == 2 || D == 3, "a Margolus block has 2 or 3 axes") };
    // The step's own test, `method == Method::ExactFast`, in the same
    // words: the compiler knows its answer here without following `method`
    // through the step's loops, which it does not do (a `match` on
    // `method` kept the call in the firmware).
    if D == 2 && method == Method::ExactFast {
        return exact_fast_2d(problem, rng);
    }
    solve::<D>(method, problem, rng)
}

/// [`Method::ExactFast`] in 2D.
fn exact_fast_2d(problem: &MoveProblem, rng: &mut Stream) -> Assignment {
    let (free, count) = block::<2>(problem);
    if count > free.count_ones() as usize {
        return stay(problem, count);
    }
    exact_table_2d(problem, free, count, rng)
}

/// Every method but 2D exact-fast, which [`assign_moves`] takes to the
/// table.
fn solve<const D: usize>(method: Method, problem: &MoveProblem, rng: &mut Stream) -> Assignment {
    let (free, count) = block::<D>(problem);
    if count > free.count_ones() as usize {
        return stay(problem, count);
    }
    match method {
        Method::ExactFast if D == 3 => exact_3d(problem, free, count, |ways| rng.below(ways)),
        // 2D exact-fast never comes here; were it to, exhaustive search
        // reaches the same optimum.
        Method::Exhaustive | Method::ExactFast => exhaustive(problem, free, count, rng),
        Method::Greedy => greedy(problem, free, count, rng),
    }
}

/// The free cells of the block and its number of particles, the
/// preconditions checked in debug builds.
#[inline]
fn block<const D: usize>(problem: &MoveProblem) -> (u8, usize) {
    let cells = 1usize << D;
    debug_assert!(well_formed(problem, cells), "malformed block: {problem:?}");
    (problem.free & block_mask(cells), problem.count.min(MAX_CELLS))
}

/// Everyone where they are: the answer to a block with more particles
/// than free cells (a broken precondition, caught in debug builds).
fn stay(problem: &MoveProblem, count: usize) -> Assignment {
    let mut stay = Assignment::default();
    stay.target[..count].copy_from_slice(&problem.current[..count]);
    stay
}

/// Number of axes on which two local cells (below 8) differ (M5.6): the
/// popcount of their 3-bit xor, read from a table of nibbles, since neither
/// baseline x86-64 nor Cortex-M has a popcount instruction.
#[inline]
const fn dist(a: u8, b: u8) -> u8 {
    (0x3221_2110u32 >> (4 * ((a ^ b) & 7))) as u8 & 0xf
}

/// Bits of the cells a block of `cells` cells has.
#[inline]
const fn block_mask(cells: usize) -> u8 {
    (u8::MAX as usize >> (MAX_CELLS - cells)) as u8
}

/// The preconditions of [`assign_moves`], for `debug_assert!`.
fn well_formed(problem: &MoveProblem, cells: usize) -> bool {
    let free = problem.free & block_mask(cells);
    if problem.count > MAX_CELLS || problem.count > free.count_ones() as usize {
        return false;
    }
    let mut seen = 0u8;
    for i in 0..problem.count {
        let (now, want) = (problem.current[i], problem.desired[i]);
        if usize::from(now) >= cells || usize::from(want) >= cells {
            return false;
        }
        let bit = 1 << now;
        if free & bit == 0 || seen & bit != 0 {
            return false;
        }
        seen |= bit;
    }
    true
}

/// Weight of cost1 in the combined cost `PRIMARY * cost1 + cost2`: cost2 is
/// at most 8 particles * 3 axes = 24 < 32, so one integer comparison orders
/// assignments as M5.6 asks, (cost1, cost2) lexicographically.
const PRIMARY: u8 = 32;

/// `costs[i][t]`: combined cost of putting particle `i` in cell `t`.
type MoveCosts = [[u8; MAX_CELLS]; MAX_CELLS];

/// The combined cost of every (particle, cell) pair; at most 32 * 3 + 3.
/// Inlined, as the compiler did while greedy was its only caller at run
/// time (the 2D table's fallback is the other): a call costs greedy 13
/// instructions a block.
#[inline(always)]
const fn move_costs(problem: &MoveProblem, count: usize) -> MoveCosts {
    let mut costs = [[0; MAX_CELLS]; MAX_CELLS];
    let mut i = 0;
    while i < count {
        let mut t = 0;
        while t < MAX_CELLS {
            let cell = t as u8;
            costs[i][t] = PRIMARY * dist(cell, problem.desired[i]) + dist(cell, problem.current[i]);
            t += 1;
        }
        i += 1;
    }
    costs
}

// ---------------------------------------------------------------- exhaustive

/// The depth-first search of [`Method::Exhaustive`].
struct Search<'a> {
    /// `steps[i][t]`: particle `i` in cell `t` costs `cost1 << 8 | cost2`.
    /// Both sums stay below 256, so comparing packed sums compares
    /// (cost1, cost2) lexicographically; this packing is not the fast
    /// method's weighting, so the reference shares no shortcut with it.
    steps: [[u16; MAX_CELLS]; MAX_CELLS],
    free: u8,
    count: usize,
    /// Cells chosen so far, particle by particle.
    path: [u8; MAX_CELLS],
    /// Best packed cost seen, the leaves at that cost seen so far, and the
    /// one of them the reservoir holds.
    best: u16,
    ties: u32,
    kept: [u8; MAX_CELLS],
    rng: &'a mut Stream,
}

impl Search<'_> {
    /// Particle `i` tries every free cell not in `used`. Leaves are scored
    /// in the loop of the last particle rather than in a call of their own:
    /// half the tree's nodes are leaves.
    fn descend(&mut self, i: usize, used: u8, sum: u16) {
        let row = self.steps[i];
        let last = i + 1 == self.count;
        let mut open = self.free & !used;
        while open != 0 {
            let cell = open.trailing_zeros() as usize;
            open &= open - 1;
            self.path[i] = cell as u8;
            let sum = sum + row[cell];
            if last {
                self.leaf(sum);
            } else {
                self.descend(i + 1, used | 1 << cell, sum);
            }
        }
    }

    #[inline]
    fn leaf(&mut self, cost: u16) {
        if cost < self.best {
            self.best = cost;
            self.ties = 1;
            self.kept = self.path;
        } else if cost == self.best {
            // Reservoir sampling: after n optimal leaves each has been kept
            // with probability 1/n, so the tie-break is uniform.
            self.ties += 1;
            if self.rng.below(self.ties) == 0 {
                self.kept = self.path;
            }
        }
    }
}

fn exhaustive(problem: &MoveProblem, free: u8, count: usize, rng: &mut Stream) -> Assignment {
    let mut steps = [[0; MAX_CELLS]; MAX_CELLS];
    for (i, row) in steps.iter_mut().enumerate().take(count) {
        for (cell, step) in (0..).zip(row.iter_mut()) {
            *step = u16::from(dist(cell, problem.desired[i])) << 8
                | u16::from(dist(cell, problem.current[i]));
        }
    }
    let mut search = Search {
        steps,
        free,
        count,
        path: [0; MAX_CELLS],
        best: u16::MAX,
        ties: 0,
        kept: [0; MAX_CELLS],
        rng,
    };
    // No particle: the one (empty) assignment.
    if count > 0 {
        search.descend(0, 0, 0);
    }
    Assignment {
        target: search.kept,
    }
}

// ---------------------------------------------------------- exact, subsets

/// For every set of used cells reachable by placing particles `0..k` in
/// order (`k` its popcount): the least combined cost of placing the rest,
/// and how many placements of the rest reach it. An optimal assignment of
/// a full 3D block has at most 8! = 40320 completions, so `u16` holds them.
/// The compiler builds the 2D table with it; the tests count 3D optima
/// with it.
struct Completions {
    cost: [u16; 1 << MAX_CELLS],
    ways: [u16; 1 << MAX_CELLS],
}

/// Every subset of the 8 cells, fewest cells first, so the dynamic programme
/// takes them a size at a time without counting bits.
const SUBSETS_BY_SIZE: [u8; 1 << MAX_CELLS] = subsets_by_size();
/// `SUBSETS_BY_SIZE[SIZE_START[p]..SIZE_START[p + 1]]` are the sets of `p`
/// cells (the partial sums of the binomials C(8, p)).
const SIZE_START: [usize; MAX_CELLS + 2] = [0, 1, 9, 37, 93, 163, 219, 247, 255, 256];

const fn subsets_by_size() -> [u8; 1 << MAX_CELLS] {
    let mut out = [0; 1 << MAX_CELLS];
    let mut size = 0;
    while size <= MAX_CELLS {
        let mut n = SIZE_START[size];
        let mut mask = 0;
        while mask < 1 << MAX_CELLS {
            if (mask as u8).count_ones() as usize == size {
                out[n] = mask as u8;
                n += 1;
            }
            mask += 1;
        }
        assert!(n == SIZE_START[size + 1]);
        size += 1;
    }
    out
}

/// The dynamic programme over the subsets of `free` with at most `count`
/// cells (M5.6). `count` must not exceed the number of
/// free cells, so every such subset has a completion.
const fn completions(free: u8, count: usize, costs: &MoveCosts) -> Completions {
    let mut out = Completions {
        cost: [0; 1 << MAX_CELLS],
        ways: [0; 1 << MAX_CELLS],
    };
    if count == 0 {
        out.ways[0] = 1;
        return out;
    }
    // Smaller sets after larger ones, so every child is done before its
    // parent; the particle to place next is the `placed`-th. Children of the
    // last particle are complete: nothing left to pay, one way to finish.
    let mut placed = count;
    while placed > 0 {
        placed -= 1;
        let last = placed + 1 == count;
        let row = &costs[placed];
        let mut n = SIZE_START[placed];
        while n < SIZE_START[placed + 1] {
            let mask = SUBSETS_BY_SIZE[n];
            n += 1;
            if mask & !free != 0 {
                continue;
            }
            let mut best = u16::MAX;
            let mut ways = 0;
            let mut open = free & !mask;
            while open != 0 {
                let cell = open.trailing_zeros() as usize;
                open &= open - 1;
                let child = mask as usize | 1 << cell;
                let (rest, finishes) = if last {
                    (0, 1)
                } else {
                    (out.cost[child], out.ways[child])
                };
                let total = row[cell] as u16 + rest;
                // Masks, not branches: which child wins is data, and a
                // mispredicted branch costs more than this whole step.
                let tie = 0u16.wrapping_sub((total == best) as u16);
                let wins = 0u16.wrapping_sub((total <= best) as u16);
                ways = (ways & !wins) | (((ways & tie) + finishes) & wins);
                best ^= (best ^ total) & wins;
            }
            out.cost[mask as usize] = best;
            out.ways[mask as usize] = ways;
        }
    }
    out
}

/// The optimal assignment numbered `rank` (`rank < done.ways[0]`), counting
/// in order of the cells given to particle 0, then particle 1, and so on.
/// With `rank` uniform, particle `i` takes each optimal cell with probability
/// proportional to that cell's optimal completions: uniform over all optimal
/// assignments from a single draw.
const fn nth_optimal(
    free: u8,
    count: usize,
    costs: &MoveCosts,
    done: &Completions,
    mut rank: u16,
) -> [u8; MAX_CELLS] {
    let mut target = [0; MAX_CELLS];
    let mut mask = 0u8;
    let mut i = 0;
    while i < count {
        let goal = done.cost[mask as usize];
        let mut open = free & !mask;
        while open != 0 {
            let cell = open.trailing_zeros() as usize;
            open &= open - 1;
            let child = mask | 1 << cell;
            let (rest, ways) = if i + 1 == count {
                (0, 1)
            } else {
                (done.cost[child as usize], done.ways[child as usize])
            };
            if costs[i][cell] as u16 + rest == goal {
                if rank < ways {
                    target[i] = cell as u8;
                    mask = child;
                    break;
                }
                rank -= ways;
            }
        }
        i += 1;
    }
    target
}

// ------------------------------------------------------------------ exact, 3D

/// `DIST_FROM[x]`: byte `t` is the distance from cell `t` to cell `x`. A
/// particle's row of combined costs is then `DIST_FROM[want] * PRIMARY +
/// DIST_FROM[now]` in one 64-bit add: no byte exceeds 32 * 3 + 3, so no
/// carry crosses into the next cell's byte.
const DIST_FROM: [u64; MAX_CELLS] = {
    let mut rows = [0; MAX_CELLS];
    let mut x = 0;
    while x < MAX_CELLS {
        let mut t = 0;
        while t < MAX_CELLS {
            rows[x] |= (dist(t as u8, x as u8) as u64) << (8 * t);
            t += 1;
        }
        x += 1;
    }
    rows
};

/// `DIST_LANES[x][t]`: the distance from cell `t` to cell `x`.
const DIST_LANES: [Lanes; MAX_CELLS] = {
    let mut rows = [[0; MAX_CELLS]; MAX_CELLS];
    let mut x = 0;
    while x < MAX_CELLS {
        let mut t = 0;
        while t < MAX_CELLS {
            rows[x][t] = dist(t as u8, x as u8) as i16;
            t += 1;
        }
        x += 1;
    }
    rows
};

/// No particle, or no cell.
const NONE: u8 = u8::MAX;

/// [`Method::ExactFast`] in 3D (M5.6): the exhaustive optimum and the same
/// uniform choice among its optimal assignments, at about greedy's cost.
/// `draw(n)` must return a uniform rank below `n`; it is called once, and
/// only where there are `n > 1` optimal assignments.
///
/// 1. Every particle alone in wanting a free cell: each gets it, the only
///    assignment with cost1 = 0.
/// 2. One or two particles: counted directly.
/// 3. Otherwise the Hungarian method finds one optimal assignment and
///    prices that tell which (particle, cell) pairs any optimal assignment
///    may use; see [`pick`] for how those are counted and drawn from.
fn exact_3d(problem: &MoveProblem, free: u8, count: usize, draw: impl FnOnce(u32) -> u32) -> Assignment {
    let mut wanted = 0u8;
    let mut clash = 0u8;
    for &want in &problem.desired[..count] {
        let bit = 1 << (want & 7);
        clash |= wanted & bit;
        wanted |= bit;
    }
    if clash == 0 && wanted & !free == 0 {
        let mut assignment = Assignment::default();
        assignment.target[..count].copy_from_slice(&problem.desired[..count]);
        return assignment;
    }
    if count <= 2 {
        return few(problem, free, count, draw);
    }
    let mut prices = Prices::start(problem, free, count);
    for i in 0..count {
        if prices.at[i] == NONE {
            prices.augment(i);
        }
    }
    pick(&prices, count, draw)
}

/// Particle `i`'s combined cost of each cell.
fn cost_row(problem: &MoveProblem, i: usize) -> [u8; MAX_CELLS] {
    let (want, now) = (usize::from(problem.desired[i] & 7), usize::from(problem.current[i] & 7));
    (DIST_FROM[want] * u64::from(PRIMARY) + DIST_FROM[now]).to_le_bytes()
}

/// One or two particles (1 or 2 free cells at least), counted directly.
///
/// Each particle has its cells of least cost. One particle takes any of
/// them. Two take any two distinct ones, one from each, unless each has
/// the same single cell `x`: then one of them takes `x` (were neither
/// there, moving either in would lower cost1) and the other a cell of
/// least cost among the rest. Ways are numbered by particle 0's cell, or
/// by who takes `x`, and then by the other's cell, cells in order.
fn few(problem: &MoveProblem, free: u8, count: usize, draw: impl FnOnce(u32) -> u32) -> Assignment {
    let mut assignment = Assignment::default();
    // A free wanted cell is the one cheapest (cost1 0 against 1 or more).
    let cheapest = |row: &[u8; MAX_CELLS], i: usize| {
        let want = problem.desired[i] & 7;
        if free >> want & 1 != 0 { (row[usize::from(want)], 1 << want) } else { least(row, free) }
    };
    let row0 = cost_row(problem, 0);
    let (best0, tied0) = cheapest(&row0, 0);
    if count == 1 {
        let ways = tied0.count_ones();
        let rank = if ways > 1 { draw(ways) } else { 0 };
        assignment.target[0] = nth_bit(tied0, rank);
        return assignment;
    }
    let row1 = cost_row(problem, 1);
    let (best1, tied1) = cheapest(&row1, 1);
    if tied0 != tied1 || tied0 & (tied0 - 1) != 0 {
        let ways = tied0.count_ones() * tied1.count_ones() - (tied0 & tied1).count_ones();
        let mut rank = if ways > 1 { draw(ways) } else { 0 };
        for a in bits(tied0) {
            let others = tied1 & !(1 << a);
            let n = others.count_ones();
            if rank < n {
                assignment.target[0] = a as u8;
                assignment.target[1] = nth_bit(others, rank);
                break;
            }
            rank -= n;
        }
        return assignment;
    }
    let x = tied0.trailing_zeros() as u8;
    let rest = free & !tied0;
    let (rest0, others0) = least(&row0, rest);
    let (rest1, others1) = least(&row1, rest);
    // Particle 0 in x leaves particle 1 its best of the rest, and the other
    // way round.
    let total = [u16::from(best0) + u16::from(rest1), u16::from(best1) + u16::from(rest0)];
    let optimum = total[0].min(total[1]);
    let ways0 = if total[0] == optimum { others1.count_ones() } else { 0 };
    let ways1 = if total[1] == optimum { others0.count_ones() } else { 0 };
    let mut rank = if ways0 + ways1 > 1 { draw(ways0 + ways1) } else { 0 };
    let (winner, others) = if rank < ways0 {
        (0, others1)
    } else {
        rank -= ways0;
        (1, others0)
    };
    assignment.target[winner] = x;
    assignment.target[1 - winner] = nth_bit(others, rank);
    assignment
}

/// The index of the set bit of rank `rank` in `set` (lowest first).
fn nth_bit(set: u8, rank: u32) -> u8 {
    let mut rest = set;
    for _ in 0..rank {
        rest &= rest - 1;
    }
    rest.trailing_zeros() as u8
}

/// The least cost in `row` over the cells of `cells` (not empty), and the
/// cells that have it.
fn least(row: &[u8; MAX_CELLS], cells: u8) -> (u8, u8) {
    let mut best = u8::MAX;
    let mut tied = 0u8;
    let mut open = cells;
    while open != 0 {
        let cell = open.trailing_zeros() as usize;
        open &= open - 1;
        let c = row[cell];
        if c < best {
            best = c;
            tied = 0;
        }
        if c == best {
            tied |= 1 << cell;
        }
    }
    (best, tied)
}

/// Sixteen-bit lanes, one per cell: eight of them are one SSE2 register, so
/// the loops over all of a row's lanes below compile to a few vector
/// instructions where the target has them.
type Lanes = [i16; MAX_CELLS];

/// Added to the cost of a cell that is not free: more than any real cost
/// and lift together (at most 99 + 198), so such a cell is never the
/// cheapest nor tight.
const SHUT: i16 = 0x2000;

/// The Hungarian method (shortest augmenting paths), with prices
/// `q[t] = -lift[t] <= 0` on the cells. Invariants: every free cell nobody
/// holds has no lift; and each placed particle's cell minimises
/// `costs[i][t] + lift[t]` over the free cells (is *tight*). That least value
/// is the particle's own price `p[i]`, so it is never stored.
///
/// Once everyone is placed, these prices prove the assignment optimal, and
/// more (complementary slackness of the linear programme): an assignment is
/// optimal exactly when it puts every particle in a tight cell and fills
/// every cell with lift. The search for all optimal assignments needs
/// nothing else.
///
/// Bounds: while some free cell is unheld, `p[i]` is at most its cost there
/// (99), so no lift exceeds 99; the last path adds at most 99 more.
struct Prices {
    /// Combined costs, [`SHUT`] added on the cells that are not free.
    costs: [Lanes; MAX_CELLS],
    lift: Lanes,
    /// How much further than a cell the search may get before the moves
    /// of the particle in it need looking at: see [`Prices::augment`].
    defer: Lanes,
    /// `lift + defer`, what the search adds on reaching a cell.
    bias: Lanes,
    /// -1 on the cells that are not free, 0 on the others.
    shut: Lanes,
    /// The cell of each particle, or NONE.
    at: [u8; MAX_CELLS],
    /// The particle in each cell, or NONE.
    owner: [u8; MAX_CELLS],
}

impl Prices {
    /// Each particle that wants a free cell nobody before it in the list
    /// wants takes it: with no lift that cell is its cheapest (cost1 0).
    /// Everyone else waits for [`Prices::augment`].
    fn start(problem: &MoveProblem, free: u8, count: usize) -> Prices {
        let mut shut = [0; MAX_CELLS];
        for (t, lane) in shut.iter_mut().enumerate() {
            *lane = i16::from(free >> t & 1 == 0).wrapping_neg();
        }
        let mut costs = [[0; MAX_CELLS]; MAX_CELLS];
        for (lanes, i) in costs.iter_mut().zip(0..count) {
            let want = &DIST_LANES[usize::from(problem.desired[i] & 7)];
            let now = &DIST_LANES[usize::from(problem.current[i] & 7)];
            for t in 0..MAX_CELLS {
                lanes[t] = want[t] * i16::from(PRIMARY) + now[t] + (shut[t] & SHUT);
            }
        }
        let mut prices = Prices {
            costs,
            lift: [0; MAX_CELLS],
            defer: [0; MAX_CELLS],
            bias: [0; MAX_CELLS],
            shut,
            at: [NONE; MAX_CELLS],
            owner: [NONE; MAX_CELLS],
        };
        for i in 0..count {
            let want = usize::from(problem.desired[i] & 7);
            if free >> want & 1 != 0 && prices.owner[want] == NONE {
                prices.owner[want] = i as u8;
                prices.at[i] = want as u8;
                prices.defer[want] = i16::from(PRIMARY) - prices.costs[i][want];
                prices.bias[want] = prices.defer[want];
            }
        }
        prices
    }

    /// Places particle `s`, which has no cell, at the end of a cheapest
    /// alternating path: Dijkstra over the free cells, a step from particle
    /// `i` to cell `t` costing `costs[i][t] + lift[t] - p[i]` (never
    /// negative). Every cell reached sooner than the end gains lift by how
    /// much sooner, which keeps the invariants and makes the path tight. A
    /// free cell nobody holds exists, since there are at least as many free
    /// cells as particles, so the search ends there.
    ///
    /// About half the cells reached hold a particle in the cell it wants,
    /// priced `p < PRIMARY`: any other cell costs it at least `PRIMARY - p`
    /// (`defer`) more. Its moves are looked at only once the search has got
    /// that much further, as if they were a node of their own at that
    /// distance; mostly the path ends first. Reaching a cell therefore
    /// counts `lift + defer` (`bias`), and `defer` is taken off again where
    /// the true distance matters. A cell reached sooner than the end but
    /// never expanded still gains its lift: its holder's price rises with
    /// it, and by the bound no other cell becomes cheaper than its own.
    fn augment(&mut self, s: usize) {
        let mut reach = [i16::MAX; MAX_CELLS];
        let mut via = [0i16; MAX_CELLS];
        // -1 on settled cells and on cells that are not free.
        let mut closed = self.shut;
        // The particle being expanded, and its distance less its price.
        let (mut row, mut offset) = (s, 0i16);
        let (end, length) = loop {
            let costs = &self.costs[row];
            let from = row as i16;
            // Distance (with defer) times 8 plus the cell, so that one
            // minimum gives the nearest open cell and, among equals, the
            // first.
            let mut key = [0; MAX_CELLS];
            for t in 0..MAX_CELLS {
                let d = offset + costs[t] + self.bias[t];
                let nearer = d < reach[t];
                reach[t] = if nearer { d } else { reach[t] };
                via[t] = if nearer { from } else { via[t] };
                let ranked = reach[t].wrapping_shl(3) | t as i16;
                key[t] = if closed[t] == 0 { ranked } else { i16::MAX };
            }
            let least = min_lane(&key);
            let (next, best) = (usize::from(least as u8 & 7), least >> 3);
            if self.owner[next] == NONE {
                break (next, best);
            }
            closed[next] = -1;
            row = usize::from(self.owner[next]);
            // The holder's price is what its (tight) cell costs it.
            offset = best - self.costs[row][next] - self.bias[next];
        };
        // `reach - defer` is the true distance; the holder's price rises
        // with its cell's lift, so its defer shrinks as much.
        for t in 0..MAX_CELLS {
            let gain = (length - reach[t] + self.defer[t]).max(0) & !self.shut[t];
            self.lift[t] += gain;
            self.defer[t] = (self.defer[t] - gain).max(0);
            self.bias[t] = self.lift[t] + self.defer[t];
        }
        // Everyone on the path moves one cell along it; `s` takes the first.
        let mut cell = end as u8;
        loop {
            let i = via[usize::from(cell)] as u8;
            let left = self.at[usize::from(i)];
            let c = usize::from(cell);
            self.owner[c] = i;
            self.at[usize::from(i)] = cell;
            self.defer[c] = (i16::from(PRIMARY) - self.costs[usize::from(i)][c] - self.lift[c]).max(0);
            self.bias[c] = self.lift[c] + self.defer[c];
            if usize::from(i) == s {
                break;
            }
            cell = left;
        }
    }

    /// The tight cells of the placed particle `i`. A price below
    /// [`PRIMARY`] means a particle in the cell it wants, every other cell
    /// of which costs it at least that much before any lift: that cell
    /// alone, without comparing.
    #[inline]
    fn tight(&self, i: usize) -> u8 {
        let at = usize::from(self.at[i] & 7);
        let costs = &self.costs[i];
        let price = costs[at] + self.lift[at];
        if price < i16::from(PRIMARY) {
            return 1 << at;
        }
        // -1 in the lanes of the tight cells: one vector compare.
        sign_mask(&core::array::from_fn(|t| i16::from(costs[t] + self.lift[t] == price).wrapping_neg()))
    }

    /// The cells every optimal assignment fills: those with lift.
    fn must(&self) -> u8 {
        sign_mask(&core::array::from_fn(|t| i16::from(self.lift[t] > 0).wrapping_neg()))
    }
}

/// The lanes that are negative, as a mask (bit `t` for lane `t`): a pack
/// of the lanes to bytes and a move of their sign bits with SSE2, which
/// every x86-64 has, where the compiler would otherwise gather the bits one
/// at a time.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn sign_mask(lanes: &Lanes) -> u8 {
    use core::arch::x86_64::{_mm_loadu_si128, _mm_movemask_epi8, _mm_packs_epi16};
    // SAFETY: SSE2 is part of every x86-64 target; `Lanes` is 16 bytes, all
    // of which the unaligned load reads. Packing saturates, so each byte
    // keeps its lane's sign; the low eight bits of the move are the lanes'.
    unsafe {
        let v = _mm_loadu_si128(lanes.as_ptr().cast());
        _mm_movemask_epi8(_mm_packs_epi16(v, v)) as u8
    }
}

/// The lanes that are negative, as a mask (bit `t` for lane `t`): with
/// Neon, which every AArch64 has, a compare of the lanes with 0, a narrow
/// to bytes, each byte's own bit kept and the bytes added across.
#[cfg(target_arch = "aarch64")]
#[inline(always)]
fn sign_mask(lanes: &Lanes) -> u8 {
    use core::arch::aarch64::{vaddv_u8, vand_u8, vcltzq_s16, vcreate_u8, vld1q_s16, vmovn_u16};
    // SAFETY: Neon is part of every AArch64 target; the load reads the 16
    // bytes of `Lanes`. The narrowed compare is 0xff or 0 a byte, so after
    // the mask byte t holds bit t alone, and the sum is their union.
    unsafe {
        let negative = vmovn_u16(vcltzq_s16(vld1q_s16(lanes.as_ptr())));
        vaddv_u8(vand_u8(negative, vcreate_u8(0x8040_2010_0804_0201)))
    }
}

/// The lanes that are negative, as a mask (bit `t` for lane `t`).
#[cfg(not(any(target_arch = "x86_64", target_arch = "aarch64")))]
#[inline(always)]
fn sign_mask(lanes: &Lanes) -> u8 {
    sign_bits(lanes)
}

/// [`sign_mask`] a lane at a time: what other targets use, and what the
/// tests hold the vector ones to.
#[cfg(any(test, not(any(target_arch = "x86_64", target_arch = "aarch64"))))]
#[inline(always)]
fn sign_bits(lanes: &Lanes) -> u8 {
    let mut cells = 0u8;
    for (t, &lane) in lanes.iter().enumerate() {
        cells |= u8::from(lane < 0) << t;
    }
    cells
}

/// The least of eight lanes, halving the width each step.
#[inline]
fn min_lane(lanes: &Lanes) -> i16 {
    let mut half = [0; MAX_CELLS / 2];
    for t in 0..MAX_CELLS / 2 {
        half[t] = lanes[t].min(lanes[t + MAX_CELLS / 2]);
    }
    half[0].min(half[2]).min(half[1].min(half[3]))
}

/// One optimal assignment, uniformly, from the placed prices.
///
/// A particle with one tight cell takes it in every optimal assignment, so
/// that cell is struck from the others' tight cells, until no particle left
/// has one. The rest fall apart into groups that share no tight cell, whose
/// choices are independent. Each group's ways are counted, the total is
/// their product, and one draw of a rank, read digit by digit in the
/// groups' counts, picks a way in every group.
fn pick(prices: &Prices, count: usize, draw: impl FnOnce(u32) -> u32) -> Assignment {
    let mut target = prices.at;
    let mut tight = [0u8; MAX_CELLS];
    // The particles with a choice, and the cells of those without.
    let (mut open, mut taken) = (0u8, 0u8);
    for (i, cells) in tight.iter_mut().enumerate().take(count) {
        *cells = prices.tight(i);
        let several = *cells & (*cells - 1) != 0;
        open |= u8::from(several) << i;
        taken |= *cells & u8::from(several).wrapping_sub(1);
    }
    if open == 0 {
        // One tight cell each: the assignment found is the only optimum.
        return Assignment { target };
    }
    loop {
        let mut settled = 0u8;
        for i in bits(open) {
            tight[i] &= !taken;
            if tight[i] & (tight[i] - 1) == 0 {
                taken |= tight[i];
                settled |= 1 << i;
            }
        }
        if settled == 0 {
            break;
        }
        open &= !settled;
    }
    let must = prices.must();
    let mut groups = [Group::default(); MAX_CELLS / 2];
    let mut found = 0;
    let mut total = 1u32;
    let mut table = Ways::new();
    while open != 0 {
        let (members, cells) = group_of(&tight, open);
        open &= !members;
        let group = &mut groups[found];
        group.fill(&tight, members);
        group.count(cells & must, &mut table);
        total *= group.ways;
        found += 1;
    }
    let mut rank = if total > 1 { draw(total) } else { 0 };
    for group in &groups[..found] {
        let digit = rank % group.ways;
        rank /= group.ways;
        let chosen = group.nth(digit, &table);
        for (&i, &cell) in group.members.iter().zip(&chosen).take(group.len) {
            target[usize::from(i)] = cell;
        }
    }
    Assignment { target }
}

/// What [`bits`] returns.
pub(crate) struct Bits(u8);

impl Iterator for Bits {
    type Item = usize;

    #[inline]
    fn next(&mut self) -> Option<usize> {
        if self.0 == 0 {
            return None;
        }
        let i = self.0.trailing_zeros() as usize;
        self.0 &= self.0 - 1;
        Some(i)
    }
}

/// The indices of the set bits of `set`, lowest first.
#[inline]
pub(crate) fn bits(set: u8) -> Bits {
    Bits(set)
}

/// The first particle of `open` and every particle of `open` linked to it
/// by shared tight cells, and the cells they share.
fn group_of(tight: &[u8; MAX_CELLS], open: u8) -> (u8, u8) {
    let first = open.trailing_zeros() as usize;
    let mut members = 1u8 << first;
    let mut cells = tight[first];
    loop {
        let mut joined = 0u8;
        for i in bits(open & !members) {
            if tight[i] & cells != 0 {
                joined |= 1 << i;
                cells |= tight[i];
            }
        }
        if joined == 0 {
            return (members, cells);
        }
        members |= joined;
    }
}

/// The most sets of cells the members of a group can end in: C(8, 4).
const MAX_ENDS: usize = 70;

/// Particles that share tight cells with each other and with no one else:
/// their ways are independent of every other group's.
#[derive(Clone, Copy)]
struct Group {
    members: [u8; MAX_CELLS],
    /// Each member's tight cells.
    choices: [u8; MAX_CELLS],
    len: usize,
    /// The sets of cells the members can end in that fill every cell of the
    /// group that must be filled, and how many ways there are in all.
    ends: [u8; MAX_ENDS],
    end_count: usize,
    ways: u32,
}

impl Default for Group {
    fn default() -> Group {
        Group { members: [0; MAX_CELLS], choices: [0; MAX_CELLS], len: 0, ends: [0; MAX_ENDS], end_count: 0, ways: 0 }
    }
}

/// For every set of cells `used`, the number of ways members `0..k` of its
/// group can take exactly those cells, `k` being the size of the set. Groups
/// share no cell, so one table serves them all; only the empty set is
/// common, and it is never read. At most 8! ways, so `u16` holds them.
struct Ways([u16; 1 << MAX_CELLS]);

impl Ways {
    fn new() -> Ways {
        Ways([0; 1 << MAX_CELLS])
    }
}

impl Group {
    /// Lists `members` with their choices, those with two first: the sets
    /// of cells the first members can take then stay few.
    fn fill(&mut self, tight: &[u8; MAX_CELLS], members: u8) {
        let mut pair = 0u8;
        for i in bits(members) {
            let rest = tight[i] & (tight[i] - 1);
            pair |= u8::from(rest & (rest - 1) == 0) << i;
        }
        for i in bits(pair).chain(bits(members & !pair)) {
            self.members[self.len] = i as u8;
            self.choices[self.len] = tight[i];
            self.len += 1;
        }
    }

    /// Fills `table` for this group a member at a time, from the sets the
    /// members before reach, then keeps the final sets that hold `must`.
    fn count(&mut self, must: u8, table: &mut Ways) {
        let (mut a, mut b) = ([0u8; MAX_ENDS], [0u8; MAX_ENDS]);
        let (mut sets, mut next) = (&mut a, &mut b);
        let mut len = 1;
        table.0[0] = 1;
        for &choices in &self.choices[..self.len] {
            let mut grown = 0;
            for &used in &sets[..len] {
                let ways = table.0[usize::from(used)];
                let mut open = choices & !used;
                while open != 0 {
                    let bigger = used | open & open.wrapping_neg();
                    open &= open - 1;
                    let slot = &mut table.0[usize::from(bigger)];
                    if *slot == 0 {
                        next[grown] = bigger;
                        grown += 1;
                    }
                    *slot += ways;
                }
            }
            core::mem::swap(&mut sets, &mut next);
            len = grown;
        }
        self.ways = 0;
        for &used in &sets[..len] {
            if must & !used == 0 {
                self.ends[self.end_count] = used;
                self.end_count += 1;
                self.ways += u32::from(table.0[usize::from(used)]);
            }
        }
    }

    /// The way of rank `rank` (below `ways`): the final set whose ways reach
    /// past the rank, then, last member first, the cell whose removal leaves
    /// a set with ways reaching past what is left of it.
    fn nth(&self, mut rank: u32, table: &Ways) -> [u8; MAX_CELLS] {
        let mut chosen = [0u8; MAX_CELLS];
        let mut used = 0u8;
        for &end in &self.ends[..self.end_count] {
            let ways = u32::from(table.0[usize::from(end)]);
            if rank < ways {
                used = end;
                break;
            }
            rank -= ways;
        }
        for k in (0..self.len).rev() {
            let mut open = self.choices[k] & used;
            while open != 0 {
                let cell = open & open.wrapping_neg();
                open &= open - 1;
                let before = used & !cell;
                let ways = if k == 0 { u32::from(before == 0) } else { u32::from(table.0[usize::from(before)]) };
                if rank < ways {
                    chosen[k] = cell.trailing_zeros() as u8;
                    used = before;
                    break;
                }
                rank -= ways;
            }
        }
        chosen
    }
}

// ------------------------------------------------------------ exact, 2D table

/// Cells of a 2D block.
const CELLS_2D: usize = 4;
/// Table keys: one base-6 digit per cell, see [`digit`].
pub(crate) const KEYS_2D: usize = 6 * 6 * 6 * 6;
/// The place value of each cell's digit in a key.
pub(crate) const PLACE_2D: [u16; CELLS_2D] = [1, 6, 36, 216];

/// A cell's digit in a 2D key: 0 free and empty, 1 not free (an obstacle or
/// a wall cell), `2 + m` a particle that wants the cell `c ^ m` (`m` the
/// axes it wants to cross, bit 0 for x, bit 1 for y).
#[inline]
pub(crate) const fn digit(free: bool, particle: Option<u8>) -> u16 {
    match particle {
        Some(m) => 2 + (m & 3) as u16,
        None if free => 0,
        None => 1,
    }
}

/// One optimal assignment of a 2D block, packed for the step: bits `2c`,
/// `2c + 1` the cell the particle now in cell `c` goes to (0 where `c`
/// holds none), bits 12-14 how many particles do not get their desired
/// cell; bits 8-11 and 15 are 0.
pub(crate) type Move2 = u16;

/// The key of a problem's block.
fn table_key(problem: &MoveProblem, free: u8, count: usize) -> usize {
    let mut wants = [None; CELLS_2D];
    for i in 0..count {
        let c = usize::from(problem.current[i] & 3);
        wants[c] = Some((problem.desired[i] ^ problem.current[i]) & 3);
    }
    let mut key = 0;
    for c in 0..CELLS_2D {
        key += usize::from(PLACE_2D[c] * digit(free & (1 << c) != 0, wants[c]));
    }
    key
}

/// The block a table key stands for, particles in increasing cell order.
const fn decode_key(key: usize) -> MoveProblem {
    let mut problem = MoveProblem { free: 0, count: 0, current: [0; MAX_CELLS], desired: [0; MAX_CELLS], speed2: [0.0; MAX_CELLS] };
    let mut cell = 0;
    while cell < CELLS_2D {
        let d = key / PLACE_2D[cell] as usize % 6;
        if d != 1 {
            problem.free |= 1 << cell;
        }
        if d >= 2 {
            problem.current[problem.count] = cell as u8;
            problem.desired[problem.count] = cell as u8 ^ (d - 2) as u8;
            problem.count += 1;
        }
        cell += 1;
    }
    problem
}

/// Whether [`TABLE_2D`] lists `key`: no particle of the block wants a
/// blocked cell (an obstacle or a wall), 944 of the 1296 keys. The step
/// never asks for another: M5.4 has turned such a wish into staying. Of
/// these it asks only for blocks with two particles or more, one of them
/// wanting to move (815 keys; `Kernel::assign` settles the others itself);
/// the other 129 serve a direct caller of [`assign_moves`] at a cost of 4
/// bytes, as their lists are almost all those of the 815.
const fn listed_2d(key: usize) -> bool {
    let block = decode_key(key);
    let mut i = 0;
    while i < block.count {
        if block.free >> block.desired[i] & 1 == 0 {
            return false;
        }
        i += 1;
    }
    true
}

/// Every optimal assignment of the block with key `key`, by the dynamic
/// programme over subsets, in the order of [`nth_optimal`]'s ranks (the
/// particles in cell order, each list ordered by the first particle's
/// target, then the second's, ...), and how many there are.
const fn optimal_list_2d(key: usize) -> ([Move2; MAX_TIES_2D], usize) {
    let block = decode_key(key);
    let costs = move_costs(&block, block.count);
    let done = completions(block.free, block.count, &costs);
    let ways = done.ways[0] as usize;
    assert!(ways >= 1 && ways <= MAX_TIES_2D);
    let mut list = [0; MAX_TIES_2D];
    let mut rank = 0;
    while rank < ways {
        let target = nth_optimal(block.free, block.count, &costs, &done, rank as u16);
        let (mut packed, mut displaced) = (0u16, 0u16);
        let mut i = 0;
        while i < block.count {
            packed |= (target[i] as u16) << (2 * block.current[i]);
            displaced += (target[i] != block.desired[i]) as u16;
            i += 1;
        }
        list[rank] = packed | displaced << 12;
        rank += 1;
    }
    (list, ways)
}

/// The most optimal assignments any 2D block has.
pub(crate) const MAX_TIES_2D: usize = 5;

/// Bits of a span holding the start of its list in [`Table2d::moves`];
/// the list's length (1 to [`MAX_TIES_2D`]) sits above them.
const START_BITS: u32 = 13;

/// The list number of a key [`TABLE_2D`] does not list.
const UNLISTED: u8 = u8::MAX;

/// Every particle stays: the move [`UNLISTED`] stands for (see
/// [`optimal_moves_2d`]).
const STAY_2D: Move2 = 0b11_10_01_00;

/// The optimal assignments of the keys without a wish for a blocked cell
/// ([`listed_2d`]), each distinct list stored once: key `k`'s list is
/// number `list[k]`, `moves[s..s + n]` with `s = span[list[k]] & (2^13 -
/// 1)`, `n = span[list[k]] >> 13`.
///
/// About a fifth of the 1296 keys' lists: 944 keys are listed, and many
/// share a list (the same targets and count of displaced particles: the
/// cells a key's particles want matter, not which of them are empty), so
/// 252 distinct lists remain. The longer lists are laid down first and
/// a list found inside those already laid down is not laid down again, so
/// most single moves take no room of their own. A list number is a byte,
/// and `span` has 256 entries, so reading it needs no bounds check.
struct Table2d<const MOVES: usize> {
    list: [u8; KEYS_2D],
    span: [u16; 256],
    moves: [Move2; MOVES],
}

/// The most moves [`Table2d::moves`] could need while it is built.
const MOVES_BOUND_2D: usize = KEYS_2D * MAX_TIES_2D;

/// [`TABLE_2D`] with room to spare, and how many moves it holds.
const BUILT_2D: (Table2d<MOVES_BOUND_2D>, usize) = {
    let mut lists = [[0; MAX_TIES_2D]; KEYS_2D];
    let mut lens = [0usize; KEYS_2D];
    let mut key = 0;
    while key < KEYS_2D {
        if listed_2d(key) {
            (lists[key], lens[key]) = optimal_list_2d(key);
        }
        key += 1;
    }
    let mut table = Table2d { list: [UNLISTED; KEYS_2D], span: [0; 256], moves: [0; MOVES_BOUND_2D] };
    let (mut spans, mut laid) = (0, 0);
    // Longest lists first, so that a shorter one may be found inside them.
    let mut len = MAX_TIES_2D;
    while len >= 1 {
        let mut key = 0;
        while key < KEYS_2D {
            if lens[key] == len {
                let list = &lists[key];
                // The same list already has a number?
                let mut n = 0;
                while n < spans && !same_moves(&table.moves, table.span[n], list, len) {
                    n += 1;
                }
                if n == spans {
                    let start = find_moves(&table.moves, laid, list, len);
                    if start == laid {
                        let mut i = 0;
                        while i < len {
                            table.moves[laid] = list[i];
                            laid += 1;
                            i += 1;
                        }
                    }
                    assert!(spans < UNLISTED as usize && start < 1 << START_BITS);
                    table.span[spans] = (start | len << START_BITS) as u16;
                    spans += 1;
                }
                table.list[key] = n as u8;
            }
            key += 1;
        }
        len -= 1;
    }
    // The numbers no key has (UNLISTED among them): everyone stays.
    let stay = find_moves(&table.moves, laid, &[STAY_2D; MAX_TIES_2D], 1);
    if stay == laid {
        table.moves[laid] = STAY_2D;
        laid += 1;
    }
    while spans < 256 {
        table.span[spans] = (stay | 1 << START_BITS) as u16;
        spans += 1;
    }
    (table, laid)
};

/// Where a span's list starts in [`Table2d::moves`], and its length.
const fn span_bounds(span: u16) -> (usize, usize) {
    ((span & ((1 << START_BITS) - 1)) as usize, (span >> START_BITS) as usize)
}

/// Whether `moves[start..]` begins with `list[..len]`.
const fn moves_at(moves: &[Move2], start: usize, list: &[Move2; MAX_TIES_2D], len: usize) -> bool {
    let mut i = 0;
    while i < len && moves[start + i] == list[i] {
        i += 1;
    }
    i == len
}

/// Whether the list of `span` in `moves` is `list[..len]`.
const fn same_moves(moves: &[Move2], span: u16, list: &[Move2; MAX_TIES_2D], len: usize) -> bool {
    let (start, n) = span_bounds(span);
    n == len && moves_at(moves, start, list, len)
}

/// Where `list[..len]` first occurs in `moves[..laid]`, or `laid`.
const fn find_moves(moves: &[Move2], laid: usize, list: &[Move2; MAX_TIES_2D], len: usize) -> usize {
    let mut start = 0;
    while start + len <= laid {
        if moves_at(moves, start, list, len) {
            return start;
        }
        start += 1;
    }
    laid
}

/// The moves [`TABLE_2D`] holds.
const MOVES_2D: usize = BUILT_2D.1;

/// The optimal assignments of the keys the step can ask for, and a few
/// more (see [`Table2d`]), built by the compiler.
static TABLE_2D: Table2d<MOVES_2D> = {
    let built = &BUILT_2D.0;
    let mut moves = [0; MOVES_2D];
    let mut i = 0;
    while i < MOVES_2D {
        moves[i] = built.moves[i];
        i += 1;
    }
    Table2d { list: built.list, span: built.span, moves }
};

/// The optimal assignments of the 2D block with key `key`, a key the table
/// lists ([`listed_2d`]; checked in debug builds), as every key the step
/// asks for is. For another key (`< KEYS_2D`) a release build gets the one
/// move "everyone stays".
#[inline]
pub(crate) fn optimal_moves_2d(key: usize) -> &'static [Move2] {
    let list = TABLE_2D.list[key];
    debug_assert!(list != UNLISTED, "the 2D table has no key {key}");
    listed_moves_2d(list)
}

/// The moves of list number `list` of [`TABLE_2D`].
#[inline]
fn listed_moves_2d(list: u8) -> &'static [Move2] {
    let (start, len) = span_bounds(TABLE_2D.span[usize::from(list)]);
    &TABLE_2D.moves[start..start + len]
}

/// One of `moves`, uniformly (a draw only where there is a choice).
#[inline]
pub(crate) fn pick_move(moves: &[Move2], rng: &mut Stream) -> Move2 {
    match moves.len() {
        1 => moves[0],
        n => moves[rng.below(n as u32) as usize],
    }
}

fn exact_table_2d(problem: &MoveProblem, free: u8, count: usize, rng: &mut Stream) -> Assignment {
    let key = table_key(problem, free, count);
    let packed = match TABLE_2D.list[key] {
        UNLISTED => unlisted_move_2d(key, rng),
        list => pick_move(listed_moves_2d(list), rng),
    };
    // The table speaks of the particle in each cell; the problem's particle
    // order is arbitrary, so each particle reads its target by its cell.
    let mut assignment = Assignment::default();
    for i in 0..count {
        assignment.target[i] = (packed >> (2 * (problem.current[i] & 3))) as u8 & 3;
    }
    assignment
}

/// One optimal move of a block with a wish for a blocked cell, which the
/// step never has (M5.4) and only a caller of [`assign_moves`] can pose:
/// from the list of the programme that builds the table, so the same draw
/// gives the move the table would.
#[cold]
fn unlisted_move_2d(key: usize, rng: &mut Stream) -> Move2 {
    let (list, ways) = optimal_list_2d(key);
    pick_move(&list[..ways], rng)
}

// --------------------------------------------------------------------- greedy

fn greedy(problem: &MoveProblem, free: u8, count: usize, rng: &mut Stream) -> Assignment {
    // Fastest first; a stable insertion sort keeps equal speeds in problem
    // order (and a NaN speed where it is).
    let mut order = [0usize; MAX_CELLS];
    for i in 0..count {
        let mut slot = i;
        while slot > 0 && problem.speed2[order[slot - 1]] < problem.speed2[i] {
            order[slot] = order[slot - 1];
            slot -= 1;
        }
        order[slot] = i;
    }
    let costs = move_costs(problem, count);
    let mut taken = 0u8;
    let mut assignment = Assignment::default();
    for &i in &order[..count] {
        let mut best = u8::MAX;
        let mut tied = [0u8; MAX_CELLS];
        let mut ties = 0;
        let mut open = free & !taken;
        while open != 0 {
            let cell = open.trailing_zeros() as u8;
            open &= open - 1;
            let c = costs[i][usize::from(cell)];
            if c < best {
                best = c;
                ties = 0;
            }
            if c == best {
                tied[ties] = cell;
                ties += 1;
            }
        }
        let pick = if ties > 1 { rng.below(ties as u32) as usize } else { 0 };
        let cell = tied[pick];
        assignment.target[i] = cell;
        taken |= 1 << cell;
    }
    assignment
}

#[cfg(test)]
mod tests {
    extern crate std;

    use std::vec::Vec;

    use super::*;
    use crate::rules::rng::block_stream;

    /// Every target free and inside the block, no two particles on one cell.
    fn valid(problem: &MoveProblem, assignment: &Assignment, cells: usize) -> bool {
        let mut used = 0u8;
        for &t in &assignment.target[..problem.count] {
            if usize::from(t) >= cells || problem.free & (1 << t) == 0 || used & (1 << t) != 0 {
                return false;
            }
            used |= 1 << t;
        }
        true
    }

    /// Every valid assignment, by brute force (sharing nothing with the
    /// methods but [`cost`]): the optimum and the optimal assignments.
    fn optimal_set(problem: &MoveProblem, cells: usize) -> ((u32, u32), Vec<Assignment>) {
        fn visit(
            problem: &MoveProblem,
            cells: usize,
            partial: &mut Assignment,
            i: usize,
            best: &mut ((u32, u32), Vec<Assignment>),
        ) {
            if i == problem.count {
                let c = cost(problem, partial);
                if c < best.0 {
                    *best = (c, Vec::new());
                }
                if c == best.0 {
                    best.1.push(*partial);
                }
                return;
            }
            for t in 0..cells as u8 {
                if problem.free & (1 << t) != 0 && !partial.target[..i].contains(&t) {
                    partial.target[i] = t;
                    visit(problem, cells, partial, i + 1, best);
                }
            }
            partial.target[i] = 0;
        }
        let mut best = ((u32::MAX, u32::MAX), Vec::new());
        visit(problem, cells, &mut Assignment::default(), 0, &mut best);
        best
    }

    /// `problem` with its particles listed in `order`.
    fn reorder(problem: &MoveProblem, order: &[usize]) -> MoveProblem {
        let mut out = *problem;
        for (slot, &i) in order.iter().enumerate() {
            out.current[slot] = problem.current[i];
            out.desired[slot] = problem.desired[i];
            out.speed2[slot] = problem.speed2[i];
        }
        out
    }

    /// Every ordering of `0..n`.
    fn permutations(n: usize) -> Vec<Vec<usize>> {
        (0..n.pow(n as u32))
            .map(|code| {
                (0..n)
                    .map(|k| code / n.pow(k as u32) % n)
                    .collect::<Vec<_>>()
            })
            .filter(|p| (0..n).all(|k| p.contains(&k)))
            .collect()
    }

    /// Runs all three methods on one block and checks them against each
    /// other; returns the exhaustive cost.
    fn check_block<const D: usize>(
        problem: &MoveProblem,
        rng: &mut crate::rules::rng::Stream,
    ) -> (u32, u32) {
        let cells = 1 << D;
        let exhaustive = assign_moves::<D>(Method::Exhaustive, problem, rng);
        let fast = assign_moves::<D>(Method::ExactFast, problem, rng);
        let greedy = assign_moves::<D>(Method::Greedy, problem, rng);
        for a in [&exhaustive, &fast, &greedy] {
            assert!(valid(problem, a, cells), "{problem:?} -> {a:?}");
        }
        let optimum = cost(problem, &exhaustive);
        assert_eq!(cost(problem, &fast), optimum, "{problem:?}");
        assert!(cost(problem, &greedy) >= optimum, "{problem:?}");
        optimum
    }

    #[test]
    fn every_2d_block_exact_fast_matches_exhaustive() {
        // Expect: for each of the 6^4 = 1296 block states (per cell: free,
        // blocked, or a particle wanting one of 4 cells) in every particle
        // order, all methods give valid assignments, exhaustive reaches the
        // brute-force optimum, exact-fast equals it, greedy is no better.
        let mut rng = block_stream(1, 0, 0);
        let mut states = 0;
        // Under Miri every 64th state.
        let stride = crate::sized(1, 64);
        for key in (0..KEYS_2D).step_by(stride) {
            let mut block = decode_key(key);
            states += 1;
            for i in 0..block.count {
                block.speed2[i] = rng.below(3) as f32; // ties included
            }
            let (best, _) = optimal_set(&block, 4);
            for order in permutations(block.count) {
                let problem = reorder(&block, &order);
                assert_eq!(check_block::<2>(&problem, &mut rng), best, "{problem:?}");
            }
        }
        assert_eq!(KEYS_2D, 1296);
        assert_eq!(states, KEYS_2D.div_ceil(stride));
    }

    #[test]
    fn optimal_lists_2d_hold_every_optimum_once_in_rank_order() {
        // Expect: for each of the 1296 keys, the list the table is built
        // from (and that exact-fast computes for a key the table does not
        // hold) is exactly the brute-force set of optimal assignments, each
        // once (so a uniform pick from it is a uniform tie-break), each with
        // its count of particles not in their desired cell, in the brute
        // force's order: by the first particle's cell, then the second's...
        // That order is the tie-break's (the draw's rank picks the entry),
        // so it is pinned here. The longest list is MAX_TIES_2D long: 5.
        // Under Miri every 16th key, whose longest list can only be shorter.
        let stride = crate::sized(1, 16);
        let mut most = 0;
        for key in (0..KEYS_2D).step_by(stride) {
            let block = decode_key(key);
            let (_, optimal) = optimal_set(&block, 4);
            let expected: Vec<u16> = optimal
                .iter()
                .map(|a| {
                    (0..block.count).fold(0, |p, i| {
                        let displaced = u16::from(a.target[i] != block.desired[i]) << 12;
                        (p | u16::from(a.target[i]) << (2 * block.current[i])) + displaced
                    })
                })
                .collect();
            let (list, ways) = optimal_list_2d(key);
            assert_eq!(list[..ways], expected[..], "key {key}");
            most = most.max(ways);
        }
        if stride == 1 {
            assert_eq!(most, MAX_TIES_2D);
        }
        assert!(most <= MAX_TIES_2D);
        assert_eq!(MAX_TIES_2D, 5);
    }

    #[test]
    fn compact_table_2d_holds_the_full_list_of_every_key_without_a_blocked_wish() {
        // Expect: for every key whose particles all want free cells, the
        // table's list is the full list, entry for entry in rank order (so
        // a draw picks the same move as from a table of all 1296 keys);
        // every key with a wish for a blocked cell has no list, its number
        // leads to "everyone stays", and exact-fast still gives it the full
        // list's move for every draw. 944 keys share 252 lists of 322
        // moves (the stay move among them): the table takes 1296 + 512 +
        // 644 = 2452 bytes of flash (5744 for all keys).
        let stride = crate::sized(1, 16);
        let mut listed = 0;
        for key in (0..KEYS_2D).step_by(stride) {
            let (list, ways) = optimal_list_2d(key);
            let block = decode_key(key);
            if block.desired[..block.count].iter().all(|&want| block.free >> want & 1 != 0) {
                assert_eq!(optimal_moves_2d(key), &list[..ways], "key {key}");
                listed += 1;
            } else {
                assert_eq!(TABLE_2D.list[key], UNLISTED, "key {key}");
                for rank in 0..ways {
                    let mut draw = block_stream(rank as u64, 0, 0);
                    let mut expected = draw.clone();
                    let picked = if ways > 1 { list[expected.below(ways as u32) as usize] } else { list[0] };
                    let moved = exact_table_2d(&block, block.free, block.count, &mut draw);
                    for i in 0..block.count {
                        assert_eq!(moved.target[i], (picked >> (2 * block.current[i])) as u8 & 3, "key {key}");
                    }
                }
            }
        }
        assert_eq!(listed_moves_2d(UNLISTED), [STAY_2D]);
        if stride == 1 {
            let lists = TABLE_2D.list.iter().filter(|&&n| n != UNLISTED).max().map_or(0, |&n| n + 1);
            assert_eq!((listed, lists, MOVES_2D), (944, 252, 322));
        }
        assert_eq!(core::mem::size_of_val(&TABLE_2D), 2452);
    }

    #[test]
    fn the_step_asks_the_table_only_for_keys_it_holds() {
        // Expect: every block the step can hand the table (Kernel::assign
        // in kernel.rs, whose key is the sum of the cells' digits) has a
        // list: a block with at least two particles (the step settles one
        // particle alone), on cells that are not blocked (no particle sits
        // on an obstacle or beyond a face), at least one of them wanting to
        // move (the step settles a block where nobody does), and none
        // wanting a blocked cell (M5.4 has made that wish staying): 815
        // blocks, each its own key.
        let mut keys = Vec::new();
        for blocked in 0..16u8 {
            for occ in (0..16u8).filter(|&o| o & blocked == 0 && o.count_ones() >= 2) {
                let cells: Vec<u8> = (0..4).filter(|&c| occ >> c & 1 != 0).collect();
                for wishes in 0..4usize.pow(cells.len() as u32) {
                    let want = |i: usize| (wishes >> (2 * i)) as u8 & 3;
                    let wants: Vec<u8> = (0..cells.len()).map(want).collect();
                    if wants.iter().all(|&m| m == 0) || cells.iter().zip(&wants).any(|(&c, &m)| blocked >> (c ^ m) & 1 != 0) {
                        continue;
                    }
                    let mut key = 0;
                    for c in 0..4u8 {
                        let particle = cells.iter().position(|&p| p == c).map(|i| wants[i]);
                        key += usize::from(PLACE_2D[usize::from(c)] * digit(blocked >> c & 1 == 0, particle));
                    }
                    assert_ne!(TABLE_2D.list[key], UNLISTED, "blocked {blocked:#06b} occupied {occ:#06b} wants {wants:?}");
                    keys.push(key);
                }
            }
        }
        keys.sort_unstable();
        keys.dedup();
        assert_eq!(keys.len(), 815);
    }

    /// A random 3D block: `count` particles on distinct cells, random wishes
    /// and speeds, each other cell blocked with probability 1/4.
    fn random_block_3d(rng: &mut crate::rules::rng::Stream, count: usize) -> MoveProblem {
        let mut cells = [0, 1, 2, 3, 4, 5, 6, 7];
        for i in (1..MAX_CELLS).rev() {
            cells.swap(i, rng.below(i as u32 + 1) as usize);
        }
        let mut problem = MoveProblem {
            count,
            ..MoveProblem::default()
        };
        for (i, &cell) in cells.iter().enumerate() {
            if i < count {
                problem.current[i] = cell;
                problem.desired[i] = rng.below(8) as u8;
                problem.speed2[i] = (rng.below(4) as f32) * 0.25;
                problem.free |= 1 << cell;
            } else if rng.below(4) != 0 {
                problem.free |= 1 << cell;
            }
        }
        problem
    }

    #[test]
    fn random_3d_blocks_exact_fast_matches_exhaustive() {
        // Expect: over 108,000 random 3D blocks, 12,000 of each particle
        // count 0..=8 (full blocks included), all methods give valid
        // assignments, exact-fast reaches the exhaustive cost and greedy
        // never beats it. On every 50th block the number of optimal
        // assignments the dynamic programme counts equals a brute-force
        // count.
        let mut rng = block_stream(2, 0, 0);
        // Under Miri 20 blocks of at most 4 particles, 7 counted.
        let (blocks, counts, every) = (crate::sized(108_000, 20), crate::sized(9, 5), crate::sized(50, 3));
        for n in 0..blocks {
            let problem = random_block_3d(&mut rng, n % counts);
            let optimum = check_block::<3>(&problem, &mut rng);
            if n % every == 0 {
                let (best, optimal) = optimal_set(&problem, 8);
                assert_eq!(best, optimum, "{problem:?}");
                let costs = move_costs(&problem, problem.count);
                let ways = completions(problem.free, problem.count, &costs).ways[0];
                assert_eq!(usize::from(ways), optimal.len(), "{problem:?}");
            }
        }
    }

    /// Checks that `problem` has `ties` optimal assignments, draws 3,000
    /// (24 under Miri)    /// times that many from `method`, and checks each optimal assignment's
    /// frequency against the binomial.
    fn check_uniform<const D: usize>(
        method: Method,
        problem: &MoveProblem,
        ties: usize,
        seed: u64,
    ) {
        let (_, optimal) = optimal_set(problem, 1 << D);
        assert_eq!(optimal.len(), ties, "{problem:?}");
        let draws = crate::sized(3_000, 24) * ties;
        let mut hits = std::vec![0u32; ties];
        let mut rng = block_stream(seed, 0, 0);
        for _ in 0..draws {
            let a = assign_moves::<D>(method, problem, &mut rng);
            let k = optimal
                .iter()
                .position(|o| o.target[..problem.count] == a.target[..problem.count]);
            hits[k.expect("drew a non-optimal assignment")] += 1;
        }
        // Each count is binomial(draws, 1/ties); 5 sd bands fail by chance
        // with probability ~6e-7 each.
        let p = 1.0 / ties as f64;
        let mean = draws as f64 * p;
        let sd = (draws as f64 * p * (1.0 - p)).sqrt();
        for &h in &hits {
            assert!(
                (f64::from(h) - mean).abs() < 5.0 * sd,
                "{method:?} {problem:?}: {hits:?}"
            );
        }
    }

    fn block(free: u8, current: &[u8], desired: &[u8]) -> MoveProblem {
        let mut problem = MoveProblem {
            free,
            count: current.len(),
            ..MoveProblem::default()
        };
        problem.current[..current.len()].copy_from_slice(current);
        problem.desired[..desired.len()].copy_from_slice(desired);
        problem
    }

    #[test]
    fn sign_mask_is_the_lanes_signs() {
        // Every pattern of signs, each lane's magnitude from a stream (0 is
        // not negative; -1 and i16::MIN are), against the lane-by-lane mask.
        let mut rng = block_stream(5, 0, 0);
        for pattern in 0..=255u8 {
            for _ in 0..8 {
                let lanes: Lanes = core::array::from_fn(|t| {
                    let size = (rng.bits(16) as i16) & i16::MAX;
                    if pattern >> t & 1 != 0 { -1 - size } else { size }
                });
                assert_eq!(sign_mask(&lanes), pattern, "{lanes:?}");
                assert_eq!(sign_bits(&lanes), pattern, "{lanes:?}");
            }
        }
    }

    #[test]
    fn ties_are_broken_uniformly() {
        // Expect: where several assignments are optimal, exact-fast and
        // exhaustive pick each with equal frequency, within 5 binomial sd.
        // 2D: cells 1 and 2 both want the empty cell 0 (2 optimal: one moves
        // in, the other stays), and the first block with the most ties (5).
        let pair_2d = block(0b1111, &[1, 2], &[0, 0]);
        let key = (0..KEYS_2D).find(|&k| optimal_list_2d(k).1 == MAX_TIES_2D).unwrap();
        let most_2d = decode_key(key);
        // 3D: cells 1, 2, 4 all want the empty cell 0 (3 optimal: one moves
        // in); cells 1, 2, 4 all want the far cell 7 (9 optimal: one moves
        // in, the others to distinct cells next to 7); cells 6, 0, 5, 3 all
        // want cell 7 (4 optimal: the far particle from 0 ends in 7, or in
        // the cell of a neighbour of 7 that moves into 7).
        let three_3d = block(0xff, &[1, 2, 4], &[0, 0, 0]);
        let mixed_3d = block(0xff, &[1, 2, 4], &[7, 7, 7]);
        let even_3d = block(0xff, &[6, 0, 5, 3], &[7, 7, 7, 7]);
        // Under Miri exact-fast only: exhaustive tries every permutation
        // per draw (the other tests still check it under Miri).
        for &method in [Method::ExactFast, Method::Exhaustive].iter().take(crate::sized(2, 1)) {
            check_uniform::<2>(method, &pair_2d, 2, 10);
            check_uniform::<2>(method, &most_2d, MAX_TIES_2D, 11);
            check_uniform::<3>(method, &three_3d, 3, 12);
            check_uniform::<3>(method, &mixed_3d, 9, 13);
            check_uniform::<3>(method, &even_3d, 4, 14);
        }
    }

    /// What exact-fast gives `problem` (3D) for every rank its draw could
    /// return, in rank order; one assignment where it does not draw.
    fn exact_fast_by_rank(problem: &MoveProblem) -> Vec<Assignment> {
        let (free, count) = (problem.free, problem.count);
        let mut ways = None;
        let first = exact_3d(problem, free, count, |n| {
            ways = Some(n);
            0
        });
        let Some(n) = ways else { return std::vec![first] };
        assert!(n > 1, "drew among {n} for {problem:?}");
        (0..n)
            .map(|rank| {
                exact_3d(problem, free, count, |m| {
                    assert_eq!(m, n, "{problem:?}");
                    rank
                })
            })
            .collect()
    }

    /// A random 3D block as the kernel builds them: each other cell blocked
    /// with probability 1/4, each particle wanting its own cell moved along
    /// each axis with probability 1/2, and where that cell is blocked,
    /// staying (M5.4).
    fn kernel_block_3d(rng: &mut crate::rules::rng::Stream, count: usize) -> MoveProblem {
        let mut problem = random_block_3d(rng, count);
        for i in 0..count {
            let want = problem.current[i] ^ rng.below(8) as u8;
            problem.desired[i] = if problem.free >> want & 1 != 0 { want } else { problem.current[i] };
        }
        problem
    }

    #[test]
    fn exact_fast_3d_numbers_every_optimum_once() {
        // Expect: over 7,200 random 3D blocks (400 of each particle count
        // 0..=8 with any wishes, blocked ones included, and as many with
        // the kernel's wishes), the ranks exact-fast's draw can return give
        // distinct valid assignments, each at the brute-force optimum, as
        // many as there are optimal assignments (so every optimum has
        // exactly one rank and a uniform rank is a uniform optimum); and it
        // draws only where there are several.
        let mut rng = block_stream(6, 0, 0);
        // Under Miri 10 blocks of at most 4 particles, 5 of each kind.
        let (blocks, counts) = (crate::sized(7_200, 10), crate::sized(9, 5));
        for n in 0..blocks {
            let count = n % counts;
            let problem =
                if n % (2 * counts) < counts { random_block_3d(&mut rng, count) } else { kernel_block_3d(&mut rng, count) };
            let (best, optimal) = optimal_set(&problem, 8);
            let mut ranked = exact_fast_by_rank(&problem);
            assert_eq!(ranked.len(), optimal.len(), "{problem:?}");
            for a in &ranked {
                assert!(valid(&problem, a, 8), "{problem:?} -> {a:?}");
                assert_eq!(cost(&problem, a), best, "{problem:?} -> {a:?}");
            }
            ranked.sort_unstable_by_key(|a| a.target);
            ranked.dedup();
            assert_eq!(ranked.len(), optimal.len(), "a rank repeats for {problem:?}");
        }
    }

    #[test]
    fn exact_fast_3d_draws_once_where_there_is_a_choice() {
        // Expect: on random 3D blocks exact-fast takes from the stream
        // exactly what one draw below the number of optimal assignments
        // takes where there are several, and nothing where there is one, so
        // the same seed gives the same world.
        let mut rng = block_stream(7, 0, 0);
        // Under Miri 10 blocks of at most 4 particles.
        let (blocks, counts) = (crate::sized(2_700, 10), crate::sized(9, 5));
        for n in 0..blocks {
            let problem = kernel_block_3d(&mut rng, n % counts);
            let ways = optimal_set(&problem, 8).1.len() as u32;
            let (mut used, mut expected) = (rng.clone(), rng.clone());
            assign_moves::<3>(Method::ExactFast, &problem, &mut used);
            if ways > 1 {
                expected.below(ways);
            }
            for _ in 0..4 {
                assert_eq!(used.bits(16), expected.bits(16), "{problem:?}");
            }
            rng.next_u64();
        }
    }

    #[test]
    fn exact_fast_3d_ties_are_broken_uniformly() {
        // Expect: exact-fast picks each optimal assignment with equal
        // frequency, within 5 binomial sd, on blocks where it takes each of
        // its routes to a choice: two particles after one cell beside an
        // obstacle (4 optima: who takes it, and where the other goes), a
        // wish for a blocked cell (4), a half-full block (9), two thirds
        // full (8), and a full block (12).
        let pair = block(0b1011_1111, &[3, 0], &[5, 5]);
        let blocked = block(0b1111_1101, &[4, 5, 3, 2, 7], &[4, 2, 7, 1, 4]);
        let half = block(0xff, &[7, 2, 6, 0, 5], &[5, 6, 3, 3, 6]);
        let six = block(0xff, &[5, 2, 0, 6, 4, 3], &[1, 5, 0, 3, 3, 1]);
        let full = block(0xff, &[2, 5, 4, 6, 7, 0, 1, 3], &[0, 2, 3, 3, 2, 7, 0, 1]);
        // Under Miri the first two blocks (2 and 5 particles): the brute
        // force that counts the optima tries 8^count assignments.
        let cases = [(20, &pair, 4), (21, &blocked, 4), (22, &half, 9), (23, &six, 8), (24, &full, 12)];
        for &(seed, problem, ties) in cases.iter().take(crate::sized(5, 2)) {
            check_uniform::<3>(Method::ExactFast, problem, ties, seed);
        }
    }

    #[test]
    fn particle_that_gains_nothing_stays() {
        // Expect (cost2 rule, M5.6): a lone particle wanting its own cell
        // stays, with every method, 2D and 3D. Two neighbours that both want
        // cell 1 of a 2D block gain nothing by swapping or moving on (cost1
        // is 1 either way), so both stay with the exact methods; greedy is
        // not held to it (particle 0 takes cell 1 first and pushes the other
        // out, the approximation error M5.6 reports).
        let mut rng = block_stream(3, 0, 0);
        for method in [Method::Exhaustive, Method::ExactFast, Method::Greedy] {
            for cell in 0..4 {
                let lone = block(0b1111, &[cell], &[cell]);
                assert_eq!(
                    assign_moves::<2>(method, &lone, &mut rng).target[0],
                    cell
                );
            }
            for cell in 0..8 {
                let lone = block(0xff, &[cell], &[cell]);
                assert_eq!(
                    assign_moves::<3>(method, &lone, &mut rng).target[0],
                    cell
                );
            }
        }
        let pair = block(0b1111, &[0, 1], &[1, 1]);
        for method in [Method::Exhaustive, Method::ExactFast] {
            assert_eq!(
                assign_moves::<2>(method, &pair, &mut rng).target[..2],
                [0, 1]
            );
        }
    }

    #[test]
    fn greedy_serves_the_fastest_first() {
        // Expect: two particles want the empty cell 0 of a 3D block; greedy
        // gives it to the faster one whichever is listed first, and the
        // slower one stays.
        let mut rng = block_stream(4, 0, 0);
        for fast in 0..2 {
            let mut problem = block(0xff, &[1, 2], &[0, 0]);
            problem.speed2[fast] = 0.5;
            problem.speed2[1 - fast] = 0.25;
            let a = assign_moves::<3>(Method::Greedy, &problem, &mut rng);
            assert_eq!(a.target[fast], 0);
            assert_eq!(a.target[1 - fast], problem.current[1 - fast]);
        }
    }
}
