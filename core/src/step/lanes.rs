//! The plain block of a 2D world of 8-bit velocities (the aggregation's
//! and the cluster's, most of a 2D gas): the block's stored velocities as
//! one 64-bit word of byte lanes, lane `2c + k` holding cell `c`'s
//! component `k`, so that M5.3's first test is a handful of word
//! operations for the whole block. It makes the draws of
//! [`Kernel::general`] in the same order, so it gives the same world bit
//! for bit, and the tests hold it to that.

use crate::rules::collision::pick_pair;
use crate::rules::quant::Quant;
use crate::rules::rng::Stream;
use crate::step::block::{cells_of, each_cell};
use crate::step::clamp::clamp_counted;
use crate::step::kernel::{per_cell, pushed_small, stored_speed2, Kernel, BLOCKED_KEY_2D, FIELDS, IDENTITY, KEY_2D_WANTS};
use crate::step::partition::BlockRow;
use crate::storage::layout::mark;

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

/// Cell `c`'s velocity from a 2D block's byte lanes, in fine units of
/// `2^-fine` quanta (M1c).
#[inline(always)]
fn lane_fine(lanes: u64, c: usize, fine: u32) -> [i32; 3] {
    let [x, y] = lane_ints(lanes, c);
    [i32::from(x) << fine, i32::from(y) << fine, 0]
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

impl<Q: Quant, const D: usize, const CELLS: usize> Kernel<'_, Q, D, CELLS> {
    /// M5.1 (a uniform force) and M5.2 (on `pair`, when both its cells hold
    /// a particle) on a block of byte lanes ([`Kernel::lean_2d`]), then M1:
    /// the lanes after rounding, and the cells whose velocity changed. Out
    /// of line: most blocks of most steps need neither.
    #[inline(never)]
    pub(crate) fn change_lanes(&mut self, mut lanes: u64, occ: u8, pair: Option<(usize, usize)>, rng: &mut Stream) -> (u64, u8) {
        let class = &self.shared.one;
        // Cell c's lanes replaced by the rounding of x (M1).
        let round_into = |lanes: u64, c: usize, x: [i32; 3], rng: &mut Stream| {
            with_lane_ints(lanes, c, Q::round::<2>(x, rng).map(|q| Q::from_int(q).to_int()))
        };
        if self.shared.lean_push.is_none() {
            // The collision alone: its two results rounded in cell order
            // (a < c in every pair), as the loop below would.
            let Some((a, c)) = pair else { return (lanes, 0) };
            debug_assert!(a < c);
            let Some((xa, xc)) = self.collide_two(lane_fine(lanes, a, Q::FINE), lane_fine(lanes, c, Q::FINE), (*class, *class), true, rng) else {
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
        let mut x = [[0i32; 3]; CELLS];
        let mut pending = 0u8;
        if let Some(dv) = self.shared.lean_push {
            for c in cells_of(occ) {
                let mut y = pushed_small(lane_fine(lanes, c, Q::FINE), dv);
                clamp_counted::<D>(&mut y, Q::UNIT, class, &mut self.counters);
                x[c] = y;
            }
            pending = occ;
        }
        if let Some((a, c)) = pair {
            let get = |c: usize| if pending >> c & 1 != 0 { x[c] } else { lane_fine(lanes, c, Q::FINE) };
            if let Some(pair) = self.collide_two(get(a), get(c), (*class, *class), true, rng) {
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
    pub(crate) fn lean_2d(&mut self, row: &BlockRow, x0: usize, index: u64, occ: u8) {
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
        if sh.lean_push.is_some() || pair.is_some() {
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
    pub(crate) fn write_rows(&mut self, row: &BlockRow, x0: usize, lanes: u64, pending: u8) {
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
    pub(crate) fn finish_2d(&mut self, row: &BlockRow, x0: usize, occ: u8, lanes: u64, want: u8, pending: u8, rng: &mut Stream) {
        let sh = self.shared;
        let velocity = self.planes.velocity;
        // M5.6.
        let wants = [want & 3, want >> 2 & 3, want >> 4 & 3, want >> 6];
        let mut per_cell = [0u8; CELLS];
        per_cell[..4].copy_from_slice(&wants);
        let key = 2 * usize::from(BLOCKED_KEY_2D[usize::from(occ)]) + usize::from(KEY_2D_WANTS[usize::from(want)]);
        let targets = self.assign(occ, |c| { let [x, y] = lane_ints(lanes, c); stored_speed2([i32::from(x), i32::from(y)]) }, 0, &per_cell, key, rng);
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
}

#[cfg(test)]
mod tests {
    use super::*;
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
}
