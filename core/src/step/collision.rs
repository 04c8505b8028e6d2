//! The collision stage (M5.2): the rule of `rules::collision` on the
//! block's pair, with the rule the description chooses, M1b when on, and
//! the clamp.

use crate::api::desc::Collisions;
use crate::rules::collision::{collide_limited, collide_pair, difference, energy_neutral, shares, turned, HALVES};
use crate::rules::fixed::{csqrt, sq};
use crate::rules::rng::Stream;
use crate::rules::class::Class;
use crate::step::clamp::clamp_counted;
use crate::step::block::{Kernel, Widths};

/// M5.2b's limit on a squared speed in fine units (M1c): a unit speed
/// `unit` less `sqrt(D)` quanta (`2^fine` fine units each) rounded up,
/// the most stochastic rounding can add to a speed, squared.
#[inline]
fn speed_limit2<const D: usize>(unit: i32, fine: u32) -> u64 {
    let limit = unit as u64 - csqrt((D as u64) << (2 * fine), 1 << fine);
    limit * limit
}

impl<const D: usize, const CELLS: usize> Kernel<'_, D, CELLS> {
    /// M5.2 on two particles of classes `(ca, cc)` with velocities `va`,
    /// `vc` in fine units: eqs. 7-8 with `R` uniform (or M5.2b), M1b when
    /// on, then the clamp of both; counts the collision. `equal` says
    /// every mass is the same. `None` where the collision changes neither
    /// velocity, whatever `R`: two equal velocities within the speed limit
    /// (eqs. 7-8 give both the centre-of-mass velocity, which is theirs),
    /// so a pair at rest draws nothing for it.
    #[inline(always)]
    pub(crate) fn collide_two<W: Widths>(&mut self, va: [i32; 3], vc: [i32; 3], (ca, cc): (Class, Class), equal: bool, rng: &mut Stream) -> Option<([i32; 3], [i32; 3])> {
        self.counters.collisions += 1;
        let w = W::width(self.shared);
        // Component by component: an array comparison is a `memcmp` call
        // on small cores.
        if (va[0] ^ vc[0]) | (va[1] ^ vc[1]) | (va[2] ^ vc[2]) == 0 && sq::<D>(va) <= (w.unit as u64) * (w.unit as u64) {
            return None;
        }
        let masses = (!equal).then_some((ca.relative, cc.relative));
        let s = if equal { HALVES } else { shares(ca.relative, cc.relative) };
        let e = self.shared.restitution;
        let (mut xa, mut xc) = match self.shared.rules.collision_rule() {
            Collisions::Paper => collide_pair::<D>(va, vc, s, e, turned::<D>(difference::<D>(va, vc), rng), masses),
            // Below the limit by sqrt(D) quanta, so that rounding (less than a
            // quantum per component) cannot store a speed above 1 either.
            Collisions::SpeedLimited => collide_limited(va, vc, s, e, speed_limit2::<D>(w.unit, w.fine), masses, rng, D),
        };
        if self.shared.rules.has_energy_neutral() {
            (xa, xc) = energy_neutral(xa, xc, s, w.fine, masses);
        }
        clamp_counted::<D>(&mut xa, w.unit, &ca, &mut self.counters);
        clamp_counted::<D>(&mut xc, w.unit, &cc, &mut self.counters);
        Some((xa, xc))
    }
}
