//! Why the last call was refused, in words: the detail every refusal
//! carries (the field or part at fault, `desc.size[1] is odd`), kept where
//! C asks for it after the status, as C libraries that explain their
//! errors keep it: per thread (`dlerror`, `errno`) and per handle
//! (`sqlite3_errmsg`).
//!
//! Every export's body returns a [`Refusal`]: the status C gets, and the
//! detail. [`guard`](crate::guard) records the detail for the calling
//! thread, and for the world the call entered (`handle.rs`, beside the
//! registry's entry). Details are static text: nothing is allocated, and a
//! pointer handed out stays valid for the library's life.

use core::ffi::{c_char, CStr};

use mpca_core::Error;

use crate::{mpca_status, mpca_world};

/// A refused call: the status returned to C and the detail recorded.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Refusal {
    pub(crate) status: mpca_status,
    /// NUL-terminated static text, by its start alone (as core's errors
    /// hold theirs), so a refusal stays two words; NULL for the status's
    /// message.
    pub(crate) detail: *const c_char,
}

impl Refusal {
    /// A refusal of this boundary's own, with its detail; in a library
    /// without details, with the status's message (no text of its own is
    /// linked).
    #[inline(always)]
    pub(crate) const fn new(status: mpca_status, detail: &'static CStr) -> Refusal {
        let detail = if cfg!(feature = "details") { detail.as_ptr() } else { core::ptr::null() };
        Refusal { status, detail }
    }
}

impl Refusal {
    /// A refusal whose detail `detail` works out, where it takes more than
    /// a literal: called only in a library that keeps details (the
    /// feature `details`); the status message stands in elsewhere.
    #[inline(always)]
    pub(crate) fn computed(status: mpca_status, detail: impl FnOnce() -> &'static CStr) -> Refusal {
        if cfg!(feature = "details") { Refusal::new(status, detail()) } else { Refusal::from(status) }
    }
}

/// A status alone: its message will be the detail (a NULL pointer, a busy
/// world: the status says all there is to say), looked up once the call
/// ends (`Call::finish`), so no refusal holds a copy of the lookup.
impl From<mpca_status> for Refusal {
    #[inline]
    fn from(status: mpca_status) -> Refusal {
        Refusal { status, detail: core::ptr::null() }
    }
}

/// A core error: its status, and the detail that names the field (in a
/// library without details, the status's message, as for a status alone).
impl From<Error> for Refusal {
    #[inline]
    fn from(e: Error) -> Refusal {
        Refusal::new(mpca_status::of_error(e), e.c_detail())
    }
}

impl Refusal {
    /// The detail as text: the status's message where the refusal has no
    /// detail of its own.
    #[cfg(feature = "hosted")]
    pub(crate) fn text(self) -> *const c_char {
        if self.detail.is_null() { crate::mpca_status_message(self.status as u32) } else { self.detail }
    }
}

/// The empty detail: what a world whose last call succeeded answers.
const NONE: &CStr = c"";

/// Records a refusal for the calling thread: hosted builds its text, in
/// the thread's slot; firmware builds the refusal as it is, its text
/// looked up when asked for, so a firmware that never asks links no
/// messages.
#[inline(never)]
pub(crate) fn refused(r: Refusal) {
    #[cfg(feature = "hosted")]
    crate::sys::set_thread_detail(r.text());
    #[cfg(not(feature = "hosted"))]
    firmware::LAST.set(r);
}

/// Firmware builds have neither threads nor a registry (one call at a
/// time): one record for the library, the last refusal.
#[cfg(not(feature = "hosted"))]
mod firmware {
    use core::ffi::c_char;
    use core::sync::atomic::{AtomicPtr, AtomicU32, Ordering::Relaxed};

    use super::Refusal;
    use crate::mpca_status;

    /// A refusal as two atomics (each stored and loaded alone, which every
    /// core has): status OK for none yet.
    pub(super) struct Record {
        status: AtomicU32,
        detail: AtomicPtr<c_char>,
    }

