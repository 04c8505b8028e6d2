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

use crate::{Error, ErrorKind};
use crate::api::checks::finite;
use crate::rules::vector::{dot, normalise};
use crate::rules::fixed::{mulq, sat, scaled, DIAGONAL_Q30};

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
        /// only its x and y count (as for [`World::add_obstacle`](crate::World::add_obstacle)'s normal),
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
    /// The points within `radius` of the segment from `a` to `b` (a disc
    /// or sphere where `a = b`); in 2D only x and y count.
    Capsule {
        /// One end of the segment.
        a: [f32; 3],
        /// The other end.
        b: [f32; 3],
        /// Radius, greater than zero.
        radius: f32,
    },
}

/// Eq. 9 in fine units (M1c): `v' = v - (1 + e)(N.v)N` with the normal
/// `n` in Q30 and the restitution `e` in Q16, for a particle moving into
/// the surface (`N.v < 0`; the step makes sure of that by choosing `N`).
/// `N.v` is the exact dot product, rounded down once. A particle moving
/// away along `N` is returned unchanged, never turned back into the
/// obstacle.
#[inline]
pub(crate) fn reflect(v: [i32; 3], n: [i32; 3], e: i32) -> [i32; 3] {
    let exact = dot_q30(v, n);
    if exact >= 0 {
        return v;
    }
    let s = mulq(sat(exact >> 30), (1 << 16) + e, 16);
    [0, 1, 2].map(|k| sat(i64::from(v[k]) - i64::from(mulq(s, n[k], 30))))
}

/// The exact dot product of a velocity (or a Q30 vector) with a Q30 one.
#[inline]
pub(crate) fn dot_q30(v: [i32; 3], n: [i32; 3]) -> i64 {
    (0..3).map(|k| i64::from(v[k]) * i64::from(n[k])).sum()
}

/// A normal in Q30 (M1c), converted from its float where it is read:
/// `round(n_k 2^30)`.
#[inline]
pub(crate) fn normal_q30(n: [f32; 3]) -> [i32; 3] {
    n.map(|c| scaled(c, 1.0, 30).clamp(-(1 << 30), 1 << 30) as i32)
}

/// The unit vector along `dir`, whose components are -1, 0 or 1, in Q30
/// from the exact constants of M1c (an axis, a 2D or a 3D diagonal).
#[inline]
pub(crate) fn axis_q30(dir: [i32; 3]) -> [i32; 3] {
    let count = dir.iter().filter(|&&c| c != 0).count();
    let unit = match count {
        1 => 1 << 30,
        2 => DIAGONAL_Q30[0],
        _ => DIAGONAL_Q30[1],
    };
    dir.map(|c| c * unit)
}

/// The surface entry of `cell`, if any, by binary search.
#[inline]
pub(crate) fn surface_at(table: &[Surface], cell: u32) -> Option<&Surface> {
    table.binary_search_by_key(&cell, |s| s.cell).ok().map(|i| &table[i])
}

impl Shape {
    /// The shape from four values, as C's `mpca_shape` and an image's body
    /// table (M12, M13) hold it: `kind` 0 a half-space (`a` a point, `b`
    /// the normal), 1 a box (`a`, `b` its corners), 2 a disc (`a`'s x and
    /// y its centre), 3 a sphere (`a` its centre), 4 a capsule (`a`, `b`
    /// its ends); `radius` for the last three. `None` for another kind.
    pub fn from_parts(kind: u32, a: [f32; 3], b: [f32; 3], radius: f32) -> Option<Shape> {
        Some(match kind {
            0 => Shape::HalfSpace { point: a, normal: b },
            1 => Shape::Box { min: a, max: b },
            2 => Shape::Disc { centre: [a[0], a[1]], radius },
            3 => Shape::Sphere { centre: a, radius },
            4 => Shape::Capsule { a, b, radius },
            _ => return None,
        })
    }

    /// The four values [`Shape::from_parts`] takes back.
    pub fn parts(&self) -> (u32, [f32; 3], [f32; 3], f32) {
        match *self {
            Shape::HalfSpace { point, normal } => (0, point, normal, 0.0),
            Shape::Box { min, max } => (1, min, max, 0.0),
            Shape::Disc { centre, radius } => (2, [centre[0], centre[1], 0.0], [0.0; 3], radius),
            Shape::Sphere { centre, radius } => (3, centre, [0.0; 3], radius),
            Shape::Capsule { a, b, radius } => (4, a, b, radius),
        }
    }

    /// The shape as a world of `dim` dimensions uses it: in 2D a
    /// half-space's normal loses its z, as [`World::add_obstacle`](crate::World::add_obstacle)'s does
    /// (every other shape reads only the axes the world has).
    pub(crate) fn in_dim(self, dim: usize) -> Shape {
        match self {
            Shape::HalfSpace { point, normal } => Shape::HalfSpace { point, normal: in_plane(normal, dim) },
            Shape::Capsule { a, b, radius } => Shape::Capsule { a: in_plane(a, dim), b: in_plane(b, dim), radius },
            other => other,
        }
    }

