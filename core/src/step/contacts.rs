//! Contacts (M5.7): a particle refused the cell it wanted meets the
//! particle placed there, head on, by eqs. 7-8 with `R` along the refused
//! move.

use crate::rules::collision::{collide_pair, difference, energy_neutral, shares, HALVES};
use crate::rules::fixed::{mulq, rsqrt, sq};
use crate::rules::obstacle::dot_q30;
use crate::step::block::{cells_of, Block, Shared};
use crate::step::clamp::clamp_counted;
use crate::step::reflection::back_normal;
use crate::storage::world::Counters;

/// M5.7: every particle refused the cell it wanted (`want`, by the
/// assignment's `targets`) meets the particle that holds that cell, in the
/// order of the refused particles' cells: eqs. 7-8 with `R` from the wanted
/// cell back towards the refused particle's, if it was closing in, then the
/// clamp to `unit` fine units. `mass_index` holds each cell's mass index
/// (read where particles carry masses), by the cell the particle started
/// in. With `R` fixed, `|d| R` is the length of
/// `d` (rounded to nearest) times the Q30 axis (M1c): one square root a
/// contact. Out of line, one copy for both velocity widths: only worlds
/// with contacts come here, and they pay one call a block.
#[inline(never)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn contacts<const D: usize, const CELLS: usize>(
    sh: &Shared<'_>,
    b: &mut Block<D, CELLS>,
    want: &[u8; CELLS],
    targets: u32,
    mass_index: &[u8; CELLS],
    unit: i32,
    fine: u32,
    counters: &mut Counters,
) {
    let equal = !sh.desc.has_masses();
    let class = |c: usize| if equal { sh.one } else { sh.class(mass_index[c]) };
    for a in cells_of(b.occ) {
        let wanted = a ^ usize::from(want[a]);
        if want[a] == 0 || (targets >> (4 * a) & 7) as usize == wanted {
            continue;
        }
        // The particle placed in the wanted cell, if any.
        let Some(h) = cells_of(b.occ).find(|&h| (targets >> (4 * h) & 7) as usize == wanted) else { continue };
        let r = back_normal::<D>(a, wanted);
        let (xa, xh) = (b.velocity(a, fine), b.velocity(h, fine));
        let d = difference::<D>(xa, xh);
        if dot_q30(d, r) >= 0 {
            continue;
        }
        let (ca, ch) = (class(a), class(h));
        let masses = (!equal).then_some((ca.relative, ch.relative));
        let s = if equal { HALVES } else { shares(ca.relative, ch.relative) };
        let length = rsqrt(sq::<D>(d)) as i32;
        let t = r.map(|c| mulq(length, c, 30));
        let (mut ya, mut yh) = collide_pair::<D>(xa, xh, s, sh.restitution, t, masses);
        if sh.desc.has_energy_neutral() {
            (ya, yh) = energy_neutral(ya, yh, s, fine, masses);
        }
        clamp_counted::<D>(&mut ya, unit, &ca, counters);
        clamp_counted::<D>(&mut yh, unit, &ch, counters);
        b.set(a, ya);
        b.set(h, yh);
    }
}
