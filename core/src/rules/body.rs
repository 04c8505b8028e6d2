//! Kinematic obstacles (M13): bodies the caller moves, what the world keeps
//! of each, and the two rules that read a body's velocity: the push-out of
//! a particle a body takes, and eq. 9 in the frame of a moving surface.

use crate::{Error, ErrorKind};
use crate::api::obstacles::E;
use crate::api::checks::{finite, restitution};
use crate::rules::obstacle::{dot_q30, Shape};
use crate::rules::fixed::sat;

/// What a body exchanged with the particles: momentum in the body's
/// integers (M13: each particle's relative mass, 24 bits, times its change
/// of velocity in fine units, summed wrapping), and counts. A body keeps
/// the tally of the step under way and the last finished one. The step
/// also keeps one per body surface entry, which one block at most touches
/// in a step (a particle asks only for cells of its own block), so blocks
/// on any thread add to them without atomics; the step's end gathers them
/// into their bodies.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(C)]
pub(crate) struct Tally {
    pub momentum: [i64; 3],
    pub reflected: u32,
    pub pushed: u32,
    pub crushed: u32,
    pub spare: u32,
}

impl Tally {
    const ZERO: Tally = Tally { momentum: [0; 3], reflected: 0, pushed: 0, crushed: 0, spare: 0 };

    /// Adds a change of velocity `dv` (fine units) of a particle of
    /// relative mass `relative` to the momentum.
    pub(crate) fn add_change(&mut self, relative: u32, dv: [i32; 3]) {
        for k in 0..3 {
            self.momentum[k] = self.momentum[k].wrapping_add(i64::from(relative) * i64::from(dv[k]));
        }
    }

    /// Adds another tally, wrapping: sums in any order are the same.
    pub(crate) fn add(&mut self, o: &Tally) {
        for k in 0..3 {
            self.momentum[k] = self.momentum[k].wrapping_add(o.momentum[k]);
        }
        self.reflected = self.reflected.wrapping_add(o.reflected);
        self.pushed = self.pushed.wrapping_add(o.pushed);
        self.crushed = self.crushed.wrapping_add(o.crushed);
    }
}

/// One body surface cell (M13): as a static [`Surface`](crate::rules::obstacle::Surface),
/// with the body's index in place of the mask flag.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub(crate) struct BodySurface {
    pub cell: u32,
    pub normal: [f32; 3],
    pub restitution: f32,
    pub body: u32,
}

/// The body surface entry of `cell`, with its index in the table.
#[inline]
pub(crate) fn body_surface_at(table: &[BodySurface], cell: u32) -> Option<(usize, &BodySurface)> {
    table.binary_search_by_key(&cell, |s| s.cell).ok().map(|i| (i, &table[i]))
}

/// A slot of the body table. `kind` 0 is a free slot; otherwise the shape
/// is `kind - 1`, `a`, `b` and `radius` ([`Shape::from_parts`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub(crate) struct Body {
    pub kind: u32,
    pub restitution: f32,
    pub a: [f32; 3],
    pub b: [f32; 3],
    pub radius: f32,
    pub velocity: [f32; 3],
    /// The velocity in fine units (M1c), which the step and the push-outs
    /// read: converted when the body is set or loaded.
    pub fine: [i32; 3],
    pub spare: u32,
    pub current: Tally,
    pub last: Tally,
}

/// The head of the body table's plane: the world's count of particles the
/// bodies crushed, the redraws since the last step (M13's `r`) and the
/// used entries of the body surface table.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(C)]
pub(crate) struct BodiesHead {
    pub crushed: u64,
    pub redraws: u32,
    pub surfaces: u32,
}

impl Body {
    /// A free slot.
    pub(crate) const ZERO: Body = Body {
        kind: 0,
        restitution: 0.0,
        a: [0.0; 3],
        b: [0.0; 3],
        radius: 0.0,
        velocity: [0.0; 3],
        fine: [0; 3],
        spare: 0,
        current: Tally::ZERO,
        last: Tally::ZERO,
    };

    /// A body of `shape`, velocity `u` and restitution `e`, checked for a
    /// world of `dim` dimensions.
    pub(crate) fn new(shape: Shape, u: [f32; 3], e: f32, dim: usize) -> Result<Body, Error> {
        let mut body = Body { restitution: e, ..Body::ZERO };
        body.set(shape, u, dim)?;
        restitution(e, E)?;
        Ok(body)
    }

    /// Gives the body a new shape and velocity (checked), keeping its
    /// restitution and tallies.
    #[inline(never)]
    pub(crate) fn set(&mut self, shape: Shape, u: [f32; 3], dim: usize) -> Result<(), Error> {
        shape.check(dim)?;
        finite(&u, c"velocity")?;
        let mut u = u;
        if dim == 2 {
            u[2] = 0.0;
        }
        // Decided exactly, as for a particle's velocity: a speed of 1 is
        // taken, whatever the rounding of a sum of squares would say.
        if !crate::api::speed::slow(&u[..dim]) {
            return Err(Error::new(ErrorKind::SpeedRange, c"velocity"));
        }
        // Kind 0 is a free slot: a shape's kind is stored one up.
        let (kind, a, b, radius) = shape.in_dim(dim).parts();
        let kind = kind + 1;
        (self.kind, self.a, self.b, self.radius, self.velocity) = (kind, a, b, radius, u);
        Ok(())
    }

    /// The body's shape, or `None` for a free slot or a slot no version of
    /// the library writes.
    pub(crate) fn shape(&self) -> Option<Shape> {
        Shape::from_parts(self.kind.checked_sub(1)?, self.a, self.b, self.radius)
    }
}

/// `v - u`, component by component: both within the saturation bound, so
/// the difference fits an `i32`.
#[inline]
pub(crate) fn relative(v: [i32; 3], u: [i32; 3]) -> [i32; 3] {
    [0, 1, 2].map(|k| v[k] - u[k])
}

/// M13's push-out velocity: what the particle had into the surface,
/// relative to it, removed, `v' = v - min(0, (v - u).N) N` (`N` a unit
/// normal in Q30); what it had along the surface is kept.
pub(crate) fn pushed_velocity(v: [i32; 3], u: [i32; 3], n: [i32; 3]) -> [i32; 3] {
    let into = dot_q30(relative(v, u), n);
    if into >= 0 {
        return v;
    }
    // `into` is below 2^60 in magnitude; rounded down once to fine units.
    let s = into >> 30;
    [0, 1, 2].map(|k| sat(i64::from(v[k]) - ((s * i64::from(n[k])) >> 30)))
}

/// The offsets M13's push-out tries, for a world of `dim` dimensions, in
/// rings: `ring` 1 holds the offsets with every component in -1..=1, ring 2
/// those reaching 2; each is passed to `f` with its ring, in x-fastest
/// order within the ring (the caller orders them by `d.N`).
pub(crate) fn for_ring(dim: usize, ring: i32, f: &mut dyn FnMut([i32; 3])) {
    let zr = if dim == 3 { -ring..=ring } else { 0..=0 };
    for dz in zr {
        for dy in -ring..=ring {
            for dx in -ring..=ring {
                let d = [dx, dy, dz];
                if d.iter().map(|c| c.abs()).max() == Some(ring) {
                    f(d);
                }
            }
        }
    }
}
