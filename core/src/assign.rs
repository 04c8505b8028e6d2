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
//!   assignments. In 2D a table built at compile time holds, for each of the
//!   1296 block states, every optimal assignment; in 3D a dynamic programme
//!   over subsets of the 8 cells counts the optimal completions of every
//!   partial assignment and one draw picks among them.
//! - [`Method::Greedy`], the paper's 3D approximation: the particles, fastest
//!   first, each take their best untaken cell.

use crate::rng::Stream;

/// How particles are assigned to the cells of their block (M5.6).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Method {
    /// Every permutation, the paper's method and the reference: 4! leaves in
    /// 2D, 8! = 40320 for a full 3D block.
    Exhaustive = 0,
    /// The exhaustive optimum at a small fraction of its cost: a compile-time
    /// table in 2D, dynamic programming over cell subsets in 3D.
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
pub fn assign_moves<const D: usize>(method: Method, problem: &MoveProblem, rng: &mut Stream) -> Assignment {
    const { assert!(D == 2 || D == 3, "a Margolus block has 2 or 3 axes") };
    let cells = 1usize << D;
    let free = problem.free & block_mask(cells);
    let count = problem.count.min(MAX_CELLS);
    debug_assert!(well_formed(problem, cells), "malformed block: {problem:?}");
    if count > free.count_ones() as usize {
        let mut stay = Assignment::default();
        stay.target[..count].copy_from_slice(&problem.current[..count]);
        return stay;
    }
    match method {
        Method::Exhaustive => exhaustive(problem, free, count, rng),
        Method::ExactFast if D == 2 => exact_table_2d(problem, free, count, rng),
        Method::ExactFast => exact_subsets(problem, free, count, rng),
        Method::Greedy => greedy(problem, free, count, rng),
    }
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

/// The dynamic programme of [`Method::ExactFast`] (M5.6), over the subsets of
/// `free` with at most `count` cells. `count` must not exceed the number of
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

fn exact_subsets(problem: &MoveProblem, free: u8, count: usize, rng: &mut Stream) -> Assignment {
    let costs = move_costs(problem, count);
    let done = completions(free, count, &costs);
    let total = done.ways[0];
    let rank = if total > 1 { rng.below(u32::from(total)) as u16 } else { 0 };
    Assignment {
        target: nth_optimal(free, count, &costs, &done, rank),
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
/// holds none), bits 8-11 the cells occupied afterwards, bits 12-14 how
/// many particles do not get their desired cell.
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

/// The optimal assignments of a key, and how many there are.
const fn optima(key: usize) -> (MoveProblem, MoveCosts, Completions) {
    let block = decode_key(key);
    let costs = move_costs(&block, block.count);
    let done = completions(block.free, block.count, &costs);
    (block, costs, done)
}

/// Every optimal assignment of every key, listed one after the other.
const MOVES_TOTAL_2D: usize = {
    let mut total = 0;
    let mut key = 0;
    while key < KEYS_2D {
        total += optima(key).2.ways[0] as usize;
        key += 1;
    }
    total
};

/// Bits of an index entry holding the start of its list; the count of
/// optimal assignments (1 to 5) sits above them.
const START_BITS: u32 = 13;
const _: () = assert!(MOVES_TOTAL_2D < 1 << START_BITS);

/// `(index, moves)`: key `k`'s optimal assignments are `moves[s..s + n]`
/// with `s = index[k] & (2^13 - 1)`, `n = index[k] >> 13`. Built by the
/// compiler with the same dynamic programme as 3D; every key has at least
/// one optimal assignment and at most [`MAX_TIES_2D`].
static TABLE_2D: ([u16; KEYS_2D], [Move2; MOVES_TOTAL_2D]) = {
    let mut index = [0u16; KEYS_2D];
    let mut moves = [0u16; MOVES_TOTAL_2D];
    let mut at = 0;
    let mut key = 0;
    while key < KEYS_2D {
        let (block, costs, done) = optima(key);
        let ways = done.ways[0] as usize;
        assert!(ways >= 1 && ways <= MAX_TIES_2D);
        index[key] = (at | ways << START_BITS) as u16;
        let mut rank = 0;
        while rank < ways {
            let target = nth_optimal(block.free, block.count, &costs, &done, rank as u16);
            let (mut packed, mut after, mut displaced) = (0u16, 0u16, 0u16);
            let mut i = 0;
            while i < block.count {
                packed |= (target[i] as u16) << (2 * block.current[i]);
                after |= 1 << target[i];
                displaced += (target[i] != block.desired[i]) as u16;
                i += 1;
            }
            moves[at] = packed | after << 8 | displaced << 12;
            at += 1;
            rank += 1;
        }
        key += 1;
    }
    (index, moves)
};

/// The most optimal assignments any 2D block has.
pub(crate) const MAX_TIES_2D: usize = 5;

/// The optimal assignments of the 2D block with key `key` (`< KEYS_2D`).
#[inline]
pub(crate) fn optimal_moves_2d(key: usize) -> &'static [Move2] {
    let entry = usize::from(TABLE_2D.0[key]);
    let start = entry & ((1 << START_BITS) - 1);
    &TABLE_2D.1[start..start + (entry >> START_BITS)]
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
    let packed = pick_move(optimal_moves_2d(table_key(problem, free, count)), rng);
    // The table speaks of the particle in each cell; the problem's particle
    // order is arbitrary, so each particle reads its target by its cell.
    let mut assignment = Assignment::default();
    for i in 0..count {
        assignment.target[i] = (packed >> (2 * (problem.current[i] & 3))) as u8 & 3;
    }
    assignment
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
    use crate::rng::block_stream;

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
        rng: &mut crate::rng::Stream,
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
        for key in 0..KEYS_2D {
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
        assert_eq!(states, 1296);
    }

    #[test]
    fn table_2d_lists_every_optimal_assignment_once() {
        // Expect: each key's list holds exactly the brute-force set of
        // optimal assignments, each once (so a uniform pick from it is a
        // uniform tie-break), each with the cells occupied after it and its
        // count of particles not in their desired cell; and the longest list
        // is MAX_TIES_2D long: 5, as an independent brute force over the
        // 1296 states also finds.
        let mut most = 0;
        for key in 0..KEYS_2D {
            let block = decode_key(key);
            let (_, optimal) = optimal_set(&block, 4);
            let mut expected: Vec<u16> = optimal
                .iter()
                .map(|a| {
                    (0..block.count).fold(0, |p, i| {
                        let displaced = u16::from(a.target[i] != block.desired[i]) << 12;
                        (p | u16::from(a.target[i]) << (2 * block.current[i]) | 1 << (8 + a.target[i])) + displaced
                    })
                })
                .collect();
            let mut listed = optimal_moves_2d(key).to_vec();
            expected.sort_unstable();
            listed.sort_unstable();
            assert_eq!(listed, expected, "key {key:#o}");
            most = most.max(listed.len());
        }
        assert_eq!(most, MAX_TIES_2D);
        assert_eq!(MAX_TIES_2D, 5);
    }

    /// A random 3D block: `count` particles on distinct cells, random wishes
    /// and speeds, each other cell blocked with probability 1/4.
    fn random_block_3d(rng: &mut crate::rng::Stream, count: usize) -> MoveProblem {
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
        for n in 0..108_000 {
            let problem = random_block_3d(&mut rng, n % 9);
            let optimum = check_block::<3>(&problem, &mut rng);
            if n % 50 == 0 {
                let (best, optimal) = optimal_set(&problem, 8);
                assert_eq!(best, optimum, "{problem:?}");
                let costs = move_costs(&problem, problem.count);
                let ways = completions(problem.free, problem.count, &costs).ways[0];
                assert_eq!(usize::from(ways), optimal.len(), "{problem:?}");
            }
        }
    }

    /// Checks that `problem` has `ties` optimal assignments, draws 3,000
    /// times that many from `method`, and checks each optimal assignment's
    /// frequency against the binomial.
    fn check_uniform<const D: usize>(
        method: Method,
        problem: &MoveProblem,
        ties: usize,
        seed: u64,
    ) {
        let (_, optimal) = optimal_set(problem, 1 << D);
        assert_eq!(optimal.len(), ties, "{problem:?}");
        let draws = 3_000 * ties;
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
    fn ties_are_broken_uniformly() {
        // Expect: where several assignments are optimal, exact-fast and
        // exhaustive pick each with equal frequency, within 5 binomial sd.
        // 2D: cells 1 and 2 both want the empty cell 0 (2 optimal: one moves
        // in, the other stays), and the first block with the most ties (5).
        let pair_2d = block(0b1111, &[1, 2], &[0, 0]);
        let key = (0..KEYS_2D).find(|&k| optimal_moves_2d(k).len() == MAX_TIES_2D).unwrap();
        let most_2d = decode_key(key);
        // 3D: cells 1, 2, 4 all want the empty cell 0 (3 optimal: one moves
        // in); cells 1, 2, 4 all want the far cell 7 (9 optimal: one moves
        // in, the others to distinct cells next to 7); cells 6, 0, 5, 3 all
        // want cell 7 (4 optimal: the far particle from 0 ends in 7, or in
        // the cell of a neighbour of 7 that moves into 7).
        let three_3d = block(0xff, &[1, 2, 4], &[0, 0, 0]);
        let mixed_3d = block(0xff, &[1, 2, 4], &[7, 7, 7]);
        let even_3d = block(0xff, &[6, 0, 5, 3], &[7, 7, 7, 7]);
        for method in [Method::ExactFast, Method::Exhaustive] {
            check_uniform::<2>(method, &pair_2d, 2, 10);
            check_uniform::<2>(method, &most_2d, MAX_TIES_2D, 11);
            check_uniform::<3>(method, &three_3d, 3, 12);
            check_uniform::<3>(method, &mixed_3d, 9, 13);
            check_uniform::<3>(method, &even_3d, 4, 14);
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
