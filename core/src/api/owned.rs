//! An owning world on the global allocator (feature `alloc`): a convenience,
//! never a requirement. It is what the C ABI's `mpca_world_create` returns.

extern crate alloc;

use alloc::alloc::{alloc_zeroed, dealloc};
use core::alloc::Layout;
use core::ops::{Deref, DerefMut};
use core::ptr::NonNull;

use crate::{world_bytes, Description, Error, ErrorKind, World, WORLD_ALIGN};

/// A world in memory the library allocated and frees on drop.
pub struct WorldBox {
    /// The allocation, as the allocator returned it: the world starts
    /// there (the allocation is aligned), and it is what `dealloc` takes.
    /// A pointer derived from the `&mut World` covers only the world's
    /// bytes, not the alignment slack after them, so freeing through it
    /// would free bytes it may not reach (Miri's Stacked Borrows: UB).
    base: NonNull<u8>,
    world: NonNull<World>,
}

impl WorldBox {
    /// Allocates and builds a world for `desc`.
    pub fn new(desc: &Description) -> Result<WorldBox, Error> {
        // The allocation is aligned, so the alignment slack of world_bytes
        // is not needed; it is kept so that the size is the one reported.
        let size = world_bytes(desc)?;
        let layout = Layout::from_size_align(size, WORLD_ALIGN).map_err(|_| Error::new(ErrorKind::TooLarge, crate::storage::layout::TOTAL))?;
        // SAFETY: size > 0 (the header alone is larger).
        let ptr = NonNull::new(unsafe { alloc_zeroed(layout) }).ok_or(Error::new(ErrorKind::OutOfMemory, c"the world's memory"))?;
        // SAFETY: the allocation is `size` bytes, ours until freed below.
        let memory = unsafe { core::slice::from_raw_parts_mut(ptr.as_ptr(), size) };
        match World::init(desc, memory) {
            Ok(world) => {
                world.head.owned = 1;
                Ok(WorldBox { base: ptr, world: NonNull::from(world) })
            }
            Err(e) => {
                // SAFETY: allocated above with this layout.
                unsafe { dealloc(ptr.as_ptr(), layout) };
                Err(e)
            }
        }
    }

    /// Gives up ownership; [`WorldBox::from_raw`] takes it back. The
    /// pointer is the allocation's, valid for all of it.
    pub fn into_raw(self) -> *mut u8 {
        let p = self.base.as_ptr();
        core::mem::forget(self);
        p
    }

    /// Takes back a world from [`WorldBox::into_raw`]. A pointer that holds
    /// no live world, or one the library did not allocate, is refused.
    ///
    /// # Safety
    /// As [`World::from_ptr`]; the world must not be in use elsewhere, and
    /// if it is owned, `ptr` must be the pointer [`WorldBox::into_raw`]
    /// returned (or one derived from it), valid for the whole allocation.
    pub unsafe fn from_raw(ptr: *mut u8) -> Result<WorldBox, Error> {
        // SAFETY: forwarded to the caller.
        let world = unsafe { World::from_ptr(ptr)? };
        if !world.is_owned() {
            return Err(Error::new(ErrorKind::NotOwned, c"world"));
        }
        let base = NonNull::new(ptr).ok_or(Error::new(ErrorKind::NotAWorld, c"world"))?;
        Ok(WorldBox { base, world: NonNull::from(world) })
    }
}

impl Deref for WorldBox {
    type Target = World;
    fn deref(&self) -> &World {
        // SAFETY: the box owns a live world.
        unsafe { self.world.as_ref() }
    }
}

impl DerefMut for WorldBox {
    fn deref_mut(&mut self) -> &mut World {
        // SAFETY: the box owns a live world, borrowed mutably through it.
        unsafe { self.world.as_mut() }
    }
}

impl Drop for WorldBox {
    fn drop(&mut self) {
        let world = &mut **self;
        let size = world_bytes(world.description()).unwrap_or(0);
        world.retire();
        if let Ok(layout) = Layout::from_size_align(size, WORLD_ALIGN) {
            // SAFETY: `base` was allocated in `new` with exactly this
            // layout (the description, hence world_bytes, never changes).
            unsafe { dealloc(self.base.as_ptr(), layout) };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boxes_round_trip_and_refuse_strangers() {
        let desc = Description::new_2d(8, 8);
        let mut b = WorldBox::new(&desc).unwrap();
        b.add_particle([1, 1, 0], [0.5, 0.0, 0.0]).unwrap();
        let raw = b.into_raw();
        // SAFETY: from into_raw just above.
        let mut b = unsafe { WorldBox::from_raw(raw) }.unwrap();
        b.step(3);
        assert_eq!(b.stats().particles, 1);
        drop(b);

        let mut memory = [0u64; 256];
        let bytes = unsafe { core::slice::from_raw_parts_mut(memory.as_mut_ptr().cast::<u8>(), 2048) };
        let w = World::init(&desc, bytes).unwrap();
        let p = w.as_ptr();
        // SAFETY: p points at a live world in `memory`.
        assert_eq!(unsafe { WorldBox::from_raw(p) }.err().map(|e| e.kind()), Some(ErrorKind::NotOwned));
    }
}
