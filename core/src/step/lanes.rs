//! The plain block of a 2D world of 8-bit velocities (the aggregation's
//! and the cluster's, most of a 2D gas) as a representation of the
//! pipeline ([`Stored`]): the block's stored velocities as one 64-bit word
//! of byte lanes, lane `2c + k` holding cell `c`'s component `k`, so that
//! M5.3's first test is a handful of word operations for the whole block.

use crate::rules::quant::Quant;
use crate::step::assign::per_cell;
use crate::step::block::Stored;
use crate::step::partition::BlockRow;
use crate::storage::cells::Cells;

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

/// A plain 2D block of an 8-bit world as the pipeline holds it: its
/// stored velocities as one word of byte lanes, lane `2c + k` holding cell
/// `c`'s component `k`, read and written a block row (two cells, one
/// 32-bit word) at a time.
pub(crate) struct Lanes {
    lanes: u64,
    /// The occupied cells in the low byte, those whose velocity changed
    /// (`dirty`) in the high: two fields in all, so that the block goes
    /// to and from a call in two registers.
    cells: u16,
}

// Generic in `D` for the pipeline's sake; only 2D blocks are lanes.
impl<const D: usize> Stored<D> for Lanes {
    #[inline(always)]
    fn occ(&self) -> u8 {
        self.cells as u8
    }

    #[inline(always)]
    fn dirty(&self) -> u8 {
        (self.cells >> 8) as u8
    }

    #[inline(always)]
    fn stored(&self, c: usize) -> [i32; D] {
        let (ints, mut q) = (lane_ints(self.lanes, c), [0; D]);
        for k in 0..D {
            q[k] = i32::from(ints[k]);
        }
        q
    }

    #[inline(always)]
    fn put(&mut self, c: usize, q: [i32; D]) {
        self.lanes = with_lane_ints(self.lanes, c, [q[0], q[1]]);
        self.cells |= 1 << (8 + c);
    }

    /// Lane `i`'s byte, one indexed load where `i` is not a constant (a
    /// shift of the word by `8 i` takes three instructions).
    #[inline(always)]
    fn component(&self, i: usize) -> i32 {
        i32::from(self.lanes.to_le_bytes()[i] as i8)
    }

    #[inline(always)]
    fn inward(&self) -> u8 {
        inward_lanes(self.lanes, self.cells as u8)
    }
}

impl Lanes {
    /// The block whose block rows start at cells `x0 + row.cell[r]` of the
    /// velocity plane, both rows read whole, occupied or not: the lanes of
    /// an empty cell are never read as a velocity (every use is masked by
    /// `occ`), and a row written back whole writes them back as they were.
    ///
    /// # Safety
    /// `x0 + 1 + row.cell[r]` lies in the plane for both rows (the row
    /// plan's bound, `RowPlan::lean_below`).
    #[inline(always)]
    pub(crate) unsafe fn load<Q: Quant, const D: usize>(velocity: Cells<'_, [Q; D]>, row: &BlockRow, x0: usize, occ: u8) -> Lanes {
        let mut lanes = 0u64;
        for r in 0..2 {
            // SAFETY: the caller's bound.
            let pair = unsafe { velocity.pair_unchecked(x0 + row.cell[r]) };
            lanes |= u64::from(Q::lanes_2d(pair)) << (32 * r);
        }
        Lanes { lanes, cells: u16::from(occ) }
    }

    /// Cell `c`'s stored velocity as the plane holds it.
    #[inline(always)]
    pub(crate) fn to_plane<Q: Quant, const D: usize>(&self, c: usize) -> [Q; D] {
        // Cell c's two lanes, as the first cell of a pair.
        Q::pair_from_lanes(cell_lanes(self.lanes, c))[0]
    }

    /// The block rows holding a velocity that changed, written back whole
    /// (the row's other cell as it was read), where no particle moved.
    ///
    /// # Safety
    /// As for [`Lanes::load`], with the same `velocity`, `row` and `x0`.
    #[inline(never)]
    pub(crate) unsafe fn write_rows<Q: Quant, const D: usize>(&self, velocity: Cells<'_, [Q; D]>, row: &BlockRow, x0: usize) {
        for r in 0..2 {
            if self.cells >> (8 + 2 * r) & 3 != 0 {
                // SAFETY: the caller's bound.
                unsafe { velocity.set_pair_unchecked(x0 + row.cell[r], Q::pair_from_lanes((self.lanes >> (32 * r)) as u32)) };
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
    fn lanes_give_every_parts_world_at_the_row_ends() {
        // Expect: a crowded periodic 8 x 6 world of 8-bit velocities
        // (every block of a row but the wrapping one is held as lanes,
        // whose reads and writes are unchecked under the row plan's
        // bound: under Miri they are checked here) steps to the same
        // world, bit for bit, as through the pipeline with every part,
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
