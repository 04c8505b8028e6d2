//! What a hosted library without Rust's `std` takes from the C library it
//! is loaded with: memory (`malloc`, `calloc`, `free`, `posix_memalign`),
//! a lock for the registry of handles (core's atomics, waiting with
//! `sched_yield`), a thread-local slot for each thread's last refusal
//! (`pthread_key_create`, `pthread_getspecific`, `pthread_setspecific`;
//! `TlsAlloc` and its kin on Windows), and, for a panic, one line on
//! stderr (`write`) and `abort`. These are the only C functions libmpca calls (`readelf -d`
//! shows `libc.so.6` as its one dependency).
//!
//! Why not `std`: linking it brings its panic machinery (the default hook,
//! backtraces, symbol demangling, DWARF parsing), a large part of the
//! stripped shared library, for a panic that is a bug and should end the
//! program anyway; and it needs GCC's unwinder, `libgcc_s`, at run time.
//! The feature `catch-panics` builds with `std` and its panic boundary
//! instead (lib.rs).

use core::cell::UnsafeCell;
use core::ffi::c_void;
use core::ops::{Deref, DerefMut};
use core::sync::atomic::{AtomicBool, Ordering};

// `link`: so that libmpca.so names libc.so.6 as needed, and rustc lists
// -lc among the libraries a static link needs. (Elsewhere, Windows say,
// the C runtime is linked anyway.)
#[cfg_attr(unix, link(name = "c"))]
unsafe extern "C" {
    fn malloc(size: usize) -> *mut c_void;
    fn calloc(count: usize, size: usize) -> *mut c_void;
    fn free(p: *mut c_void);
    #[cfg(unix)]
    fn posix_memalign(out: *mut *mut c_void, align: usize, size: usize) -> core::ffi::c_int;
    #[cfg(all(unix, not(any(test, feature = "catch-panics"))))]
    fn write(fd: core::ffi::c_int, buf: *const c_void, count: usize) -> isize;
    #[cfg(not(any(test, feature = "catch-panics")))]
    fn abort() -> !;
    #[cfg(unix)]
    fn sched_yield() -> core::ffi::c_int;
}

/// Rust's global allocator in hosted builds: the C library's `malloc`
/// family, so the memory of a world from mpca_world_create is counted,
/// traced and limited as the program's own.
pub(crate) struct CAllocator;

/// The alignment `malloc` guarantees (that of `max_align_t`: 16 on 64-bit
/// targets, 8 on 32-bit ones, as `std`'s allocator assumes too). A
/// request for more goes through `posix_memalign`.
const MALLOC_ALIGN: usize = if usize::BITS >= 64 { 16 } else { 8 };

impl CAllocator {
    /// Whether plain `malloc` meets `layout`'s alignment: C promises its
    /// fundamental alignment only for blocks at least that large.
    fn plain(layout: core::alloc::Layout) -> bool {
        layout.align() <= MALLOC_ALIGN && layout.align() <= layout.size()
    }

    /// An over-aligned block, or NULL.
    fn aligned(layout: core::alloc::Layout) -> *mut u8 {
        #[cfg(unix)]
        {
            let mut p = core::ptr::null_mut();
            // posix_memalign asks for a multiple of the pointer's size.
            let align = layout.align().max(size_of::<usize>());
            // SAFETY: `p` is a valid out-parameter; `align` is a power of
            // two (Layout's) and a multiple of sizeof(void *).
            if unsafe { posix_memalign(&mut p, align, layout.size()) } == 0 { p.cast() } else { core::ptr::null_mut() }
        }
        // No portable C function: no request of this library is aligned
        // beyond malloc's (a world's header asks for 8).
        #[cfg(not(unix))]
        {
            let _ = layout;
            core::ptr::null_mut()
        }
    }
}

