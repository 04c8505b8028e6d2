//! Adding obstacles to a world (M7): cells, shapes and masks, their
//! surface entries kept sorted, and the checks that leave a world unchanged
//! when an addition is refused; and the entries a shape takes, asked before
//! it is added (of a world, or of a description before its world is made).

use core::ffi::CStr;

use crate::{Error, ErrorKind};
use crate::api::checks::{finite, restitution};
use crate::api::desc::{Boundary, Description};
use crate::rules::faces::{resolve, Beyond};
use crate::rules::obstacle::{centre, in_plane, surface_at, Shape, Surface};
use crate::rules::vector::normalise;
use crate::storage::cells::Cells;
use crate::storage::layout::put_bit;
use crate::storage::world::World;

/// The detail of a world or description without obstacles asked for them.
const NO_OBSTACLES: &CStr = c"desc.obstacles";
/// The detail of a refused obstacle or body restitution.
pub(crate) const E: &CStr = c"e";

/// A set of cells, as a predicate on coordinates.
pub(crate) type Mask<'a> = &'a dyn Fn([usize; 3]) -> bool;

/// Gives a surface cell's outward normal, unnormalised, given the set of
/// cells that will be obstacles.
type NormalFn<'a> = &'a dyn Fn(&Frame, [usize; 3], Mask<'_>) -> [f32; 3];

/// What M7's surface test reads of a world: its cells per axis, its faces
/// (M4) and its dimension. A description has them before its world does.
#[derive(Clone, Copy)]
pub(crate) struct Frame {
    pub(crate) n: [usize; 3],
    pub(crate) boundary: [[Boundary; 2]; 3],
    pub(crate) dim: usize,
}

impl Frame {
    /// The neighbour of `c` at offset `off`, after the boundary rules (M4).
    pub(crate) fn beyond(&self, c: [usize; 3], off: [i32; 3]) -> Beyond {
        let at = [0, 1, 2].map(|k| c[k] as isize + off[k] as isize);
        resolve(self.n, &self.boundary, at)
    }

    /// Whether the neighbour of `c` at `off` is free once the cells for which
    /// `obstacle` holds are obstacles: inside and not an obstacle, or beyond
    /// an open face.
    fn free_after(&self, c: [usize; 3], off: [i32; 3], obstacle: Mask<'_>) -> bool {
        match self.beyond(c, off) {
            Beyond::Inside(nb) => !obstacle(nb),
            Beyond::Wall(_) => false,
            Beyond::Open => true,
        }
    }

    /// Calls `f` with every offset of the `3^D - 1` neighbourhood.
    fn for_neighbours(&self, mut f: impl FnMut([i32; 3])) {
        let zr = if self.dim == 3 { -1..=1 } else { 0..=0 };
        for dz in zr {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    if (dx, dy, dz) != (0, 0, 0) {
                        f([dx, dy, dz]);
                    }
                }
            }
        }
    }

    /// Whether cell `c` has a free neighbour once the cells for which
    /// `obstacle` holds are obstacles. Out of line: every pass of an
    /// addition asks it.
    #[inline(never)]
    pub(crate) fn is_surface(&self, c: [usize; 3], obstacle: Mask<'_>) -> bool {
        let mut free = false;
        self.for_neighbours(|off| free |= self.free_after(c, off, obstacle));
        free
    }

    /// Calls `f` with each cell next to `c` for which `obstacle` holds (an
    /// obstacle before `a`) and that `a` does not add, stopping at the
    /// first error.
    #[inline(never)]
    fn for_old_neighbours(
        &self,
        a: &Addition<'_>,
        obstacle: Mask<'_>,
        c: [usize; 3],
        f: &mut dyn FnMut([usize; 3]) -> Result<(), Error>,
    ) -> Result<(), Error> {
        let mut result = Ok(());
        self.for_neighbours(|off| {
            if let (Ok(()), Beyond::Inside(nb)) = (result, self.beyond(c, off)) {
                if obstacle(nb) && !(a.inside)(nb) {
                    result = f(nb);
                }
            }
        });
        result
    }

    /// M7's normal for an arbitrary mask: the sum of the unit directions to
    /// the free neighbours (not normalised; zero where it is undefined).
    fn mask_normal(&self, c: [usize; 3], obstacle: Mask<'_>) -> [f32; 3] {
        let mut sum = [0.0f32; 3];
        self.for_neighbours(|off| {
            if self.free_after(c, off, obstacle) {
                let d = normalise(off.map(|o| o as f32)).unwrap_or([0.0; 3]);
                for k in 0..3 {
                    sum[k] += d[k];
                }
            }
        });
        sum
    }
}

