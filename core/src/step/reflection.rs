//! Reflection off obstacles and walls (M5.4): eq. 9 with the surface the
//! wanted cell belongs to, and the cases where a particle already leaving
//! the surface keeps its velocity or turns back off the face it came
//! through.

use crate::api::desc::Boundary;
use crate::rules::collision::WIDEST;
use crate::rules::faces::{resolve, Beyond, Coords};
use crate::rules::fixed::scaled;
#[cfg(feature = "obstacles")]
use crate::rules::body::body_surface_at;
use crate::rules::fixed::sat;
use crate::rules::obstacle::{axis_q30, dot_q30, normal_q30, reflect, surface_at, Surface};
use crate::rules::class::Class;
use crate::rules::rng::Stream;
use crate::step::block::{Carried, Kernel, Shared, Site, Stored, Widths};
use crate::step::clamp::clamp_counted;
use crate::step::rounding::round_one;
use crate::storage::layout::{row_words, test_bit};
use crate::storage::world::Counters;

/// The unit normal from cell `to` back towards cell `from` of the same
/// block, in Q30 (M1c).
pub(crate) fn back_normal<const D: usize>(from: usize, to: usize) -> [i32; 3] {
    let mut n = [0; 3];
    for k in 0..D {
        n[k] = ((from >> k) & 1) as i32 - ((to >> k) & 1) as i32;
    }
    axis_q30(n)
}

impl<const D: usize, const CELLS: usize> Kernel<'_, D, CELLS> {
    /// M5.4 for the particle in cell `c` of `b`, which wants to cross the
    /// axes `m`: whether the cell it wants is blocked, in which case its
    /// velocity is reflected ([`reflect_off`]) and rounded at once (M1),
    /// and it stays.
    #[inline(always)]
    pub(crate) fn reflects<W: Widths>(&mut self, site: &Site<'_>, b: &mut impl Stored<D>, c: usize, m: u8, carried: &Carried<CELLS>, rng: &mut Stream) -> bool {
        let t = c ^ usize::from(m);
        if m == 0 || site.blocked >> t & 1 == 0 {
            return false;
        }
        let w = W::width(self.shared);
        if let Some(x) = reflect_off(self.shared, b.fine(c, w.fine), c, Wanted { site, cell: t }, &carried.class(self.shared, c), w.unit, &mut self.counters, D) {
            round_one::<W, D, CELLS>(b, c, x, self.shared, rng);
        }
        true
    }
}

/// A blocked cell a particle wants (M5.4): its number `cell` in the block
/// at `site`.
#[derive(Clone, Copy)]
pub(crate) struct Wanted<'s, 'r> {
    pub(crate) site: &'s Site<'r>,
    pub(crate) cell: usize,
}

