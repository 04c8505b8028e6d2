//! Kinematic obstacles (M13): adding, moving and removing bodies, the
//! redraw of their cells and surface entries that each of these makes, the
//! push-out of the particles a body takes, and what each body gave the
//! particles.
//!
//! A change is checked in full (the shape, the speed, the room in the body
//! surface table for the world as it will be) before anything is written,
//! so a refused call leaves the world as it was.
//!
//! Every call here is made between steps, rarely: the helpers that several
//! of them share stay out of line (`#[inline(never)]`), one copy each, so
//! that the C library that holds them stays small.

use core::ffi::CStr;

use crate::{Error, ErrorKind};
use crate::rules::body::{for_ring, pushed_velocity, Body, BodiesHead, BodySurface, Tally};
use crate::rules::class::Class;
use crate::rules::faces::Beyond;
use crate::rules::fixed::{magnitude, to_fine, unit_scale};
use crate::rules::obstacle::{centre, normal_q30, Shape};
use crate::rules::quant::{with_quant, Quant, Width};
use crate::rules::rng::StepKey;
use crate::rules::vector::{dot, normalise};
use crate::api::obstacles::{Frame, Mask};
use crate::step::clamp::clamp_counted;
use crate::storage::cells::Cells;
use crate::storage::layout::{head_and_bodies, mark, put_bit, store, stored, view_ref, Site};
use crate::storage::world::World;

/// What a body gave the particles in the last step (M13): reflections off
/// its cells during the step, and the push-outs of the moves made before
/// it. A game pushes its rigid body back by minus `momentum`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BodyStats {
    /// `sum m (v' - v)` over those reflections and push-outs, in the
    /// world's mass times cells per step.
    pub momentum: [f64; 3],
    /// Particles reflected off the body's cells.
    pub reflected: u32,
    /// Particles pushed out of cells the body took.
    pub pushed: u32,
    /// Particles removed for want of a free cell near the body
    /// ([`crate::Stats::crushed`] counts them for the whole world).
    pub crushed: u32,
}

/// A change of one slot of the body table: the slot and what it will hold.
#[derive(Clone, Copy)]
struct Change {
    slot: usize,
    body: Body,
}

impl Change {
    /// No change: the table as it is.
    const NONE: Change = Change { slot: usize::MAX, body: Body::ZERO };
}

/// What drawing bodies (M13) reads: the faces and sizes, the body table
/// (`count` slots, `body(i)` each) and which cells are static obstacles.
/// A world's, or an image's before it is loaded.
pub(crate) struct Draw<'a> {
    pub(crate) frame: Frame,
    pub(crate) count: usize,
    pub(crate) body: &'a dyn Fn(usize) -> Body,
    pub(crate) is_static: Mask<'a>,
}

impl Draw<'_> {
    /// The body that covers cell `c`: the first in table order whose shape
    /// holds its centre, unless a static obstacle does.
    #[inline(never)]
    pub(crate) fn owner(&self, c: [usize; 3]) -> Option<(usize, Body)> {
        let first = (0..self.count).map(|i| (i, (self.body)(i))).find(|(_, b)| b.shape().is_some_and(|s| s.contains(centre(c), self.frame.dim)));
        first.filter(|_| !(self.is_static)(c))
    }

    /// The box of cells, per axis `lo..hi`, that holds every body's cells.
    #[inline(never)]
    fn body_box(&self) -> ([usize; 3], [usize; 3]) {
        let (n, dim) = (self.frame.n, self.frame.dim);
        let (mut lo, mut hi) = (n, [0; 3]);
        for i in 0..self.count {
            if let Some(s) = (self.body)(i).shape() {
                let (a, z) = s.bounds(n, dim);
                for k in 0..3 {
                    (lo[k], hi[k]) = (lo[k].min(a[k]), hi[k].max(z[k]));
                }
            }
        }
        (lo, hi)
    }

    /// The body surface entry of cell `c`, covered by body `i`, where
    /// `taken` says which cells are obstacles (static or a body's): none
    /// where no neighbour is free (M13).
    #[inline(never)]
    fn entry(&self, taken: Mask<'_>, c: [usize; 3], i: usize, b: &Body) -> Option<BodySurface> {
        if !self.frame.is_surface(c, taken) {
            return None;
        }
        let normal = push_normal(b, c, self.frame.dim);
        let n = self.frame.n;
        Some(BodySurface { cell: (c[0] + n[0] * (c[1] + n[1] * c[2])) as u32, normal, restitution: b.restitution, body: i as u32 })
    }

    /// The entries the body surface table needs for these bodies.
    #[inline(never)]
    pub(crate) fn entries(&self) -> usize {
        let taken = |q: [usize; 3]| (self.is_static)(q) || self.owner(q).is_some();
        let (lo, hi) = self.body_box();
        let mut needed = 0usize;
        for_cells(lo, hi, &mut |c| {
            if let Some((i, b)) = self.owner(c) {
                needed += usize::from(self.entry(&taken, c, i, &b).is_some());
            }
        });
        needed
    }
}