/// Obstacles to add: the cells in `lo..hi` for which `inside` holds, and
/// how each new surface cell's outward normal is found.
struct Addition<'a> {
    lo: [usize; 3],
    hi: [usize; 3],
    inside: Mask<'a>,
    normal: NormalFn<'a>,
}

impl Addition<'_> {
    /// Calls `f` with every cell added, stopping at the first error. Out of
    /// line: one loop serves every pass.
    #[inline(never)]
    fn each(&self, f: &mut dyn FnMut([usize; 3]) -> Result<(), Error>) -> Result<(), Error> {
        let (lo, hi) = (self.lo, self.hi);
        for z in lo[2]..hi[2] {
            for y in lo[1]..hi[1] {
                for x in lo[0]..hi[0] {
                    if (self.inside)([x, y, z]) {
                        f([x, y, z])?;
                    }
                }
            }
        }
        Ok(())
    }

    /// Calls `then` with the shape `shape` (checked here) as an addition to
    /// `frame`. One copy for every caller: shapes are added and asked
    /// about rarely.
    #[inline(never)]
    fn of_shape(
        shape: Shape,
        frame: &Frame,
        then: &mut dyn FnMut(&Addition<'_>) -> Result<usize, Error>,
    ) -> Result<usize, Error> {
        let dim = frame.dim;
        shape.check(dim)?;
        let shape = shape.in_dim(dim);
        let (lo, hi) = shape.bounds(frame.n, dim);
        let normal = |_: &Frame, c, _: Mask<'_>| shape.normal(centre(c), dim);
        then(&Addition { lo, hi, inside: &|c| shape.contains(centre(c), dim), normal: &normal })
    }
}

/// The obstacles an [`Addition`] is made to: which cells are obstacles and
/// which hold particles, the surface table and each cell's index in it.
struct Before<'a> {
    /// The static obstacles (M7; a body's cells are free to them, M13).
    obstacle: Mask<'a>,
    occupied: Mask<'a>,
    /// The cells bodies cover (M13), which a static obstacle may not take.
    body: Mask<'a>,
    table: &'a [Surface],
    cell: &'a dyn Fn([usize; 3]) -> u32,
}

impl Before<'_> {
    /// The first pass of an addition: checks every cell it adds and every
    /// surface normal it makes or changes against the obstacles as they
    /// will be, and counts the surface entries it adds: what the table must
    /// have free for it. (Entries of cells it covers are dropped, but only
    /// after, so they are not counted as room.)
    fn entries_added(&self, frame: &Frame, a: &Addition<'_>) -> Result<usize, Error> {
        let after = |c: [usize; 3]| (self.obstacle)(c) || (a.inside)(c);
        let mut added = 0usize;
        a.each(&mut |c| {
            if (self.occupied)(c) {
                return Err(Error::new(ErrorKind::CellOccupied, c"the obstacle"));
            }
            if (self.body)(c) {
                return Err(Error::new(ErrorKind::CellObstacle, c"the obstacle"));
            }
            if frame.is_surface(c, &after) {
                normalise((a.normal)(frame, c, &after)).ok_or(Error::new(ErrorKind::UndefinedNormal, c"a surface cell of the obstacle"))?;
                added += usize::from(surface_at(self.table, (self.cell)(c)).is_none());
            }
            frame.for_old_neighbours(a, self.obstacle, c, &mut |nb| {
                let old = surface_at(self.table, (self.cell)(nb));
                if old.is_some_and(|s| s.from_mask != 0) && frame.is_surface(nb, &after) {
                    normalise(frame.mask_normal(nb, &after)).ok_or(Error::new(ErrorKind::UndefinedNormal, c"a mask cell beside the obstacle"))?;
                }
                Ok(())
            })
        })?;
        Ok(added)
    }
}

impl Description {
    /// The surface entries (M7) `shape` takes as the first obstacle of a
    /// world of this description: the `surface_capacity` it needs, so that
    /// a capacity can be set before the world is made. A world that holds
    /// several shapes needs at most the sum of theirs, added in any order
    /// (where shapes touch, they need fewer).
    ///
    /// Refused as the world would refuse the description
    /// ([`Description::validate`]) or the shape ([`World::add_shape`]);
    /// `NotEnabled` for a description without obstacles.
    pub fn surface_entries(&self, shape: Shape) -> Result<u32, Error> {
        let l = self.plan()?;
        if !self.has_obstacles() {
            return Err(Error::new(ErrorKind::NotEnabled, NO_OBSTACLES));
        }
        let frame = Frame { n: l.n, boundary: self.boundary, dim: self.dim as usize };
        let none = |_: [usize; 3]| false;
        let empty = Before { obstacle: &none, occupied: &none, body: &none, table: &[], cell: &|_| 0 };
        // At most the world's cell count, which a u32 holds (`Layout::of`).
        Addition::of_shape(shape, &frame, &mut |a| empty.entries_added(&frame, a)).map(|n| n as u32)
    }
}

