//! `mpca_world`: handles, their life cycle, stepping, statistics and hash.

use mpca_core::World;

use crate::{check_size, guard, handle, mpca_desc, mpca_status, Refusal};

/// An opaque world, reached through its handle: the `mpca_world *` that
/// mpca_world_create or mpca_world_init wrote. A handle is only ever passed
/// back to this library, never dereferenced. (Not `repr(C)`, so cbindgen
/// declares it as an incomplete type.)
///
/// Hosted builds (the default, feature `hosted`): a handle is a value the
/// library issues, not the world's address, and no value is issued twice in
/// a process. The library keeps a registry of the live ones and asks it before
/// it reads any memory, so every value that is not the handle of a live
/// world is refused with `MPCA_STATUS_BAD_HANDLE` (NULL with
/// `MPCA_STATUS_NULL_POINTER`) without a read: the handle of a destroyed or
/// deinitialised world, even after its memory was freed or reused by the
/// allocator or by a new world; the address of a world or of a copy of its
/// bytes; any forged value. Building a world with mpca_world_init in memory
/// that holds a live world ends that world: its handle is refused from then
/// on (unless a call is inside it: see Threads). Where pointers are 32 bits wide the values run out after 2^32 - 1
/// worlds in a process; create and init then return
/// `MPCA_STATUS_OUT_OF_MEMORY`.
///
/// Threads (hosted builds): a world may be used from any thread, and calls
/// on it from several threads at once never race: the registry decides
/// who is inside. A call taking `const mpca_world *` only reads the world,
/// and any number of those run together. A call taking `mpca_world *`
/// changes it (mpca_world_step_parallel included) and runs alone: it waits
/// for the reading calls inside to return (they wait for nothing, so the
/// wait ends) while new calls are refused, and it returns
/// `MPCA_STATUS_BUSY` at once, changing nothing, when another changing call
/// or a parallel step is inside. Calls that end or replace a world do not
/// wait: mpca_world_deinit, mpca_world_destroy, mpca_world_load, and
/// mpca_world_init or mpca_world_init_from_image over its memory, return
/// `MPCA_STATUS_BUSY` while any call is inside it (from any thread, or from
/// a task of its step) and leave it alive; init in memory of a world
/// mpca_world_create allocated returns `MPCA_STATUS_OVERLAP`. During a
/// parallel step only its mpca_world_step_task calls reach the world. So a
/// call on a world completes before a step or change begins, or begins
/// after it ends, or is refused; a program that wants a refused call done
/// makes it again.
///
/// Firmware builds (without `hosted`: no allocator, no registry): the handle
/// is the world's address in the caller's memory, and the world's header
/// holds a tag tied to that address, which mpca_world_deinit clears.
/// Promised: NULL, and a value not aligned as a world's start, are refused
/// without a read. Any other handle is read (the tag and the length after
/// it: 16 bytes, 12 on 32-bit targets) and refused with
/// `MPCA_STATUS_BAD_HANDLE` unless it holds the tag of a world built at
/// exactly that address: so a deinitialised world whose memory is untouched
/// since, a copy of a world's bytes at another address, and memory that
/// never held a world are refused (bar a 2^-64 chance that such memory holds
/// that very tag). Not promised: once the memory of a deinitialised world is
/// freed or handed to anything else, passing its handle reads that memory,
/// which is undefined behaviour if it is gone (as for any dangling pointer);
/// and once mpca_world_init builds a new world at the same address, the old
/// handle equals the new one and reaches the new world. End a world with
/// mpca_world_deinit and drop its handle before the memory is reused. A
/// firmware world is used by one call at a time.
pub struct mpca_world {
    _opaque: [u8; 0],
}