    impl Record {
        const fn new() -> Record {
            Record { status: AtomicU32::new(0), detail: AtomicPtr::new(core::ptr::null_mut()) }
        }

        pub(super) fn set(&self, r: Refusal) {
            self.status.store(r.status as u32, Relaxed);
            self.detail.store(r.detail.cast_mut(), Relaxed);
        }

        /// The refusal's text; NULL for none.
        pub(super) fn text(&self) -> *const c_char {
            let status = self.status.load(Relaxed);
            if status == mpca_status::Ok as u32 {
                return core::ptr::null();
            }
            let detail = self.detail.load(Relaxed).cast_const();
            if detail.is_null() { crate::mpca_status_message(status) } else { detail }
        }
    }

    pub(super) static LAST: Record = Record::new();
}

/// The detail of this thread's last refused call, from any function of the
/// library (a description's check, a world's creation, a call on any
/// world): where the problem is, as the field, argument or part at fault,
/// with what is wrong with it where the status does not say:
/// `desc.size[1]`, `velocity`, `desc.emitter_capacity is 0`, `checksum`
/// (of an image). Fields are named as the Rust crate's description names
/// them, which mpca_desc follows with `_` for `.` (`desc.drag.rate` is
/// `drag_rate`); arguments by their names in this header. A status that
/// says all there is (a NULL pointer, MPCA_STATUS_BUSY) has its message as
/// the detail. "" while no call of this thread was refused. A call that
/// succeeds does not clear it: ask after a status other than
/// `MPCA_STATUS_OK`, as with `errno`, and print it after
/// mpca_status_message(status): "a world size is odd; Margolus blocks need
/// even sizes: desc.size[1]". Never NULL; static text, never to be freed, valid for the library's
/// life. Firmware builds (without the `hosted` feature) have no threads:
/// one record for the whole library. A library built without the feature
/// `details` gives the status's message as every detail.
#[unsafe(no_mangle)]
pub extern "C" fn mpca_last_error() -> *const c_char {
    #[cfg(feature = "hosted")]
    let detail = crate::sys::thread_detail();
    #[cfg(not(feature = "hosted"))]
    let detail = firmware::LAST.text();
    if detail.is_null() { NONE.as_ptr() } else { detail }
}

/// The detail of the last call on `world`, if it was refused, as
/// mpca_last_error gives it; "" if that call succeeded or no call was made
/// on the world yet. The last call is the last to enter the world: every
/// call taking it but those refused before reaching it (a NULL or dead
/// handle, MPCA_STATUS_BUSY) and mpca_world_step_task, whose refusals
/// only mpca_last_error records. Calls that only read the world
/// (`const mpca_world *`) count too, so with several threads on one world
/// the answer is the last of theirs to end. Never NULL; static text, never
/// to be freed. A NULL or dead handle gets a detail saying so.
///
/// Firmware builds keep one record for the library (no registry knows the
/// worlds): the answer is mpca_last_error's, whatever `world`.
#[unsafe(no_mangle)]
pub extern "C" fn mpca_world_last_error(world: *const mpca_world) -> *const c_char {
    #[cfg(feature = "hosted")]
    let detail = match crate::handle::last_detail(world) {
        Some(d) => d,
        None => return c"world (not a live handle)".as_ptr(),
    };
    #[cfg(not(feature = "hosted"))]
    let detail = {
        let _ = world;
        firmware::LAST.text()
    };
    if detail.is_null() { NONE.as_ptr() } else { detail }
}

#[cfg(all(test, feature = "hosted"))]
mod tests {
    use core::ffi::CStr;
    use core::ptr::null_mut;

    use crate::*;

