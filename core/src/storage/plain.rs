//! Plain data: the element types a world's planes are viewed as in its
//! bytes.

/// Marks plain data that any bit pattern makes valid, so planes of it can be
/// viewed in the world's bytes.
///
/// # Safety
/// Implementors are `Copy`, have no padding that matters and no invalid bit
/// patterns.
pub(crate) unsafe trait Plain: Copy {}
// SAFETY: primitive integers and floats accept every bit pattern.
unsafe impl Plain for u8 {}
unsafe impl Plain for i8 {}
unsafe impl Plain for u16 {}
unsafe impl Plain for i16 {}
unsafe impl Plain for u32 {}
unsafe impl Plain for u64 {}
unsafe impl Plain for f32 {}
// SAFETY: an array of plain values is plain: no padding between elements,
// and every element accepts every bit pattern.
unsafe impl<T: Plain, const N: usize> Plain for [T; N] {}
