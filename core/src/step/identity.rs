//! M6b in the step: a block's ids, ages and tags go with its particles to
//! the cells M5.6 assigns them, and every age counts the step. Nothing
//! here draws or changes a velocity, so the world's other planes are the
//! same with these planes or without them.

use crate::api::desc::Identity;
use crate::step::block::{cells_of, Identified, Site};

/// Moves the planes `on` of the particles `occ` of the block at `site`
/// to their cells after M5.6, `targets` (4 bits a cell, as `assign` gives
/// them), each age one step older (saturating): those that are still in
/// the world, whose target is set in `after` (the targets are distinct;
/// one gone through an open face or at the end of its lifetime left its
/// target clear). Out of line and for blocks of either size: one
/// copy serves every instantiation of the pipeline.
#[inline(never)]
pub(crate) fn carry(planes: Identified<'_>, site: &Site<'_>, occ: u8, after: u8, targets: u32, on: Identity) {
    let target = |c: usize| (targets >> (4 * c) & 7) as usize;
    let mut stayed = 0u8;
    for c in cells_of(occ) {
        stayed |= (after >> target(c) & 1) << c;
    }
    // Read in full before any is written: a particle may move into a cell
    // another leaves.
    let (mut id, mut age, mut tag) = ([0u32; 8], [0u32; 8], [0u8; 8]);
    for c in cells_of(stayed) {
        let at = site.cell(c);
        if on.ids() {
            id[c] = planes.id.get(at);
        }
        if on.ages() {
            age[c] = planes.age.get(at);
        }
        if on.tags() {
            tag[c] = planes.tag.get(at);
        }
    }
    for c in cells_of(stayed) {
        let t = target(c);
        let to = site.cell(t);
        if on.ids() && t != c {
            planes.id.set(to, id[c]);
        }
        if on.ages() {
            planes.age.set(to, age[c].saturating_add(1));
        }
        if on.tags() && t != c {
            planes.tag.set(to, tag[c]);
        }
    }
}