/// The detail of a world or description without bodies asked for one.
const NO_BODIES: &CStr = c"desc.obstacles or desc.body_capacity";

impl crate::Description {
    /// The body surface entries (M13) a body of `shape` takes alone, where
    /// the shape lies, in a world of this description: what
    /// `body_surface_capacity` must hold for it. Bodies together need at
    /// most the sum of theirs (a cell with a free neighbour among them has
    /// one alone too), and static obstacles only take entries away; the
    /// same shape elsewhere may take a few more or fewer, as its cells fall
    /// on the grid.
    ///
    /// Refused as the world would refuse the description or the shape
    /// (`add_body`); `NotEnabled` for a description without bodies.
    pub fn body_surface_entries(&self, shape: Shape) -> Result<u32, Error> {
        let l = self.plan()?;
        if !self.has_bodies() {
            return Err(Error::new(ErrorKind::NotEnabled, NO_BODIES));
        }
        let dim = self.dim as usize;
        let body = Body::new(shape, [0.0; 3], 1.0, dim)?;
        let frame = Frame { n: l.n, boundary: self.boundary, dim };
        // At most the world's cell count, which a u32 holds (`Layout::of`).
        Ok(Draw { frame, count: 1, body: &|_| body, is_static: &|_| false }.entries() as u32)
    }
}

impl World {
    /// The body table's head and slots; `NotEnabled` in a world without
    /// bodies (M13: `obstacles` and a `body_capacity`). Out of line: one
    /// copy for every call that reads the table.
    #[inline(never)]
    fn bodies(&self) -> Result<(BodiesHead, &[Body]), Error> {
        if !self.head.desc.has_bodies() {
            return Err(Error::new(ErrorKind::NotEnabled, NO_BODIES));
        }
        let bytes = self.plane_bytes(self.layout().bodies());
        let (head, table) = bytes.split_at(core::mem::size_of::<BodiesHead>());
        Ok((view_ref::<BodiesHead>(head)[0], view_ref(table)))
    }

    /// Adds a body of `shape` moving at `u` (cells per step, `|u| <= 1`)
    /// with restitution `e`, and returns its id: the first free slot of the
    /// body table, which [`World::move_body`], [`World::remove_body`] and
    /// [`World::body_stats`] take. The body covers the cells of its shape
    /// that no static obstacle or earlier body covers; particles in them
    /// are pushed out (M13).
    ///
    /// Refused, changing nothing: `NotEnabled` without bodies,
    /// `BodyTableFull`, `BadShape` and `NotFinite` for the shape,
    /// `SpeedRange`, `RestitutionRange`, `SurfaceTableFull` where the body
    /// surface table would not hold the cells.
    pub fn add_body(&mut self, shape: Shape, u: [f32; 3], e: f32) -> Result<u32, Error> {
        let (_, table) = self.bodies()?;
        let slot = table.iter().position(|b| b.kind == 0).ok_or(Error::new(ErrorKind::BodyTableFull, c"desc.body_capacity"))?;
        let body = self.with_fine_velocity(Body::new(shape, u, e, self.dim())?);
        self.redraw(Change { slot, body })?;
        Ok(slot as u32)
    }

