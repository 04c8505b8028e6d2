//! Checks of the values a caller hands in: finite numbers, restitutions,
//! masses and speeds (M1). One function each, used by every call that
//! takes such a value, so that every call refuses the same values.

use crate::Error;

pub(crate) fn finite(values: &[f32]) -> Result<(), Error> {
    if values.iter().all(|v| v.is_finite()) { Ok(()) } else { Err(Error::NotFinite) }
}

pub(crate) fn restitution(e: f32) -> Result<(), Error> {
    finite(&[e])?;
    if (0.0..=1.0).contains(&e) { Ok(()) } else { Err(Error::RestitutionRange) }
}

pub(crate) fn mass(m: f32) -> Result<(), Error> {
    finite(&[m])?;
    if m > 0.0 { Ok(()) } else { Err(Error::MassRange) }
}

/// A velocity no faster than 1 (M1), in the components given.
pub(crate) fn slow(u: impl IntoIterator<Item = f32>) -> bool {
    u.into_iter().map(|c| c * c).sum::<f32>() <= 1.0
}