// SAFETY: every block comes from malloc, calloc or posix_memalign, aligned
// as asked (`plain`, or posix_memalign's own promise), at least as large,
// and is given back to free, which takes each of them.
unsafe impl core::alloc::GlobalAlloc for CAllocator {
    unsafe fn alloc(&self, layout: core::alloc::Layout) -> *mut u8 {
        // SAFETY: malloc accepts any size.
        if Self::plain(layout) { unsafe { malloc(layout.size()).cast() } } else { Self::aligned(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: core::alloc::Layout) -> *mut u8 {
        if Self::plain(layout) {
            // calloc: a large world's zeroed pages come from the system
            // untouched instead of being written.
            // SAFETY: calloc accepts any size.
            unsafe { calloc(layout.size(), 1).cast() }
        } else {
            let p = Self::aligned(layout);
            if !p.is_null() {
                // SAFETY: `p` is a fresh block of layout.size() bytes.
                unsafe { p.write_bytes(0, layout.size()) };
            }
            p
        }
    }

    unsafe fn dealloc(&self, p: *mut u8, _: core::alloc::Layout) {
        // SAFETY: `p` came from this allocator (GlobalAlloc's contract).
        unsafe { free(p.cast()) }
    }
}

/// The thread's record of its last refusal (`last_error.rs`): a slot of
/// the system's thread-local storage holding the detail's address. No
/// memory is allocated for it, and nothing is to be freed when a thread
/// ends: the details are static. The slot is made by the first refusal.
#[cfg(any(unix, windows))]
mod thread_record {
    use core::ffi::{c_char, c_void};
    use core::sync::atomic::{AtomicUsize, Ordering};

    #[cfg(all(unix, any(target_os = "macos", target_os = "ios")))]
    type Key = core::ffi::c_ulong;
    #[cfg(all(unix, not(any(target_os = "macos", target_os = "ios"))))]
    type Key = core::ffi::c_uint;

    #[cfg(unix)]
    unsafe extern "C" {
        fn pthread_key_create(key: *mut Key, destructor: Option<unsafe extern "C" fn(*mut c_void)>) -> core::ffi::c_int;
        fn pthread_key_delete(key: Key) -> core::ffi::c_int;
        fn pthread_getspecific(key: Key) -> *mut c_void;
        fn pthread_setspecific(key: Key, value: *const c_void) -> core::ffi::c_int;
    }

    #[cfg(windows)]
    type Key = u32;

    #[cfg(windows)]
    #[link(name = "kernel32")]
    unsafe extern "system" {
        fn TlsAlloc() -> u32;
        fn TlsFree(index: u32) -> i32;
        fn TlsGetValue(index: u32) -> *mut c_void;
        fn TlsSetValue(index: u32, value: *mut c_void) -> i32;
    }

    /// The slot, plus one (0: not made yet).
    static SLOT: AtomicUsize = AtomicUsize::new(0);

    /// The slot, made on first use; `None` where the system has none left
    /// (then nothing is recorded).
    fn slot(make: bool) -> Option<Key> {
        let k = SLOT.load(Ordering::Acquire);
        if k != 0 {
            return Some((k - 1) as Key);
        }
        if !make {
            return None;
        }
        #[cfg(unix)]
        let made = {
            let mut key: Key = 0;
            // SAFETY: `key` is a valid out-parameter; no destructor.
            (unsafe { pthread_key_create(&mut key, None) } == 0).then_some(key)
        };
        #[cfg(windows)]
        // SAFETY: TlsAlloc takes nothing.
        let made = Some(unsafe { TlsAlloc() }).filter(|&i| i != u32::MAX);
        let key = made?;
        match SLOT.compare_exchange(0, key as usize + 1, Ordering::AcqRel, Ordering::Acquire) {
            Ok(_) => Some(key),
            // Another thread made one first: that one is the slot.
            Err(other) => {
                // SAFETY: `key` was made above and never used.
                #[cfg(unix)]
                unsafe {
                    pthread_key_delete(key);
                }
                // SAFETY: as above.
                #[cfg(windows)]
                unsafe {
                    TlsFree(key);
                }
                Some((other - 1) as Key)
            }
        }
    }

    /// Sets the calling thread's record.
    pub(crate) fn set(detail: *const c_char) {
        if let Some(key) = slot(true) {
            // SAFETY: `key` is a slot made by `slot`, never deleted.
            #[cfg(unix)]
            unsafe {
                pthread_setspecific(key, detail.cast());
            }
            // SAFETY: as above.
            #[cfg(windows)]
            unsafe {
                TlsSetValue(key, detail.cast_mut().cast());
            }
        }
    }

    /// The calling thread's record; NULL before its first refusal.
    pub(crate) fn get() -> *const c_char {
        let Some(key) = slot(false) else { return core::ptr::null() };
        // SAFETY: as in `set`; a slot never set reads NULL.
        #[cfg(unix)]
        let p = unsafe { pthread_getspecific(key) };
        // SAFETY: as above.
        #[cfg(windows)]
        let p = unsafe { TlsGetValue(key) };
        p.cast_const().cast()
    }
}

/// Records a refusal's detail for the calling thread.
#[cfg(any(unix, windows))]
pub(crate) fn set_thread_detail(detail: *const core::ffi::c_char) {
    thread_record::set(detail);
}

/// The calling thread's last refusal's detail, or NULL.
#[cfg(any(unix, windows))]
pub(crate) fn thread_detail() -> *const core::ffi::c_char {
    thread_record::get()
}

/// Elsewhere no thread-local slot is called for: one record for the
/// library, as in firmware builds.
#[cfg(not(any(unix, windows)))]
static RECORD: core::sync::atomic::AtomicPtr<core::ffi::c_char> = core::sync::atomic::AtomicPtr::new(core::ptr::null_mut());

#[cfg(not(any(unix, windows)))]
pub(crate) fn set_thread_detail(detail: *const core::ffi::c_char) {
    RECORD.store(detail.cast_mut(), Ordering::Relaxed);
}

#[cfg(not(any(unix, windows)))]
pub(crate) fn thread_detail() -> *const core::ffi::c_char {
    RECORD.load(Ordering::Relaxed).cast_const()
}

/// Gives the processor to another thread, where the system has a call for it.
pub(crate) fn yield_now() {
    #[cfg(unix)]
    // SAFETY: sched_yield takes nothing and cannot fail in a way that matters.
    unsafe {
        sched_yield();
    }
    #[cfg(not(unix))]
    core::hint::spin_loop();
}

/// A lock on core's atomics: what the registry of handles needs from
/// `std::sync::Mutex` (every hold is a few map operations long), without
/// `std`. A waiting thread spins briefly, then yields.
pub(crate) struct Lock<T> {
    held: AtomicBool,
    value: UnsafeCell<T>,
}

// SAFETY: the value is reached only through a `Held`, and one `Held` at a
// time exists (the flag, taken with Acquire and released with Release,
// orders each holder's accesses after the previous holder's).
unsafe impl<T: Send> Sync for Lock<T> {}

impl<T> Lock<T> {
    pub(crate) const fn new(value: T) -> Lock<T> {
        Lock { held: AtomicBool::new(false), value: UnsafeCell::new(value) }
    }

    /// Waits until the lock is free and takes it; the returned guard frees
    /// it when dropped, also when a panic unwinds (catch-panics builds).
    /// Out of line: one copy for every use of the registry.
    #[inline(never)]
    pub(crate) fn lock(&self) -> Held<'_, T> {
        let mut waited = 0u32;
        while self.held.compare_exchange_weak(false, true, Ordering::Acquire, Ordering::Relaxed).is_err() {
            while self.held.load(Ordering::Relaxed) {
                waited = waited.saturating_add(1);
                if waited < 64 { core::hint::spin_loop() } else { yield_now() }
            }
        }
        Held { lock: self }
    }
}

/// The value of a [`Lock`] while held.
pub(crate) struct Held<'a, T> {
    lock: &'a Lock<T>,
}

