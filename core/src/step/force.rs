//! The force (M5.1) and the flow drag (M5.1b) on a block's particles: the
//! stages before the collision, which draw nothing.

use crate::rules::fixed::{fit, mulq, sat};
use crate::rules::class::Class;
use crate::step::block::{cells_of, Stored};
use crate::step::clamp::clamp_counted;
use crate::step::block::{Carried, Kernel, Parts, Site, Widths};
use crate::step::rounding::Changes;

/// M5.1's sum `x + dv` of a velocity within a unit speed and a push (fine
/// units), fitted to the bound with its direction kept (M1c).
#[inline(always)]
pub(crate) fn pushed(x: [i32; 3], dv: [i64; 3]) -> [i32; 3] {
    fit([0, 1, 2].map(|k| i64::from(x[k]) + dv[k]))
}

/// [`pushed`] for a push whose components are below `2^29`
/// ([`Shared::lean_push`](crate::step::block::Shared::lean_push)): the sum
/// is within the bound already, so it is the same value taken in 32 bits.
#[inline(always)]
pub(crate) fn pushed_small(x: [i32; 3], dv: [i32; 3]) -> [i32; 3] {
    [x[0] + dv[0], x[1] + dv[1], x[2] + dv[2]]
}

impl<const D: usize, const CELLS: usize> Kernel<'_, D, CELLS> {
    /// Whether M5.1 or M5.1b may change a velocity of the block.
    #[inline(always)]
    pub(crate) fn pushes<P: Parts>(&self) -> bool {
        let sh = self.shared;
        sh.lean_push.is_some() || P::ALL && (sh.summed || sh.push.is_some() || sh.drag.is_some())
    }

    /// M5.1 external force on every particle of `b`: `v <- v + dt F / m`
    /// (eqs. 4-5), in fine units, then the clamp. A force that changes
    /// nothing is no step 1: a zero-valued part gives the same world as a
    /// world without it (M9). The particles of `resting` take no uniform
    /// push (M5.7b).
    #[inline(always)]
    pub(crate) fn force<W: Widths, P: Parts>(&mut self, site: &Site<'_>, b: &impl Stored<D>, changes: &mut Changes<CELLS>, carried: &Carried<CELLS>, resting: u8) {
        let sh = self.shared;
        let fine = W::width(sh).fine;
        // A plain block's uniform force, small enough to add in 32 bits;
        // where the block has every part, the loop below serves it too (one
        // loop: less code).
        let small = if P::ALL { None } else { sh.lean_push };
        if let Some(dv) = small {
            for c in cells_of(b.occ()) {
                self.push::<W>(changes, c, pushed_small(b.fine(c, fine), dv), &carried.class(sh, c));
            }
        } else if P::ALL {
            for c in cells_of(b.occ()) {
                let class = carried.class(sh, c);
                let mut dv = if sh.summed {
                    sh.terms.push(sh.part.cell_coords(site.row, [site.xs[c & 1], 0, 0], c), site.cell(c), &class)
                } else {
                    sh.push.unwrap_or_default()
                };
                // M5.7b: the sum less the uniform push, which a resting
                // particle's support takes (the sum is exact: M1c).
                if resting >> c & 1 != 0 {
                    let g = sh.push.unwrap_or_default();
                    dv = [dv[0] - g[0], dv[1] - g[1], dv[2] - g[2]];
                }
                // Component by component: an array comparison is a
                // `memcmp` call on small cores.
                if dv[0] | dv[1] | dv[2] != 0 {
                    // The stored velocity (nothing changed it yet), read
                    // through the one copy of that read `small-step` has.
                    self.push::<W>(changes, c, pushed(changes.velocity(b, c, fine), dv), &class);
                }
            }
        }
    }

    /// M5.1 for the particle in cell `c` of class `class`, whose velocity
    /// with its push is `x`: the clamp (M5.5).
    #[inline(always)]
    fn push<W: Widths>(&mut self, changes: &mut Changes<CELLS>, c: usize, mut x: [i32; 3], class: &Class) {
        clamp_counted::<D>(&mut x, W::width(self.shared).unit, class, &mut self.counters);
        changes.set(c, x);
    }

    /// M5.1b flow drag: `v <- (v + a u) / (1 + a)`, `u` the flow at the
    /// cell (none without the feature `fields`: `Description::check`), as
    /// the weighted mean `C v + (1 - C) u` with `C` in Q16 (M1c), then the
    /// clamp.
    #[inline(always)]
    pub(crate) fn drag<W: Widths>(&mut self, site: &Site<'_>, b: &impl Stored<D>, changes: &mut Changes<CELLS>, carried: &Carried<CELLS>) {
        let sh = self.shared;
        let drag = if cfg!(feature = "fields") { sh.drag.as_ref() } else { None };
        let Some(flow) = drag else { return };
        let keep = flow.keep;
        for c in cells_of(b.occ()) {
            let u = flow.at(sh.part.cell_coords(site.row, [site.xs[c & 1], 0, 0], c), site.cell(c));
            let mut x = changes.velocity(b, c, W::width(sh).fine);
            for k in 0..D {
                x[k] = sat(i64::from(mulq(x[k], keep, 16)) + i64::from(mulq(u[k], (1 << 16) - keep, 16)));
            }
            self.push::<W>(changes, c, x, &carried.class(sh, c));
        }
    }
}
