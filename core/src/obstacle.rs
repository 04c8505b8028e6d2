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

use crate::collision::dot;
use crate::desc::{finite, restitution, Boundary};
use crate::world::{put_bit, Plain, World};
use crate::Error;

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
        /// Outward normal; need not be unit length, must not be zero.
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

/// `v / |v|`, or `None` where the length is zero or not finite.
pub(crate) fn normalise(v: [f32; 3]) -> Option<[f32; 3]> {
    let len = libm::sqrtf(dot(v, v));
    (len.is_finite() && len > 1e-6).then(|| [v[0] / len, v[1] / len, v[2] / len])
}

/// Eq. 9: `v' = v - (1 + e)(N.v)N`. Applied only to a particle moving into
/// the surface (`N.v < 0`); one already moving away along `N` keeps its
/// velocity, since eq. 9 would turn it back into the obstacle. Either way the
/// particle stays this step (M5.4).
#[inline]
pub(crate) fn reflect(v: [f32; 3], n: [f32; 3], e: f32) -> [f32; 3] {
    let vn = dot(v, n);
    if vn >= 0.0 {
        return v;
    }
    let s = (1.0 + e) * vn;
    [v[0] - s * n[0], v[1] - s * n[1], v[2] - s * n[2]]
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

/// What lies at a neighbour of a cell.
enum Beyond {
    Inside([usize; 3]),
    Wall,
    Open,
}

impl Shape {
    fn check(&self, dim: usize) -> Result<(), Error> {
        match *self {
            Shape::HalfSpace { point, normal } => {
                finite(&point)?;
                finite(&normal)?;
                normalise(normal).ok_or(Error::BadShape)?;
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
    fn bounds(&self, n: [usize; 3]) -> ([usize; 3], [usize; 3]) {
        let (lo, hi): ([f32; 3], [f32; 3]) = match *self {
            Shape::HalfSpace { .. } => return ([0; 3], n),
            Shape::Box { min, max } => (min, max),
            Shape::Disc { centre, radius } => {
                ([centre[0] - radius, centre[1] - radius, 0.0], [centre[0] + radius, centre[1] + radius, 1.0])
            }
            Shape::Sphere { centre, radius } => (centre.map(|c| c - radius), centre.map(|c| c + radius)),
        };
        let mut a = [0usize; 3];
        let mut b = [1usize; 3];
        for k in 0..3 {
            // Centre i + 0.5 >= lo  <=>  i >= lo - 0.5; float-to-int casts
            // saturate, so huge shapes are clipped to the world.
            a[k] = (libm::floorf(lo[k] - 0.5).max(0.0) as usize).min(n[k]);
            b[k] = ((libm::floorf(hi[k] - 0.5) + 1.0).max(0.0) as usize).min(n[k]);
        }
        (a, b)
    }
}

fn centre(c: [usize; 3]) -> [f32; 3] {
    c.map(|v| v as f32 + 0.5)
}

impl World {
    /// The neighbour of `c` at offset `off`, after the boundary rules (M4).
    fn beyond(&self, c: [usize; 3], off: [i32; 3]) -> Beyond {
        let l = self.layout();
        let mut out = [0usize; 3];
        let mut wall = false;
        let mut open = false;
        for k in 0..3 {
            let v = c[k] as i64 + i64::from(off[k]);
            let n = l.n[k] as i64;
            if (0..n).contains(&v) {
                out[k] = v as usize;
                continue;
            }
            let face = self.head.desc.boundary[k][usize::from(v >= n)];
            match face {
                Boundary::Periodic => out[k] = v.rem_euclid(n) as usize,
                Boundary::Wall => wall = true,
                Boundary::Open => open = true,
            }
        }
        // A cell beyond a wall and an open face at once is wall (M4 corner).
        if wall {
            Beyond::Wall
        } else if open {
            Beyond::Open
        } else {
            Beyond::Inside(out)
        }
    }

    /// Whether the neighbour of `c` at `off` is free once the cells for which
    /// `obstacle` holds are obstacles: inside and not an obstacle, or beyond
    /// an open face.
    fn free_after(&self, c: [usize; 3], off: [i32; 3], obstacle: Mask<'_>) -> bool {
        match self.beyond(c, off) {
            Beyond::Inside(nb) => !obstacle(nb),
            Beyond::Wall => false,
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

    /// Adds the cells in `lo..hi` for which `inside` holds as obstacles of
    /// restitution `e`; `normal` gives each surface cell's outward normal
    /// (normalised here). Two passes: the first checks everything and counts
    /// new surface entries, the second writes.
    fn add_obstacles(
        &mut self,
        lo: [usize; 3],
        hi: [usize; 3],
        e: f32,
        inside: Mask<'_>,
        normal: NormalFn<'_>,
    ) -> Result<(), Error> {
        if !self.head.desc.obstacles {
            return Err(Error::NotEnabled);
        }
        restitution(e)?;
        let l = *self.layout();
        let obstacle_after = |w: &World, c: [usize; 3]| {
            w.is_obstacle(l.site(c[0], c[1], c[2])) || inside(c)
        };
        let surface_normal = |w: &World, c: [usize; 3]| -> Result<Option<[f32; 3]>, Error> {
            let after = |nb| obstacle_after(w, nb);
            let mut free = false;
            w.for_neighbours(|off| free |= w.free_after(c, off, &after));
            if !free {
                return Ok(None);
            }
            normalise(normal(w, c, &|nb| obstacle_after(w, nb))).map(Some).ok_or(Error::UndefinedNormal)
        };
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
        let used = self.head.surfaces as usize;
        let mut new_entries = 0usize;
        {
            let table: &[Surface] = &self.plane::<Surface>(l.surface)[..used];
            let w: &World = self;
            each(&mut |c| {
                let s = l.site(c[0], c[1], c[2]);
                if w.occupied(s) {
                    return Err(Error::CellOccupied);
                }
                if surface_normal(w, c)?.is_some() && surface_at(table, s.cell as u32).is_none() {
                    new_entries += 1;
                }
                Ok(())
            })?;
        }
        let capacity = l.surface.len / core::mem::size_of::<Surface>();
        if used + new_entries > capacity {
            return Err(Error::SurfaceTableFull);
        }
        // Pass 2: normals first (they read the plane as it will be), then
        // the bits. Cannot fail: pass 1 checked every cell.
        let mut count = used;
        each(&mut |c| {
            let s = l.site(c[0], c[1], c[2]);
            if let Ok(Some(n)) = surface_normal(self, c) {
                let (head, p) = self.planes::<u8>();
                let entry = Surface { cell: s.cell as u32, normal: n, restitution: e };
                match p.surface[..count].binary_search_by_key(&entry.cell, |t| t.cell) {
                    Ok(i) => p.surface[i] = entry,
                    Err(i) => {
                        p.surface.copy_within(i..count, i + 1);
                        p.surface[i] = entry;
                        count += 1;
                        head.surfaces = count as u32;
                    }
                }
            }
            Ok(())
        })?;
        each(&mut |c| {
            let s = l.site(c[0], c[1], c[2]);
            put_bit(self.planes::<u8>().1.obstacle, s.bit, true);
            Ok(())
        })
    }

    /// Makes one cell an obstacle with the given outward normal (normalised
    /// here) and restitution.
    pub fn add_obstacle(&mut self, pos: [u32; 3], normal: [f32; 3], e: f32) -> Result<(), Error> {
        let s = self.locate(pos)?;
        finite(&normal)?;
        let mut nrm = normal;
        if self.dim() == 2 {
            nrm[2] = 0.0;
        }
        normalise(nrm).ok_or(Error::UndefinedNormal)?;
        let c = pos.map(|v| v as usize);
        let _ = s;
        self.add_obstacles(c, c.map(|v| v + 1), e, &|q| q == c, &|_, _, _| nrm)
    }

    /// Adds a shape's cells as obstacles with restitution `e`, normals from
    /// the shape's exact geometry (M7).
    pub fn add_shape(&mut self, shape: Shape, e: f32) -> Result<(), Error> {
        let dim = self.dim();
        shape.check(dim)?;
        let (lo, hi) = shape.bounds(self.layout().n);
        self.add_obstacles(lo, hi, e, &|c| shape.contains(centre(c), dim), &|_, c, _| shape.normal(centre(c), dim))
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
        let normal = |w: &World, c: [usize; 3], obstacle_after: Mask<'_>| {
            let mut sum = [0.0f32; 3];
            w.for_neighbours(|off| {
                if w.free_after(c, off, obstacle_after) {
                    let d = normalise(off.map(|o| o as f32)).unwrap_or([0.0; 3]);
                    for k in 0..3 {
                        sum[k] += d[k];
                    }
                }
            });
            sum
        };
        self.add_obstacles([0; 3], l.n, e, &inside, &normal)
    }

    /// Whether `pos` is an obstacle (false outside the world).
    pub fn obstacle_at(&self, pos: [u32; 3]) -> bool {
        self.locate(pos).is_ok_and(|s| self.is_obstacle(s))
    }

    /// The surface entry of the obstacle at `pos`, if it is a surface cell.
    pub fn surface(&self, pos: [u32; 3]) -> Option<Surface> {
        let s = self.locate(pos).ok()?;
        let table: &[Surface] = self.plane(self.layout().surface);
        surface_at(&table[..self.head.surfaces as usize], s.cell as u32).copied()
    }
}