impl World {
    /// This world's [`Frame`].
    pub(crate) fn frame(&self) -> Frame {
        Frame { n: self.layout().n, boundary: self.head.desc.boundary, dim: self.dim() }
    }

    fn surfaces_used(&self) -> &[Surface] {
        &self.plane::<Surface>(self.layout().surface())[..self.head.surfaces as usize]
    }

    /// [`Before::entries_added`] of the obstacles, particles and surface
    /// table as they are.
    #[inline(never)]
    fn entries_added(&self, a: &Addition<'_>) -> Result<usize, Error> {
        let l = *self.layout();
        let site = |c: [usize; 3]| l.site(c[0], c[1], c[2]);
        let before = Before {
            obstacle: &|c| self.is_static(site(c)),
            occupied: &|c| self.occupied(site(c)),
            body: &|c| self.is_body(site(c)),
            table: self.surfaces_used(),
            cell: &|c| site(c).cell as u32,
        };
        before.entries_added(&self.frame(), a)
    }

    /// The surface entries adding `shape` to this world now takes: what its
    /// table must have free for [`World::add_shape`] to succeed (which
    /// also checks the restitution). Refused as `add_shape` would refuse
    /// the shape: `CellOccupied` if it covers a particle, and so on.
    pub fn surface_entries(&self, shape: Shape) -> Result<u32, Error> {
        if !self.head.desc.has_obstacles() {
            return Err(Error::new(ErrorKind::NotEnabled, NO_OBSTACLES));
        }
        Addition::of_shape(shape, &self.frame(), &mut |a| self.entries_added(a)).map(|n| n as u32)
    }

    /// Inserts or replaces the entry of `entry.cell`; the caller checked that
    /// the table has room.
    fn put_surface(&mut self, entry: Surface) {
        let (head, p) = &mut self.byte_planes();
        let used = head.surfaces as usize;
        match p.surface[..used].binary_search_by_key(&entry.cell, |t| t.cell) {
            Ok(i) => p.surface[i] = entry,
            Err(i) => {
                p.surface.copy_within(i..used, i + 1);
                p.surface[i] = entry;
                head.surfaces += 1;
            }
        }
    }

    fn drop_surface(&mut self, cell: u32) {
        let (head, p) = &mut self.byte_planes();
        let used = head.surfaces as usize;
        if let Ok(i) = p.surface[..used].binary_search_by_key(&cell, |t| t.cell) {
            p.surface.copy_within(i + 1..used, i);
            head.surfaces -= 1;
        }
    }

