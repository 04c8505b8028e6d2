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
//! - **Details**: every refusal also leaves a detail that names the field,
//!   argument or part at fault, for the thread (mpca_last_error) and the
//!   world called (mpca_world_last_error): `last_error.rs`.
//! - **Panics** never unwind into C. No input is meant to panic: a panic is
//!   a bug (fuzzing has found none since the checked accessors). The
//!   default build, like a C library whose `assert` fails, writes one line
//!   on stderr (`mpca: panicked at FILE:LINE:COLUMN: MESSAGE`) and calls
//!   `abort()`; it is built with `panic = "abort"` (the workspace's
//!   profiles set it) and without Rust's `std`, whose panic machinery
//!   (hook, backtraces, DWARF reader, demangler) would be a large part of
//!   the stripped shared library and would need `libgcc_s` at run time,
//!   for a world the panic may have left half stepped anyway (`sys.rs`). With the feature `catch-panics` (which links
//!   `std`; build it with `panic = "unwind"`) every export runs inside
//!   `catch_unwind` instead and returns `MPCA_STATUS_PANIC`, and the
//!   program goes on without that world: the C tests build it so. Firmware
//!   builds (no `hosted`) halt in a spin loop.
//! - **Threads** (hosted builds): a world may be used from any thread. The
//!   registry lets calls that only read a world (`const mpca_world *`) in
//!   together and a call that changes it (a step, parallel or not, an
//!   edit, its end) in alone, once the reads inside returned, and refuses
//!   any other call with `MPCA_STATUS_BUSY` at once; during a parallel step
//!   only its tasks reach the world (`parallel.rs`). Firmware builds: one
//!   call at a time.
#![no_std]
#![deny(missing_docs)]
#![allow(non_camel_case_types)]
#![allow(clippy::missing_safety_doc)] // the C header is the contract; see each function's docs

// The panic boundary's catch_unwind, and the unit tests' harness.
#[cfg(any(test, feature = "catch-panics"))]
extern crate std;

#[cfg(feature = "hosted")]
extern crate alloc;

// Without std no unwinding exists (rustc refuses the build less clearly).
#[cfg(all(feature = "hosted", not(any(test, feature = "catch-panics")), panic = "unwind"))]
compile_error!("libmpca without catch-panics is built with panic = \"abort\" (the workspace's dev and release profiles set it)");

mod bodies;
mod call;
mod desc;
mod emitters;
mod forces;
mod handle;
mod last_error;
mod obstacles;
#[cfg(feature = "hosted")]
mod parallel;
mod particles;
mod snapshot;
mod status;
/// What the library calls in the C library: not part of its header.
/// cbindgen:ignore
#[cfg(feature = "hosted")]
mod sys;
mod world;

pub(crate) use call::{fits, guard, Call};
pub use bodies::*;
pub use desc::*;
pub use emitters::*;
pub use forces::*;
pub use last_error::{mpca_last_error, mpca_world_last_error};
pub(crate) use last_error::Refusal;
pub use obstacles::*;
#[cfg(feature = "hosted")]
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
    assert!(size_of::<mpca_desc>() == 200 && align_of::<mpca_desc>() == 8);
    assert!(size_of::<mpca_stats>() == 152 && align_of::<mpca_stats>() == 8);
    assert!(size_of::<mpca_body_stats>() == 40 && align_of::<mpca_body_stats>() == 8);
    assert!(size_of::<mpca_region_stats>() == 48 && align_of::<mpca_region_stats>() == 8);
    assert!(size_of::<mpca_particle>() == 44 && align_of::<mpca_particle>() == 4);
    assert!(size_of::<mpca_cell>() == 48 && align_of::<mpca_cell>() == 4);
    assert!(size_of::<mpca_emitter>() == 56 && align_of::<mpca_emitter>() == 4);
    assert!(size_of::<mpca_particle_columns>() == 8 + 5 * size_of::<*mut f32>() && align_of::<mpca_particle_columns>() == align_of::<*mut f32>());
    assert!(size_of::<mpca_status>() == 4 && size_of::<mpca_boundary>() == 4);
};

/// Checks the leading `struct_size` of a versioned structure; `detail`
/// names the structure.
#[inline]
pub(crate) fn check_size<T>(struct_size: u32, detail: &'static core::ffi::CStr) -> Result<(), Refusal> {
    if struct_size as usize == core::mem::size_of::<T>() { Ok(()) } else { Err(Refusal::new(mpca_status::BadStructSize, detail)) }
}

/// Hosted builds allocate through the C library (with `std` too, so that
/// every hosted build, the one the panic-boundary tests use included, runs
/// the same allocator).
#[cfg(feature = "hosted")]
#[global_allocator]
static ALLOCATOR: sys::CAllocator = sys::CAllocator;

/// Where no `std` provides one (not in unit tests, whose harness links it,
/// nor with catch-panics, which a cargo build holding the workspace's tests
/// turns on: tests/Cargo.toml): hosted builds report the panic and abort
/// (`sys::die`).
#[cfg(all(feature = "hosted", not(any(test, feature = "catch-panics"))))]
#[panic_handler]
fn on_panic(info: &core::panic::PanicInfo<'_>) -> ! {
    sys::die(info)
}

#[cfg(not(any(test, feature = "hosted")))]
#[panic_handler]
fn on_panic(_: &core::panic::PanicInfo<'_>) -> ! {
    // Firmware builds: no unwinding exists to cross into C, nor a stderr;
    // halt here.
    loop {
        core::hint::spin_loop();
    }
}

/// Panics on purpose, so tests can show what a panic does: with
/// `catch-panics` it returns `MPCA_STATUS_PANIC` instead of unwinding into
/// C; otherwise the program aborts after one line on stderr. Only in builds
/// with the `panic-test` feature.
#[cfg(feature = "panic-test")]
#[unsafe(no_mangle)]
pub extern "C" fn mpca_debug_panic() -> mpca_status {
    guard(|_| panic!("mpca_debug_panic was called"))
}
