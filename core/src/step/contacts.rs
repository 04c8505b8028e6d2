//! Contacts (M5.7): a particle refused the cell it wanted meets the
//! particle placed there, head on, by eqs. 7-8 with `R` along the refused
//! move.

use crate::rules::collision::{collide_pair, energy_neutral, shares};
use crate::rules::vector::dot;
use crate::step::block::{cells_of, Block, Shared};
use crate::step::clamp::clamp_counted;
use crate::step::reflection::back_normal;
use crate::storage::world::Counters;

/// M5.7: every particle refused the cell it wanted (`want`, by the
/// assignment's `targets`) meets the particle that holds that cell, in the
/// order of the refused particles' cells: eqs. 7-8 with `R` from the wanted
/// cell back towards the refused particle's, if it was closing in, then the
/// clamp to `scale` quanta. `mass` holds each cell's mass, by the cell the
/// particle started in. Out of line, one copy for both velocity widths:
/// only worlds with contacts come here, and they pay one call a block.
#[inline(never)]
pub(crate) fn contacts<const D: usize, const CELLS: usize>(
    sh: &Shared<'_>,
    b: &mut Block<D, CELLS>,
    want: &[u8; CELLS],
    targets: u32,
    mass: &[f32; CELLS],
    scale: f32,
    counters: &mut Counters,
) {
    let equal = !sh.desc.has_masses();
    for a in cells_of(b.occ) {
        let wanted = a ^ usize::from(want[a]);
        if want[a] == 0 || (targets >> (4 * a) & 7) as usize == wanted {
            continue;
        }
        // The particle placed in the wanted cell, if any.
        let Some(h) = cells_of(b.occ).find(|&h| (targets >> (4 * h) & 7) as usize == wanted) else { continue };
        let r = back_normal::<D>(a, wanted);
        let (xa, xh) = (b.velocity(a), b.velocity(h));
        if dot([xa[0] - xh[0], xa[1] - xh[1], xa[2] - xh[2]], r) >= 0.0 {
            continue;
        }
        let (ma, mh) = (mass[a], mass[h]);
        let s = if equal { (0.5, 0.5) } else { shares(ma, mh) };
        let (mut ya, mut yh) = collide_pair::<D>(xa, xh, s, sh.desc.restitution, r);
        if sh.desc.has_energy_neutral() {
            (ya, yh) = energy_neutral::<D>(ya, yh, s);
        }
        clamp_counted::<D>(&mut ya, scale, ma, counters);
        clamp_counted::<D>(&mut yh, scale, mh, counters);
        b.set(a, ya);
        b.set(h, yh);
    }
}
