//! The emitters' part of a step (M6): each emitter, in the order they
//! were added, places its particles before any block of the step.

use crate::rules::emitter::{spread_velocity, split_rate, Emitter, Slot};
use crate::rules::rng::StepKey;
use crate::storage::layout::{Grid, Site};
use crate::storage::world::World;

impl World {
    /// Runs every emitter once (M6), at the start of a step.
    pub(crate) fn emit(&mut self) {
        let (seed, step, dim) = (self.head.desc.seed, self.head.step, self.dim());
        let unit = crate::rules::quant::unit_of(self.head.desc.quantization);
        let key = StepKey::emitters(seed, step);
        for i in 0..self.head.emitters as usize {
            let slot: Slot = self.slots()[i];
            let e = slot.emitter;
            let mut rng = key.stream(i as u64);
            // An absurd rate asks for u64::MAX.
            let (whole, threshold) = split_rate(e.rate);
            let wanted = whole.saturating_add(u64::from(rng.bits(24) < threshold));
            if wanted == 0 {
                continue;
            }
            let grid = self.layout().grid();
            // Cells, counted in machine words (not u64: small cores add
            // those in pairs of instructions).
            let mut free = 0usize;
            each_site(grid, &e, |s| free += usize::from(!self.occupied(s) && !self.is_obstacle(s)));
            let mut placing = wanted.min(free as u64);
            // M6b: no more particles than ids are left; the rest is
            // shortfall as well.
            if self.head.desc.identity_planes().ids() {
                placing = placing.min(u64::from(self.ids_left()));
            }
            let placing = placing as usize;
            self.head.counters.shortfall = self.head.counters.shortfall.saturating_add(wanted - placing as u64);
            let mut need = placing;
            let mut left = free;
            let mut chosen = |w: &mut World, s| {
                if need == 0 || w.occupied(s) || w.is_obstacle(s) {
                    return;
                }
                // Selection sampling: take this cell with chance need/left,
                // which picks a uniform subset of `placing` free cells.
                // `left` counts cells, so it fits the u32 of `below`.
                let take = (rng.below(left as u32) as usize) < need;
                left -= 1;
                if take {
                    need -= 1;
                    let v = spread_velocity(&e, dim, unit, &mut rng);
                    w.place_emitted(s, v, slot.class, e.lifetime as u16, &mut rng);
                }
            };
            each_site(grid, &e, |s| chosen(self, s));
            // Saturating: an image (M12) may carry any count.
            let stats = &mut self.planes::<u8>().1.emitters[i].stats;
            stats.requested = stats.requested.saturating_add(wanted);
            stats.delivered = stats.delivered.saturating_add(placing as u64);
            self.head.counters.emitted = self.head.counters.emitted.saturating_add(placing as u64);
            self.head.counters.particles += placing as u64;
        }
    }
}

/// Calls `f` with every site of the emitter's region.
fn each_site(l: Grid, e: &Emitter, mut f: impl FnMut(Site)) {
    for z in e.min[2] as usize..e.max[2] as usize {
        for y in e.min[1] as usize..e.max[1] as usize {
            for x in e.min[0] as usize..e.max[0] as usize {
                f(l.site(x, y, z));
            }
        }
    }
}
