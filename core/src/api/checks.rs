//! Checks of the values a caller hands in: finite numbers, restitutions
//! and masses (M1; speeds have `speed.rs`). One function each, used by
//! every call that takes such a value, so that every call refuses the same
//! values.

use crate::Error;

/// Every value finite: an exponent short of all ones (from the bits, as
/// the comparisons below).
pub(crate) fn finite(values: &[f32]) -> Result<(), Error> {
    if values.iter().all(|v| v.to_bits() & 0x7f80_0000 != 0x7f80_0000) { Ok(()) } else { Err(Error::NotFinite) }
}

pub(crate) fn restitution(e: f32) -> Result<(), Error> {
    finite(&[e])?;
    if !negative(e) && size(e) <= size(1.0) { Ok(()) } else { Err(Error::RestitutionRange) }
}

pub(crate) fn mass(m: f32) -> Result<(), Error> {
    finite(&[m])?;
    if positive(m) { Ok(()) } else { Err(Error::MassRange) }
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
