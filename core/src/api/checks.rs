//! Checks of the values a caller hands in: finite numbers, restitutions
//! and masses (M1; speeds have `speed.rs`). One function each, used by
//! every call that takes such a value, so that every call refuses the same
//! values. Each takes the detail of its refusals from its caller, which
//! knows the field it checks.

use core::ffi::CStr;

use crate::{Error, ErrorKind};

/// Every value finite: an exponent short of all ones (from the bits, as
/// the comparisons below).
pub(crate) fn all_finite(values: &[f32]) -> bool {
    values.iter().all(|v| v.to_bits() & 0x7f80_0000 != 0x7f80_0000)
}

// The three below build their refusals where they are called (always
// inlined): a detail handed on to a function that is not would stay
// referenced in a build without details, and with it every text of the
// library (they share one section of strings).

/// [`all_finite`], or `NotFinite` with `detail`.
#[cfg_attr(feature = "details", inline(always))]
pub(crate) fn finite(values: &[f32], detail: &'static CStr) -> Result<(), Error> {
    if all_finite(values) { Ok(()) } else { Err(Error::new(ErrorKind::NotFinite, detail)) }
}

/// A restitution in `[0, 1]`; `detail` names the field, not finite or out
/// of range (the kind says which).
#[cfg_attr(feature = "details", inline(always))]
pub(crate) fn restitution(e: f32, detail: &'static CStr) -> Result<(), Error> {
    finite(&[e], detail)?;
    if !negative(e) && size(e) <= size(1.0) { Ok(()) } else { Err(Error::new(ErrorKind::RestitutionRange, detail)) }
}

/// A mass above 0; `detail` as for [`restitution`].
#[cfg_attr(feature = "details", inline(always))]
pub(crate) fn mass(m: f32, detail: &'static CStr) -> Result<(), Error> {
    finite(&[m], detail)?;
    if positive(m) { Ok(()) } else { Err(Error::new(ErrorKind::MassRange, detail)) }
}

// The checks compare finite floats through their bits, since a comparison
// of floats is a library routine on cores without a floating-point unit.

/// `x < 0` for a finite `x` (not -0).
#[inline]
pub(crate) fn negative(x: f32) -> bool {
    x.to_bits() > 0x8000_0000
}

/// `x > 0` for a finite `x`.
#[inline]
pub(crate) fn positive(x: f32) -> bool {
    x.to_bits() as i32 > 0
}

/// `|x|` as an integer in the same order (the sign shifted out).
#[inline]
pub(crate) fn size(x: f32) -> u32 {
    x.to_bits() << 1
}
