//! Obstacles (M7): single cells, shapes with exact normals, and masks.
//! Each call adds all of its cells or, refused, none.

use mpca_core::Shape;

use crate::world::{world_mut, world_ref};
use crate::{array, guard, mpca_status, mpca_world, slice, write};

/// Makes the cell at `pos` an obstacle with outward `normal` (3 values,
/// normalised by the library) and restitution `e`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_add_obstacle(world: *mut mpca_world, pos: *const u32, normal: *const f32, e: f32) -> mpca_status {
    guard(|| {
        let w = unsafe { world_mut(world)? };
        let (pos, n) = unsafe { (array(pos)?, array(normal)?) };
        Ok(w.add_obstacle(pos, n, e)?)
    })
}

/// Every cell whose centre lies on the far side of the plane through `point`
/// with outward `normal` (3 values each): a floor when the normal points up.
/// In 2D only the x and y of `normal` count, as for mpca_world_add_obstacle;
/// a normal with neither is refused (`MPCA_STATUS_BAD_SHAPE`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_add_half_space(world: *mut mpca_world, point: *const f32, normal: *const f32, e: f32) -> mpca_status {
    guard(|| {
        let w = unsafe { world_mut(world)? };
        let (point, normal) = unsafe { (array(point)?, array(normal)?) };
        Ok(w.add_shape(Shape::HalfSpace { point, normal }, e)?)
    })
}

/// Every cell whose centre lies in the box `min <= c <= max` (3 values each,
/// cell units: cell i has its centre at i + 0.5).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_add_box(world: *mut mpca_world, min: *const f32, max: *const f32, e: f32) -> mpca_status {
    guard(|| {
        let w = unsafe { world_mut(world)? };
        let (min, max) = unsafe { (array(min)?, array(max)?) };
        Ok(w.add_shape(Shape::Box { min, max }, e)?)
    })
}

/// A disc of centre (`cx`, `cy`) and radius `radius` (2D worlds only).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_add_disc(world: *mut mpca_world, cx: f32, cy: f32, radius: f32, e: f32) -> mpca_status {
    guard(|| {
        let w = unsafe { world_mut(world)? };
        Ok(w.add_shape(Shape::Disc { centre: [cx, cy], radius }, e)?)
    })
}

/// A sphere of centre `centre` (3 values) and radius `radius` (3D only).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_add_sphere(world: *mut mpca_world, centre: *const f32, radius: f32, e: f32) -> mpca_status {
    guard(|| {
        let w = unsafe { world_mut(world)? };
        let centre = unsafe { array(centre)? };
        Ok(w.add_shape(Shape::Sphere { centre, radius }, e)?)
    })
}

/// Every cell whose byte in `mask` (`len` bytes, one per cell, x fastest)
/// is not zero. Surface normals are the normalised sum of the directions to
/// the free neighbours; a mask where one vanishes is refused
/// (`MPCA_STATUS_UNDEFINED_NORMAL`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_add_obstacle_mask(world: *mut mpca_world, mask: *const u8, len: usize, e: f32) -> mpca_status {
    guard(|| {
        let w = unsafe { world_mut(world)? };
        let mask = unsafe { slice(mask, len, mpca_status::BadLength)? };
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
    guard(|| {
        let w = unsafe { world_ref(world)? };
        let pos = unsafe { array::<u32, 3>(pos)? };
        let e = unsafe { write(out_restitution)? };
        if out_normal.is_null() {
            return Err(mpca_status::NullPointer);
        }
        w.cell(pos)?;
        let s = w.surface(pos).ok_or(mpca_status::NotASurface)?;
        // SAFETY: the C contract: out_normal has room for 3 floats.
        unsafe { core::ptr::copy_nonoverlapping(s.normal.as_ptr(), out_normal, 3) };
        *e = s.restitution;
        Ok(())
    })
}
