//! Obstacles (M7) and the reflection off them (M5.4, eq. 9).
//!
//! Obstacle cells are a bit plane. Surface cells (those with a free cell
//! among their `3^D - 1` neighbours, so a particle can ask to move into them)
//! also get an entry in a table sorted by cell index, holding the unit outward
//! normal and the restitution. Shapes give exact normals from their geometry
//! at the cell centre; an arbitrary mask gives the normalised sum of the
//! directions to the free neighbours. A surface cell whose normal would be
//! undefined is refused, and so is anything that does not fit: adding an
//! obstacle either succeeds whole or changes nothing.

use crate::Error;
use crate::api::desc::{finite, restitution, Boundary};
use crate::rules::vector::{dot, normalise};
use crate::step::partition::{resolve, Beyond, Coords};
use crate::storage::cells::Cells;
use crate::storage::layout::{put_bit, row_words, test_bit, Plain};
use crate::storage::world::World;

/// One obstacle surface cell.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct Surface {
    /// Dense cell index `x + nx (y + ny z)`.
    pub cell: u32,
    /// Unit outward normal, pointing into free space.
    pub normal: [f32; 3],
    /// Restitution `e` of eq. 9.
    pub restitution: f32,
    /// 1 where the normal is M7's free-neighbour normal of a mask, which is
    /// recomputed when obstacles are added next to the cell; 0 where it was
    /// given or came from a shape's geometry.
    pub from_mask: u32,
}

// SAFETY: u32 and f32 fields, no padding, every bit pattern valid.
unsafe impl Plain for Surface {}

/// Obstacle shapes with exact normals (M7). Coordinates are in cell units;
/// cell `(i, j, k)` has its centre at `(i + 0.5, j + 0.5, k + 0.5)` and
/// belongs to the shape when its centre does.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// Every cell on the far side of the plane through `point` with outward
    /// unit normal `normal` (a floor when the normal points up).
    HalfSpace {
        /// A point on the plane.
        point: [f32; 3],
        /// Outward normal; need not be unit length, must not be zero. In 2D
        /// only its x and y count (as for [`World::add_obstacle`]'s normal),
        /// and they must not both be zero.
        normal: [f32; 3],
    },
    /// An axis-aligned box `min <= centre <= max`.
    Box {
        /// Lower corner.
        min: [f32; 3],
        /// Upper corner.
        max: [f32; 3],
    },
    /// A disc (2D worlds only).
    Disc {
        /// Centre.
        centre: [f32; 2],
        /// Radius, greater than zero.
        radius: f32,
    },
    /// A sphere (3D worlds only).
    Sphere {
        /// Centre.
        centre: [f32; 3],
        /// Radius, greater than zero.
        radius: f32,
    },
}