impl<T> Deref for Held<'_, T> {
    type Target = T;
    fn deref(&self) -> &T {
        // SAFETY: this guard holds the lock: no other reference exists.
        unsafe { &*self.lock.value.get() }
    }
}

impl<T> DerefMut for Held<'_, T> {
    fn deref_mut(&mut self) -> &mut T {
        // SAFETY: as in deref, and `&mut self` makes this the only one.
        unsafe { &mut *self.lock.value.get() }
    }
}

impl<T> Drop for Held<'_, T> {
    fn drop(&mut self) {
        self.lock.held.store(false, Ordering::Release);
    }
}

/// A panic in a library without `std` (lib.rs says why it is not caught):
/// one line on stderr, `mpca: panicked at FILE:LINE:COLUMN: MESSAGE`, cut
/// at 255 bytes, then `abort()`, as a C library's failed `assert` does.
#[cfg(not(any(test, feature = "catch-panics")))]
pub(crate) fn die(info: &core::panic::PanicInfo<'_>) -> ! {
    /// The line, built in place: one `write`, so that lines of threads
    /// that panic together do not interleave. What does not fit is cut,
    /// keeping room for the newline.
    struct Line(heapless::Vec<u8, 256>);
    impl core::fmt::Write for Line {
        fn write_str(&mut self, s: &str) -> core::fmt::Result {
            let room = self.0.capacity() - 1 - self.0.len();
            let take = s.len().min(room);
            // Fits: take is at most the room left.
            let _ = self.0.extend_from_slice(&s.as_bytes()[..take]);
            Ok(())
        }
    }
    // A second panic (in the formatting below, or on another thread
    // meanwhile) aborts at once.
    static PANICKED: AtomicBool = AtomicBool::new(false);
    if PANICKED.swap(true, Ordering::Relaxed) {
        // SAFETY: abort takes nothing and does not return.
        unsafe { abort() }
    }
    let mut line = Line(heapless::Vec::new());
    let _ = match info.location() {
        // The location's parts written one by one: `{at}` would pass the
        // file name through `Formatter::pad`, a large routine that no
        // other message of this library calls.
        Some(at) => {
            use core::fmt::Write;
            let _ = line.write_str("mpca: panicked at ");
            let _ = line.write_str(at.file());
            core::fmt::write(&mut line, format_args!(":{}:{}: {}", at.line(), at.column(), info.message()))
        }
        None => core::fmt::write(&mut line, format_args!("mpca: panicked: {}", info.message())),
    };
    // The room write_str kept.
    let _ = line.0.push(b'\n');
    #[cfg(unix)]
    // SAFETY: the vector's bytes are initialised, len() of them.
    unsafe {
        write(2, line.0.as_ptr().cast(), line.0.len());
    }
    // SAFETY: abort takes nothing and does not return.
    unsafe { abort() }
}

