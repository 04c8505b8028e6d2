//! The Hungarian method (shortest augmenting paths) of 3D exact-fast
//! (M5.6): one optimal assignment and prices on the cells that mark every
//! (particle, cell) pair an optimal assignment may use.

use super::{dist, MoveProblem, MAX_CELLS, PRIMARY};

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
pub(super) const NONE: u8 = u8::MAX;

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
pub(super) struct Prices {
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
    pub(super) at: [u8; MAX_CELLS],
    /// The particle in each cell, or NONE.
    owner: [u8; MAX_CELLS],
}

impl Prices {
    /// Each particle that wants a free cell nobody before it in the list
    /// wants takes it: with no lift that cell is its cheapest (cost1 0).
    /// Everyone else waits for [`Prices::augment`].
    pub(super) fn start(problem: &MoveProblem, free: u8, count: usize) -> Prices {
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
    pub(super) fn augment(&mut self, s: usize) {
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
    pub(super) fn tight(&self, i: usize) -> u8 {
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
    pub(super) fn must(&self) -> u8 {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rules::rng::block_stream;

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

}
