//! `mpca_status`: every export's return value, and its messages.

use core::ffi::{c_char, CStr};

use mpca_core::Error;

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
    /// and should be destroyed.
    Panic = 3,
    /// A structure's `struct_size` does not match this library's.
    BadStructSize = 4,
    /// An enumeration or flag field holds a value this library does not know.
    BadEnum = 5,
    /// The output buffer is too small; the count needed was written.
    OutputTooSmall = 6,
    /// The cell is not an obstacle surface cell.
    NotASurface = 7,
    /// The world is inside mpca_world_step_parallel: only
    /// mpca_world_step_task reaches it until that returns.
    Busy = 8,
    /// The ticket is not the parallel step in flight on this world (a task
    /// of an earlier step, or no step in flight).
    StaleTask = 9,
    /// The task index is not below the step's task count.
    TaskIndex = 10,
    /// This task of the step was run already.
    TaskDone = 11,
    /// Two memory ranges of the call overlap: an image and the memory of
    /// the world it is saved from, loaded into or built in.
    Overlap = 12,
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
    /// A flow drag rate is negative (M5.1b).
    BadDrag = 140,
    /// An error this version of the C ABI does not know by name.
    Unknown = 199,
}

impl From<Error> for mpca_status {
    fn from(e: Error) -> Self {
        use mpca_status as S;
        match e {
            Error::BadDimension => S::BadDimension,
            Error::Dim3Disabled => S::Dim3Disabled,
            Error::SizeZero => S::SizeZero,
            Error::SizeOdd => S::SizeOdd,
            Error::TooLarge => S::TooLarge,
            Error::PeriodicMismatch => S::PeriodicMismatch,
            Error::NotFinite => S::NotFinite,
            Error::NegativeDt => S::NegativeDt,
            Error::BadVortex => S::BadVortex,
            Error::BadDrag => S::BadDrag,
            Error::RestitutionRange => S::RestitutionRange,
            Error::MassRange => S::MassRange,
            Error::SpeedRange => S::SpeedRange,
            Error::Q16Disabled => S::Q16Disabled,
            Error::FeatureDisabled => S::FeatureDisabled,
            Error::NotEnabled => S::NotEnabled,
            Error::CapacityRange => S::CapacityRange,
            Error::BufferTooSmall => S::BufferTooSmall,
            Error::OutOfBounds => S::OutOfBounds,
            Error::CellOccupied => S::CellOccupied,
            Error::CellObstacle => S::CellObstacle,
            Error::NoParticle => S::NoParticle,
            Error::MassTableFull => S::MassTableFull,
            Error::SurfaceTableFull => S::SurfaceTableFull,
            Error::UndefinedNormal => S::UndefinedNormal,
            Error::EmitterTableFull => S::EmitterTableFull,
            Error::BadEmitter => S::BadEmitter,
            Error::LifetimeRange => S::LifetimeRange,
            Error::BadShape => S::BadShape,
            Error::BadResolution => S::BadResolution,
            Error::BadLength => S::BadLength,
            Error::NotAWorld => S::BadHandle,
            Error::NotOwned => S::NotOwned,
            Error::OutOfMemory => S::OutOfMemory,
            Error::OutputTooSmall => S::OutputTooSmall,
            Error::NotAnImage => S::NotAnImage,
            Error::ImageVersion => S::ImageVersion,
            Error::ImageLength => S::ImageLength,
            Error::ImageChecksum => S::ImageChecksum,
            Error::ImageInvalid => S::ImageInvalid,
            Error::ImageMismatch => S::ImageMismatch,
            _ => S::Unknown,
        }
    }
}

