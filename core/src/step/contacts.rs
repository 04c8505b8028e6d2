//! Contacts (M5.7): a particle refused the cell it wanted meets the
//! particle placed there, head on, by eqs. 7-8 with `R` along the refused
//! move.

use crate::rules::collision::{collide_pair, difference, energy_neutral, shares, HALVES};
use crate::rules::fixed::{mulq, rsqrt, sq};
use crate::rules::obstacle::dot_q30;
use crate::step::block::{cells_of, Shared, Stored};
use crate::step::clamp::clamp_counted;
use crate::step::reflection::back_normal;
use crate::step::rounding::Changes;
use crate::storage::world::Counters;

/// M5.7: every particle refused the cell it wanted (`want`, by the
/// assignment's `targets`) meets the particle that holds that cell, in the
/// order of the refused particles' cells: eqs. 7-8 with `R` from the wanted
/// cell back towards the refused particle's, if it was closing in, then the
/// clamp to `unit` fine units. `mass_index` holds each cell's mass index,
/// by the cell the particle started in, where particles carry masses.
/// With `R` fixed, `|d| R` is the length of `d` (rounded to nearest) times
/// the Q30 axis (M1c): one square root a contact. Out of line, one copy for both velocity widths: only worlds
/// with contacts come here, and they pay one call a block.
#[inline(never)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn contacts<const D: usize, const CELLS: usize>(
    sh: &Shared<'_>,
    b: &impl Stored<D>,
    changes: &mut Changes<CELLS>,
    want: u32,
    targets: u32,
    mass_index: Option<[u8; CELLS]>,
    unit: i32,
    fine: u32,
    counters: &mut Counters,
) {
    // Folds to none in a build without masses.
    let mass_index = if sh.rules.has_masses() { mass_index } else { None };
    let equal = mass_index.is_none();
    let class = |c: usize| match mass_index {
        Some(m) => sh.class(m[c]),
        None => sh.one,
    };
    let occ = b.occ();
    for a in cells_of(occ) {
        let m = (want >> (D * a)) as usize & ((1 << D) - 1);
        let wanted = a ^ m;
        if m == 0 || (targets >> (4 * a) & 7) as usize == wanted {
            continue;
        }
        // The particle placed in the wanted cell, if any.
        let Some(h) = cells_of(occ).find(|&h| (targets >> (4 * h) & 7) as usize == wanted) else { continue };
        let r = back_normal::<D>(a, wanted);
        let (xa, xh) = (changes.velocity(b, a, fine), changes.velocity(b, h, fine));
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
        if sh.rules.has_energy_neutral() {
            (ya, yh) = energy_neutral(ya, yh, s, fine, masses);
        }
        clamp_counted::<D>(&mut ya, unit, &ca, counters);
        clamp_counted::<D>(&mut yh, unit, &ch, counters);
        changes.set(a, ya);
        changes.set(h, yh);
    }
}
