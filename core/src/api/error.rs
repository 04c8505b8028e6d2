//! Errors are values (STYLE.md practice 3): every refusal says what kind
//! of problem it is and names the field or part at fault, and the world is
//! left exactly as it was.

#[cfg(feature = "details")]
use core::ffi::c_char;
use core::ffi::CStr;
use core::fmt;

/// What kind of problem made the library refuse a request: the part of an
/// [`Error`] a program matches on.
///
/// Each kind carries a number ([`ErrorKind::code`]) that the C ABI returns
/// as its `mpca_status`. Numbers are never reused or changed: a new kind
/// takes a new one. 2 and 6 are shared with statuses the C ABI also
/// returns for its own checks (a bad handle, a short output buffer); the
/// rest lie in 100..199.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
#[repr(u32)]
pub enum ErrorKind {
    /// The dimension is neither 2 nor 3.
    BadDimension = 100,
    /// 3D worlds need the `dim3` feature, which this build left out.
    Dim3Disabled = 101,
    /// A size is zero (M1).
    SizeZero = 102,
    /// A size is odd, so Margolus blocks cannot tile the axis (M1).
    SizeOdd = 103,
    /// The world's cell count, bit index or byte count overflows this target.
    TooLarge = 104,
    /// Only one face of an axis is periodic; periodicity joins both (M4).
    PeriodicMismatch = 105,
    /// A floating-point input is NaN or infinite.
    NotFinite = 106,
    /// The time step is negative.
    NegativeDt = 107,
    /// The vortex core radius is not greater than zero.
    BadVortex = 108,
    /// A flow drag setting is out of range: a negative rate (M5.1b), or
    /// turbulence (M5.1c).
    BadDrag = 140,
    /// A restitution lies outside `[0, 1]` (M1).
    RestitutionRange = 109,
    /// A mass is not strictly positive (M1).
    MassRange = 110,
    /// A velocity has `|v| > 1` (M1).
    SpeedRange = 111,
    /// 16-bit velocities need the `q16` feature, which this build left out.
    Q16Disabled = 112,
    /// The description asks for a part (obstacles, fields, per-particle
    /// masses) or a rule (an assignment method other than exact-fast, a
    /// collision rule beyond the paper's) that this build left out.
    FeatureDisabled = 113,
    /// The world was built without the part this call uses (M9).
    NotEnabled = 114,
    /// A capacity in the description is beyond what the storage can index.
    CapacityRange = 115,
    /// The buffer handed in is smaller than `world_bytes` asked for.
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
    /// An obstacle surface cell would have no defined normal (M7).
    UndefinedNormal = 123,
    /// The emitter table is full.
    EmitterTableFull = 124,
    /// An emitter region is empty or reversed, or a rate is negative.
    BadEmitter = 125,
    /// A lifetime is longer than the age plane can count.
    LifetimeRange = 126,
    /// A shape is degenerate (zero normal, reversed box, negative radius).
    BadShape = 127,
    /// An output resolution is zero, larger than the world, or the output
    /// buffer has the wrong length.
    BadResolution = 128,
    /// A per-cell input slice has the wrong length.
    BadLength = 129,
    /// The memory does not hold a world (wrong tag, destroyed or forged).
    NotAWorld = 2,
    /// The world lives in caller memory; only the caller can free it.
    NotOwned = 131,
    /// The allocator refused the memory.
    OutOfMemory = 132,
    /// The output buffer is smaller than what is to be written into it
    /// ([`crate::World::snapshot_bytes`] for an image).
    OutputTooSmall = 6,
    /// The bytes do not start with the magic of a world image (M12).
    NotAnImage = 133,
    /// The image is of a format version this library does not read (M12).
    ImageVersion = 134,
    /// The image is shorter or longer than its header says: cut short, or
    /// with bytes after its end (M12).
    ImageLength = 135,
    /// The image's checksum does not match its bytes: it was damaged (M12).
    ImageChecksum = 136,
    /// The image's checksum matches, but what it holds is not a world this
    /// library could have written: an unknown value, a count that does not
    /// add up, a particle on an obstacle, a velocity out of range (M12).
    ImageInvalid = 137,
    /// The image holds a world of another size or plan of planes than the
    /// world it is loaded into (M12).
    ImageMismatch = 138,
    /// Every id of the world's life was given: no particle can be added
    /// (M6b).
    IdsExhausted = 141,
    /// Every slot of the body table holds a body (M13).
    BodyTableFull = 142,
    /// The id names no body: never given, or its body was removed (M13).
    NoBody = 143,
}

/// The one table of messages. It writes both [`ErrorKind::c_message`],
/// whose match must name every variant, and [`ErrorKind::ALL`], so a
/// variant cannot be added without being listed.
macro_rules! messages {
    ($($variant:ident => $text:literal,)*) => {
        impl ErrorKind {
            /// Every kind, in declaration order: for the C ABI's check that
            /// each one has its status.
            pub const ALL: &'static [ErrorKind] = &[$(ErrorKind::$variant),*];

            /// A short, static description of the kind, NUL-terminated so
            /// the C ABI hands out the same bytes without copying.
            pub const fn c_message(self) -> &'static CStr {
                match self {
                    $(ErrorKind::$variant => $text,)*
                }
            }
        }
    };
}