impl mpca_status {
    /// The message, as a static C string.
    pub(crate) fn message(self) -> &'static CStr {
        use mpca_status as S;
        match self {
            S::Ok => c"success",
            S::NullPointer => c"a pointer argument was NULL",
            S::BadHandle => c"the world handle is not a live world",
            S::Panic => c"mpca panicked (a bug); destroy the world",
            S::BadStructSize => c"struct_size does not match this library's structure",
            S::BadEnum => c"an enumeration or flag field holds an unknown value",
            S::OutputTooSmall => c"the output buffer is too small; the count needed was written",
            S::NotASurface => c"the cell is not an obstacle surface cell",
            S::Busy => c"the world is in a parallel step; only its tasks may run until it returns",
            S::StaleTask => c"the ticket is not the parallel step in flight on this world",
            S::TaskIndex => c"the task index is not below the step's task count",
            S::TaskDone => c"this task of the step was run already",
            S::Overlap => c"an image overlaps the memory of the world it is saved from, loaded into or built in",
            S::BadDimension => c"dimension must be 2 or 3",
            S::Dim3Disabled => c"3D worlds are not built into this library",
            S::SizeZero => c"a world size is zero",
            S::SizeOdd => c"a world size is odd; Margolus blocks need even sizes",
            S::TooLarge => c"the world is too large for this target",
            S::PeriodicMismatch => c"periodic boundaries must be set on both faces of an axis",
            S::NotFinite => c"a floating-point input is NaN or infinite",
            S::NegativeDt => c"the time step must not be negative",
            S::BadVortex => c"the vortex core radius must be greater than zero",
            S::BadDrag => c"the flow drag rate must not be negative",
            S::RestitutionRange => c"a restitution lies outside [0, 1]",
            S::MassRange => c"a mass must be greater than zero",
            S::SpeedRange => c"a speed must not exceed 1 cell per step",
            S::Q16Disabled => c"16-bit velocities are not built into this library",
            S::FeatureDisabled => c"the description uses a part this library was built without",
            S::NotEnabled => c"the world was created without this part",
            S::CapacityRange => c"a capacity is out of range",
            S::BufferTooSmall => c"the memory is smaller than mpca_world_bytes asked for",
            S::OutOfBounds => c"a position lies outside the world",
            S::CellOccupied => c"the cell already holds a particle",
            S::CellObstacle => c"the cell is an obstacle",
            S::NoParticle => c"the cell holds no particle",
            S::MassTableFull => c"the table of distinct masses is full",
            S::SurfaceTableFull => c"the obstacle surface table is full",
            S::UndefinedNormal => c"an obstacle surface cell would have no defined normal",
            S::EmitterTableFull => c"the emitter table is full",
            S::BadEmitter => c"an emitter region is empty or reversed, or its rate is negative",
            S::LifetimeRange => c"a lifetime is longer than 65535 steps",
            S::BadShape => c"a shape is degenerate",
            S::BadResolution => c"the output resolution or buffer length is wrong",
            S::BadLength => c"a per-cell input has the wrong length, or a length exceeds PTRDIFF_MAX bytes",
            S::NotOwned => c"the world lives in caller memory: deinit it and free the memory yourself",
            S::OutOfMemory => c"the allocator refused the memory",
            S::NotAnImage => c"the bytes are not an mpca world image",
            S::ImageVersion => c"the image is of a format version this library does not read",
            S::ImageLength => c"the image is shorter or longer than its header says",
            S::ImageChecksum => c"the image's checksum does not match: it was damaged",
            S::ImageInvalid => c"the image does not hold a consistent world",
            S::ImageMismatch => c"the image holds a world of another size or layout than this one",
            S::Unknown => c"an error this version of the C ABI does not name",
        }
    }
}

/// A static, NUL-terminated English message for `status`; never NULL, never
/// to be freed. Values that are not statuses get a message saying so.
#[unsafe(no_mangle)]
pub extern "C" fn mpca_status_message(status: u32) -> *const c_char {
    match status_from_u32(status) {
        Some(s) => s.message().as_ptr(),
        None => c"not an mpca status".as_ptr(),
    }
}

/// The status numbered `n`, if there is one.
pub(crate) fn status_from_u32(n: u32) -> Option<mpca_status> {
    use mpca_status as S;
    const ALL: [mpca_status; 53] = [
        S::Ok, S::NullPointer, S::BadHandle, S::Panic, S::BadStructSize, S::BadEnum, S::OutputTooSmall, S::NotASurface,
        S::Busy, S::StaleTask, S::TaskIndex, S::TaskDone, S::Overlap,
        S::BadDimension, S::Dim3Disabled, S::SizeZero, S::SizeOdd, S::TooLarge, S::PeriodicMismatch,
        S::NotFinite, S::NegativeDt, S::BadVortex, S::BadDrag, S::RestitutionRange, S::MassRange, S::SpeedRange,
        S::Q16Disabled, S::FeatureDisabled, S::NotEnabled, S::CapacityRange, S::BufferTooSmall,
        S::OutOfBounds, S::CellOccupied, S::CellObstacle, S::NoParticle, S::MassTableFull,
        S::SurfaceTableFull, S::UndefinedNormal, S::EmitterTableFull, S::BadEmitter, S::LifetimeRange,
        S::BadShape, S::BadResolution, S::BadLength, S::NotOwned, S::OutOfMemory,
        S::NotAnImage, S::ImageVersion, S::ImageLength, S::ImageChecksum, S::ImageInvalid, S::ImageMismatch, S::Unknown,
    ];
    ALL.iter().copied().find(|s| *s as u32 == n)
}
