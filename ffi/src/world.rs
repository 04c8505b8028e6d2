//! `mpca_world`: handles, their life cycle, stepping, statistics and hash.

use mpca_core::World;

use crate::{check_size, guard, mpca_desc, mpca_status, read, write};

/// An opaque world. It lives in memory the caller handed to mpca_world_init
/// or that mpca_world_create allocated. (Not `repr(C)`, so cbindgen declares
/// it as an incomplete type.)
pub struct mpca_world {
    _opaque: [u8; 0],
}

/// Registry of the worlds mpca_world_create made and mpca_world_destroy
/// freed, so that a destroyed handle is refused without reading freed memory.
#[cfg(feature = "std")]
mod registry {
    use std::collections::BTreeSet;
    use std::sync::Mutex;

    struct Sets {
        live: BTreeSet<usize>,
        dead: BTreeSet<usize>,
    }

    static SETS: Mutex<Sets> = Mutex::new(Sets { live: BTreeSet::new(), dead: BTreeSet::new() });

    fn with<R>(f: impl FnOnce(&mut Sets) -> R) -> R {
        let mut g = SETS.lock().unwrap_or_else(|e| e.into_inner());
        f(&mut g)
    }

    pub fn born(p: usize) {
        with(|s| {
            s.dead.remove(&p);
            s.live.insert(p);
        });
    }

    /// A world built by mpca_world_init at `p`, perhaps where a destroyed
    /// one was: the address is live memory again.
    pub fn reused(p: usize) {
        with(|s| {
            s.dead.remove(&p);
        });
    }

    pub fn died(p: usize) {
        with(|s| {
            s.live.remove(&p);
            s.dead.insert(p);
        });
    }

    /// False for the address of a destroyed world not since reused.
    pub fn may_read(p: usize) -> bool {
        with(|s| s.live.contains(&p) || !s.dead.contains(&p))
    }
}

/// The world behind a handle: NULL and dead handles are refused.
pub(crate) unsafe fn world_mut<'a>(w: *mut mpca_world) -> Result<&'a mut World, mpca_status> {
    if w.is_null() {
        return Err(mpca_status::NullPointer);
    }
    #[cfg(feature = "std")]
    if !registry::may_read(w as usize) {
        return Err(mpca_status::BadHandle);
    }
    // SAFETY: the C contract: a handle is a pointer this library returned.
    // Its tag is checked before anything else is read.
    unsafe { World::from_ptr(w.cast::<u8>()) }.map_err(|_| mpca_status::BadHandle)
}

/// Read-only twin of [`world_mut`].
pub(crate) unsafe fn world_ref<'a>(w: *const mpca_world) -> Result<&'a World, mpca_status> {
    unsafe { world_mut(w.cast_mut()) }.map(|w| &*w)
}

/// Builds an empty world in `memory` (`len` bytes, any alignment, at least
/// mpca_world_bytes) and writes its handle to `out_world`. Nothing is
/// allocated. The world stays valid until mpca_world_deinit or until the
/// memory is freed or reused; do not move or copy the memory meanwhile.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_init(
    desc: *const mpca_desc,
    memory: *mut core::ffi::c_void,
    len: usize,
    out_world: *mut *mut mpca_world,
) -> mpca_status {
    guard(|| {
        let d = unsafe { read(desc)? }.to_core()?;
        let out = unsafe { write(out_world)? };
        let bytes = unsafe { crate::slice_mut(memory.cast::<u8>(), len)? };
        let world = World::init(&d, bytes)?;
        let p = world.as_ptr();
        #[cfg(feature = "std")]
        registry::reused(p as usize);
        *out = p.cast::<mpca_world>();
        Ok(())
    })
}

/// Marks a world made by mpca_world_init as ended, so its handle is refused
/// from now on; the caller then frees or reuses the memory. A world made by
/// mpca_world_create is refused with `MPCA_STATUS_BAD_HANDLE`: destroy it.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_deinit(world: *mut mpca_world) -> mpca_status {
    guard(|| {
        let w = unsafe { world_mut(world)? };
        if w.is_owned() {
            return Err(mpca_status::BadHandle);
        }
        w.retire();
        Ok(())
    })
}

/// Allocates and builds an empty world; mpca_world_destroy frees it.
/// Hosted builds only (the default `std` feature): firmware builds have
/// neither this nor mpca_world_destroy.
#[cfg(feature = "std")]
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_create(desc: *const mpca_desc, out_world: *mut *mut mpca_world) -> mpca_status {
    guard(|| {
        let d = unsafe { read(desc)? }.to_core()?;
        let out = unsafe { write(out_world)? };
        let p = mpca_core::WorldBox::new(&d)?.into_raw();
        registry::born(p as usize);
        *out = p.cast::<mpca_world>();
        Ok(())
    })
}

/// Frees a world made by mpca_world_create. NULL is accepted and does
/// nothing. A destroyed handle, a world in caller memory
/// (`MPCA_STATUS_NOT_OWNED`) or anything else is refused.
#[cfg(feature = "std")]
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_destroy(world: *mut mpca_world) -> mpca_status {
    guard(|| {
        if world.is_null() {
            return Ok(());
        }
        unsafe { world_mut(world)? };
        // SAFETY: a live world handle (checked above).
        let b = unsafe { mpca_core::WorldBox::from_raw(world.cast::<u8>())? };
        registry::died(world as usize);
        drop(b);
        Ok(())
    })
}

/// Advances the world `steps` steps.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_step(world: *mut mpca_world, steps: u64) -> mpca_status {
    guard(|| {
        unsafe { world_mut(world)? }.step(steps);
        Ok(())
    })
}

/// Writes the description the world was built from (with any changes
/// made since by the set functions) to `out`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_desc(world: *const mpca_world, out: *mut mpca_desc) -> mpca_status {
    guard(|| {
        let w = unsafe { world_ref(world)? };
        *unsafe { write(out)? } = mpca_desc::from_core(w.description());
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
    guard(|| {
        let w = unsafe { world_ref(world)? };
        let out = unsafe { write(out)? };
        check_size::<mpca_stats>(out.struct_size)?;
        let s = w.stats();
        *out = mpca_stats {
            struct_size: out.struct_size,
            reserved: 0,
            step: s.step,
            particles: s.particles,
            emitted: s.emitted,
            exited: s.exited,
            expired: s.expired,
            emit_shortfall: s.emit_shortfall,
            collisions: s.collisions,
            clamps: s.clamps,
            displaced: s.displaced,
            blocks_processed: s.blocks_processed,
            blocks_skipped: s.blocks_skipped,
            momentum: s.momentum,
            kinetic_energy: s.kinetic_energy,
            clamp_energy: s.clamp_energy,
            bytes_per_cell: s.bytes_per_cell,
        };
        Ok(())
    })
}

/// A 64-bit hash of every particle's cell, stored velocity, mass and
/// lifetime: equal worlds hash equal on every target and through every API.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_hash(world: *const mpca_world, out_hash: *mut u64) -> mpca_status {
    guard(|| {
        let w = unsafe { world_ref(world)? };
        *unsafe { write(out_hash)? } = w.state_hash();
        Ok(())
    })
}