    fn text(p: *const core::ffi::c_char) -> &'static str {
        // SAFETY: the library's last-error functions return static,
        // NUL-terminated text.
        unsafe { CStr::from_ptr(p) }.to_str().unwrap()
    }

    #[test]
    fn the_thread_and_the_world_keep_the_detail_of_their_last_refusal() {
        // SAFETY, for every export below: each pointer is NULL or a live
        // local of the size the header asks for.
        unsafe {
            let mut d = core::mem::MaybeUninit::<mpca_desc>::uninit();
            assert_eq!(mpca_desc_defaults(d.as_mut_ptr(), 2, 8, 7, 0), mpca_status::Ok);
            let mut d = d.assume_init();
            // A description refused: the thread's detail names the field.
            assert_eq!(mpca_desc_validate(&d), mpca_status::SizeOdd);
            assert_eq!(text(mpca_last_error()), "desc.size[1]");
            d.size[1] = 8;
            d.boundary[0][0] = 7;
            assert_eq!(mpca_desc_validate(&d), mpca_status::BadEnum);
            assert_eq!(text(mpca_last_error()), "desc.boundary");
            d.boundary[0][0] = 0;
            // A success leaves the thread's record as it was.
            assert_eq!(mpca_desc_validate(&d), mpca_status::Ok);
            assert_eq!(text(mpca_last_error()), "desc.boundary");
            let mut w = null_mut();
            assert_eq!(mpca_world_create(&d, &mut w), mpca_status::Ok);
            assert_eq!(text(mpca_world_last_error(w)), "");
            // A refused call on the world: both name the argument.
            let v = [2.0f32, 0.0, 0.0];
            assert_eq!(mpca_world_add_particle(w, [1u32, 1, 0].as_ptr(), v.as_ptr()), mpca_status::SpeedRange);
            assert_eq!((text(mpca_last_error()), text(mpca_world_last_error(w))), ("velocity", "velocity"));
            // A status without a detail of its own gives its message.
            assert_eq!(mpca_world_add_particle(w, core::ptr::null(), v.as_ptr()), mpca_status::NullPointer);
            assert_eq!(text(mpca_world_last_error(w)), text(mpca_status_message(mpca_status::NullPointer as u32)));
            // The world's next call succeeds: its detail is cleared, the
            // thread's is kept.
            let mut count = 0usize;
            assert_eq!(mpca_world_particle_count(w, &mut count), mpca_status::Ok);
            assert_eq!(text(mpca_world_last_error(w)), "");
            assert_eq!(text(mpca_last_error()), text(mpca_status_message(mpca_status::NullPointer as u32)));
            assert_eq!(mpca_world_destroy(w), mpca_status::Ok);
            assert_eq!(text(mpca_world_last_error(w)), "world (not a live handle)");
            assert_eq!(text(mpca_world_last_error(core::ptr::null())), "world (not a live handle)");
        }
    }

    #[test]
    fn another_threads_refusals_leave_this_threads_detail() {
        // SAFETY: a live local of the size the header asks for.
        unsafe {
            let mut d = core::mem::MaybeUninit::<mpca_desc>::uninit();
            assert_eq!(mpca_desc_defaults(d.as_mut_ptr(), 2, 0, 8, 0), mpca_status::Ok);
            assert_eq!(mpca_desc_validate(d.as_ptr()), mpca_status::SizeZero);
        }
        assert_eq!(text(mpca_last_error()), "desc.size[0]");
        let other = std::thread::spawn(|| {
            // A fresh thread has no refusal yet; then its own.
            let before = text(mpca_last_error());
            // SAFETY: as above.
            unsafe {
                let mut d = core::mem::MaybeUninit::<mpca_desc>::uninit();
                assert_eq!(mpca_desc_defaults(d.as_mut_ptr(), 4, 8, 8, 0), mpca_status::Ok);
                assert_eq!(mpca_desc_validate(d.as_ptr()), mpca_status::BadDimension);
            }
            (before, text(mpca_last_error()))
        })
        .join()
        .unwrap();
        assert_eq!(other, ("", "desc.dim"));
        assert_eq!(text(mpca_last_error()), "desc.size[0]");
    }
}