    /// Adds `a`'s cells as obstacles of restitution `e`, each new surface
    /// cell's normal normalised here; `from_mask` says it is M7's
    /// free-neighbour normal.
    ///
    /// Existing obstacle cells next to the new ones are kept up to date: an
    /// entry whose cell no longer has a free neighbour is dropped, and a
    /// free-neighbour normal is computed again. Two passes: the first checks
    /// everything against the obstacles as they will be
    /// ([`Before::entries_added`]), the second writes.
    fn add_obstacles(&mut self, a: &Addition<'_>, e: f32, from_mask: bool) -> Result<(), Error> {
        // `has_obstacles`: a build without obstacles keeps none of this.
        if !self.head.desc.has_obstacles() {
            return Err(Error::new(ErrorKind::NotEnabled, NO_OBSTACLES));
        }
        restitution(e, E)?;
        let (l, frame) = (*self.layout(), self.frame());
        let site = |c: [usize; 3]| l.site(c[0], c[1], c[2]);
        let new_entries = self.entries_added(a)?;
        let capacity = l.surface().len / core::mem::size_of::<Surface>();
        if self.head.surfaces as usize + new_entries > capacity {
            return Err(Error::new(ErrorKind::SurfaceTableFull, c"desc.surface_capacity"));
        }

        // Pass 2: the bits, then the entries, read off the plane as it now is.
        // Nothing here can fail: pass 1 checked every cell.
        a.each(&mut |c| {
            put_bit(Cells::new(self.byte_planes().1.obstacle), site(c).bit, true);
            Ok(())
        })?;
        a.each(&mut |c| {
            let w: &World = self;
            let plane = |q: [usize; 3]| w.is_static(site(q));
            let cell = site(c).cell as u32;
            let entry = frame
                .is_surface(c, &plane)
                .then(|| normalise((a.normal)(&frame, c, &plane)))
                .flatten()
                .map(|n| Surface { cell, normal: n, restitution: e, from_mask: u32::from(from_mask) });
            match entry {
                Some(entry) => self.put_surface(entry),
                None => self.drop_surface(cell),
            }
            let mut stale = [[0usize; 3]; 26];
            let mut count = 0;
            let w: &World = self;
            let _ = frame.for_old_neighbours(a, &|q| w.is_static(site(q)), c, &mut |nb| {
                stale[count] = nb;
                count += 1;
                Ok(())
            });
            for &nb in &stale[..count] {
                let w: &World = self;
                let plane = |q: [usize; 3]| w.is_static(site(q));
                let cell = site(nb).cell as u32;
                let Some(old) = surface_at(w.surfaces_used(), cell).copied() else { continue };
                if !frame.is_surface(nb, &plane) {
                    self.drop_surface(cell);
                } else if old.from_mask != 0 {
                    if let Some(n) = normalise(frame.mask_normal(nb, &plane)) {
                        self.put_surface(Surface { normal: n, ..old });
                    }
                }
            }
            Ok(())
        })?;
        // M13: a body cell next to the new cells may have lost its last
        // free neighbour: the body surface table is made again (it can only
        // shrink; the body cells stay as they are).
        #[cfg(feature = "obstacles")]
        self.refresh_bodies();
        Ok(())
    }

    /// Makes one cell an obstacle with the given outward normal (normalised
    /// here) and restitution.
    pub fn add_obstacle(&mut self, pos: [u32; 3], normal: [f32; 3], e: f32) -> Result<(), Error> {
        self.locate(pos)?;
        finite(&normal, c"normal")?;
        let nrm = in_plane(normal, self.dim());
        normalise(nrm).ok_or(Error::new(ErrorKind::UndefinedNormal, c"normal"))?;
        let c = pos.map(|v| v as usize);
        let a = Addition { lo: c, hi: c.map(|v| v + 1), inside: &|q| q == c, normal: &|_, _, _| nrm };
        self.add_obstacles(&a, e, false)
    }

    /// Adds a shape's cells as obstacles with restitution `e`, normals from
    /// the shape's exact geometry (M7). [`World::surface_entries`] says how
    /// many surface entries it takes.
    // Out of line: one copy for the C library's exports of every shape.
    #[inline(never)]
    pub fn add_shape(&mut self, shape: Shape, e: f32) -> Result<(), Error> {
        Addition::of_shape(shape, &self.frame(), &mut |a| self.add_obstacles(a, e, false).map(|()| 0)).map(drop)
    }

    /// Adds every cell whose byte in `mask` (one per cell, x fastest) is not
    /// zero as an obstacle with restitution `e`. A surface cell's normal is
    /// the normalised sum of the unit directions to its free neighbours (M7);
    /// a mask where that sum vanishes for some surface cell (a wall one cell
    /// thick, say) is refused with `UndefinedNormal`.
    pub fn add_obstacle_mask(&mut self, mask: &[u8], e: f32) -> Result<(), Error> {
        let l = *self.layout();
        if mask.len() != l.cells {
            return Err(Error::new(ErrorKind::BadLength, c"mask"));
        }
        let inside = |c: [usize; 3]| mask[l.site(c[0], c[1], c[2]).cell] != 0;
        let normal = |f: &Frame, c, obstacle: Mask<'_>| f.mask_normal(c, obstacle);
        self.add_obstacles(&Addition { lo: [0; 3], hi: l.n, inside: &inside, normal: &normal }, e, true)
    }

    /// Whether `pos` is an obstacle (false outside the world).
    pub fn obstacle_at(&self, pos: [u32; 3]) -> bool {
        self.locate(pos).is_ok_and(|s| self.is_obstacle(s))
    }

    /// The surface entry of the obstacle at `pos`, if it is a surface cell.
    pub fn surface(&self, pos: [u32; 3]) -> Option<Surface> {
        let s = self.locate(pos).ok()?;
        let table: &[Surface] = self.plane(self.layout().surface());
        surface_at(&table[..self.head.surfaces as usize], s.cell as u32).copied()
    }
}
