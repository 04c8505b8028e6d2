//! The C boundary: what a caller of an export vouches for, and the only
//! places the library relies on it.
//!
//! Every export runs its body through [`guard`], which hands it a [`Call`].
//! The `Call` stands for the promise the header asks of C: each pointer
//! argument is NULL or points at memory valid, for as long as the call
//! runs, for the access its documentation names (one structure or value to
//! read, one to write, `len` elements), aligned for its type, and not
//! reached through another argument or the world's own memory while the
//! call writes it. The accessors of `Call` turn such pointers into values
//! and references after the checks that need no trust (NULL, a length no
//! object can have); each argues its one `unsafe` step from that promise.
//! Exports use nothing else to reach caller memory, so they hold no
//! `unsafe` of their own.
//!
//! Handles are not caller memory: [`Call::world`] resolves one through the
//! registry of `handle.rs` before anything is read, and enters the world
//! there for as long as the call runs (the `Call` leaves it when it ends,
//! recording the call's detail for the world: `last_error.rs`).

#[cfg(feature = "hosted")]
use core::cell::Cell;
use core::marker::PhantomData;

use mpca_core::World;

use crate::handle::{self, Access};
use crate::last_error::{self, Refusal};
use crate::{mpca_status, mpca_world};

/// One call of an export and its caller's promise (module docs). Only
/// [`guard`] makes one; the references its accessors return live no longer
/// than the call.
pub(crate) struct Call<'c> {
    /// Invariant in `'c`, and neither `Send` nor `Sync`: the promise holds
    /// on the caller's thread, for this call.
    _call: PhantomData<*mut &'c ()>,
    /// The world this call entered in the registry, and for what; left
    /// when the call ends, its detail recorded. Firmware builds have no
    /// registry to leave, nor a record per world.
    #[cfg(feature = "hosted")]
    entered: Cell<Option<(*const mpca_world, Access)>>,
}

impl Call<'_> {
    /// The call ends with `result`: the world it entered records it and
    /// is left, the thread records a refusal, and the status comes back.
    /// Out of line: every export ends here.
    #[inline(never)]
    fn finish(self, result: Result<(), Refusal>) -> mpca_status {
        match result {
            Ok(()) => {
                #[cfg(feature = "hosted")]
                self.end(None);
                mpca_status::Ok
            }
            Err(r) => {
                #[cfg(feature = "hosted")]
                self.end(Some(r));
                last_error::refused(r);
                r.status
            }
        }
    }

    /// The call ends with refusal `r` (`None`: success): the world it
    /// entered records it, and is left.
    #[cfg(feature = "hosted")]
    fn end(&self, r: Option<Refusal>) {
        if let Some((w, access)) = self.entered.take() {
            handle::leave(w, access, r.map_or(core::ptr::null(), Refusal::text));
        }
    }
}

#[cfg(feature = "hosted")]
impl Drop for Call<'_> {
    /// The call is over (returned, or unwinding to the panic boundary): no
    /// reference it handed out is used any more. One that unwound records
    /// the panic's message.
    fn drop(&mut self) {
        self.end(Some(Refusal::from(mpca_status::Panic)));
    }
}

/// Runs an export's body with the caller's promise, inside the panic
/// boundary where there is one (`catch-panics`; lib.rs), records a
/// refusal's detail for the thread and the world, and turns its result
/// into a status.
///
/// Called only as the whole body of an export (a `pub extern "C" fn` of
/// this crate): that is what makes the [`Call`] it hands out true. The
/// test `guard_is_called_only_by_exports` below checks the sources for it.
#[inline]
pub(crate) fn guard(body: impl for<'c> FnOnce(&Call<'c>) -> Result<(), Refusal>) -> mpca_status {
    let call = Call {
        _call: PhantomData,
        #[cfg(feature = "hosted")]
        entered: Cell::new(None),
    };
    // The closure owns the call, so it is dropped (its world left) when the
    // body unwinds, and finished when it returns.
    let body = move || {
        let result = body(&call);
        call.finish(result)
    };
    #[cfg(feature = "catch-panics")]
    return match std::panic::catch_unwind(core::panic::AssertUnwindSafe(body)) {
        Ok(status) => status,
        Err(_) => {
            last_error::refused(Refusal::from(mpca_status::Panic));
            mpca_status::Panic
        }
    };
    #[cfg(not(feature = "catch-panics"))]
    body()
}