/// Builds an empty world in `memory` (`len` bytes, any alignment, at least
/// mpca_world_bytes; more than PTRDIFF_MAX is refused with
/// `MPCA_STATUS_BAD_LENGTH`) and writes its handle to `out_world`. Nothing is
/// allocated. The world stays valid until mpca_world_deinit or until the
/// memory is freed or reused; do not move or copy the memory meanwhile.
/// A world built over a live one ends it (see `mpca_world` for what its
/// handle then does), unless a call is inside that one: then this returns
/// `MPCA_STATUS_BUSY` and changes nothing (hosted builds; see Threads at
/// `mpca_world`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_init(
    desc: *const mpca_desc,
    memory: *mut core::ffi::c_void,
    len: usize,
    out_world: *mut *mut mpca_world,
) -> mpca_status {
    guard(|c| {
        // Read inside the result (moved out, it would be copied).
        let d = c.get(desc)?.to_core();
        let d = d.as_ref().map_err(|&s| s)?;
        let out = c.out(out_world)?;
        let bytes = c.slice_mut(memory.cast::<u8>(), len, mpca_status::BadLength)?;
        let claim = handle::claim(memory.cast(), len)?;
        let number = handle::reserve()?;
        let world = World::init(d, bytes)?;
        out.set(handle::issue(number, claim, world));
        Ok(())
    })
}

/// Ends a world made by mpca_world_init, so its handle is refused from now
/// on; the caller then frees or reuses the memory. A world made by
/// mpca_world_create is refused with `MPCA_STATUS_BAD_HANDLE`: destroy it.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_deinit(world: *mut mpca_world) -> mpca_status {
    guard(|c| {
        let w = c.world_to_end(world)?;
        if w.is_owned() {
            return Err(Refusal::new(mpca_status::BadHandle, c"world (from mpca_world_create: destroy it)"));
        }
        w.retire();
        handle::revoke(world);
        Ok(())
    })
}

/// Allocates and builds an empty world; mpca_world_destroy frees it.
/// Hosted builds only (the default `hosted` feature): firmware builds have
/// neither this nor mpca_world_destroy.
#[cfg(feature = "hosted")]
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_create(desc: *const mpca_desc, out_world: *mut *mut mpca_world) -> mpca_status {
    guard(|c| {
        let d = c.get(desc)?.to_core()?;
        let out = c.out(out_world)?;
        let number = handle::reserve()?;
        let world = mpca_core::WorldBox::new(&d)?;
        // Owned through the handle from now on; mpca_world_destroy frees it.
        out.set(handle::issue_owned(number, world));
        Ok(())
    })
}

/// Frees a world made by mpca_world_create. NULL is accepted and does
/// nothing. A destroyed handle, a world in caller memory
/// (`MPCA_STATUS_NOT_OWNED`) or anything else is refused.
#[cfg(feature = "hosted")]
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_destroy(world: *mut mpca_world) -> mpca_status {
    guard(|c| {
        if world.is_null() {
            return Ok(());
        }
        let at = c.enter(world, handle::Access::End)?;
        // SAFETY: the registry holds `at` for a live handle, entered for
        // Write, so no other call is inside (as in `Call::world`); from_raw
        // checks the tag, and that the library allocated it.
        let owned = unsafe { mpca_core::WorldBox::from_raw(at)? };
        handle::revoke(world);
        drop(owned);
        Ok(())
    })
}

/// Advances the world `steps` steps.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_step(world: *mut mpca_world, steps: u64) -> mpca_status {
    guard(|c| {
        c.world(world)?.step(steps);
        Ok(())
    })
}

/// Writes the description the world was built from (with any changes
/// made since by the set functions) to `out`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_desc(world: *const mpca_world, out: *mut mpca_desc) -> mpca_status {
    guard(|c| {
        let w = c.world_ref(world)?;
        c.out(out)?.set(mpca_desc::from_core(w.description()));
        Ok(())
    })
}

