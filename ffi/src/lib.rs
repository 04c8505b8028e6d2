//! # libmpca: the C ABI of mpca
//!
//! Every export is `mpca_*`, returns an [`mpca_status`] (0 is success) and
//! writes its results through out-parameters. The rules at this boundary:
//!
//! - **NULL** for any pointer argument returns `MPCA_STATUS_NULL_POINTER`;
//!   nothing is dereferenced first.
//! - **Handles** (`handle.rs`): in hosted builds a value the library issues
//!   once and looks up in a registry of live worlds before reading any
//!   memory, so a destroyed, deinitialised or forged handle returns
//!   `MPCA_STATUS_BAD_HANDLE` whatever became of the memory. Firmware
//!   builds have no registry: the handle is the world's address, checked by
//!   a tag tied to it, with the limits `mpca_world` documents.
//! - **Bad values** (NaN, infinities, out-of-range numbers, unknown enum
//!   values, wrong `struct_size`) return a status and leave the world
//!   unchanged.
//! - **Panics** never unwind into C. With the default `std` feature every
//!   export runs inside `catch_unwind` and returns `MPCA_STATUS_PANIC`;
//!   without it (firmware builds, which abort on panic by target default) a
//!   panic halts in a spin loop. No input is meant to panic: a panic is a bug.
//! - **Threads**: a world may move between threads but must not be used
//!   from two at once, except for the tasks of a parallel step
//!   (`parallel.rs`), during which the registry refuses every other call on
//!   the world with `MPCA_STATUS_BUSY`.
#![no_std]
#![deny(missing_docs)]
#![allow(non_camel_case_types)]
#![allow(clippy::missing_safety_doc)] // the C header is the contract; see each function's docs

#[cfg(feature = "std")]
extern crate std;

mod call;
mod desc;
mod emitters;
mod forces;
mod handle;
mod obstacles;
#[cfg(feature = "std")]
mod parallel;
mod particles;
mod snapshot;
mod status;
mod world;

pub(crate) use call::{fits, guard, Call};
pub use desc::*;
pub use emitters::*;
pub use forces::*;
pub use obstacles::*;
#[cfg(feature = "std")]
pub use parallel::*;
pub use particles::*;
pub use snapshot::*;
pub use status::*;
pub use world::*;

/// Major version of this library.
pub const MPCA_VERSION_MAJOR: u32 = 0;
/// Minor version of this library.
pub const MPCA_VERSION_MINOR: u32 = 1;
/// Patch version of this library.
pub const MPCA_VERSION_PATCH: u32 = 0;

/// The library's version, "MAJOR.MINOR.PATCH", as a static string.
#[unsafe(no_mangle)]
pub extern "C" fn mpca_version() -> *const core::ffi::c_char {
    const V: &core::ffi::CStr = match core::ffi::CStr::from_bytes_with_nul(concat!(env!("CARGO_PKG_VERSION"), "\0").as_bytes()) {
        Ok(v) => v,
        Err(_) => c"?",
    };
    V.as_ptr()
}

// The layout C sees, fixed: the C tests assert the same with _Static_assert.
const _: () = {
    use core::mem::{align_of, size_of};
    assert!(size_of::<mpca_desc>() == 168 && align_of::<mpca_desc>() == 8);
    assert!(size_of::<mpca_stats>() == 144 && align_of::<mpca_stats>() == 8);
    assert!(size_of::<mpca_region_stats>() == 48 && align_of::<mpca_region_stats>() == 8);
    assert!(size_of::<mpca_particle>() == 32 && align_of::<mpca_particle>() == 4);
    assert!(size_of::<mpca_cell>() == 36 && align_of::<mpca_cell>() == 4);
    assert!(size_of::<mpca_emitter>() == 56 && align_of::<mpca_emitter>() == 4);
    assert!(size_of::<mpca_status>() == 4 && size_of::<mpca_boundary>() == 4);
};

/// 0 or 1 as a bool; anything else is `BadEnum`.
#[inline]
pub(crate) fn flag(v: u32) -> Result<bool, mpca_status> {
    match v {
        0 => Ok(false),
        1 => Ok(true),
        _ => Err(mpca_status::BadEnum),
    }
}

/// Checks the leading `struct_size` of a versioned structure.
#[inline]
pub(crate) fn check_size<T>(struct_size: u32) -> Result<(), mpca_status> {
    if struct_size as usize == core::mem::size_of::<T>() { Ok(()) } else { Err(mpca_status::BadStructSize) }
}

#[cfg(not(feature = "std"))]
#[panic_handler]
fn on_panic(_: &core::panic::PanicInfo<'_>) -> ! {
    // Firmware builds: no unwinding exists to cross into C; halt here.
    loop {
        core::hint::spin_loop();
    }
}

/// Panics on purpose, inside the panic boundary, so tests can show that a
/// panic returns `MPCA_STATUS_PANIC` instead of unwinding into C. Only in
/// builds with the `panic-test` feature.
#[cfg(feature = "panic-test")]
#[unsafe(no_mangle)]
pub extern "C" fn mpca_debug_panic() -> mpca_status {
    guard(|_| panic!("mpca_debug_panic was called"))
}
