//! Handles: how the `mpca_world *` C holds reaches its world, and how it
//! stops reaching it.
//!
//! Hosted builds (`std`): a handle is a number this library issued, never
//! the world's address, and no number is issued twice in a process. A
//! registry maps the live ones to their worlds, and is asked before any
//! memory is read, so a handle whose world ended is refused whatever has
//! since happened to that memory.
//!
//! Firmware builds (no `std`, so no registry): the handle is the world's
//! address, and only the tag in the world's header tells a live world from
//! anything else (`mpca_world` in the header says what that promises).

use mpca_core::World;

use crate::{mpca_status, mpca_world};

#[cfg(feature = "std")]
pub(crate) use hosted::{issue, reserve, resolve, revoke};

#[cfg(not(feature = "std"))]
pub(crate) use firmware::{issue, reserve, resolve, revoke};

#[cfg(feature = "std")]
mod hosted {
    use core::ptr::NonNull;
    use std::collections::BTreeMap;
    use std::sync::{Mutex, MutexGuard};

    use super::{mpca_status, mpca_world, World};

    /// A live world: where it starts, how many bytes it spans, and whether
    /// the library allocated it.
    struct Entry {
        at: NonNull<u8>,
        bytes: usize,
        owned: bool,
    }

    // SAFETY: the registry stores the address and hands it back; it never
    // reads or writes the world through it. Who uses the world, from which
    // thread, is the C contract's business (one thread at a time).
    unsafe impl Send for Entry {}

    struct Registry {
        /// How many handle numbers have been taken.
        taken: usize,
        /// Live worlds by handle value.
        live: BTreeMap<usize, Entry>,
    }

    static REGISTRY: Mutex<Registry> = Mutex::new(Registry { taken: 0, live: BTreeMap::new() });

    fn registry() -> MutexGuard<'static, Registry> {
        // Every change below is one insert, remove or retain, so a panic
        // elsewhere while the lock was held left nothing half-done.
        REGISTRY.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// The handle value of number `n`: a bijection of `usize` (xor-shifts
    /// and a multiplication by an odd constant are each invertible), so
    /// distinct numbers give distinct values, and 0 (NULL) only for 0, which
    /// is never issued. Scrambled so that a value near a handle (the handle
    /// plus an offset) is not another handle.
    fn value(n: usize) -> usize {
        const HALF: u32 = usize::BITS / 2;
        let mut x = n ^ (n >> HALF);
        x = x.wrapping_mul(0x9e37_79b9_7f4a_7c15_u64 as usize);
        x ^ (x >> HALF)
    }

    /// A handle number set aside for a world about to be built.
    pub(crate) struct Reserved(usize);

    /// Takes the next handle number, before the world is built, so that
    /// nothing can fail once it is. A number whose world is then refused is
    /// never used; numbers are not reused either way.
    pub(crate) fn reserve() -> Result<Reserved, mpca_status> {
        let mut r = registry();
        // 2^64 - 1 numbers never run out; 2^32 - 1 on 32-bit targets might.
        r.taken = r.taken.checked_add(1).ok_or(mpca_status::OutOfMemory)?;
        Ok(Reserved(r.taken))
    }

    /// Registers a world just built and returns its handle. A world built in
    /// caller memory that held live worlds ends them: their handles are
    /// refused from now on.
    pub(crate) fn issue(number: Reserved, world: &mut World) -> *mut mpca_world {
        let entry = Entry { at: NonNull::from(&mut *world).cast(), bytes: world.size_in_bytes(), owned: world.is_owned() };
        let handle = value(number.0);
        let mut r = registry();
        if !entry.owned {
            let (start, end) = (entry.at.as_ptr() as usize, entry.at.as_ptr() as usize + entry.bytes);
            r.live.retain(|_, e| {
                let (s, t) = (e.at.as_ptr() as usize, e.at.as_ptr() as usize + e.bytes);
                e.owned || t <= start || end <= s
            });
        }
        r.live.insert(handle, entry);
        core::ptr::without_provenance_mut(handle)
    }

    /// Where the world of a live handle is; `BadHandle` for anything else,
    /// found without reading any memory `handle` might point to.
    pub(crate) fn resolve(handle: *const mpca_world) -> Result<*mut u8, mpca_status> {
        registry().live.get(&handle.addr()).map(|e| e.at.as_ptr()).ok_or(mpca_status::BadHandle)
    }

    /// Ends a handle: it is refused from now on.
    pub(crate) fn revoke(handle: *const mpca_world) {
        registry().live.remove(&handle.addr());
    }

    #[cfg(test)]
    mod tests {
        use super::value;

        #[test]
        fn handle_values_of_distinct_numbers_differ_and_are_not_null() {
            let values: std::collections::BTreeSet<usize> = (1..=100_000).map(value).collect();
            assert_eq!(values.len(), 100_000);
            assert!(!values.contains(&0));
            // No handle is another plus a small offset.
            for v in (1..=1000).map(value) {
                for d in 1..=256 {
                    assert!(!values.contains(&v.wrapping_add(d)) && !values.contains(&v.wrapping_sub(d)));
                }
            }
        }
    }
}

#[cfg(not(feature = "std"))]
mod firmware {
    use super::{mpca_status, mpca_world, World};

    /// Nothing to set aside: the handle is the world's address.
    pub(crate) struct Reserved;

    pub(crate) fn reserve() -> Result<Reserved, mpca_status> {
        Ok(Reserved)
    }

    /// The world's address, which its header's tag is tied to.
    pub(crate) fn issue(_: Reserved, world: &mut World) -> *mut mpca_world {
        world.as_ptr().cast()
    }

    /// The handle itself; its tag is checked by the caller.
    pub(crate) fn resolve(handle: *const mpca_world) -> Result<*mut u8, mpca_status> {
        Ok(handle.cast_mut().cast())
    }

    /// Nothing to do: `World::retire` cleared the tag.
    pub(crate) fn revoke(_: *const mpca_world) {}
}