/// Statistics of a world (M10). Set `struct_size` before the call.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct mpca_stats {
    /// `sizeof(mpca_stats)`, set by the caller.
    pub struct_size: u32,
    /// Reserved, 0.
    pub reserved: u32,
    /// Steps taken.
    pub step: u64,
    /// Particles now.
    pub particles: u64,
    /// Particles placed by emitters.
    pub emitted: u64,
    /// Particles that left by open faces.
    pub exited: u64,
    /// Particles whose lifetime ended.
    pub expired: u64,
    /// Particles emitters could not place for lack of room.
    pub emit_shortfall: u64,
    /// Particles bodies removed for want of a free cell near them (M13).
    pub crushed: u64,
    /// Particle-particle collisions.
    pub collisions: u64,
    /// Velocities scaled back to |v| = 1.
    pub clamps: u64,
    /// Particles not placed in their desired cell.
    pub displaced: u64,
    /// Blocks processed in the last step.
    pub blocks_processed: u64,
    /// Blocks skipped as empty in the last step.
    pub blocks_skipped: u64,
    /// Total momentum.
    pub momentum: [f64; 3],
    /// Total kinetic energy.
    pub kinetic_energy: f64,
    /// Kinetic energy removed by clamps.
    pub clamp_energy: f64,
    /// Bytes of the world's memory per cell.
    pub bytes_per_cell: f64,
}

/// Fills `out` (whose `struct_size` the caller set) with the statistics.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_stats(world: *const mpca_world, out: *mut mpca_stats) -> mpca_status {
    guard(|c| {
        let w = c.world_ref(world)?;
        // The caller set the leading struct_size; the rest may be anything.
        let size = *c.get(out.cast_const().cast::<u32>())?;
        check_size::<mpca_stats>(size, c"out->struct_size")?;
        let s = w.stats();
        c.out(out)?.set(mpca_stats {
            struct_size: size,
            reserved: 0,
            step: s.step,
            particles: s.particles,
            emitted: s.emitted,
            exited: s.exited,
            expired: s.expired,
            emit_shortfall: s.emit_shortfall,
            crushed: s.crushed,
            collisions: s.collisions,
            clamps: s.clamps,
            displaced: s.displaced,
            blocks_processed: s.blocks_processed,
            blocks_skipped: s.blocks_skipped,
            momentum: s.momentum,
            kinetic_energy: s.kinetic_energy,
            clamp_energy: s.clamp_energy,
            bytes_per_cell: s.bytes_per_cell,
        });
        Ok(())
    })
}

/// A 64-bit hash of every particle's cell, stored velocity, mass and
/// lifetime: equal worlds hash equal on every target and through every API.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_hash(world: *const mpca_world, out_hash: *mut u64) -> mpca_status {
    guard(|c| {
        let w = c.world_ref(world)?;
        c.out(out_hash)?.set(w.state_hash());
        Ok(())
    })
}

/// The particles inside a box of cells and their motion, from
/// mpca_world_region_stats. Set `struct_size` before the call.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct mpca_region_stats {
    /// `sizeof(mpca_region_stats)`, set by the caller.
    pub struct_size: u32,
    /// Reserved, 0.
    pub reserved: u32,
    /// Particles in the box.
    pub particles: u64,
    /// Their momentum, sum m v.
    pub momentum: [f64; 3],
    /// Their kinetic energy, sum m |v|^2 / 2.
    pub kinetic_energy: f64,
}

/// Fills `out` (whose `struct_size` the caller set) with the particles in
/// the box of cells `min <= pos < max` (3 values each, per axis; the third
/// is ignored in 2D) and their momentum and kinetic energy, summed as
/// mpca_world_stats sums them: a box covering the world gives its figures
/// exactly. For effects that trigger on what a region holds. An empty or
/// reversed box (`min >= max` on an axis) is refused with
/// `MPCA_STATUS_BAD_SHAPE`, one reaching beyond the world with
/// `MPCA_STATUS_OUT_OF_BOUNDS`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_region_stats(
    world: *const mpca_world,
    min: *const u32,
    max: *const u32,
    out: *mut mpca_region_stats,
) -> mpca_status {
    guard(|c| {
        let w = c.world_ref(world)?;
        let (min, max) = (c.array(min)?, c.array(max)?);
        let size = *c.get(out.cast_const().cast::<u32>())?;
        check_size::<mpca_region_stats>(size, c"out->struct_size")?;
        let r = w.region_stats(min, max)?;
        c.out(out)?.set(mpca_region_stats {
            struct_size: size,
            reserved: 0,
            particles: r.particles,
            momentum: r.momentum,
            kinetic_energy: r.kinetic_energy,
        });
        Ok(())
    })
}
