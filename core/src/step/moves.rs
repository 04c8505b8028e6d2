//! The desired move (M5.3): per particle, the axes of the block it wants
//! to cross, each with the probability the move table gives its stored
//! component; and, where the cell it wants is blocked, the reflection
//! (M5.4) in its place.

use crate::rules::rng::Stream;
use crate::step::block::{each_occupied, inward_axes, Carried, Kernel, Parts, Shared, Site, Stored, Widths};

impl<const D: usize, const CELLS: usize> Kernel<'_, D, CELLS> {
    /// M5.3 and M5.4 on the block `b`: the axes each particle wants to
    /// cross and may (a wish for a blocked cell reflected and turned into
    /// staying), `D` bits a cell (bit `D c + k` for cell `c`'s axis `k`).
    /// Only a move that stays inside the block can be wanted: towards +k
    /// from the low side of the block, towards -k from the high.
    ///
    /// In 2D one 64-bit output of the stream, drawn where some particle
    /// could cross an axis, holds in byte `2c + k` the high 8 of the 16
    /// random bits for cell `c`'s axis `k` ([`Kernel::crosses`]). In 3D,
    /// 16 bits an axis come from the stream (48 a particle that could
    /// cross some axis).
    #[inline(always)]
    pub(crate) fn desire<W: Widths, P: Parts, R: Stored<D>>(&mut self, site: &Site<'_>, b: &mut R, carried: &Carried<CELLS>, rng: &mut Stream) -> u32 {
        let mut want = 0u32;
        if D == 2 {
            let inward = b.inward();
            if inward == 0 {
                return 0;
            }
            // Lane i's random byte as byte i of an array: one indexed load.
            let bytes = rng.next_u64().to_le_bytes();
            let sh = self.shared;
            let mut todo = u32::from(inward);
            while todo != 0 {
                let i = todo.trailing_zeros() as usize;
                todo &= todo - 1;
                if Self::crosses::<W>(sh, b.component(i), bytes[i], rng) {
                    want |= 1 << i;
                }
                // M5.4 once both axes of the cell are decided.
                if P::ALL && todo & (3 << (i & !1)) == 0 && self.reflects::<W>(site, b, i / 2, (want >> (i & !1)) as u8 & 3, carried, rng) {
                    want &= !(3 << (i & !1));
                }
            }
            return want;
        }
        // 8-bit velocities: the cells unrolled, so that what depends on a
        // cell folds at compile time. 16-bit: a loop, which keeps a copy of
        // M5.3 for each of eight cells out of the library.
        each_occupied!(!P::ALL && !W::width(self.shared).wide(), CELLS, b.occ(), c => {
            let mut m = self.decide_3d::<W>(b.stored(c), c, rng);
            if P::ALL && self.reflects::<W>(site, b, c, m, carried, rng) {
                m = 0;
            }
            want |= u32::from(m) << (D * c);
        });
        want
    }

    /// M5.3 in 2D for one axis whose stored component is `q`: whether the
    /// particle wants to cross it. `high` is the high 8 of its 16 random
    /// bits; the low 8 come from the stream only where the high 8 alone
    /// cannot decide (they equal the limit's high 8: one case in 256). The
    /// decision is that of 16 uniform bits, drawn without bookkeeping for
    /// most axes.
    #[inline(always)]
    pub(crate) fn crosses<W: Widths>(sh: &Shared<'_>, q: i32, high: u8, rng: &mut Stream) -> bool {
        let high = u32::from(high);
        let w = W::width(sh);
        // 8 bits: the limit's high byte from a table of its own, one load
        // (the firmware has no room for that table).
        #[cfg(not(feature = "small-step"))]
        if !w.wide() {
            let top = u32::from(sh.tops[usize::from(q as u8)]);
            return high < top || high == top && rng.bits(8) <= w.move_limit(sh.moves, sh.rules.drift, q) & 0xff;
        }
        let limit = w.move_limit(sh.moves, sh.rules.drift, q);
        let top = limit >> 8;
        high < top || high == top && rng.bits(8) <= limit & 0xff
    }

    /// M5.3 in 3D for the particle in cell `c` of stored velocity `q`.
    #[inline(always)]
    fn decide_3d<W: Widths>(&self, q: [i32; D], c: usize, rng: &mut Stream) -> u8 {
        let inward = inward_axes::<D>(q, c);
        if inward == 0 {
            return 0;
        }
        let (table, drift, w) = (self.shared.moves, self.shared.rules.drift, W::width(self.shared));
        let r = u64::from(rng.bits(32)) | u64::from(rng.bits(16)) << 32;
        let mut m = 0u8;
        for k in 0..D {
            m |= u8::from((r >> (16 * k)) as u32 & 0xffff <= w.move_limit(table, drift, q[k])) << k;
        }
        m & inward
    }
}