/// Eq. 9: `v' = v - (1 + e)(N.v)N`, for a particle moving into the surface
/// (`N.v < 0`; the step makes sure of that by choosing `N`). A particle
/// moving away along `N` is returned unchanged, never turned back into the
/// obstacle.
#[inline]
pub(crate) fn reflect(v: [f32; 3], n: [f32; 3], e: f32) -> [f32; 3] {
    let vn = dot(v, n);
    if vn >= 0.0 {
        return v;
    }
    let s = (1.0 + e) * vn;
    [v[0] - s * n[0], v[1] - s * n[1], v[2] - s * n[2]]
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

/// The surface entry of `cell`, if any, by binary search.
#[inline]
pub(crate) fn surface_at(table: &[Surface], cell: u32) -> Option<&Surface> {
    table.binary_search_by_key(&cell, |s| s.cell).ok().map(|i| &table[i])
}

/// A set of cells, as a predicate on coordinates.
type Mask<'a> = &'a dyn Fn([usize; 3]) -> bool;

/// Gives a surface cell's outward normal, unnormalised, given the set of
/// cells that will be obstacles.
type NormalFn<'a> = &'a dyn Fn(&World, [usize; 3], Mask<'_>) -> [f32; 3];

impl Shape {
    /// The shape as a world of `dim` dimensions uses it: in 2D a
    /// half-space's normal loses its z, as [`World::add_obstacle`]'s does
    /// (every other shape reads only the axes the world has).
    fn in_dim(self, dim: usize) -> Shape {
        match self {
            Shape::HalfSpace { point, normal } => Shape::HalfSpace { point, normal: in_plane(normal, dim) },
            other => other,
        }
    }

    /// Checks every float as given, then the shape as the world uses it.
    fn check(&self, dim: usize) -> Result<(), Error> {
        match *self {
            Shape::HalfSpace { point, normal } => {
                finite(&point)?;
                finite(&normal)?;
                normalise(in_plane(normal, dim)).ok_or(Error::BadShape)?;
            }
            Shape::Box { min, max } => {
                finite(&min)?;
                finite(&max)?;
                if (0..dim).any(|k| min[k] > max[k]) {
                    return Err(Error::BadShape);
                }
            }
            Shape::Disc { centre, radius } => {
                finite(&[centre[0], centre[1], radius])?;
                if dim != 2 {
                    return Err(Error::BadDimension);
                }
                if radius <= 0.0 {
                    return Err(Error::BadShape);
                }
            }
            Shape::Sphere { centre, radius } => {
                finite(&centre)?;
                finite(&[radius])?;
                if dim != 3 {
                    return Err(Error::BadDimension);
                }
                if radius <= 0.0 {
                    return Err(Error::BadShape);
                }
            }
        }
        Ok(())
    }

    fn contains(&self, c: [f32; 3], dim: usize) -> bool {
        match *self {
            Shape::HalfSpace { point, normal } => {
                let mut s = 0.0;
                for k in 0..dim {
                    s += (c[k] - point[k]) * normal[k];
                }
                s <= 0.0
            }
            Shape::Box { min, max } => (0..dim).all(|k| min[k] <= c[k] && c[k] <= max[k]),
            Shape::Disc { centre, radius } => {
                let (dx, dy) = (c[0] - centre[0], c[1] - centre[1]);
                dx * dx + dy * dy <= radius * radius
            }
            Shape::Sphere { centre, radius } => {
                let d = [c[0] - centre[0], c[1] - centre[1], c[2] - centre[2]];
                dot(d, d) <= radius * radius
            }
        }
    }

    /// The outward normal at a cell centre inside the shape (not normalised;
    /// zero where the geometry defines none).
    fn normal(&self, c: [f32; 3], dim: usize) -> [f32; 3] {
        match *self {
            Shape::HalfSpace { normal, .. } => normal,
            Shape::Box { min, max } => {
                // The nearest face, or the sum of the nearest faces where
                // several are equally near (edges and corners).
                let mut best = f32::INFINITY;
                for k in 0..dim {
                    best = best.min(c[k] - min[k]).min(max[k] - c[k]);
                }
                let mut n = [0.0; 3];
                for k in 0..dim {
                    if c[k] - min[k] == best {
                        n[k] -= 1.0;
                    }
                    if max[k] - c[k] == best {
                        n[k] += 1.0;
                    }
                }
                n
            }
            Shape::Disc { centre, .. } => [c[0] - centre[0], c[1] - centre[1], 0.0],
            Shape::Sphere { centre, .. } => [c[0] - centre[0], c[1] - centre[1], c[2] - centre[2]],
        }
    }

    /// Cells whose centres may lie inside, per axis `lo..hi`.
    fn bounds(&self, n: [usize; 3], dim: usize) -> ([usize; 3], [usize; 3]) {
        let (lo, hi): ([f32; 3], [f32; 3]) = match *self {
            Shape::HalfSpace { .. } => return ([0; 3], n),
            Shape::Box { min, max } => (min, max),
            Shape::Disc { centre, radius } => {
                ([centre[0] - radius, centre[1] - radius, 0.0], [centre[0] + radius, centre[1] + radius, 1.0])
            }
            Shape::Sphere { centre, radius } => (centre.map(|c| c - radius), centre.map(|c| c + radius)),
        };
        // Axes the world does not have span their single cell.
        let mut a = [0usize; 3];
        let mut b = n;
        for k in 0..dim {
            // Centre i + 0.5 >= lo  <=>  i >= lo - 0.5; float-to-int casts
            // saturate, so huge shapes are clipped to the world.
            a[k] = (libm::floorf(lo[k] - 0.5).max(0.0) as usize).min(n[k]);
            b[k] = ((libm::floorf(hi[k] - 0.5) + 1.0).max(0.0) as usize).min(n[k]);
        }
        (a, b)
    }
}

/// A normal without the z a 2D world does not have.
fn in_plane(normal: [f32; 3], dim: usize) -> [f32; 3] {
    if dim == 2 { [normal[0], normal[1], 0.0] } else { normal }
}

fn centre(c: [usize; 3]) -> [f32; 3] {
    c.map(|v| v as f32 + 0.5)
}

impl World {
    /// The neighbour of `c` at offset `off`, after the boundary rules (M4).
    fn beyond(&self, c: [usize; 3], off: [i32; 3]) -> Beyond {
        let at = [0, 1, 2].map(|k| c[k] as isize + off[k] as isize);
        resolve(self.layout().n, &self.head.desc.boundary, at)
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
        let zr = if self.dim() == 3 { -1..=1 } else { 0..=0 };
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
    /// `obstacle` holds are obstacles.
    fn is_surface(&self, c: [usize; 3], obstacle: Mask<'_>) -> bool {
        let mut free = false;
        self.for_neighbours(|off| free |= self.free_after(c, off, obstacle));
        free
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

    fn surfaces_used(&self) -> &[Surface] {
        &self.plane::<Surface>(self.layout().surface())[..self.head.surfaces as usize]
    }

    /// Inserts or replaces the entry of `entry.cell`; the caller checked that
    /// the table has room.
    fn put_surface(&mut self, entry: Surface) {
        let (head, p) = self.planes::<u8>();
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
        let (head, p) = self.planes::<u8>();
        let used = head.surfaces as usize;
        if let Ok(i) = p.surface[..used].binary_search_by_key(&cell, |t| t.cell) {
            p.surface.copy_within(i + 1..used, i);
            head.surfaces -= 1;
        }
    }

    /// Adds the cells in `lo..hi` for which `inside` holds as obstacles of
    /// restitution `e`; `normal` gives each new surface cell's outward normal
    /// (normalised here), `from_mask` says it is M7's free-neighbour normal.
    ///
    /// Existing obstacle cells next to the new ones are kept up to date: an
    /// entry whose cell no longer has a free neighbour is dropped, and a
    /// free-neighbour normal is computed again. Two passes: the first checks
    /// everything against the obstacles as they will be, the second writes.
    fn add_obstacles(
        &mut self,
        lo: [usize; 3],
        hi: [usize; 3],
        e: f32,
        inside: Mask<'_>,
        normal: NormalFn<'_>,
        from_mask: bool,
    ) -> Result<(), Error> {
        if !self.head.desc.obstacles {
            return Err(Error::NotEnabled);
        }
        restitution(e)?;
        let l = *self.layout();
        let site = |c: [usize; 3]| l.site(c[0], c[1], c[2]);
        let each = |f: &mut dyn FnMut([usize; 3]) -> Result<(), Error>| -> Result<(), Error> {
            for z in lo[2]..hi[2] {
                for y in lo[1]..hi[1] {
                    for x in lo[0]..hi[0] {
                        if inside([x, y, z]) {
                            f([x, y, z])?;
                        }
                    }
                }
            }
            Ok(())
        };
        // Existing obstacle cells next to new cell `c`, outside the new set.
        let old_neighbours = |w: &World, c: [usize; 3], f: &mut dyn FnMut([usize; 3]) -> Result<(), Error>| {
            let mut result = Ok(());
            w.for_neighbours(|off| {
                if let (Ok(()), Beyond::Inside(nb)) = (result, w.beyond(c, off)) {
                    if w.is_obstacle(site(nb)) && !inside(nb) {
                        result = f(nb);
                    }
                }
            });
            result
        };

        // Pass 1: check, and count the entries to add.
        let mut new_entries = 0usize;
        {
            let w: &World = self;
            let after = |c: [usize; 3]| w.is_obstacle(site(c)) || inside(c);
            let table = w.surfaces_used();
            each(&mut |c| {
                if w.occupied(site(c)) {
                    return Err(Error::CellOccupied);
                }
                if w.is_surface(c, &after) {
                    normalise(normal(w, c, &after)).ok_or(Error::UndefinedNormal)?;
                    new_entries += usize::from(surface_at(table, site(c).cell as u32).is_none());
                }
                old_neighbours(w, c, &mut |nb| {
                    let old = surface_at(table, site(nb).cell as u32);
                    if old.is_some_and(|s| s.from_mask != 0) && w.is_surface(nb, &after) {
                        normalise(w.mask_normal(nb, &after)).ok_or(Error::UndefinedNormal)?;
                    }
                    Ok(())
                })
            })?;
        }
        let capacity = l.surface().len / core::mem::size_of::<Surface>();
        if self.head.surfaces as usize + new_entries > capacity {
            return Err(Error::SurfaceTableFull);
        }

        // Pass 2: the bits, then the entries, read off the plane as it now is.
        // Nothing here can fail: pass 1 checked every cell.
        each(&mut |c| {
            put_bit(Cells::new(self.planes::<u8>().1.obstacle), site(c).bit, true);
            Ok(())
        })?;
        each(&mut |c| {
            let w: &World = self;
            let plane = |q: [usize; 3]| w.is_obstacle(site(q));
            let cell = site(c).cell as u32;
            let entry = w
                .is_surface(c, &plane)
                .then(|| normalise(normal(w, c, &plane)))
                .flatten()
                .map(|n| Surface { cell, normal: n, restitution: e, from_mask: u32::from(from_mask) });
            match entry {
                Some(entry) => self.put_surface(entry),
                None => self.drop_surface(cell),
            }
            let mut stale = [[0usize; 3]; 26];
            let mut count = 0;
            let _ = old_neighbours(self, c, &mut |nb| {
                stale[count] = nb;
                count += 1;
                Ok(())
            });
            for &nb in &stale[..count] {
                let w: &World = self;
                let plane = |q: [usize; 3]| w.is_obstacle(site(q));
                let cell = site(nb).cell as u32;
                let Some(old) = surface_at(w.surfaces_used(), cell).copied() else { continue };
                if !w.is_surface(nb, &plane) {
                    self.drop_surface(cell);
                } else if old.from_mask != 0 {
                    if let Some(n) = normalise(w.mask_normal(nb, &plane)) {
                        self.put_surface(Surface { normal: n, ..old });
                    }
                }
            }
            Ok(())
        })
    }

    /// Makes one cell an obstacle with the given outward normal (normalised
    /// here) and restitution.
    pub fn add_obstacle(&mut self, pos: [u32; 3], normal: [f32; 3], e: f32) -> Result<(), Error> {
        self.locate(pos)?;
        finite(&normal)?;
        let nrm = in_plane(normal, self.dim());
        normalise(nrm).ok_or(Error::UndefinedNormal)?;
        let c = pos.map(|v| v as usize);
        self.add_obstacles(c, c.map(|v| v + 1), e, &|q| q == c, &|_, _, _| nrm, false)
    }

    /// Adds a shape's cells as obstacles with restitution `e`, normals from
    /// the shape's exact geometry (M7).
    pub fn add_shape(&mut self, shape: Shape, e: f32) -> Result<(), Error> {
        let dim = self.dim();
        shape.check(dim)?;
        let shape = shape.in_dim(dim);
        let (lo, hi) = shape.bounds(self.layout().n, dim);
        let normal = |_: &World, c, _: Mask<'_>| shape.normal(centre(c), dim);
        self.add_obstacles(lo, hi, e, &|c| shape.contains(centre(c), dim), &normal, false)
    }

    /// Adds every cell whose byte in `mask` (one per cell, x fastest) is not
    /// zero as an obstacle with restitution `e`. A surface cell's normal is
    /// the normalised sum of the unit directions to its free neighbours (M7);
    /// a mask where that sum vanishes for some surface cell (a wall one cell
    /// thick, say) is refused with `UndefinedNormal`.
    pub fn add_obstacle_mask(&mut self, mask: &[u8], e: f32) -> Result<(), Error> {
        let l = *self.layout();
        if mask.len() != l.cells {
            return Err(Error::BadLength);
        }
        let inside = |c: [usize; 3]| mask[l.site(c[0], c[1], c[2]).cell] != 0;
        let normal = |w: &World, c, obstacle: Mask<'_>| w.mask_normal(c, obstacle);
        self.add_obstacles([0; 3], l.n, e, &inside, &normal, true)
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
