//! Obstacles (M7): single cells, shapes with exact normals, and masks.
//! Each call adds all of its cells or, refused, none.

use mpca_core::Shape;

use crate::{guard, mpca_status, mpca_world};

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
        let s = w.surface(pos).ok_or(mpca_status::NotASurface)?;
        normal.set(s.normal);
        e.set(s.restitution);
        Ok(())
    })
}