messages! {
    BadDimension => c"dimension must be 2 or 3",
    Dim3Disabled => c"3D worlds are not built in (feature dim3)",
    SizeZero => c"a world size is zero",
    SizeOdd => c"a world size is odd; Margolus blocks need even sizes",
    TooLarge => c"the world is too large for this target",
    PeriodicMismatch => c"periodic boundaries must be set on both faces of an axis",
    NotFinite => c"a floating-point input is NaN or infinite",
    NegativeDt => c"the time step must not be negative",
    BadVortex => c"the vortex core radius must be greater than zero",
    BadDrag => c"a flow drag setting is out of range (a negative rate, or turbulence)",
    RestitutionRange => c"a restitution lies outside [0, 1]",
    MassRange => c"a mass must be greater than zero",
    SpeedRange => c"a speed must not exceed 1 cell per step",
    Q16Disabled => c"16-bit velocities are not built in (feature q16)",
    FeatureDisabled => c"the description uses a part this build left out",
    NotEnabled => c"the world was created without this part",
    CapacityRange => c"a capacity is out of range",
    BufferTooSmall => c"the memory is smaller than world_bytes asked for",
    OutOfBounds => c"a position lies outside the world",
    CellOccupied => c"the cell already holds a particle",
    CellObstacle => c"the cell is an obstacle",
    NoParticle => c"the cell holds no particle",
    MassTableFull => c"the table of distinct masses is full",
    SurfaceTableFull => c"the obstacle surface table is full",
    UndefinedNormal => c"an obstacle surface cell would have no defined normal",
    EmitterTableFull => c"the emitter table is full",
    BadEmitter => c"an emitter region is empty or reversed, or its rate is negative",
    LifetimeRange => c"a lifetime is longer than 65535 steps",
    BadShape => c"a shape is degenerate",
    BadResolution => c"the output resolution or buffer length is wrong",
    BadLength => c"a per-cell input has the wrong length, or a length exceeds the largest object size",
    NotAWorld => c"the memory does not hold a live world",
    NotOwned => c"the world lives in caller memory; the caller frees it",
    OutOfMemory => c"the allocator refused the memory",
    OutputTooSmall => c"the output buffer is too small",
    NotAnImage => c"the bytes are not an mpca world image",
    ImageVersion => c"the image is of a format version this library does not read",
    ImageLength => c"the image is shorter or longer than its header says",
    ImageChecksum => c"the image's checksum does not match: it was damaged",
    ImageInvalid => c"the image does not hold a consistent world",
    ImageMismatch => c"the image holds a world of another size or layout than this one",
    IdsExhausted => c"every particle id of the world's life was given",
    BodyTableFull => c"the body table is full",
    NoBody => c"no body has this id",
}

impl ErrorKind {
    /// The kind's stable number, the `mpca_status` the C ABI returns for it.
    pub const fn code(self) -> u32 {
        self as u32
    }

    /// A short, static description of the kind.
    pub const fn message(self) -> &'static str {
        match self.c_message().to_str() {
            Ok(text) => text,
            // Every message above is an ASCII literal.
            Err(_) => "",
        }
    }
}

impl fmt::Display for ErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.message())
    }
}

/// Why the library refused a request: its [`kind`](Error::kind), what is
/// wrong, to match on, and a [`detail`](Error::detail) that names where:
/// the field, argument or part at fault, with what is wrong with it where
/// the kind does not say (`desc.size[1]`, `desc.emitter_capacity is 0`).
/// Nothing was changed when one of these is returned.
///
/// ```
/// use mpca::{Description, ErrorKind};
///
/// let e = Description::new_2d(8, 7).validate().unwrap_err();
/// assert_eq!(e.kind(), ErrorKind::SizeOdd);
/// assert_eq!(e.detail(), "desc.size[1]");
/// assert_eq!(e.to_string(), "a world size is odd; Margolus blocks need even sizes: desc.size[1]");
/// ```
///
/// The detail is static text: an error is made without allocating, and is
/// `Copy`. Two errors are equal when their kinds and details are. A build
/// without the feature `details` (firmware, where flash is short) keeps
/// the kind alone, and gives its message as the detail.
#[derive(Clone, Copy)]
pub struct Error {
    kind: ErrorKind,
    /// NUL-terminated static text, held by its start alone, so that the
    /// results of the many calls that refuse stay small, and the C ABI
    /// hands the same bytes out.
    #[cfg(feature = "details")]
    detail: *const c_char,
}

// SAFETY: `detail` points at static text that is never written: sharing it
// between threads is sharing a `&'static CStr`.
unsafe impl Send for Error {}
// SAFETY: as for Send.
unsafe impl Sync for Error {}