    /// Checks every float as given, then the shape as the world uses it.
    pub(crate) fn check(&self, dim: usize) -> Result<(), Error> {
        use ErrorKind as K;
        match *self {
            Shape::HalfSpace { point, normal } => {
                let detail = c"shape";
                finite(&point, detail)?;
                finite(&normal, detail)?;
                normalise(in_plane(normal, dim)).ok_or(Error::new(K::BadShape, c"shape: normal of length 0"))?;
            }
            Shape::Box { min, max } => {
                let detail = c"shape";
                finite(&min, detail)?;
                finite(&max, detail)?;
                if (0..dim).any(|k| min[k] > max[k]) {
                    return Err(Error::new(K::BadShape, c"shape: box min above max"));
                }
            }
            Shape::Disc { centre, radius } => {
                finite(&[centre[0], centre[1], radius], c"shape")?;
                if dim != 2 {
                    return Err(Error::new(K::BadDimension, c"shape: a disc in 3D"));
                }
                if radius <= 0.0 {
                    return Err(Error::new(K::BadShape, c"shape: radius"));
                }
            }
            Shape::Sphere { centre, radius } => {
                let detail = c"shape";
                finite(&centre, detail)?;
                finite(&[radius], detail)?;
                if dim != 3 {
                    return Err(Error::new(K::BadDimension, c"shape: a sphere in 2D"));
                }
                if radius <= 0.0 {
                    return Err(Error::new(K::BadShape, c"shape: radius"));
                }
            }
            Shape::Capsule { a, b, radius } => {
                let detail = c"shape";
                finite(&a, detail)?;
                finite(&b, detail)?;
                finite(&[radius], detail)?;
                if radius <= 0.0 {
                    return Err(Error::new(K::BadShape, c"shape: radius"));
                }
            }
        }
        Ok(())
    }

    pub(crate) fn contains(&self, c: [f32; 3], dim: usize) -> bool {
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
            Shape::Capsule { radius, .. } => {
                let d = self.off_axis(c, dim);
                dot(d, d) <= radius * radius
            }
        }
    }

    /// For a capsule, `c` less the point of its segment nearest to `c`
    /// (in the world's `dim` axes); zero for every other shape.
    fn off_axis(&self, c: [f32; 3], dim: usize) -> [f32; 3] {
        let Shape::Capsule { a, b, .. } = *self else { return [0.0; 3] };
        let (mut ab, mut ac) = ([0.0f32; 3], [0.0f32; 3]);
        for k in 0..dim {
            ab[k] = b[k] - a[k];
            ac[k] = c[k] - a[k];
        }
        let len2 = dot(ab, ab);
        let t = if len2 > 0.0 { (dot(ac, ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
        [0, 1, 2].map(|k| ac[k] - t * ab[k])
    }

    /// The outward normal at a cell centre inside the shape (not normalised;
    /// zero where the geometry defines none).
    pub(crate) fn normal(&self, c: [f32; 3], dim: usize) -> [f32; 3] {
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
            Shape::Capsule { .. } => self.off_axis(c, dim),
        }
    }

    /// Cells whose centres may lie inside, per axis `lo..hi`.
    pub(crate) fn bounds(&self, n: [usize; 3], dim: usize) -> ([usize; 3], [usize; 3]) {
        let (lo, hi): ([f32; 3], [f32; 3]) = match *self {
            Shape::HalfSpace { .. } => return ([0; 3], n),
            Shape::Box { min, max } => (min, max),
            Shape::Disc { centre, radius } => {
                ([centre[0] - radius, centre[1] - radius, 0.0], [centre[0] + radius, centre[1] + radius, 1.0])
            }
            Shape::Sphere { centre, radius } => (centre.map(|c| c - radius), centre.map(|c| c + radius)),
            Shape::Capsule { a, b, radius } => {
                ([0, 1, 2].map(|k| a[k].min(b[k]) - radius), [0, 1, 2].map(|k| a[k].max(b[k]) + radius))
            }
        };
        // Axes the world does not have span their single cell.
        let mut a = [0usize; 3];
        let mut b = n;
        for k in 0..dim {
            // Centre i + 0.5 >= lo  <=>  i >= lo - 0.5: from floor(lo - 0.5)
            // to floor(hi - 0.5) inclusive, clipped to the world. Below 0
            // the floor is clipped anyway, and above it the cast truncates,
            // which is the floor there; float-to-int casts saturate, so
            // huge shapes are clipped too.
            let (from, to) = (lo[k] - 0.5, hi[k] - 0.5);
            a[k] = if from > 0.0 { (from as usize).min(n[k]) } else { 0 };
            b[k] = if to >= 0.0 { (to as usize).saturating_add(1).min(n[k]) } else { 0 };
        }
        (a, b)
    }
}

/// A normal without the z a 2D world does not have.
pub(crate) fn in_plane(normal: [f32; 3], dim: usize) -> [f32; 3] {
    if dim == 2 { [normal[0], normal[1], 0.0] } else { normal }
}

pub(crate) fn centre(c: [usize; 3]) -> [f32; 3] {
    c.map(|v| v as f32 + 0.5)
}

