//! Checks of the values a caller hands in: finite numbers, restitutions
//! and masses (M1; speeds have `speed.rs`). One function each, used by
//! every call that takes such a value, so that every call refuses the same
//! values.

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