/// Whether `len` values of `T` fit in one object: at most `isize::MAX`
/// bytes, the bound `core::slice::from_raw_parts` requires.
#[inline]
pub(crate) fn fits<T>(len: usize) -> bool {
    len <= isize::MAX as usize / core::mem::size_of::<T>().max(1)
}

/// An out-parameter, checked not NULL: written once the call has decided
/// what to write, so a refusal that comes later leaves it untouched.
pub(crate) struct Out<'c, T> {
    at: *mut T,
    _call: PhantomData<&'c mut T>,
}

impl<T> Out<'_, T> {
    /// Writes `value`, without reading or dropping what was there (the
    /// caller's memory may be uninitialised).
    #[inline]
    pub(crate) fn set(self, value: T) {
        // SAFETY: `at` is not NULL (`Call::out`) and, by the caller's
        // promise, valid and aligned for writing a `T` until the call
        // returns, which `'c` outlives no more than the call.
        unsafe { self.at.write(value) }
    }
}

impl<'c> Call<'c> {
    /// The structure or value at `p`, read in place; NULL is refused.
    #[inline]
    pub(crate) fn get<T: 'c>(&self, p: *const T) -> Result<&'c T, mpca_status> {
        // SAFETY: the caller's promise: `p` is NULL, which `as_ref` turns
        // into None, or an aligned, readable, initialised `T`, not written
        // through any other path until the call returns.
        unsafe { p.as_ref() }.ok_or(mpca_status::NullPointer)
    }

