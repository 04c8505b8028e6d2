//! `mpca_status`: every export's return value, and its messages.

use core::ffi::{c_char, CStr};

use mpca_core::{Error, ErrorKind};

/// The result of every call. `MPCA_STATUS_OK` is 0; every other value names
/// one cause. Numbers are never reused: new causes get new numbers.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[allow(non_camel_case_types)]
pub enum mpca_status {
    /// Success.
    Ok = 0,
    /// A pointer argument was NULL.
    NullPointer = 1,
    /// The world handle is not a live world: destroyed, deinitialised, never
    /// created, or the wrong kind of memory.
    BadHandle = 2,
    /// The library panicked (a bug in mpca); the world may be inconsistent
    /// and should be destroyed. Only a library built with the feature
    /// `catch-panics` returns it: the default one aborts instead.
    Panic = 3,
    /// A structure's `struct_size` does not match this library's.
    BadStructSize = 4,
    /// An enumeration or flag field holds a value this library does not know.
    BadEnum = 5,
    /// The output buffer is too small; the count needed was written.
    OutputTooSmall = 6,
    /// The cell is not an obstacle surface cell.
    NotASurface = 7,
    /// Another call is inside the world and this one cannot share it (the
    /// rule at `mpca_world`): a parallel step (only mpca_world_step_task
    /// reaches the world until it returns) or another call that changes
    /// it; or, for a call that ends or replaces the world (deinit, destroy,
    /// load, a world built over its memory), any call. Nothing was changed;
    /// the call may be made again.
    Busy = 8,
    /// The ticket is not the parallel step in flight on this world (a task
    /// of an earlier step, or no step in flight).
    StaleTask = 9,
    /// The task index is not below the step's task count.
    TaskIndex = 10,
    /// This task of the step was run already.
    TaskDone = 11,
    /// Two memory ranges of the call overlap: an image and the memory of
    /// the world it is saved from, loaded into or built in; or the memory
    /// handed to mpca_world_init or mpca_world_init_from_image and a world
    /// mpca_world_create allocated (hosted builds).
    Overlap = 12,
    /// A tag is above 255: tags are one byte (M6b).
    TagRange = 13,
    /// The dimension is neither 2 nor 3.
    BadDimension = 100,
    /// 3D worlds are not built into this library.
    Dim3Disabled = 101,
    /// A world size is zero.
    SizeZero = 102,
    /// A world size is odd; Margolus blocks need even sizes.
    SizeOdd = 103,
    /// The world is too large for this target.
    TooLarge = 104,
    /// Periodic boundaries must be set on both faces of an axis.
    PeriodicMismatch = 105,
    /// A floating-point input is NaN or infinite.
    NotFinite = 106,
    /// The time step is negative.
    NegativeDt = 107,
    /// The vortex core radius is not greater than zero.
    BadVortex = 108,
    /// A restitution lies outside [0, 1].
    RestitutionRange = 109,
    /// A mass is not greater than zero.
    MassRange = 110,
    /// A speed exceeds 1 cell per step.
    SpeedRange = 111,
    /// 16-bit velocities are not built into this library.
    Q16Disabled = 112,
    /// The description uses a part this library was built without.
    FeatureDisabled = 113,
    /// The world was created without the part this call uses.
    NotEnabled = 114,
    /// A capacity is out of range.
    CapacityRange = 115,
    /// The memory is smaller than mpca_world_bytes asked for.
    BufferTooSmall = 116,
    /// A position lies outside the world.
    OutOfBounds = 117,
    /// The cell already holds a particle.
    CellOccupied = 118,
    /// The cell is an obstacle.
    CellObstacle = 119,
    /// The cell holds no particle.
    NoParticle = 120,
    /// The table of distinct masses is full.
    MassTableFull = 121,
    /// The obstacle surface table is full.
    SurfaceTableFull = 122,
    /// An obstacle surface cell would have no defined normal.
    UndefinedNormal = 123,
    /// The emitter table is full.
    EmitterTableFull = 124,
    /// An emitter region is empty or reversed, or its rate is negative.
    BadEmitter = 125,
    /// A lifetime is longer than 65535 steps.
    LifetimeRange = 126,
    /// A shape is degenerate.
    BadShape = 127,
    /// The output resolution or buffer length is wrong (a length over
    /// PTRDIFF_MAX bytes included).
    BadResolution = 128,
    /// A length is wrong: a per-cell input not of the world's cell count, or
    /// more bytes than an object can have (over PTRDIFF_MAX).
    BadLength = 129,
    /// The world lives in caller memory: use mpca_world_deinit, and free the
    /// memory yourself.
    NotOwned = 131,
    /// The allocator refused the memory.
    OutOfMemory = 132,
    /// The bytes do not start with the magic of a world image.
    NotAnImage = 133,
    /// The image is of a format version this library does not read.
    ImageVersion = 134,
    /// The image is shorter or longer than its header says: cut short, or
    /// the length passed runs past its end.
    ImageLength = 135,
    /// The image's checksum does not match its bytes: it was damaged.
    ImageChecksum = 136,
    /// The image is well framed and its checksum matches, but it does not
    /// hold a consistent world.
    ImageInvalid = 137,
    /// The image holds a world of another size or plan of memory than the
    /// world it is loaded into.
    ImageMismatch = 138,
    /// A flow drag setting is out of range: a negative rate (M5.1b), or
    /// turbulence (M5.1c).
    BadDrag = 140,
    /// Every particle id of the world's life was given: no particle can be
    /// added, and emitters count what they ask for as shortfall (M6b).
    IdsExhausted = 141,
    /// Every slot of the body table holds a body (M13).
    BodyTableFull = 142,
    /// The id names no body: never given, or its body was removed (M13).
    NoBody = 143,
    /// An error this version of the C ABI does not know by name.
    Unknown = 199,
}

