//! [`Method::ExactFast`](super::Method::ExactFast) in 3D (M5.6): the common
//! blocks settled directly, the others by the Hungarian method
//! ([`super::hungarian`]) and a count of the optimal assignments its prices
//! allow, one draw picking among them.

use super::hungarian::{Prices, NONE};
use super::{bits, dist, Assignment, MoveProblem, MAX_CELLS, PRIMARY};

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
///
/// [`Method::ExactFast`]: super::Method::ExactFast
pub(super) fn exact_3d(problem: &MoveProblem, free: u8, count: usize, draw: impl FnOnce(u32) -> u32) -> Assignment {
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

#[cfg(test)]
mod tests {
    extern crate std;

    use std::vec::Vec;

    use super::*;
    use crate::rules::assign::tests::{block, check_uniform, optimal_set, random_block_3d, valid};
    use crate::rules::assign::{assign_moves, cost, Method};
    use crate::rules::rng::block_stream;

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

}