    /// `N` values at `p` (3 for positions, velocities and normals);
    /// NULL is refused.
    #[inline]
    pub(crate) fn array<T: Copy + 'c, const N: usize>(&self, p: *const T) -> Result<[T; N], mpca_status> {
        // `[T; N]` has the alignment of `T`, and the promise covers N
        // values: one array.
        self.get(p.cast::<[T; N]>()).copied()
    }

    /// The out-parameter at `p`, to be written later; NULL is refused now.
    #[inline]
    pub(crate) fn out<T: 'c>(&self, p: *mut T) -> Result<Out<'c, T>, mpca_status> {
        if p.is_null() {
            return Err(mpca_status::NullPointer);
        }
        Ok(Out { at: p, _call: PhantomData })
    }

    /// `len` values at `p`. NULL is refused even when `len` is 0, and a
    /// length no object can have with `too_long`, before any slice exists.
    #[inline]
    pub(crate) fn slice<T: 'c>(&self, p: *const T, len: usize, too_long: mpca_status) -> Result<&'c [T], mpca_status> {
        if p.is_null() {
            return Err(mpca_status::NullPointer);
        }
        if !fits::<T>(len) {
            return Err(too_long);
        }
        // SAFETY: not NULL, `len` values span at most isize::MAX bytes, and
        // the caller's promise: `p` points at `len` readable, initialised
        // values, not written through any other path until the call returns.
        Ok(unsafe { core::slice::from_raw_parts(p, len) })
    }

    /// `len` writable values at `p`, refused as in [`Call::slice`].
    #[inline]
    pub(crate) fn slice_mut<T: 'c>(&self, p: *mut T, len: usize, too_long: mpca_status) -> Result<&'c mut [T], mpca_status> {
        if p.is_null() {
            return Err(mpca_status::NullPointer);
        }
        if !fits::<T>(len) {
            return Err(too_long);
        }
        // SAFETY: as in `slice`, for `len` writable values that the caller
        // reaches through no other argument and that lie outside the world
        // (the caller's promise), so this is their only reference.
        Ok(unsafe { core::slice::from_raw_parts_mut(p, len) })
    }

    /// [`Call::slice_mut`] where `p` is not NULL, `None` where it is: an
    /// output the caller may leave out.
    #[inline]
    pub(crate) fn slice_mut_or_null<T: 'c>(&self, p: *mut T, len: usize, too_long: mpca_status) -> Result<Option<&'c mut [T]>, mpca_status> {
        if p.is_null() { Ok(None) } else { self.slice_mut(p, len, too_long).map(Some) }
    }

    /// Enters the world behind a handle for `access` until the call ends,
    /// and returns where it is: NULL, dead handles and a world busy with
    /// another call (hosted builds) are refused. An export enters one world.
    pub(crate) fn enter(&self, w: *const mpca_world, access: Access) -> Result<*mut u8, mpca_status> {
        if w.is_null() {
            return Err(mpca_status::NullPointer);
        }
        let at = handle::enter(w, access)?;
        #[cfg(feature = "hosted")]
        {
            debug_assert!(self.entered.get().is_none(), "a call enters one world");
            self.entered.set(Some((w, access)));
        }
        Ok(at)
    }

    /// The world behind a handle, for a call that changes it.
    #[inline]
    pub(crate) fn world(&self, w: *mut mpca_world) -> Result<&'c mut World, Refusal> {
        let at = self.world_at(w, Access::Write)?;
        // SAFETY: entered for Write (`world_at`): the registry lets no other
        // call inside until this one ends, which `'c` does not outlive
        // (firmware: one call at a time).
        Ok(unsafe { &mut *at })
    }

    /// The world behind a handle, for a call that ends or replaces it
    /// (deinit, load): refused with `Busy` while any call is inside.
    #[inline]
    pub(crate) fn world_to_end(&self, w: *mut mpca_world) -> Result<&'c mut World, Refusal> {
        let at = self.world_at(w, Access::End)?;
        // SAFETY: as in `world`; End admits no other call either.
        Ok(unsafe { &mut *at })
    }

    /// The world behind a handle, for a call that only reads it: others
    /// may read it at the same time, none change it.
    #[inline]
    pub(crate) fn world_ref(&self, w: *const mpca_world) -> Result<&'c World, Refusal> {
        let at = self.world_at(w, Access::Read)?;
        // SAFETY: entered for Read: while this call runs the registry lets
        // only calls that read the world inside, and they hold shared
        // references only.
        Ok(unsafe { &*at })
    }

    /// Enters the world behind a handle for `access` and finds it. One
    /// function behind the three above, so each export's call is small.
    #[inline(never)]
    fn world_at(&self, w: *const mpca_world, access: Access) -> Result<*mut World, Refusal> {
        let at = self.enter(w, access)?;
        // SAFETY: hosted builds: `at` is where a world was built and
        // registered, and its handle was not revoked since, so the memory
        // is that world's (the C contract: memory handed to mpca_world_init
        // stays until deinit). Firmware builds: the C contract that a
        // handle is an address this library returned, still readable.
        // Either way the tag is checked before anything else is read.
        unsafe { World::from_ptr_raw(at) }.map_err(|e| Refusal::new(mpca_status::BadHandle, e.c_detail()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accessors_refuse_null_and_impossible_lengths_before_reading() {
        let status = guard(|c| {
            assert_eq!(c.get::<u32>(core::ptr::null()).err(), Some(mpca_status::NullPointer));
            assert_eq!(c.array::<f32, 3>(core::ptr::null()).err(), Some(mpca_status::NullPointer));
            assert!(matches!(c.out::<u64>(core::ptr::null_mut()), Err(mpca_status::NullPointer)));
            assert_eq!(c.slice::<u8>(core::ptr::null(), 0, mpca_status::BadLength).err(), Some(mpca_status::NullPointer));
            // A dangling but aligned pointer: only the length is looked at.
            let far = core::ptr::NonNull::<f32>::dangling().as_ptr();
            assert_eq!(c.slice(far.cast_const(), usize::MAX / 2, mpca_status::BadLength).err(), Some(mpca_status::BadLength));
            assert_eq!(c.slice_mut(far, usize::MAX / 4 + 1, mpca_status::BadResolution).err(), Some(mpca_status::BadResolution));
            assert_eq!(c.world(core::ptr::null_mut()).err().map(|r| r.status), Some(mpca_status::NullPointer));
            Ok(())
        });
        assert_eq!(status, mpca_status::Ok);
    }

    #[test]
    fn accessors_read_and_write_what_they_are_given() {
        let (value, values) = (7u32, [1.0f32, 2.0, 3.0]);
        let mut out = core::mem::MaybeUninit::<[f32; 3]>::uninit();
        let mut buf = [0u16; 4];
        let status = guard(|c| {
            assert_eq!(*c.get(&value)?, 7);
            assert_eq!(c.array::<f32, 3>(values.as_ptr())?, values);
            c.out(out.as_mut_ptr())?.set([4.0, 5.0, 6.0]);
            c.slice_mut(buf.as_mut_ptr(), 4, mpca_status::BadLength)?.copy_from_slice(&[1, 2, 3, 4]);
            assert_eq!(c.slice(buf.as_ptr(), 3, mpca_status::BadLength)?, &[1, 2, 3]);
            Ok(())
        });
        assert_eq!(status, mpca_status::Ok);
        // SAFETY: written by `set` above.
        assert_eq!(unsafe { out.assume_init() }, [4.0, 5.0, 6.0]);
    }

    /// The exports as C uses them, small enough for Miri, which checks
    /// that every accessor's reference is valid and unaliased while used:
    /// a world in caller memory and one in library memory, particles, a
    /// step, the exports, an image saved and built into new memory, and
    /// the refusals that must not read or write.
    #[test]
    fn exports_reach_caller_memory_only_as_promised() {
        use crate::*;
        use core::ptr::{null, null_mut};
        // SAFETY, for every call below: each pointer is NULL or a live
        // local of the size the header asks for.
        unsafe {
            let mut d = core::mem::MaybeUninit::<mpca_desc>::uninit();
            assert_eq!(mpca_desc_defaults(d.as_mut_ptr(), 2, 8, 6, 0), mpca_status::Ok);
            let d = d.assume_init();
            let mut bytes = 0usize;
            assert_eq!(mpca_world_bytes(&d, &mut bytes), mpca_status::Ok);
            let mut memory = std::vec![0u8; bytes];
            let mut w = null_mut();
            assert_eq!(mpca_world_init(&d, memory.as_mut_ptr().cast(), bytes, &mut w), mpca_status::Ok);
            let mut owned = null_mut();
            assert_eq!(mpca_world_create(&d, &mut owned), mpca_status::Ok);
            for (i, pos) in [[1u32, 1, 0], [4, 2, 0], [7, 5, 0]].iter().enumerate() {
                let v = [0.5f32, -0.25 * i as f32, 0.0];
                assert_eq!(mpca_world_add_particle(w, pos.as_ptr(), v.as_ptr()), mpca_status::Ok);
                assert_eq!(mpca_world_add_particle(owned, pos.as_ptr(), v.as_ptr()), mpca_status::Ok);
            }
            assert_eq!(mpca_world_add_particle(w, [1u32, 1, 0].as_ptr(), null()), mpca_status::NullPointer);
            assert_eq!(mpca_world_step(w, 2), mpca_status::Ok);
            assert_eq!(mpca_world_step(owned, 2), mpca_status::Ok);
            let (mut h, mut g) = (0u64, 1u64);
            assert_eq!(mpca_world_hash(w, &mut h), mpca_status::Ok);
            assert_eq!(mpca_world_hash(owned, &mut g), mpca_status::Ok);
            assert_eq!(h, g);

            let mut stats = mpca_stats { struct_size: core::mem::size_of::<mpca_stats>() as u32, ..Default::default() };
            assert_eq!(mpca_world_stats(w, &mut stats), mpca_status::Ok);
            assert_eq!(stats.particles, 3);
            let (mut count, mut positions) = (0usize, [0.0f32; 9]);
            assert_eq!(mpca_world_export_positions(w, positions.as_mut_ptr(), 2, &mut count), mpca_status::OutputTooSmall);
            assert_eq!((count, positions), (3, [0.0; 9]));
            assert_eq!(mpca_world_export_positions(w, positions.as_mut_ptr(), 3, &mut count), mpca_status::Ok);
            let mut density = [0.0f32; 48];
            assert_eq!(mpca_world_density(w, [8u32, 6, 1].as_ptr(), density.as_mut_ptr(), 48), mpca_status::Ok);
            assert_eq!(density.iter().sum::<f32>(), 3.0);
            let mut region = mpca_region_stats { struct_size: core::mem::size_of::<mpca_region_stats>() as u32, ..Default::default() };
            assert_eq!(mpca_world_region_stats(w, [0u32; 3].as_ptr(), [8u32, 6, 1].as_ptr(), &mut region), mpca_status::Ok);
            assert_eq!((region.particles, region.momentum), (3, stats.momentum));

            let mut need = 0usize;
            assert_eq!(mpca_world_save(w, null_mut(), 0, &mut need), mpca_status::Ok);
            let mut image = std::vec![0u8; need];
            assert_eq!(mpca_world_save(w, image.as_mut_ptr().cast(), need, &mut need), mpca_status::Ok);
            // Saving into the world's own memory is refused before a slice
            // over either exists.
            assert_eq!(mpca_world_save(w, memory.as_mut_ptr().cast(), 64, &mut need), mpca_status::Overlap);
            let mut copy_memory = std::vec![0u8; bytes];
            let mut copy = null_mut();
            assert_eq!(
                mpca_world_init_from_image(image.as_ptr().cast(), image.len(), copy_memory.as_mut_ptr().cast(), bytes, &mut copy),
                mpca_status::Ok
            );
            assert_eq!(mpca_world_hash(copy, &mut g), mpca_status::Ok);
            assert_eq!(g, h);
            image[40] ^= 1;
            assert_eq!(mpca_world_load(copy, image.as_ptr().cast(), image.len()), mpca_status::ImageChecksum);

            assert_eq!(mpca_world_deinit(copy), mpca_status::Ok);
            assert_eq!(mpca_world_deinit(w), mpca_status::Ok);
            assert_eq!(mpca_world_step(w, 1), mpca_status::BadHandle);
            assert_eq!(mpca_world_destroy(owned), mpca_status::Ok);
            assert_eq!(mpca_world_hash(owned, &mut g), mpca_status::BadHandle);
        }
    }

    /// `guard`'s promise is true only where C called: every use of it must
    /// be the body of an export. And every export but four that only look
    /// up static strings runs inside it, the panic boundary (the last
    /// error's two must not be calls that record one).
    #[test]
    fn guard_is_called_only_by_exports() {
        let sources = [
            ("bodies.rs", include_str!("bodies.rs")),
            ("desc.rs", include_str!("desc.rs")),
            ("emitters.rs", include_str!("emitters.rs")),
            ("forces.rs", include_str!("forces.rs")),
            ("last_error.rs", include_str!("last_error.rs")),
            ("lib.rs", include_str!("lib.rs")),
            ("obstacles.rs", include_str!("obstacles.rs")),
            ("parallel.rs", include_str!("parallel.rs")),
            ("particles.rs", include_str!("particles.rs")),
            ("snapshot.rs", include_str!("snapshot.rs")),
            ("status.rs", include_str!("status.rs")),
            ("world.rs", include_str!("world.rs")),
        ];
        let is_export = |f: &'static str| f.starts_with("pub unsafe extern \"C\" fn ") || f.starts_with("pub extern \"C\" fn ");
        let name = |f: &'static str| f.split("fn ").nth(1).and_then(|r| r.split('(').next()).unwrap_or("");
        let mut unguarded = std::collections::BTreeSet::new();
        for (file, text) in sources {
            let mut function = "";
            for line in text.lines() {
                if line.contains("fn ") && !line.trim_start().starts_with("//") {
                    function = line;
                    if is_export(line) {
                        unguarded.insert(name(line));
                    }
                }
                if line.contains("guard(|") {
                    assert!(is_export(function), "{file}: guard used outside an export: {function}");
                    unguarded.remove(name(function));
                }
            }
        }
        let expected = std::collections::BTreeSet::from(["mpca_version", "mpca_status_message", "mpca_last_error", "mpca_world_last_error"]);
        assert_eq!(unguarded, expected, "exports outside the panic boundary");
    }
}
