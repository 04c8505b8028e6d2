//! Errors are values (STYLE.md practice 3): every refusal names its cause,
//! and the world is left exactly as it was.

use core::fmt;

/// Why the library refused a request. Nothing was changed when one of these
/// is returned.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Error {
    /// The dimension is neither 2 nor 3.
    BadDimension,
    /// 3D worlds need the `dim3` feature, which this build left out.
    Dim3Disabled,
    /// A size is zero (M1).
    SizeZero,
    /// A size is odd, so Margolus blocks cannot tile the axis (M1).
    SizeOdd,
    /// The world's cell count, bit index or byte count overflows this target.
    TooLarge,
    /// Only one face of an axis is periodic; periodicity joins both (M4).
    PeriodicMismatch,
    /// A floating-point input is NaN or infinite.
    NotFinite,
    /// The time step is negative.
    NegativeDt,
    /// The vortex core radius is not greater than zero.
    BadVortex,
    /// A flow drag rate is negative (M5.1b).
    BadDrag,
    /// A restitution lies outside `[0, 1]` (M1).
    RestitutionRange,
    /// A mass is not strictly positive (M1).
    MassRange,
    /// A velocity has `|v| > 1` (M1).
    SpeedRange,
    /// 16-bit velocities need the `q16` feature, which this build left out.
    Q16Disabled,
    /// The description asks for a part (obstacles, fields, per-particle
    /// masses) that this build left out.
    FeatureDisabled,
    /// The world was built without the part this call uses (M9).
    NotEnabled,
    /// A capacity in the description is beyond what the storage can index.
    CapacityRange,
    /// The buffer handed in is smaller than `world_bytes` asked for.
    BufferTooSmall,
    /// A position lies outside the world.
    OutOfBounds,
    /// The cell already holds a particle.
    CellOccupied,
    /// The cell is an obstacle.
    CellObstacle,
    /// The cell holds no particle.
    NoParticle,
    /// The table of distinct masses is full.
    MassTableFull,
    /// The obstacle surface table is full.
    SurfaceTableFull,
    /// An obstacle surface cell would have no defined normal (M7).
    UndefinedNormal,
    /// The emitter table is full.
    EmitterTableFull,
    /// An emitter region is empty or reversed, or a rate is negative.
    BadEmitter,
    /// A lifetime is longer than the age plane can count.
    LifetimeRange,
    /// A shape is degenerate (zero normal, reversed box, negative radius).
    BadShape,
    /// An output resolution is zero, larger than the world, or the output
    /// buffer has the wrong length.
    BadResolution,
    /// A per-cell input slice has the wrong length.
    BadLength,
    /// The memory does not hold a world (wrong tag, destroyed or forged).
    NotAWorld,
    /// The world lives in caller memory; only the caller can free it.
    NotOwned,
    /// The allocator refused the memory.
    OutOfMemory,
    /// The output buffer is smaller than what is to be written into it
    /// ([`crate::World::snapshot_bytes`] for an image).
    OutputTooSmall,
    /// The bytes do not start with the magic of a world image (M12).
    NotAnImage,
    /// The image is of a format version this library does not read (M12).
    ImageVersion,
    /// The image is shorter or longer than its header says: cut short, or
    /// with bytes after its end (M12).
    ImageLength,
    /// The image's checksum does not match its bytes: it was damaged (M12).
    ImageChecksum,
    /// The image's checksum matches, but what it holds is not a world this
    /// library could have written: an unknown value, a count that does not
    /// add up, a particle on an obstacle, a velocity out of range (M12).
    ImageInvalid,
    /// The image holds a world of another size or plan of planes than the
    /// world it is loaded into (M12).
    ImageMismatch,
}

impl Error {
    /// A short, static description of the error.
    pub const fn message(self) -> &'static str {
        match self {
            Error::BadDimension => "dimension must be 2 or 3",
            Error::Dim3Disabled => "3D worlds are not built in (feature dim3)",
            Error::SizeZero => "a world size is zero",
            Error::SizeOdd => "a world size is odd; Margolus blocks need even sizes",
            Error::TooLarge => "the world is too large for this target",
            Error::PeriodicMismatch => "periodic boundaries must be set on both faces of an axis",
            Error::NotFinite => "a floating-point input is NaN or infinite",
            Error::NegativeDt => "the time step must not be negative",
            Error::BadVortex => "the vortex core radius must be greater than zero",
            Error::BadDrag => "the flow drag rate must not be negative",
            Error::RestitutionRange => "a restitution lies outside [0, 1]",
            Error::MassRange => "a mass must be greater than zero",
            Error::SpeedRange => "a speed must not exceed 1 cell per step",
            Error::Q16Disabled => "16-bit velocities are not built in (feature q16)",
            Error::FeatureDisabled => "the description uses a part this build left out",
            Error::NotEnabled => "the world was created without this part",
            Error::CapacityRange => "a capacity is out of range",
            Error::BufferTooSmall => "the memory is smaller than world_bytes asked for",
            Error::OutOfBounds => "a position lies outside the world",
            Error::CellOccupied => "the cell already holds a particle",
            Error::CellObstacle => "the cell is an obstacle",
            Error::NoParticle => "the cell holds no particle",
            Error::MassTableFull => "the table of distinct masses is full",
            Error::SurfaceTableFull => "the obstacle surface table is full",
            Error::UndefinedNormal => "an obstacle surface cell would have no defined normal",
            Error::EmitterTableFull => "the emitter table is full",
            Error::BadEmitter => "an emitter region is empty or reversed, or its rate is negative",
            Error::LifetimeRange => "a lifetime is longer than 65535 steps",
            Error::BadShape => "a shape is degenerate",
            Error::BadResolution => "the output resolution or buffer length is wrong",
            Error::BadLength => "a per-cell input has the wrong length",
            Error::NotAWorld => "the memory does not hold a live world",
            Error::NotOwned => "the world lives in caller memory; the caller frees it",
            Error::OutOfMemory => "the allocator refused the memory",
            Error::OutputTooSmall => "the output buffer is too small",
            Error::NotAnImage => "the bytes are not an mpca world image",
            Error::ImageVersion => "the image is of a format version this library does not read",
            Error::ImageLength => "the image is shorter or longer than its header says",
            Error::ImageChecksum => "the image's checksum does not match: it was damaged",
            Error::ImageInvalid => "the image does not hold a consistent world",
            Error::ImageMismatch => "the image holds a world of another size or layout than this one",
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.message())
    }
}

impl core::error::Error for Error {}
