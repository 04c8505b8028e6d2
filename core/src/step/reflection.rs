//! Reflection off obstacles and walls (M5.4): eq. 9 with the surface the
//! wanted cell belongs to, and the cases where a particle already leaving
//! the surface keeps its velocity or turns back off the face it came
//! through.

use crate::api::desc::Boundary;
use crate::rules::faces::{resolve, Beyond, Coords};
use crate::rules::obstacle::{reflect, surface_at, Surface};
use crate::rules::vector::{dot, normalise};
use crate::step::block::Shared;
use crate::step::clamp::clamp_counted;
use crate::storage::layout::{row_words, test_bit};
use crate::storage::world::Counters;

/// A unit normal from cell `to` back towards cell `from` of the same block.
pub(crate) fn back_normal<const D: usize>(from: usize, to: usize) -> [f32; 3] {
    let mut n = [0.0f32; 3];
    for k in 0..D {
        n[k] = ((from >> k) & 1) as f32 - ((to >> k) & 1) as f32;
    }
    normalise(n).unwrap_or([0.0; 3])
}

/// A blocked cell a particle wants (M5.4): its number in the block, its
/// dense index in the planes (meaningless beyond a face), its coordinates
/// (possibly beyond a face) and whether it lies beyond a wall.
#[derive(Clone, Copy)]
pub(crate) struct Wanted {
    pub(crate) cell: usize,
    pub(crate) site: usize,
    pub(crate) at: Coords,
    pub(crate) wall: bool,
}

/// M5.4: the particle in cell `c` of mass `m`, with velocity `x` (in
/// quanta, `scale` to a unit speed), wants the blocked cell `to`: its
/// velocity reflected off that cell's surface (eq. 9) and clamped, or `None`
/// where the surface says the particle is already leaving and it keeps its
/// velocity. Either way the caller keeps the particle in its cell this step.
/// Rare, so kept out of the block routine's straight line, and the same
/// code for both velocity widths.
#[cold]
#[inline(never)]
pub(crate) fn reflect_off<const D: usize>(sh: &Shared<'_>, x: [f32; 3], c: usize, to: Wanted, m: f32, scale: f32, counters: &mut Counters) -> Option<[f32; 3]> {
    let t = to.cell;
    let mut surface = None;
    if to.wall {
        if let Beyond::Wall(n) = resolve(sh.n, &sh.desc.boundary, to.at) {
            surface = Some((n, sh.desc.wall_restitution));
        }
    }
    // A build without obstacles has no surface entry and no obstacle
    // cell (here and below), and no code to look either up.
    let table: &[Surface] = if cfg!(feature = "obstacles") { sh.surface } else { &[] };
    let (n, e) = surface.unwrap_or_else(|| match surface_at(table, to.site as u32) {
        // Component by component: a copy of the array through the
        // reference is a `memmove` call at opt-level z, the only one in a
        // firmware build.
        Some(s) => ([s.normal[0], s.normal[1], s.normal[2]], s.restitution),
        // Unreachable for obstacles added through the API (every cell
        // next to a free one has an entry): the direction back to the
        // particle.
        None if cfg!(feature = "obstacles") => (back_normal::<D>(c, t), sh.desc.wall_restitution),
        // Unreachable without obstacles: only cells beyond a wall are
        // blocked then, and `resolve` gave their surface above. A normal
        // of 0 would reflect nothing; the build holds no code for the
        // direction back.
        None => ([0.0; 3], sh.desc.wall_restitution),
    });
    // Without obstacles only cells beyond a wall face are blocked, and a
    // particle asks for one only moving towards it (M5.3: every axis it
    // crosses points out of the domain), so N.v < 0: a build without
    // obstacles leaves out the case below (the tests check the claim).
    let n = if !cfg!(feature = "obstacles") || dot(x, n) < 0.0 {
        n
    } else {
        // The particle already leaves the surface (N.v >= 0), yet asks
        // for one of its cells: a stair of a surface tilted against the
        // grid. Where N faces the particle's cell, the particle is on
        // the free side of that surface: it keeps its velocity and only
        // this move is refused, unless no cell along one axis of its
        // velocity is free, which would leave it stuck (a concave
        // corner where shapes overlap). Otherwise, or where N does not
        // face the particle (a half-space seen across a periodic seam, a
        // mask corner), it would press on the obstacle for ever: reflect
        // off the face it came through. M5.4.
        let mut at = to.at;
        for (k, a) in at.iter_mut().enumerate().take(D) {
            *a += ((c >> k) & 1) as isize - ((t >> k) & 1) as isize;
        }
        let back = back_normal::<D>(c, t);
        if dot(n, back) > 0.0 && axis_move_free(if cfg!(feature = "obstacles") { sh.obstacle } else { &[] }, sh.n, &sh.desc.boundary, at, x, D) {
            return None;
        }
        back
    };
    let mut x = reflect(x, n, e); // eq. 9
    clamp_counted::<D>(&mut x, scale, m, counters);
    Some(x)
}

/// M5.4: whether the particle at `at` (raw coordinates, resolved across the
/// faces `boundary` of a domain of `n` cells per axis) with velocity `v`
/// has a cell to go to along a single axis `k` of its velocity (towards
/// `sign(v_k)`, `v_k != 0`, one of the first `dim` axes) that is neither an
/// obstacle (bit plane `obstacle`) nor beyond a wall. Such a particle can
/// always move on later, so refusing it one move leaves it never stuck.
pub(crate) fn axis_move_free(obstacle: &[u64], n: [usize; 3], boundary: &[[Boundary; 2]; 3], at: Coords, v: [f32; 3], dim: usize) -> bool {
    (0..dim).any(|k| {
        if v[k] == 0.0 {
            return false;
        }
        let mut to = at;
        to[k] += if v[k] > 0.0 { 1 } else { -1 };
        match resolve(n, boundary, to) {
            Beyond::Wall(_) => false,
            Beyond::Open => true,
            Beyond::Inside(p) => !test_bit(obstacle, (p[1] + n[1] * p[2]) * row_words(n[0]) * 64 + p[0]),
        }
    })
}
