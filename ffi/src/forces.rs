//! Forces (M5.1): the uniform acceleration, the per-cell field, the
//! potential and the Rankine vortex. Each needs its bit in
//! `mpca_desc.forces`, else `MPCA_STATUS_NOT_ENABLED`. And the wind plane
//! of the flow drag (M5.1b), which needs `mpca_desc.drag_wind_field`.

use mpca_core::Vortex;

use crate::{guard, mpca_status, mpca_world};

/// Sets the uniform acceleration (3 values).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_set_gravity(world: *mut mpca_world, g: *const f32) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        Ok(w.set_gravity(c.array(g)?)?)
    })
}

/// Replaces the force field: `dim` floats per cell, cells x fastest; `len`
/// must be `dim` times the cell count.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_set_force_field(world: *mut mpca_world, forces: *const f32, len: usize) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        Ok(w.set_force_field(c.slice(forces, len, mpca_status::BadLength)?)?)
    })
}

/// Sets the force (3 values) on the cell at `pos`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_set_cell_force(world: *mut mpca_world, pos: *const u32, force: *const f32) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        let (pos, f) = (c.array(pos)?, c.array(force)?);
        Ok(w.set_cell_force(pos, f)?)
    })
}

/// Replaces the potential: one float per cell, x fastest.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_set_potential(world: *mut mpca_world, u: *const f32, len: usize) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        Ok(w.set_potential(c.slice(u, len, mpca_status::BadLength)?)?)
    })
}

/// Sets the potential of the cell at `pos`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_set_cell_potential(world: *mut mpca_world, pos: *const u32, u: f32) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        Ok(w.set_cell_potential(c.array(pos)?, u)?)
    })
}

/// Sets the Rankine vortex: centre (`cx`, `cy`), core radius and
/// circulation. Its axis is parallel to z in 3D. The force is zero at the
/// centre, however small the core.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_set_vortex(world: *mut mpca_world, cx: f32, cy: f32, core_radius: f32, circulation: f32) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        Ok(w.set_vortex(Vortex { centre: [cx, cy], core_radius, circulation })?)
    })
}

/// Replaces the wind plane (M5.1b): `dim` flow velocity components per
/// cell, cells x fastest; `len` must be `dim` times the cell count. Every
/// value finite (`MPCA_STATUS_NOT_FINITE`) and every cell's speed at most 1
/// (`MPCA_STATUS_SPEED_RANGE`; decided exactly for the floats given, so
/// (0.6, 0.8), whose squares sum to 1 + 2e-8, is over), else nothing is
/// set. Needs
/// `mpca_desc.drag_wind_field`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_set_wind_field(world: *mut mpca_world, wind: *const f32, len: usize) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        Ok(w.set_wind_field(c.slice(wind, len, mpca_status::BadLength)?)?)
    })
}

/// Sets the flow velocity (3 values, speed at most 1, decided exactly as
/// for mpca_world_set_wind_field) of the cell at `pos` in the wind plane
/// (M5.1b).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_set_cell_wind(world: *mut mpca_world, pos: *const u32, wind: *const f32) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        let (pos, u) = (c.array(pos)?, c.array(wind)?);
        Ok(w.set_cell_wind(pos, u)?)
    })
}
