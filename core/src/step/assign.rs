//! The assignment stage (M5.6): where each particle of the block goes,
//! by the method the description chooses; in 2D exact-fast by one look-up
//! in the table of every block state's optimal assignments.

use crate::rules::assign::{assign_moves, optimal_moves_2d, pick_move, Method, MoveProblem, PLACE_2D};
use crate::rules::rng::Stream;
use crate::step::block::cells_of;
use crate::step::block::Kernel;

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

/// The part of the 2D table key (M5.6) that `x` gives, `width` bits a
/// cell: each cell's field times the cell's place value, summed.
const fn key_part(x: usize, width: u32) -> u16 {
    let mut part = 0;
    let mut c = 0;
    while c < 4 {
        part += PLACE_2D[c] * ((x >> (width as usize * c)) & ((1 << width) - 1)) as u16;
        c += 1;
    }
    part
}

/// Per 2D blocked mask, the part of the table key its cells contribute
/// (digit 1 each, M5.6); twice it for an occupancy mask (digit 2 + m).
pub(crate) const BLOCKED_KEY_2D: [u16; 16] = {
    let mut t = [0; 16];
    let mut mask = 0;
    while mask < 16 {
        t[mask] = key_part(mask, 1);
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
        t[w] = key_part(w, 2);
        w += 1;
    }
    t
};

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
    want: u32,
    speed2: impl Fn(usize) -> u32,
    rng: &mut Stream,
    displaced: &mut u64,
) -> u32 {
    let mut problem = MoveProblem { free, count: occ.count_ones() as usize, ..MoveProblem::default() };
    for (i, c) in cells_of(occ).enumerate() {
        problem.current[i] = c as u8;
        problem.desired[i] = c as u8 ^ (want >> (D * c)) as u8 & ((1 << D) - 1);
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
fn solve_block_2d(method: Method, cells: (u8, u8), want: u8, speeds: &[u32; 4], rng: &mut Stream, displaced: &mut u64) -> u32 {
    solve_block::<2, 4>(method, cells, u32::from(want), |c| speeds[c], rng, displaced)
}

impl<const D: usize, const CELLS: usize> Kernel<'_, D, CELLS> {
    /// M5.6: where each particle goes, `targets >> 4c & 7` for the particle
    /// in cell `c`, counting those not placed in their desired cell. `want`
    /// holds the axes each wants to cross, `D` bits a cell (a desired cell
    /// is never blocked: M5.4 has turned such a wish into staying);
    /// `speed2` gives a cell's squared speed (for greedy).
    #[inline(always)]
    pub(crate) fn assign(&mut self, occ: u8, speed2: impl Fn(usize) -> u32, blocked: u8, want: u32, rng: &mut Stream) -> u32 {
        let axes = (1u32 << D) - 1;
        // Where nobody wants to move, or the block holds one particle, the
        // optimum is unique (everyone stays; the particle takes the free cell
        // it wants) and no method draws for it: take it directly.
        if want == 0 {
            return IDENTITY;
        }
        if occ & (occ - 1) == 0 {
            let c = occ.trailing_zeros() as usize;
            return IDENTITY ^ (want >> (D * c) & axes) << (4 * c);
        }
        let method = self.shared.rules.assignment();
        if D == 2 && method == Method::ExactFast {
            // The key's digits: 1 for a blocked cell, 2 + m for a particle
            // that wants to cross the axes m, 0 for a free cell.
            let key = BLOCKED_KEY_2D[usize::from(blocked & 15)] + 2 * BLOCKED_KEY_2D[usize::from(occ & 15)] + KEY_2D_WANTS[want as usize & 0xff];
            let packed = pick_move(optimal_moves_2d(usize::from(key)), rng);
            self.counters.displaced += u64::from(packed >> 12);
            // 2 bits a cell in the table; 4 here, as in 3D.
            return SPREAD_2D[usize::from(packed as u8)];
        }
        let cells = (occ, !blocked & Self::EVERY_CELL);
        let displaced = &mut self.counters.displaced;
        // In 2D, a method other than exact-fast is a description's choice
        // that no scene of the paper makes: one copy, out of line, serves
        // every 2D instantiation. In 3D every assignment comes here.
        if D == 2 {
            let mut speeds = [0u32; 4];
            if method == Method::Greedy {
                for c in cells_of(occ) {
                    speeds[c] = speed2(c);
                }
            }
            return solve_block_2d(method, cells, want as u8, &speeds, rng, displaced);
        }
        solve_block::<D, CELLS>(method, cells, want, speed2, rng, displaced)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rules::assign::digit;

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
