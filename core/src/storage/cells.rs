//! A plane the tasks of one step write together (M11).
//!
//! The blocks of a step never share a cell, and a row of blocks never
//! shares a domain row, its row flag or its summary words with another row
//! of blocks (M3). The tasks of a parallel step are bands of rows of blocks,
//! so no element of a plane is touched by two tasks. Two `&mut [T]` to the
//! same plane held by two threads would still break Rust's aliasing rules,
//! even where the elements they touch differ; [`Cells`] is the plane as a
//! pointer and a length instead, read and written one element at a time
//! through a shared reference, like a slice of `Cell`s that may cross
//! threads.

use core::marker::PhantomData;
use core::ptr::NonNull;

/// A plane of `T` borrowed for `'a`, read and written element by element.
///
/// # Invariant
/// Within one step, an element is accessed by at most one task: the
/// partition gives every element to exactly one row of blocks, and every
/// row of blocks to exactly one task (`Partition::band`). Every access is
/// bounds-checked, but for [`Cells::pair_unchecked`] and
/// [`Cells::set_pair_unchecked`], whose caller proves the bound.
pub(crate) struct Cells<'a, T> {
    ptr: NonNull<T>,
    len: usize,
    _borrow: PhantomData<&'a [core::cell::Cell<T>]>,
}

impl<T> Clone for Cells<'_, T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for Cells<'_, T> {}

// SAFETY: `Cells` is shared between the tasks of one step only, which access
// disjoint elements (the invariant above), so no element is read and
// written by two threads without the host's synchronisation between steps;
// `T: Send` because values move between the threads through it.
unsafe impl<T: Send> Send for Cells<'_, T> {}
// SAFETY: as for `Send`.
unsafe impl<T: Send> Sync for Cells<'_, T> {}

impl<'a, T: Copy> Cells<'a, T> {
    /// The whole of `plane`, borrowed for `'a` as `Cells` only.
    #[inline]
    pub fn new(plane: &'a mut [T]) -> Self {
        Cells { len: plane.len(), ptr: NonNull::from(plane).cast(), _borrow: PhantomData }
    }

    #[inline(always)]
    pub fn len(&self) -> usize {
        self.len
    }

    /// Element `i`.
    #[inline(always)]
    pub fn get(&self, i: usize) -> T {
        if i >= self.len {
            out_of_bounds(i, self.len);
        }
        // SAFETY: `i` is in bounds and the plane is borrowed for 'a; no other
        // task accesses element `i` (the invariant).
        unsafe { self.ptr.as_ptr().add(i).read() }
    }

    /// Elements `i` and `i + 1`, with one bounds check.
    #[inline(always)]
    pub fn pair(&self, i: usize) -> [T; 2] {
        if self.len < 2 || i > self.len - 2 {
            out_of_bounds(i + 1, self.len);
        }
        // SAFETY: as in `get`, for both elements.
        unsafe { [self.ptr.as_ptr().add(i).read(), self.ptr.as_ptr().add(i + 1).read()] }
    }

    /// Elements `i` and `i + 1`, without the bounds check: for the lanes
    /// routine, whose row plan proves the bound once for a row of blocks.
    ///
    /// # Safety
    /// `i + 1 < self.len()`.
    #[inline(always)]
    pub unsafe fn pair_unchecked(&self, i: usize) -> [T; 2] {
        debug_assert!(i < self.len && self.len - i >= 2);
        // SAFETY: both elements are in bounds (the caller's promise); the
        // rest as in `get`.
        unsafe { [self.ptr.as_ptr().add(i).read(), self.ptr.as_ptr().add(i + 1).read()] }
    }

    /// Sets elements `i` and `i + 1` without the bounds check: the lanes
    /// routine's write-back, bounded as [`Cells::pair_unchecked`] is.
    ///
    /// # Safety
    /// `i + 1 < self.len()`.
    #[inline(always)]
    pub unsafe fn set_pair_unchecked(&self, i: usize, v: [T; 2]) {
        debug_assert!(i < self.len && self.len - i >= 2);
        // SAFETY: both elements are in bounds (the caller's promise); the
        // rest as in `get`.
        unsafe {
            self.ptr.as_ptr().add(i).write(v[0]);
            self.ptr.as_ptr().add(i + 1).write(v[1]);
        }
    }

    /// Sets element `i` to `v`.
    #[inline(always)]
    pub fn set(&self, i: usize, v: T) {
        if i >= self.len {
            out_of_bounds(i, self.len);
        }
        // SAFETY: as in `get`.
        unsafe { self.ptr.as_ptr().add(i).write(v) }
    }
}

impl Cells<'_, u8> {
    /// Elements `at..at + N` together.
    #[inline(always)]
    pub fn window<const N: usize>(&self, at: usize) -> [u8; N] {
        if at > self.len || self.len - at < N {
            out_of_bounds(at + N - 1, self.len);
        }
        // SAFETY: the N bytes are in bounds (checked), any bytes are a valid
        // `[u8; N]` and the read needs no alignment; no other task accesses
        // them (the invariant).
        unsafe { self.ptr.as_ptr().add(at).cast::<[u8; N]>().read_unaligned() }
    }
}

#[cold]
#[inline(never)]
fn out_of_bounds(i: usize, len: usize) -> ! {
    panic!("plane index {i} out of bounds ({len} elements)")
}