impl Error {
    /// An error of kind `kind`, with `detail` naming where it is: a
    /// field (`desc.drag.rate`), an argument (`pos`), or a part of an
    /// image (`surface table`), and what is wrong with it where the kind
    /// does not say (`desc.emitter_capacity is 0`).
    #[inline(always)]
    pub const fn new(kind: ErrorKind, detail: &'static CStr) -> Error {
        #[cfg(feature = "details")]
        return Error { kind, detail: detail.as_ptr() };
        #[cfg(not(feature = "details"))]
        {
            let _ = detail;
            Error { kind }
        }
    }

    /// An error whose detail `detail` works out, where it takes more than
    /// a literal: called only in a build that keeps details.
    #[inline(always)]
    pub(crate) fn computed(kind: ErrorKind, detail: impl FnOnce() -> &'static CStr) -> Error {
        #[cfg(feature = "details")]
        return Error::new(kind, detail());
        #[cfg(not(feature = "details"))]
        {
            let _ = detail;
            Error { kind }
        }
    }

    /// What kind of problem it is.
    pub const fn kind(self) -> ErrorKind {
        self.kind
    }

    /// The kind's stable number, the `mpca_status` the C ABI returns.
    pub const fn code(self) -> u32 {
        self.kind.code()
    }

    /// The kind's message ([`ErrorKind::message`]).
    pub const fn message(self) -> &'static str {
        self.kind.message()
    }

    /// The detail, NUL-terminated: what the C ABI's last-error functions
    /// hand out.
    pub const fn c_detail(self) -> &'static CStr {
        #[cfg(feature = "details")]
        // SAFETY: `detail` came from a `&'static CStr` (`Error::new`): NUL-
        // terminated, valid and never written for the program's life.
        return unsafe { CStr::from_ptr(self.detail) };
        #[cfg(not(feature = "details"))]
        self.kind.c_message()
    }

    /// Where the problem is: the field, argument or part at fault, and
    /// what is wrong with it where the kind does not say.
    pub const fn detail(self) -> &'static str {
        match self.c_detail().to_str() {
            Ok(text) => text,
            // The library's details are ASCII; another crate's might not be.
            Err(_) => "",
        }
    }
}

impl PartialEq for Error {
    fn eq(&self, other: &Error) -> bool {
        self.kind == other.kind && self.c_detail() == other.c_detail()
    }
}

impl Eq for Error {}

impl core::hash::Hash for Error {
    fn hash<H: core::hash::Hasher>(&self, state: &mut H) {
        self.kind.hash(state);
        self.c_detail().hash(state);
    }
}

/// An error is of its kind: `error == ErrorKind::SizeOdd`.
impl PartialEq<ErrorKind> for Error {
    fn eq(&self, kind: &ErrorKind) -> bool {
        self.kind == *kind
    }
}

impl fmt::Debug for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Error").field("kind", &self.kind).field("detail", &self.c_detail()).finish()
    }
}

/// The kind's message, then the detail: `a world size is odd; Margolus
/// blocks need even sizes: desc.size[1]`. Without details (the feature
/// `details` off), the message alone.
impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if cfg!(feature = "details") { write!(f, "{}: {}", self.message(), self.detail()) } else { f.write_str(self.message()) }
    }
}

impl core::error::Error for Error {}

// Every message is UTF-8, so `message` never falls back to "".
const _: () = {
    let mut i = 0;
    while i < ErrorKind::ALL.len() {
        assert!(ErrorKind::ALL[i].c_message().to_str().is_ok());
        i += 1;
    }
};

#[cfg(test)]
mod tests {
    extern crate std;

    use core::ffi::CStr;

    use super::{Error, ErrorKind};

    #[test]
    fn an_error_is_its_kind_and_its_detail() {
        // Expect: two errors of one kind are equal where their details are
        // (not their addresses), of their kind either way; Display is the
        // kind's message, then the detail (the message alone without
        // details).
        let a = Error::new(ErrorKind::NotFinite, c"desc.gravity");
        let b = Error::new(ErrorKind::NotFinite, c"velocity");
        // The same text at another address.
        static GRAVITY: [u8; 13] = *b"desc.gravity\0";
        let same = Error::new(ErrorKind::NotFinite, CStr::from_bytes_with_nul(&GRAVITY).unwrap());
        assert!(a == ErrorKind::NotFinite && b == ErrorKind::NotFinite);
        assert_eq!(a.code(), ErrorKind::NotFinite.code());
        if cfg!(feature = "details") {
            assert_ne!(a, b);
            assert_eq!(a, same);
            assert_eq!(std::format!("{b}"), "a floating-point input is NaN or infinite: velocity");
            assert_eq!(b.c_detail(), c"velocity");
        } else {
            assert_eq!((a, b.detail()), (same, b.message()));
            assert_eq!(std::format!("{b}"), b.message());
        }
    }

    #[test]
    fn numbers_and_messages_are_distinct() {
        for (i, a) in ErrorKind::ALL.iter().enumerate() {
            assert!(!a.message().is_empty(), "{a:?} has no message");
            assert_eq!(a.c_message().to_bytes(), a.message().as_bytes());
            for b in &ErrorKind::ALL[..i] {
                assert_ne!(a.code(), b.code(), "{a:?} and {b:?} share a number");
                assert_ne!(a.message(), b.message(), "{a:?} and {b:?} share a message");
            }
        }
    }
}
