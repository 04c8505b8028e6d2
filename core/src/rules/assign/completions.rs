//! The dynamic programme over the subsets of a block's cells (M5.6): the
//! least cost of every partial assignment's completion and how many
//! completions reach it, and the optimal assignment of a given rank. The
//! compiler builds the 2D table of exact-fast with it.

use super::{MoveCosts, MAX_CELLS};

/// For every set of used cells reachable by placing particles `0..k` in
/// order (`k` its popcount): the least combined cost of placing the rest,
/// and how many placements of the rest reach it. An optimal assignment of
/// a full 3D block has at most 8! = 40320 completions, so `u16` holds them.
/// The compiler builds the 2D table with it; the tests count 3D optima
/// with it.
pub(super) struct Completions {
    pub(super) cost: [u16; 1 << MAX_CELLS],
    pub(super) ways: [u16; 1 << MAX_CELLS],
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
pub(super) const fn completions(free: u8, count: usize, costs: &MoveCosts) -> Completions {
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
pub(super) const fn nth_optimal(
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