/// The status of a core error, for Rust callers of this crate's rlib (the
/// fuzzers compare the C door's statuses with the core's errors).
impl From<Error> for mpca_status {
    fn from(e: Error) -> Self {
        Self::of_error(e)
    }
}

impl mpca_status {
    /// The status of a core error: the one with its number, which every
    /// error has (checked below for each at compile time), so no error
    /// hides behind `Unknown`. The number itself, not a search of the
    /// statuses for it: no code at all.
    pub(crate) const fn of_error(e: Error) -> Self {
        // SAFETY: `mpca_status` is `repr(u32)`, and the number of every
        // core error is the discriminant of one of its variants: the
        // compile-time check below looks each up among the statuses.
        unsafe { core::mem::transmute::<u32, mpca_status>(e.code()) }
    }

    /// The core error kind this status stands for, if it is one.
    const fn core_error(self) -> Option<ErrorKind> {
        let mut i = 0;
        while i < ErrorKind::ALL.len() {
            if ErrorKind::ALL[i].code() == self as u32 {
                return Some(ErrorKind::ALL[i]);
            }
            i += 1;
        }
        None
    }
}

/// Whether two C strings hold the same bytes, at compile time.
const fn same_text(a: &CStr, b: &CStr) -> bool {
    let (a, b) = (a.to_bytes(), b.to_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

// Every core error has the status of its number, with core's message (so no
// error lands on an ABI status that says something else), and every status
// this file says is a core error's (the long arm of `message`) is one.
const _: () = {
    let mut i = 0;
    while i < ErrorKind::ALL.len() {
        let e = ErrorKind::ALL[i];
        match status_from_u32(e.code()) {
            Some(s) => assert!(same_text(s.message(), e.c_message())),
            None => panic!("a core error has no mpca_status of its number"),
        }
        i += 1;
    }
    let mut i = 0;
    while i < ALL.len() {
        let _ = ALL[i].message();
        i += 1;
    }
};

impl mpca_status {
    /// The message, as a static C string: core's for the statuses of core
    /// errors, this file's for the ABI's own.
    pub(crate) const fn message(self) -> &'static CStr {
        use mpca_status as S;
        match self {
            S::Ok => c"success",
            S::NullPointer => c"a pointer argument was NULL",
            S::Panic => c"mpca panicked (a bug); destroy the world",
            S::BadStructSize => c"struct_size does not match this library's structure",
            S::BadEnum => c"an enumeration or flag field holds an unknown value",
            S::NotASurface => c"the cell is not an obstacle surface cell",
            S::Busy => c"another call is inside the world (a parallel step, or a call that changes it); nothing was done",
            S::StaleTask => c"the ticket is not the parallel step in flight on this world",
            S::TaskIndex => c"the task index is not below the step's task count",
            S::TaskDone => c"this task of the step was run already",
            S::TagRange => c"a tag is above 255",
            S::Overlap => c"an image overlaps the memory of its world, or new world memory lies in a world the library allocated",
            S::Unknown => c"an error this version of the C ABI does not name",
            // The statuses of core errors say what core says.
            S::BadHandle | S::OutputTooSmall | S::BadDimension | S::Dim3Disabled | S::SizeZero | S::SizeOdd | S::TooLarge | S::PeriodicMismatch | S::NotFinite | S::NegativeDt | S::BadVortex | S::BadDrag | S::RestitutionRange | S::MassRange | S::SpeedRange | S::Q16Disabled | S::FeatureDisabled | S::NotEnabled | S::CapacityRange | S::BufferTooSmall | S::OutOfBounds | S::CellOccupied | S::CellObstacle | S::NoParticle | S::MassTableFull | S::SurfaceTableFull | S::UndefinedNormal | S::EmitterTableFull | S::BadEmitter | S::LifetimeRange | S::BadShape | S::BadResolution | S::BadLength | S::NotOwned | S::OutOfMemory | S::NotAnImage | S::ImageVersion | S::ImageLength | S::ImageChecksum | S::ImageInvalid | S::ImageMismatch | S::IdsExhausted | S::BodyTableFull | S::NoBody => match self.core_error() {
                Some(e) => e.c_message(),
                None => panic!("a status listed as a core error's has no core error"),
            },
        }
    }
}

/// A static, NUL-terminated English message for `status`: what kind of
/// problem it is (mpca_last_error says where); never NULL, never to be
/// freed. Values that are not statuses get a message saying so.
#[unsafe(no_mangle)]
pub extern "C" fn mpca_status_message(status: u32) -> *const c_char {
    match status_from_u32(status) {
        Some(s) => s.message().as_ptr(),
        None => c"not an mpca status".as_ptr(),
    }
}

/// Every status, for looking one up by number.
const ALL: [mpca_status; 57] = {
    use mpca_status as S;
    [
        S::Ok, S::NullPointer, S::BadHandle, S::Panic, S::BadStructSize, S::BadEnum, S::OutputTooSmall, S::NotASurface,
        S::Busy, S::StaleTask, S::TaskIndex, S::TaskDone, S::Overlap, S::TagRange,
        S::BadDimension, S::Dim3Disabled, S::SizeZero, S::SizeOdd, S::TooLarge, S::PeriodicMismatch,
        S::NotFinite, S::NegativeDt, S::BadVortex, S::BadDrag, S::RestitutionRange, S::MassRange, S::SpeedRange,
        S::Q16Disabled, S::FeatureDisabled, S::NotEnabled, S::CapacityRange, S::BufferTooSmall,
        S::OutOfBounds, S::CellOccupied, S::CellObstacle, S::NoParticle, S::MassTableFull,
        S::SurfaceTableFull, S::UndefinedNormal, S::EmitterTableFull, S::BadEmitter, S::LifetimeRange,
        S::BadShape, S::BadResolution, S::BadLength, S::NotOwned, S::OutOfMemory,
        S::NotAnImage, S::ImageVersion, S::ImageLength, S::ImageChecksum, S::ImageInvalid, S::ImageMismatch, S::IdsExhausted,
        S::BodyTableFull, S::NoBody, S::Unknown,
    ]
};

/// The status numbered `n`, if there is one.
pub(crate) const fn status_from_u32(n: u32) -> Option<mpca_status> {
    let mut i = 0;
    while i < ALL.len() {
        if ALL[i] as u32 == n {
            return Some(ALL[i]);
        }
        i += 1;
    }
    None
}

/// The status of a call for a part this build left out, once its arguments
/// (`_checked`) were read and checked: no world of the build has the part.
#[cfg(not(feature = "obstacles"))]
pub(crate) fn disabled<T>(_checked: T) -> crate::Refusal {
    crate::Refusal::new(mpca_status::NotEnabled, c"bodies (feature `obstacles`)")
}
