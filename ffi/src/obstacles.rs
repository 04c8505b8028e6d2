//! Obstacles (M7): single cells, shapes with exact normals, and masks.
//! Each call adds all of its cells or, refused, none. The surface entries
//! a shape takes can be asked first, of a description or of a world.

use mpca_core::Shape;

use crate::desc::mpca_desc;
use crate::{check_size, guard, mpca_status, mpca_world, Refusal};

/// Values of `mpca_shape.kind` (M7).
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum mpca_shape_kind {
    /// Every cell on the far side of the plane through `a` with outward
    /// normal `b` (as mpca_world_add_half_space).
    HalfSpace = 0,
    /// Every cell whose centre lies in the box `a <= c <= b` (as
    /// mpca_world_add_box).
    Box = 1,
    /// A disc of centre `a` (x and y) and radius `radius`, 2D worlds only.
    Disc = 2,
    /// A sphere of centre `a` and radius `radius`, 3D worlds only.
    Sphere = 3,
    /// The points within `radius` of the segment from `a` to `b` (in 2D
    /// their x and y).
    Capsule = 4,
}

/// An obstacle shape (M7) as one value: to ask what it takes
/// (mpca_desc_surface_entries, mpca_world_surface_entries) and to add it
/// (mpca_world_add_shape). Set `struct_size` to `sizeof(mpca_shape)`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct mpca_shape {
    /// `sizeof(mpca_shape)`.
    pub struct_size: u32,
    /// An `mpca_shape_kind`.
    pub kind: u32,
    /// A point on the plane (half-space), the lower corner (box), the
    /// centre (disc, sphere), one end (capsule).
    pub a: [f32; 3],
    /// The outward normal (half-space), the upper corner (box), the other
    /// end (capsule); not read for a disc or a sphere.
    pub b: [f32; 3],
    /// The radius (disc, sphere, capsule); not read for the others.
    pub radius: f32,
}

impl mpca_shape {
    /// The core's shape; a wrong `struct_size` or an unknown kind is
    /// refused here, the geometry by the core. Out of line: six exports
    /// take a shape.
    #[inline(never)]
    pub(crate) fn to_core(self) -> Result<Shape, Refusal> {
        check_size::<mpca_shape>(self.struct_size, c"shape.struct_size")?;
        Shape::from_parts(self.kind, self.a, self.b, self.radius).ok_or(Refusal::new(mpca_status::BadEnum, c"shape.kind"))
    }
}

/// The surface entries `shape` takes as the first obstacle of a world of
/// `desc`, into `out_entries`: the `surface_capacity` it needs, asked before
/// the world is made. A world of several shapes needs at most the sum of
/// theirs. Refused as mpca_world_bytes would refuse the description and
/// mpca_world_add_shape the shape; MPCA_STATUS_NOT_ENABLED where
/// `desc.obstacles` is 0.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_desc_surface_entries(desc: *const mpca_desc, shape: *const mpca_shape, out_entries: *mut u32) -> mpca_status {
    guard(|c| {
        let d = c.get(desc)?.to_core();
        let d = d.as_ref().map_err(|&s| s)?;
        let shape = c.get(shape)?.to_core()?;
        let out = c.out(out_entries)?;
        out.set(d.surface_entries(shape)?);
        Ok(())
    })
}

/// The surface entries adding `shape` to `world` now takes, into
/// `out_entries`: what its table must have free for mpca_world_add_shape
/// to succeed. Refused as mpca_world_add_shape would refuse the shape.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_surface_entries(world: *const mpca_world, shape: *const mpca_shape, out_entries: *mut u32) -> mpca_status {
    guard(|c| {
        let w = c.world_ref(world)?;
        let shape = c.get(shape)?.to_core()?;
        let out = c.out(out_entries)?;
        out.set(w.surface_entries(shape)?);
        Ok(())
    })
}

/// Adds `shape`'s cells as obstacles of restitution `e`, with normals from
/// its exact geometry: the same as the call for its kind
/// (mpca_world_add_half_space, mpca_world_add_box, mpca_world_add_disc,
/// mpca_world_add_sphere; a capsule has only this one).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_add_shape(world: *mut mpca_world, shape: *const mpca_shape, e: f32) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        let shape = c.get(shape)?.to_core()?;
        Ok(w.add_shape(shape, e)?)
    })
}

/// Makes the cell at `pos` an obstacle with outward `normal` (3 values,
/// normalised by the library) and restitution `e`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_add_obstacle(world: *mut mpca_world, pos: *const u32, normal: *const f32, e: f32) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        let (pos, n) = (c.array(pos)?, c.array(normal)?);
        Ok(w.add_obstacle(pos, n, e)?)
    })
}

/// Every cell whose centre lies on the far side of the plane through `point`
/// with outward `normal` (3 values each): a floor when the normal points up.
/// In 2D only the x and y of `normal` count, as for mpca_world_add_obstacle;
/// a normal with neither is refused (`MPCA_STATUS_BAD_SHAPE`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_add_half_space(world: *mut mpca_world, point: *const f32, normal: *const f32, e: f32) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        let (point, normal) = (c.array(point)?, c.array(normal)?);
        Ok(w.add_shape(Shape::HalfSpace { point, normal }, e)?)
    })
}

/// Every cell whose centre lies in the box `min <= c <= max` (3 values each,
/// cell units: cell i has its centre at i + 0.5).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_add_box(world: *mut mpca_world, min: *const f32, max: *const f32, e: f32) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        let (min, max) = (c.array(min)?, c.array(max)?);
        Ok(w.add_shape(Shape::Box { min, max }, e)?)
    })
}

/// A disc of centre (`cx`, `cy`) and radius `radius` (2D worlds only).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_add_disc(world: *mut mpca_world, cx: f32, cy: f32, radius: f32, e: f32) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        Ok(w.add_shape(Shape::Disc { centre: [cx, cy], radius }, e)?)
    })
}

/// A sphere of centre `centre` (3 values) and radius `radius` (3D only).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_add_sphere(world: *mut mpca_world, centre: *const f32, radius: f32, e: f32) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        let centre = c.array(centre)?;
        Ok(w.add_shape(Shape::Sphere { centre, radius }, e)?)
    })
}

/// Every cell whose byte in `mask` (`len` bytes, one per cell, x fastest)
/// is not zero. Surface normals are the normalised sum of the directions to
/// the free neighbours; a mask where one vanishes is refused
/// (`MPCA_STATUS_UNDEFINED_NORMAL`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_add_obstacle_mask(world: *mut mpca_world, mask: *const u8, len: usize, e: f32) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        let mask = c.slice(mask, len, mpca_status::BadLength)?;
        Ok(w.add_obstacle_mask(mask, e)?)
    })
}

/// The outward normal (3 floats into `out_normal`) and restitution of the
/// obstacle surface cell at `pos`; `MPCA_STATUS_NOT_A_SURFACE` if the cell
/// is not one.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_surface(
    world: *const mpca_world,
    pos: *const u32,
    out_normal: *mut f32,
    out_restitution: *mut f32,
) -> mpca_status {
    guard(|c| {
        let w = c.world_ref(world)?;
        let pos = c.array::<u32, 3>(pos)?;
        let e = c.out(out_restitution)?;
        // 3 floats: an array of them, aligned as a float.
        let normal = c.out(out_normal.cast::<[f32; 3]>())?;
        w.cell(pos)?;
        let s = w.surface(pos).ok_or(Refusal::new(mpca_status::NotASurface, c"pos"))?;
        normal.set(s.normal);
        e.set(s.restitution);
        Ok(())
    })
}
