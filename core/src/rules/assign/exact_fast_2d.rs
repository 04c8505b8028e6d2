//! [`Method::ExactFast`](super::Method::ExactFast) in 2D (M5.6): a table,
//! built at compile time by the dynamic programme over subsets, of every
//! optimal assignment of each block state; the step draws one entry.

use super::completions::{completions, nth_optimal};
use super::{move_costs, Assignment, MoveProblem, MAX_CELLS};
use crate::rules::rng::Stream;

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
pub(super) const fn decode_key(key: usize) -> MoveProblem {
    let mut problem = MoveProblem { free: 0, count: 0, current: [0; MAX_CELLS], desired: [0; MAX_CELLS], speed2: [0; MAX_CELLS] };
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
/// the other 129 serve a direct caller of [`assign_moves`] at little cost,
/// as their lists are almost all those of the 815.
///
/// [`assign_moves`]: super::assign_moves
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
pub(super) const fn optimal_list_2d(key: usize) -> ([Move2; MAX_TIES_2D], usize) {
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

/// The moves [`TABLE_2D`] lists for `key`, `None` where it lists none
/// (a state the step never poses), for a second implementation of the
/// step (`port`).
pub(crate) fn moves_of_key_2d(key: usize) -> Option<&'static [Move2]> {
    match TABLE_2D.list.get(key) {
        None | Some(&UNLISTED) => None,
        Some(&list) => Some(listed_moves_2d(list)),
    }
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

pub(super) fn exact_table_2d(problem: &MoveProblem, free: u8, count: usize, rng: &mut Stream) -> Assignment {
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
///
/// [`assign_moves`]: super::assign_moves
#[cold]
fn unlisted_move_2d(key: usize, rng: &mut Stream) -> Move2 {
    let (list, ways) = optimal_list_2d(key);
    pick_move(&list[..ways], rng)
}

#[cfg(test)]
mod tests {
    extern crate std;

    use std::vec::Vec;

    use super::*;
    use crate::rules::assign::tests::optimal_set;
    use crate::rules::rng::block_stream;

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
        // moves (the stay move among them), and the table's size is pinned.
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

}