/// The personality routine that the unwind tables of Rust's precompiled
/// `core` and `compiler_builtins` name: they are built to unwind, and `std`,
/// which defines it, is not linked, so without this the link of a program
/// against a debug build (any build on 32-bit Arm) fails on an undefined
/// `rust_eh_personality` (rust-lang/rust#106864). Never called: nothing in
/// this library unwinds (panic = "abort"); were it called, it answers
/// `_URC_FAILURE`, so an unwinder stops instead of passing through.
///
/// Where a shared library is built (Linux, Windows), it is written in
/// assembly below instead: rustc exports every `#[no_mangle]` function of
/// a cdylib (through the version script or the DLL's module definition
/// file it writes, which a second version script cannot override with GNU
/// ld), and the library exports the header's functions alone. A symbol
/// rustc does not know of stays the library's own, hidden on ELF.
#[cfg(not(any(test, feature = "catch-panics", personality_in_asm)))]
#[unsafe(no_mangle)]
extern "C" fn rust_eh_personality() -> core::ffi::c_int {
    9
}

#[cfg(all(personality_in_asm, not(test), target_os = "linux", target_arch = "x86_64"))]
core::arch::global_asm!(
    ".globl rust_eh_personality",
    ".hidden rust_eh_personality",
    ".type rust_eh_personality, %function",
    "rust_eh_personality:",
    "mov eax, 9",
    "ret",
);

#[cfg(all(personality_in_asm, not(test), target_os = "linux", target_arch = "aarch64"))]
core::arch::global_asm!(
    ".globl rust_eh_personality",
    ".hidden rust_eh_personality",
    ".type rust_eh_personality, %function",
    "rust_eh_personality:",
    "mov w0, #9",
    "ret",
);

#[cfg(all(personality_in_asm, not(test), target_os = "linux", target_arch = "arm"))]
core::arch::global_asm!(
    ".globl rust_eh_personality",
    ".hidden rust_eh_personality",
    ".type rust_eh_personality, %function",
    "rust_eh_personality:",
    "mov r0, #9",
    "bx lr",
);

#[cfg(all(personality_in_asm, not(test), windows))]
core::arch::global_asm!(".globl rust_eh_personality", "rust_eh_personality:", "mov eax, 9", "ret");
