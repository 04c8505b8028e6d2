//! Emitters (M6).

use mpca_core::Emitter;

use crate::{check_size, guard, mpca_status, mpca_world};

/// An emitter. Set `struct_size` to `sizeof(mpca_emitter)`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct mpca_emitter {
    /// `sizeof(mpca_emitter)`.
    pub struct_size: u32,
    /// First cell of the region, inclusive.
    pub min: [u32; 3],
    /// Last cell of the region, exclusive (the third is ignored in 2D).
    pub max: [u32; 3],
    /// Mean particles per step, not negative.
    pub rate: f32,
    /// Initial velocity, in cells per step.
    pub velocity: [f32; 3],
    /// Radius of a uniform random spread added to the velocity;
    /// |velocity| + spread <= 1, decided exactly (no rounding: a sum above 1
    /// by any amount is refused).
    pub spread: f32,
    /// Mass of the emitted particles.
    pub mass: f32,
    /// Steps each particle lives, 0 for no limit, at most 65535; needs
    /// `mpca_desc.lifetimes`.
    pub lifetime: u32,
}

/// Adds an emitter; its index goes to `out_index`. A world described with
/// `emitter_capacity` 0 has no room for one: MPCA_STATUS_NOT_ENABLED; one
/// whose room is taken: MPCA_STATUS_EMITTER_TABLE_FULL.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_add_emitter(world: *mut mpca_world, emitter: *const mpca_emitter, out_index: *mut u32) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        let e = c.get(emitter)?;
        let out = c.out(out_index)?;
        check_size::<mpca_emitter>(e.struct_size, c"emitter.struct_size")?;
        let index = w.add_emitter(Emitter {
            min: e.min,
            max: e.max,
            rate: e.rate,
            velocity: e.velocity,
            spread: e.spread,
            mass: e.mass,
            lifetime: e.lifetime,
        })?;
        out.set(index as u32);
        Ok(())
    })
}

/// What emitter `index` asked for (`out_requested`) and placed
/// (`out_delivered`) since it was added: each step the whole part of its
/// rate, and one more by a draw on the fraction, asked; as many placed as
/// its region had free cells (and ids) for. The difference is its part of
/// `mpca_stats.emit_shortfall`. MPCA_STATUS_OUT_OF_BOUNDS for an index
/// past the emitters added.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_emitter_stats(
    world: *const mpca_world,
    index: u32,
    out_requested: *mut u64,
    out_delivered: *mut u64,
) -> mpca_status {
    guard(|c| {
        let w = c.world_ref(world)?;
        let (requested, delivered) = (c.out(out_requested)?, c.out(out_delivered)?);
        let s = w.emitter_stats(index as usize)?;
        requested.set(s.requested);
        delivered.set(s.delivered);
        Ok(())
    })
}

/// Changes the rate of emitter `index`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_set_emitter_rate(world: *mut mpca_world, index: u32, rate: f32) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        Ok(w.set_emitter_rate(index as usize, rate)?)
    })
}

/// Gives the particles emitter `index` places from now on the tag `tag`,
/// at most 255 (M6b); 0 until set. Needs a world with MPCA_IDENTITY_TAGS.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_set_emitter_tag(world: *mut mpca_world, index: u32, tag: u32) -> mpca_status {
    guard(|c| {
        let w = c.world(world)?;
        let tag = u8::try_from(tag).map_err(|_| mpca_status::TagRange)?;
        Ok(w.set_emitter_tag(index as usize, tag)?)
    })
}