    /// Gives body `id` a new shape (at its new place) and velocity; refused
    /// as [`World::add_body`], and with `NoBody` where `id` names none.
    pub fn move_body(&mut self, id: u32, shape: Shape, u: [f32; 3]) -> Result<(), Error> {
        let mut body = self.body(id)?;
        body.set(shape, u, self.dim())?;
        let body = self.with_fine_velocity(body);
        self.redraw(Change { slot: id as usize, body })
    }

    /// Removes body `id`: its cells are free again (M13).
    pub fn remove_body(&mut self, id: u32) -> Result<(), Error> {
        self.body(id)?;
        self.redraw(Change { slot: id as usize, body: Body::ZERO })
    }

    /// The crushed count and the redraws since the last step, for an image
    /// (M12); none without bodies.
    pub(crate) fn body_head(&self) -> Option<(u64, u32)> {
        self.bodies().ok().map(|(h, _)| (h.crushed, h.redraws))
    }

    /// Every slot of the body table, free ones too; none without bodies.
    pub(crate) fn body_table(&self) -> &[Body] {
        self.bodies().map_or(&[][..], |(_, t)| t)
    }

    /// Sets the body table from an image (M12): the crushed count, the
    /// redraws since the last step and every slot (`body(i)`), then draws
    /// the bodies.
    pub(crate) fn set_bodies(&mut self, crushed: u64, redraws: u32, body: &dyn Fn(usize) -> Body) {
        if self.bodies().is_err() {
            return;
        }
        let count = self.head.desc.body_capacity as usize;
        for i in 0..count {
            let b = body(i);
            let b = if b.kind == 0 { Body::ZERO } else { self.with_fine_velocity(b) };
            head_and_bodies(self.byte_planes().1.bodies).1[i] = b;
        }
        let (_, p) = &mut self.byte_planes();
        if let (Some(h), _) = head_and_bodies(p.bodies) {
            *h = BodiesHead { crushed, redraws, surfaces: 0 };
        }
        p.body_cells.fill(0);
        self.refresh_bodies();
    }

    /// Particles the bodies crushed, all time (M13).
    pub(crate) fn crushed_count(&self) -> u64 {
        self.bodies().map_or(0, |(h, _)| h.crushed)
    }

    /// What body `id` gave the particles in the last step.
    #[inline(never)]
    pub fn body_stats(&self, id: u32) -> Result<BodyStats, Error> {
        let t = self.body(id)?.last;
        // M13: the tally counts each particle's relative mass in 24 bits
        // against the largest mass, and velocities in fine units.
        let (unit, largest) = (self.unit(), self.largest_mass());
        let scale = f64::from(largest) / (f64::from(1u32 << 24) * f64::from(unit));
        Ok(BodyStats { momentum: t.momentum.map(|m| m as f64 * scale), reflected: t.reflected, pushed: t.pushed, crushed: t.crushed })
    }

    /// Body `id`, or `NoBody`.
    fn body(&self, id: u32) -> Result<Body, Error> {
        let (_, table) = self.bodies()?;
        table.get(id as usize).filter(|b| b.kind != 0).copied().ok_or(Error::new(ErrorKind::NoBody, c"id"))
    }

    /// Fine units to a unit speed (M1c's `W`).
    fn unit(&self) -> i32 {
        with_quant!(self.head.desc.quantization, Q => Q::UNIT)
    }

    /// The largest mass in use: the world's, or the largest in its table.
    #[inline(never)]
    fn largest_mass(&self) -> f32 {
        if !self.head.desc.has_masses() {
            return self.head.desc.mass;
        }
        // Masses are positive (checked): their bits order them as numbers.
        let table: &[f32] = self.plane(self.layout().mass_table());
        f32::from_bits(table[..self.head.masses as usize].iter().fold(self.head.desc.mass.to_bits(), |a, &m| a.max(m.to_bits())))
    }