/// M5.4: the particle in cell `c` of class `class`, with velocity `x` (in
/// fine units, `unit` to a unit speed), wants the blocked cell `to`: its
/// velocity reflected off that cell's surface (eq. 9, M1c) and clamped, or
/// `None` where the surface says the particle is already leaving and it
/// keeps its velocity. Either way the caller keeps the particle in its
/// cell this step. Rare, so kept out of the block routine's straight line,
/// and one copy for both velocity widths and both dimensions (`dim`), in
/// the build's widest ([`WIDEST`]): in 2D the third component is set to 0
/// first, which no 2D stage reads and no 2D normal has, so the 3D
/// arithmetic below is the 2D rule.
#[cold]
#[inline(never)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn reflect_off(sh: &Shared<'_>, mut x: [i32; 3], c: usize, to: Wanted, class: &Class, unit: i32, counters: &mut Counters, dim: usize) -> Option<[i32; 3]> {
    if WIDEST == 3 && dim == 2 {
        x[2] = 0;
    }
    let t = to.cell;
    // Its place in the planes (meaningless beyond a face) and its
    // coordinates (possibly beyond a face).
    let (site, at) = (to.site.cell(t), to.site.at(t));
    let mut surface = None;
    if to.site.wall >> t & 1 != 0 {
        if let Beyond::Wall(n) = resolve(sh.n, &sh.rules.boundary, at) {
            surface = Some((axis_q30(n), sh.rules.wall_restitution));
        }
    }
    // A build without obstacles has no surface entry and no obstacle
    // cell (here and below), and no code to look either up.
    let table: &[Surface] = if cfg!(feature = "obstacles") { sh.surface } else { &[] };
    // Component by component: a copy of the array through the reference
    // is a `memmove` call at opt-level z, the only one in a firmware build.
    let fixed = surface.or_else(|| surface_at(table, site as u32).map(|s| (normal_q30([s.normal[0], s.normal[1], s.normal[2]]), s.restitution)));
    // M13: a body cell's entry, with its index and its body's velocity
    // `U`; eq. 9 then acts on the velocity relative to the surface,
    // `w = v - U`, and every test below reads `w` (a static surface is a
    // body at rest).
    #[cfg(feature = "obstacles")]
    let moving = if fixed.is_none() { moving_surface(sh, site) } else { None };
    #[cfg(not(feature = "obstacles"))]
    let moving: Option<(usize, [i32; 3], [i32; 3], f32)> = None;
    let (v, u) = (x, moving.map_or([0; 3], |(_, u, _, _)| u));
    if moving.is_some() {
        // Both within the saturation bound: the difference fits.
        x = [0, 1, 2].map(|k| x[k] - u[k]);
    }
    let (n, e) = match fixed.or(moving.map(|(_, _, n, e)| (n, e))) {
        Some(surface) => surface,
        // Unreachable for obstacles added through the API (every cell
        // next to a free one has an entry): the direction back to the
        // particle.
        None if cfg!(feature = "obstacles") => (back_normal::<WIDEST>(c, t), sh.rules.wall_restitution),
        // Unreachable without obstacles: only cells beyond a wall are
        // blocked then, and `resolve` gave their surface above. A normal
        // of 0 would reflect nothing; the build holds no code for the
        // direction back.
        None => ([0; 3], sh.rules.wall_restitution),
    };
    // Without obstacles only cells beyond a wall face are blocked, and a
    // particle asks for one only moving towards it (M5.3: every axis it
    // crosses points out of the domain), so N.v < 0: a build without
    // obstacles leaves out the case below (the tests check the claim).
    let n = if !cfg!(feature = "obstacles") || dot_q30(x, n) < 0 {
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
        let mut at = at;
        for (k, a) in at.iter_mut().enumerate().take(dim) {
            *a += ((c >> k) & 1) as isize - ((t >> k) & 1) as isize;
        }
        let back = back_normal::<WIDEST>(c, t);
        if dot_q30(n, back) > 0 && axis_move_free(if cfg!(feature = "obstacles") { sh.obstacle } else { &[] }, sh.n, &sh.rules.boundary, at, x, dim) {
            return None;
        }
        back
    };
    let mut x = reflect(x, n, scaled(e, 1.0, 16) as i32); // eq. 9
    if moving.is_some() {
        x = [0, 1, 2].map(|k| sat(i64::from(u[k]) + i64::from(x[k])));
    }
    clamp_counted::<WIDEST>(&mut x, unit, class, counters);
    // M13: what the body gave the particle, tallied in the entry's cell.
    #[cfg(feature = "obstacles")]
    if let Some((i, ..)) = moving {
        let mut tally = sh.bodies.tally.get(i);
        tally.reflected = tally.reflected.wrapping_add(1);
        tally.add_change(class.relative, [0, 1, 2].map(|k| x[k] - v[k]));
        sh.bodies.tally.set(i, tally);
    }
    #[cfg(not(feature = "obstacles"))]
    let _ = v;
    Some(x)
}

/// The body surface entry of cell `site` (M13), where it is a body's: its
/// index, the body's velocity in fine units, the normal in Q30 and the
/// restitution.
#[cfg(feature = "obstacles")]
fn moving_surface(sh: &Shared<'_>, site: usize) -> Option<(usize, [i32; 3], [i32; 3], f32)> {
    let (i, s) = body_surface_at(sh.bodies.surface, site as u32)?;
    let u = sh.bodies.table.get(s.body as usize).map_or([0; 3], |b| b.fine);
    Some((i, u, normal_q30([s.normal[0], s.normal[1], s.normal[2]]), s.restitution))
}

/// M5.4: whether the particle at `at` (raw coordinates, resolved across the
/// faces `boundary` of a domain of `n` cells per axis) with velocity `v`
/// has a cell to go to along a single axis `k` of its velocity (towards
/// `sign(v_k)`, `v_k != 0`, one of the first `dim` axes) that is neither an
/// obstacle (bit plane `obstacle`) nor beyond a wall. Such a particle can
/// always move on later, so refusing it one move leaves it never stuck.
pub(crate) fn axis_move_free(obstacle: &[u64], n: [usize; 3], boundary: &[[Boundary; 2]; 3], at: Coords, v: [i32; 3], dim: usize) -> bool {
    (0..dim).any(|k| {
        if v[k] == 0 {
            return false;
        }
        let mut to = at;
        to[k] += if v[k] > 0 { 1 } else { -1 };
        match resolve(n, boundary, to) {
            Beyond::Wall(_) => false,
            Beyond::Open => true,
            Beyond::Inside(p) => !test_bit(obstacle, (p[1] + n[1] * p[2]) * row_words(n[0]) * 64 + p[0]),
        }
    })
}
