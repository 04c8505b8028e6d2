//! Bodies (M13): obstacles the caller moves. Each call redraws every body,
//! pushes out the particles a body takes, and is refused whole (changing
//! nothing) where the shape, the speed or the room does not allow it. A
//! library built without obstacles has no world with bodies: its calls
//! check their arguments and return MPCA_STATUS_NOT_ENABLED.

use crate::desc::mpca_desc;
use crate::obstacles::mpca_shape;
use crate::{check_size, guard, mpca_status, mpca_world};

/// What a body gave the particles in the last step (M13). Set
/// `struct_size` to `sizeof(mpca_body_stats)`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct mpca_body_stats {
    /// `sizeof(mpca_body_stats)`, set by the caller.
    pub struct_size: u32,
    /// Particles reflected off the body's cells in the last step.
    pub reflected: u32,
    /// Particles pushed out of cells the body took, by the moves before
    /// the last step.
    pub pushed: u32,
    /// Particles those moves removed for want of a free cell near the body.
    pub crushed: u32,
    /// The momentum the body gave the particles, `sum m (v' - v)`, in the
    /// world's mass times cells per step: push a rigid body back by minus
    /// this.
    pub momentum: [f64; 3],
}

/// The body surface entries a body of `shape` takes alone, where it lies,
/// in a world of `desc`, into `out_entries`: what `body_surface_capacity`
/// must hold for it. Bodies together need at most the sum of theirs; the
/// same shape elsewhere may take a few more or fewer, as its cells fall on
/// the grid. Refused as mpca_world_bytes would refuse the description and
/// mpca_world_add_body the shape; MPCA_STATUS_NOT_ENABLED without
/// `obstacles` and `body_capacity`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_desc_body_surface_entries(desc: *const mpca_desc, shape: *const mpca_shape, out_entries: *mut u32) -> mpca_status {
    guard(|c| {
        let d = c.get(desc)?.to_core();
        let d = d.as_ref().map_err(|&s| s)?;
        let shape = c.get(shape)?.to_core()?;
        let out = c.out(out_entries)?;
        #[cfg(feature = "obstacles")]
        out.set(d.body_surface_entries(shape)?);
        #[cfg(not(feature = "obstacles"))]
        return Err(crate::status::disabled((d, shape, out)));
        #[cfg(feature = "obstacles")]
        Ok(())
    })
}

/// Adds a body of `shape` moving at `velocity` (3 values, cells per step,
/// speed at most 1) with restitution `e`; its id goes to `out_id`. The body
/// covers the cells of its shape that no static obstacle or earlier body
/// covers, and the particles in them are pushed out. Refused:
/// MPCA_STATUS_NOT_ENABLED without `mpca_desc.body_capacity`,
/// MPCA_STATUS_BODY_TABLE_FULL, MPCA_STATUS_SURFACE_TABLE_FULL where
/// `body_surface_capacity` would not hold the body's surface cells, and the
/// shape's, speed's and restitution's own statuses.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_add_body(world: *mut mpca_world, shape: *const mpca_shape, velocity: *const f32, e: f32, out_id: *mut u32) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        let shape = c.get(shape)?.to_core()?;
        let (u, out): ([f32; 3], _) = (c.array(velocity)?, c.out(out_id)?);
        #[cfg(feature = "obstacles")]
        out.set(w.add_body(shape, u, e)?);
        #[cfg(not(feature = "obstacles"))]
        return Err(crate::status::disabled((w, shape, u, e, out)));
        #[cfg(feature = "obstacles")]
        Ok(())
    })
}

/// Gives body `id` a new shape (at its new place) and velocity (3 values);
/// refused as mpca_world_add_body, and with MPCA_STATUS_NO_BODY where `id`
/// names none.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_move_body(world: *mut mpca_world, id: u32, shape: *const mpca_shape, velocity: *const f32) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        let shape = c.get(shape)?.to_core()?;
        let u: [f32; 3] = c.array(velocity)?;
        #[cfg(feature = "obstacles")]
        return Ok(w.move_body(id, shape, u)?);
        #[cfg(not(feature = "obstacles"))]
        Err(crate::status::disabled((w, id, shape, u)))
    })
}

/// Removes body `id`; its cells are free again. MPCA_STATUS_NO_BODY where
/// `id` names none.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_remove_body(world: *mut mpca_world, id: u32) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        #[cfg(feature = "obstacles")]
        return Ok(w.remove_body(id)?);
        #[cfg(not(feature = "obstacles"))]
        Err(crate::status::disabled((w, id)))
    })
}

/// Fills `out` (whose `struct_size` the caller set) with what body `id`
/// gave the particles in the last step.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_body_stats(world: *const mpca_world, id: u32, out: *mut mpca_body_stats) -> mpca_status {
    guard(|c| {
        let w = c.world_ref(world)?;
        // The caller set the leading struct_size; the rest may be anything.
        let size = *c.get(out.cast_const().cast::<u32>())?;
        check_size::<mpca_body_stats>(size, c"out->struct_size")?;
        #[cfg(feature = "obstacles")]
        {
            let s = w.body_stats(id)?;
            c.out(out)?.set(mpca_body_stats { struct_size: size, reflected: s.reflected, pushed: s.pushed, crushed: s.crushed, momentum: s.momentum });
            Ok(())
        }
        #[cfg(not(feature = "obstacles"))]
        Err(crate::status::disabled((w, id)))
    })
}