    /// `body` with its velocity in fine units (M13: converted as the uniform
    /// wind is, once, since a world's unit never changes).
    #[inline(never)]
    fn with_fine_velocity(&self, mut body: Body) -> Body {
        let scale = unit_scale(self.unit());
        body.fine = body.velocity.map(|u| to_fine(u, scale));
        body
    }

    /// Calls `f` with what drawing the bodies reads of this world, with
    /// `change` made to its table (none: `slot` past the table).
    fn with_draw<R: Default>(&self, change: Change, f: impl FnOnce(&Draw<'_>) -> R) -> R {
        let (mut f, mut out) = (Some(f), R::default());
        self.draw(change, &mut |d| {
            if let Some(f) = f.take() {
                out = f(d);
            }
        });
        out
    }

    /// [`World::with_draw`]'s work, `f` called once. Not generic: one
    /// copy of the views of the table and the static obstacles (and of
    /// their tables of calls) for every caller.
    fn draw(&self, change: Change, f: &mut dyn FnMut(&Draw<'_>)) {
        let table = self.body_table();
        let l = *self.layout();
        let body = |i: usize| if i == change.slot { change.body } else { table[i] };
        let is_static = |c: [usize; 3]| self.is_static(l.site(c[0], c[1], c[2]));
        f(&Draw { frame: self.frame(), count: table.len(), body: &body, is_static: &is_static });
    }

    /// Makes `change` and redraws every body (M13): refused whole where
    /// the body surface table would not hold the entries; otherwise the
    /// body cells are drawn again, the body surface table rebuilt in cell
    /// order and the particles in body cells pushed out.
    fn redraw(&mut self, change: Change) -> Result<(), Error> {
        if self.with_draw(change, |d| d.entries()) > self.head.desc.body_surface_capacity as usize {
            return Err(Error::new(ErrorKind::SurfaceTableFull, c"desc.body_surface_capacity"));
        }
        head_and_bodies(self.byte_planes().1.bodies).1[change.slot] = change.body;
        self.refresh_bodies();
        self.push_out();
        let (_, p) = &mut self.byte_planes();
        if let (Some(h), _) = head_and_bodies(p.bodies) {
            h.redraws = h.redraws.wrapping_add(1);
        }
        Ok(())
    }

    /// Draws the bodies again as the table holds them: the old body cells
    /// cleared, every cell drawn to the first body covering it that is not
    /// a static obstacle, and the body surface table rebuilt from them in
    /// cell order. Also where static obstacles changed around the bodies
    /// (M7 additions), which can only take entries away.
    #[inline(never)]
    pub(crate) fn refresh_bodies(&mut self) {
        if self.bodies().is_err() {
            return;
        }
        let (_, p) = &mut self.byte_planes();
        for (o, b) in p.obstacle.iter_mut().zip(p.body_cells.iter_mut()) {
            *o &= !*b;
            *b = 0;
        }
        let (l, none) = (*self.layout(), Change::NONE);
        let (lo, hi) = self.with_draw(none, |d| d.body_box());
        for_cells(lo, hi, &mut |c| {
            if self.with_draw(none, |d| d.owner(c).is_some()) {
                let bit = l.site(c[0], c[1], c[2]).bit;
                let (_, p) = &mut self.byte_planes();
                put_bit(Cells::new(p.obstacle), bit, true);
                put_bit(Cells::new(p.body_cells), bit, true);
            }
        });
        let mut used = 0usize;
        for_cells(lo, hi, &mut |c| {
            let w: &World = self;
            let taken = |q: [usize; 3]| w.is_obstacle(l.site(q[0], q[1], q[2]));
            let entry = w.with_draw(none, |d| d.owner(c).and_then(|(i, b)| d.entry(&taken, c, i, &b)));
            if let Some(e) = entry {
                let (_, p) = &mut self.byte_planes();
                p.body_surface[used] = e;
                p.body_tally[used] = Default::default();
                used += 1;
            }
        });
        let (_, p) = &mut self.byte_planes();
        if let (Some(h), _) = head_and_bodies(p.bodies) {
            h.surfaces = used as u32;
        }
    }

    /// M13's push-out of every particle in a body cell, in cell order: to
    /// the first free candidate cell, its velocity into the surface
    /// (relative to it) removed, or crushed where none is free.
    #[inline(never)]
    fn push_out(&mut self) {
        let l = *self.layout();
        let (dim, frame) = (self.dim(), self.frame());
        let none = Change::NONE;
        let (lo, hi) = self.with_draw(none, |d| d.body_box());
        let (head, _) = match self.bodies() {
            Ok(b) => b,
            Err(_) => return,
        };
        let key = StepKey::bodies(self.head.desc.seed, self.head.step);
        for_cells(lo, hi, &mut |c| {
            let from = l.site(c[0], c[1], c[2]);
            if !self.occupied(from) || !self.is_body(from) {
                return;
            }
            let Some((i, b)) = self.with_draw(none, |d| d.owner(c)) else { return };
            let n = push_normal(&b, c, dim);
            let to = self.free_candidate(&frame, c, n);
            let index = u64::from(head.redraws) * l.cells as u64 + from.cell as u64;
            self.push_one(from, to, i, &b, normal_q30(n), &mut key.stream(index));
        });
    }

    /// M13's candidates for a particle at `c` pushed along `n`: ring 1,
    /// then ring 2, each by `d.n` from the largest down, then the nearest
    /// first (`|d|^2`), then by cell index; none behind the surface
    /// (`d.n < 0`) or beyond a wall or an open face. The first that is
    /// neither an obstacle nor occupied.
    fn free_candidate(&self, frame: &Frame, c: [usize; 3], n: [f32; 3]) -> Option<Site> {
        let l = self.layout();
        for ring in 1..=2 {
            // The first free cell in that order: the free one that orders
            // first, found in one pass.
            let mut best: Option<(f32, i32, Site)> = None;
            for_ring(frame.dim, ring, &mut |d| {
                let key = dot(d.map(|v| v as f32), n);
                let Beyond::Inside(p) = frame.beyond(c, d) else { return };
                let s = l.site(p[0], p[1], p[2]);
                if key < 0.0 || self.is_obstacle(s) || self.occupied(s) {
                    return;
                }
                let this = (key, d.iter().map(|v| v * v).sum(), s);
                let first = |b: (f32, i32, Site)| this.0 > b.0 || (this.0 == b.0 && (this.1, this.2.cell) < (b.1, b.2.cell));
                if best.is_none_or(first) {
                    best = Some(this);
                }
            });
            if let Some((_, _, s)) = best {
                return Some(s);
            }
        }
        None
    }

    /// Moves the particle at `from` to `to` with M13's velocity for a body
    /// `b` (slot `i`) of unit normal `n` (Q30), tallied; or, with no `to`,
    /// removes it as crushed.
    #[inline(never)]
    fn push_one(&mut self, from: Site, to: Option<Site>, i: usize, b: &Body, n: [i32; 3], rng: &mut crate::rules::rng::Stream) {
        let class = self.class_at(from.cell);
        let Some(to) = to else {
            let (head, p) = &mut self.byte_planes();
            put_bit(Cells::new(p.occupancy), from.bit, false);
            head.counters.particles -= 1;
            let (h, table) = head_and_bodies(p.bodies);
            if let Some(h) = h {
                h.crushed = h.crushed.saturating_add(1);
            }
            table[i].current.crushed = table[i].current.crushed.wrapping_add(1);
            return;
        };
        let dim = self.dim();
        let summary_words = self.layout().summary_words;
        let (lifetimes, masses) = (self.head.desc.lifetimes, self.head.desc.has_masses());
        // The velocities as bytes of the world's width: one copy of this for
        // both widths.
        let width = with_quant!(self.head.desc.quantization, Q => Width::of::<Q>());
        let bytes = if width.wide() { 2 } else { 1 };
        let (head, p) = &mut self.byte_planes();
        let mut v = [0i32; 3];
        for k in 0..dim {
            v[k] = stored(p.velocity, from.cell * dim + k, bytes) << width.fine;
        }
        let mut x = pushed_velocity(v, b.fine, n);
        clamp_counted::<3>(&mut x, width.unit, &class, &mut head.counters);
        // M1: 32 bits in 2D, a whole output in 3D, as the step rounds.
        let stored = if dim == 2 {
            let r = width.round::<2>(x, rng);
            [r[0], r[1], 0]
        } else {
            width.round::<3>(x, rng)
        };
        for k in 0..dim {
            store(p.velocity, to.cell * dim + k, bytes, stored[k]);
        }
        put_bit(Cells::new(p.occupancy), from.bit, false);
        put_bit(Cells::new(p.occupancy), to.bit, true);
        mark(Cells::new(p.rows), Cells::new(p.words), summary_words, to.row, to.x);
        if masses {
            p.mass_index[to.cell] = p.mass_index[from.cell];
        }
        if lifetimes {
            p.life[to.cell] = p.life[from.cell];
        }
        #[cfg(feature = "identity")]
        {
            let on = head.desc.identity_planes();
            if on.ids() {
                p.id[to.cell] = p.id[from.cell];
            }
            if on.ages() {
                p.age[to.cell] = p.age[from.cell];
            }
            if on.tags() {
                p.tag[to.cell] = p.tag[from.cell];
            }
        }
        let t = &mut head_and_bodies(p.bodies).1[i].current;
        t.pushed = t.pushed.wrapping_add(1);
        t.add_change(class.relative, [0, 1, 2].map(|k| x[k] - v[k]));
    }

    /// The class (M1c) of the particle in `cell`, as the step converts it:
    /// its relative mass and the clamp's energy factor.
    #[inline(never)]
    fn class_at(&self, cell: usize) -> Class {
        let d = &self.head.desc;
        let m = magnitude(self.mass_at(cell));
        crate::step::convert_class(m, magnitude(self.largest_mass()), d.dt, unit_scale(self.unit()), None)
    }

    /// After a step (M13): the reflections the blocks tallied per body
    /// surface entry go to their bodies, each body's tally of the step
    /// becomes its last, and the redraw count starts again.
    pub(crate) fn end_body_step(&mut self) {
        if !self.head.desc.has_bodies() {
            return;
        }
        let (_, p) = self.planes::<u8>();
        let (head, table) = head_and_bodies(p.bodies);
        let Some(head) = head else { return };
        let used = head.surfaces as usize;
        for (e, t) in p.body_surface[..used].iter().zip(p.body_tally[..used].iter_mut()) {
            if let Some(b) = table.get_mut(e.body as usize) {
                b.current.add(t);
            }
            *t = Default::default();
        }
        for b in table.iter_mut() {
            b.last = b.current;
            b.current = Tally::default();
        }
        head.redraws = 0;
    }
}

/// Calls `f` with every cell of the box `lo..hi`, in cell order.
#[inline(never)]
fn for_cells(lo: [usize; 3], hi: [usize; 3], f: &mut dyn FnMut([usize; 3])) {
    for z in lo[2]..hi[2] {
        for y in lo[1]..hi[1] {
            for x in lo[0]..hi[0] {
                f([x, y, z]);
            }
        }
    }
}

/// The unit outward normal M13 takes at cell `c` of body `b`: the shape's
/// geometry at the cell's centre, else the body's velocity, else `+x`.
#[inline(never)]
fn push_normal(b: &Body, c: [usize; 3], dim: usize) -> [f32; 3] {
    let n = b.shape().map_or([0.0; 3], |s| s.normal(centre(c), dim));
    normalise(n).or(normalise(b.velocity)).unwrap_or([1.0, 0.0, 0.0])
}
