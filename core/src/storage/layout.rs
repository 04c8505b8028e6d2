//! Where everything of a world lies in its memory: the plan of planes a
//! description gives ([`Layout`], checked in full before a byte is written),
//! the views of those planes the step and the edits borrow together
//! ([`Planes`]), where a cell lives in them ([`Site`]), and the bit and
//! summary helpers of the bit planes.

use core::ffi::CStr;
use core::mem::{align_of, size_of};

use crate::{Error, ErrorKind};
use crate::api::desc::{Checked, Description, Quantization};
use crate::rules::emitter::Slot;
use crate::rules::obstacle::Surface;
#[cfg(feature = "obstacles")]
use crate::rules::body::{Body, BodiesHead, BodySurface, Tally};
use crate::rules::class::Class;
use crate::storage::cells::Cells;
use crate::storage::plain::Plain;

// SAFETY: u32 and f32 fields, no padding, every bit pattern valid.
unsafe impl Plain for Surface {}
// SAFETY: u32 and f32 fields only, no padding, every bit pattern valid.
unsafe impl Plain for Slot {}
// SAFETY: u32 and f32 fields only, no padding, every bit pattern valid.
#[cfg(feature = "obstacles")]
unsafe impl Plain for BodySurface {}
// SAFETY: u32, f32 and i32 fields, then two tallies of i64 and u32 fields
// (`repr(C)`, 8-aligned at an offset of 64), no padding, every bit pattern
// valid.
#[cfg(feature = "obstacles")]
unsafe impl Plain for Body {}
// SAFETY: i64 and u32 fields, no padding, every bit pattern valid.
#[cfg(feature = "obstacles")]
unsafe impl Plain for BodiesHead {}
// SAFETY: i64 and u32 fields, no padding, every bit pattern valid.
#[cfg(feature = "obstacles")]
unsafe impl Plain for Tally {}
// SAFETY: f32, u32, f32, u32 and i64 fields in that order (`repr(C)`), no
// padding, every bit pattern valid.
unsafe impl Plain for Class {}

/// Views a plane of `T` as whole groups of `N` (a cell's `N` velocity
/// components, say); a partial group at the end is left out.
#[inline]
pub(crate) fn groups<T: Plain, const N: usize>(plane: &mut [T]) -> &mut [[T; N]] {
    const { assert!(N > 0) };
    // SAFETY: `[T; N]` has the alignment of `T` and the size of N of them,
    // the length is rounded down to whole groups, any bit pattern is a valid
    // `[T; N]` (Plain), and the borrow of `plane` is carried over.
    unsafe { core::slice::from_raw_parts_mut(plane.as_mut_ptr().cast::<[T; N]>(), plane.len() / N) }
}

/// Views `bytes` as a slice of `T`. Planes start 8-byte aligned by
/// construction of [`Layout`] and the header's alignment.
#[inline]
pub(crate) fn view<T: Plain>(bytes: &mut [u8]) -> &mut [T] {
    debug_assert_eq!(bytes.as_ptr() as usize % align_of::<T>(), 0);
    // SAFETY: the pointer is aligned for T (see above), the length is rounded
    // down to whole T, T accepts every bit pattern, and the borrow of `bytes`
    // is carried over to the result.
    unsafe { core::slice::from_raw_parts_mut(bytes.as_mut_ptr().cast::<T>(), bytes.len() / size_of::<T>()) }
}

/// Read-only twin of [`view`].
#[inline]
pub(crate) fn view_ref<T: Plain>(bytes: &[u8]) -> &[T] {
    debug_assert_eq!(bytes.as_ptr() as usize % align_of::<T>(), 0);
    // SAFETY: as in `view`.
    unsafe { core::slice::from_raw_parts(bytes.as_ptr().cast::<T>(), bytes.len() / size_of::<T>()) }
}

/// `bytes` as values of `T`, whose plane [`Layout::of`] sized for `count`
/// of them (the emitters' table). With `small-step`
/// (firmware) the first `count` (none where fewer fit), without the
/// division by the size that [`view`] makes, which small cores call a
/// routine for; otherwise [`view`], the same values.
#[inline]
pub(crate) fn view_counted<T: Plain>(bytes: &mut [u8], count: usize) -> &mut [T] {
    if !cfg!(feature = "small-step") {
        return view(bytes);
    }
    let count = if fits::<T>(bytes.len(), count) { count } else { 0 };
    debug_assert_eq!(bytes.as_ptr() as usize % align_of::<T>(), 0);
    // SAFETY: as in `view`, for `count` values of T, which fit in `bytes`.
    unsafe { core::slice::from_raw_parts_mut(bytes.as_mut_ptr().cast::<T>(), count) }
}

/// Read-only twin of [`view_counted`].
#[inline]
pub(crate) fn view_counted_ref<T: Plain>(bytes: &[u8], count: usize) -> &[T] {
    if !cfg!(feature = "small-step") {
        return view_ref(bytes);
    }
    let count = if fits::<T>(bytes.len(), count) { count } else { 0 };
    debug_assert_eq!(bytes.as_ptr() as usize % align_of::<T>(), 0);
    // SAFETY: as in `view_counted`.
    unsafe { core::slice::from_raw_parts(bytes.as_ptr().cast::<T>(), count) }
}

/// Whether `count` values of `T` fit in `len` bytes, `len` no more than
/// `isize::MAX` (a slice's). Without a checked multiplication, which small
/// cores make with a 64-bit library call: with `2^k <= size < 2^(k+1)`, a
/// `count` of at most `len >> k` (else too many) is below `2 len / size`,
/// so `count * size` stays below `2 len`, which fits a usize.
#[inline]
fn fits<T>(len: usize, count: usize) -> bool {
    let size = size_of::<T>();
    debug_assert!(len <= isize::MAX as usize);
    size == 0 || count <= len >> size.ilog2() && count * size <= len
}

/// Where one plane lies in the world's memory, in bytes from its start.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Plane {
    pub off: usize,
    pub len: usize,
}

/// The memory plan of a world. Every plane starts 8-byte aligned; planes a
/// scene does not use have length 0 (M9).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Layout {
    /// Cells per axis, 1 for the unused third axis of 2D.
    pub n: [usize; 3],
    pub cells: usize,
    /// 64-bit words per x-row of a bit plane (rows are padded to whole words).
    pub row_words: usize,
    /// Summary words per row in the plane `words` (see [`Layout::words`]).
    pub summary_words: usize,
    /// Every plane, in the order they lie in memory, read through the
    /// accessors below (`occupancy()`, ...): one array, which
    /// [`Layout::of`] fills in one loop. As named fields each plane was
    /// built apart and then moved into the result, copies that a
    /// Cortex-M0 paid for.
    plane: [Plane; PLANES],
    pub total: usize,
}

// `Layout::same` reads a layout as words: it must be usizes alone.
const _: () = assert!(size_of::<Layout>() == (7 + 2 * PLANES) * size_of::<usize>());

impl Layout {
    /// Whether `other` is the same plan: compared as words in one
    /// comparison of memory, not field by field, which the compiler
    /// unrolls into a compare and branch for every one of them.
    pub(crate) fn same(&self, other: &Layout) -> bool {
        self.as_usizes() == other.as_usizes()
    }

    fn as_usizes(&self) -> &[usize] {
        // SAFETY: a Layout is only usizes (sizes, counts and planes of two
        // of them, as the assertion above checks), so it has no padding and
        // is read in place as that many aligned usizes, borrowed as `self`.
        unsafe { core::slice::from_raw_parts((self as *const Layout).cast::<usize>(), size_of::<Layout>() / size_of::<usize>()) }
    }
}

/// The planes every build plans, the getters of `planes!` below.
const BASE_PLANES: usize = 13;
/// The identity planes (M6b), after the base ones, only in a build with
/// `identity`, so firmware without it plans as before.
const IDENTITY_PLANES: usize = if cfg!(feature = "identity") { 3 } else { 0 };
/// The number of planes of a [`Layout`]: then M13's, last, only in a build
/// with `obstacles`.
const PLANES: usize = BASE_PLANES + IDENTITY_PLANES + if cfg!(feature = "obstacles") { 4 } else { 0 };

/// A getter for each plane of a [`Layout`], by its index in `plane`.
macro_rules! planes {
    ($($(#[$doc:meta])* $name:ident = $index:literal,)*) => {
        impl Layout {
            $(
                $(#[$doc])*
                #[inline]
                pub(crate) fn $name(&self) -> Plane {
                    self.plane[$index]
                }
            )*
        }
    };
}

planes! {
    /// One bit per cell: whether it holds a particle.
    occupancy = 0,
    /// One byte per row `y + ny z`: 0 where the row holds no particle for
    /// sure, 1 where it may hold one (the step skips rows of 0, M3).
    rows = 1,
    /// Per row, `summary_words` words with one bit per occupancy word: 0
    /// where that word holds no particle for sure (the step skips it).
    words = 2,
    obstacle = 3,
    velocity = 4,
    mass_index = 5,
    life = 6,
    field = 7,
    potential = 8,
    /// The wind plane of M5.1b, `dim` `f32` per cell.
    wind = 9,
    mass_table = 10,
    surface = 11,
    emitters = 12,
}

impl Layout {
    /// M6b's planes, a `u32` id, a `u32` age and a `u8` tag per cell:
    /// empty in a build without `identity`.
    #[inline]
    fn identity_plane(&self, i: usize) -> Plane {
        self.plane.get(BASE_PLANES + i).copied().unwrap_or_default()
    }
    #[inline]
    pub(crate) fn id(&self) -> Plane {
        self.identity_plane(0)
    }
    #[inline]
    pub(crate) fn age(&self) -> Plane {
        self.identity_plane(1)
    }
    #[inline]
    pub(crate) fn tag(&self) -> Plane {
        self.identity_plane(2)
    }

    /// M13's planes: empty in a build without `obstacles`.
    #[cfg(feature = "obstacles")]
    #[inline]
    fn body_plane(&self, i: usize) -> Plane {
        self.plane.get(BASE_PLANES + IDENTITY_PLANES + i).copied().unwrap_or_default()
    }
    /// One bit per cell: whether a body covers it (the obstacle plane
    /// holds these cells too).
    #[cfg(feature = "obstacles")]
    #[inline]
    pub(crate) fn body_cells(&self) -> Plane {
        self.body_plane(0)
    }
    /// A [`BodiesHead`], then the body table.
    #[cfg(feature = "obstacles")]
    #[inline]
    pub(crate) fn bodies(&self) -> Plane {
        self.body_plane(1)
    }
    #[cfg(feature = "obstacles")]
    #[inline]
    pub(crate) fn body_surface(&self) -> Plane {
        self.body_plane(2)
    }
    #[cfg(feature = "obstacles")]
    #[inline]
    pub(crate) fn body_tally(&self) -> Plane {
        self.body_plane(3)
    }
}

impl Layout {
    /// Plans the memory of a checked description ([`Description::check`]).
    /// Every size computation is checked, so a description whose byte
    /// count would overflow is refused.
    pub fn of(d: Checked<'_>) -> Result<Layout, Error> {
        let dim = d.dim as usize;
        let mut n = [1usize; 3];
        for k in 0..dim {
            n[k] = usize::try_from(d.size[k]).map_err(|_| Error::new(ErrorKind::TooLarge, CELLS))?;
        }

        // Cell indices are stored as u32 (surface table), so the cell count
        // must fit one; every byte count below is checked against usize,
        // and any that overflows is the one error TooLarge.
        let cells = mul(mul(n[0], n[1], Extent::Cells)?, n[2], Extent::Cells)?;
        if u32::try_from(cells).is_err() {
            return Err(Error::new(ErrorKind::TooLarge, CELLS));
        }
        let rows = n[1] * n[2];
        let row_words = row_words(n[0]);
        // Bit planes are indexed by bit, so their bit count must fit too
        // (and with it their byte count, an eighth of it).
        let bit_plane = mul(mul(row_words, rows, Extent::Cells)?, 64, Extent::Cells)? / 8;
        let q = match d.quantization {
            Quantization::Bits8 => 1,
            Quantization::Bits16 => 2,
        };
        // `bytes` a cell where `on`.
        let per_cell = |bytes: usize, on: bool| mul(cells, bytes * usize::from(on), Extent::Cells);
        let summary_words = row_words.div_ceil(64);
        // M13's planes: the cells bodies cover, the body table after its
        // head, the body surface table and a step's tally per entry.
        #[cfg(feature = "obstacles")]
        let body = if d.has_bodies() {
            let entries = d.body_surface_capacity as usize;
            let surfaces = Extent::BodySurfaces;
            [bit_plane, mul(d.body_capacity as usize, size_of::<Body>(), Extent::Bodies)? + size_of::<BodiesHead>(), mul(entries, size_of::<BodySurface>(), surfaces)?, mul(entries, size_of::<Tally>(), surfaces)?]
        } else {
            [0; 4]
        };
        // The planes' lengths in the order they lie in memory, each
        // starting 8-byte aligned after the one before; M6b's last, and
        // only in a build with `identity` (a build without refuses them,
        // `Description::check`).
        let lens = [
            bit_plane,
            rows,
            summary_words * rows * 8,
            bit_plane * usize::from(d.obstacles),
            per_cell(dim * q, true)?,
            per_cell(1, d.per_particle_mass)?,
            per_cell(2, d.lifetimes)?,
            per_cell(dim * 4, d.forces.field)?,
            per_cell(4, d.forces.potential)?,
            per_cell(dim * 4, d.drag.field)?,
            if d.per_particle_mass { mass_plane(d.mass_classes as usize) } else { 0 },
            mul(d.surface_capacity as usize * usize::from(d.obstacles), size_of::<crate::rules::obstacle::Surface>(), Extent::Surfaces)?,
            mul(d.emitter_capacity as usize, size_of::<crate::rules::emitter::Slot>(), Extent::Emitters)?,
            #[cfg(feature = "identity")]
            per_cell(4, d.identity.ids())?,
            #[cfg(feature = "identity")]
            per_cell(4, d.identity.ages())?,
            #[cfg(feature = "identity")]
            per_cell(1, d.identity.tags())?,
            // M13's, last, only in a build with `obstacles`.
            #[cfg(feature = "obstacles")]
            body[0],
            #[cfg(feature = "obstacles")]
            body[1],
            #[cfg(feature = "obstacles")]
            body[2],
            #[cfg(feature = "obstacles")]
            body[3],
        ];
        let mut plane = lens.map(|len| Plane { off: 0, len });
        let mut at = 0usize;
        for p in &mut plane {
            p.off = at;
            // Saturating: a sum past usize::MAX is past the bound below
            // too. Slices may not exceed isize::MAX bytes.
            at = at.saturating_add(p.len).saturating_add(7) & !7;
            if at > isize::MAX as usize / 2 {
                return Err(Error::new(ErrorKind::TooLarge, TOTAL));
            }
        }
        Ok(Layout { n, cells, row_words, summary_words, plane, total: at })
    }
}

impl Description {
    /// Checks the whole description, its memory plan included (a world
    /// too large for the target is refused); the first problem found is
    /// returned.
    pub fn validate(&self) -> Result<(), Error> {
        self.plan().map(|_| ())
    }

    /// The checks ([`Description::check`]) and then the memory plan
    /// ([`Layout::of`]): what every caller that builds, sizes or loads a
    /// world needs. Out of line, so that the checks exist once in the
    /// build.
    #[inline(never)]
    pub(crate) fn plan(&self) -> Result<Layout, Error> {
        Layout::of(self.check()?)
    }
}

/// The bytes of the mass table's plane for `n` classes: the masses (`f32`),
/// padded to 8 bytes, then the step's conversion of each class (M1c),
/// scratch the step writes before it reads: in the world's memory rather
/// than on a stack a small core may not have room for, and no part of the
/// world's state (snapshots save the masses alone).
pub(crate) const fn mass_plane(n: usize) -> usize {
    (n * 4).next_multiple_of(8) + n * size_of::<Class>()
}

/// The mass table's plane `plane` of a world of `n` classes split into the
/// masses and the step's classes ([`mass_plane`]).
pub(crate) fn masses_and_classes(plane: &mut [f32], n: usize) -> (&mut [f32], &mut [Class]) {
    let (table, rest) = plane.split_at_mut(n.next_multiple_of(2));
    // SAFETY: f32 and Class accept every bit pattern (Plain), the bytes
    // are those of `rest`, borrowed as long, and `view` checks the
    // alignment (the classes start 8-aligned: `mass_plane`).
    let bytes = unsafe { core::slice::from_raw_parts_mut(rest.as_mut_ptr().cast::<u8>(), rest.len() * 4) };
    (&mut table[..n], view(bytes))
}

/// `a * b`, or `TooLarge` naming what was sized where it overflows. Out
/// of line: one copy for every size [`Layout::of`] checks.
#[inline(never)]
fn mul(a: usize, b: usize, what: Extent) -> Result<usize, Error> {
    a.checked_mul(b).ok_or_else(|| Error::computed(ErrorKind::TooLarge, || what.field()))
}

/// What [`mul`] sizes, for its refusal's detail: a tag rather than the
/// text, which a build without details then never references.
#[derive(Clone, Copy)]
enum Extent {
    /// A plane of the cells: the sizes alone make it.
    Cells,
    Surfaces,
    Emitters,
    #[cfg(feature = "obstacles")]
    Bodies,
    #[cfg(feature = "obstacles")]
    BodySurfaces,
}

impl Extent {
    fn field(self) -> &'static CStr {
        match self {
            Extent::Cells => CELLS,
            Extent::Surfaces => c"desc.surface_capacity",
            Extent::Emitters => c"desc.emitter_capacity",
            #[cfg(feature = "obstacles")]
            Extent::Bodies => c"desc.body_capacity",
            #[cfg(feature = "obstacles")]
            Extent::BodySurfaces => c"desc.body_surface_capacity",
        }
    }
}

/// The detail of a cell count or plane too large: the sizes alone make it.
const CELLS: &CStr = c"desc.size";

/// The detail of a world too large as a whole.
pub(crate) const TOTAL: &CStr = c"desc.size and the capacities";

/// Mutable views of every plane, borrowed together.
pub(crate) struct Planes<'a, Q> {
    pub occupancy: &'a mut [u64],
    pub rows: &'a mut [u8],
    pub words: &'a mut [u64],
    pub obstacle: &'a mut [u64],
    pub velocity: &'a mut [Q],
    pub mass_index: &'a mut [u8],
    pub life: &'a mut [u16],
    /// M6b's planes, in a build with `identity` alone: firmware without it
    /// hands no empty slices about.
    #[cfg(feature = "identity")]
    pub id: &'a mut [u32],
    #[cfg(feature = "identity")]
    pub age: &'a mut [u32],
    #[cfg(feature = "identity")]
    pub tag: &'a mut [u8],
    pub field: &'a mut [f32],
    pub potential: &'a mut [f32],
    pub wind: &'a mut [f32],
    /// The masses, then the step's classes ([`mass_plane`]), viewed as
    /// `f32`: [`masses_and_classes`] splits them.
    pub mass_table: &'a mut [f32],
    pub surface: &'a mut [Surface],
    pub emitters: &'a mut [Slot],
    /// M13's planes, in a build with `obstacles` alone.
    #[cfg(feature = "obstacles")]
    pub body_cells: &'a mut [u64],
    #[cfg(feature = "obstacles")]
    pub bodies: &'a mut [u8],
    #[cfg(feature = "obstacles")]
    pub body_surface: &'a mut [BodySurface],
    #[cfg(feature = "obstacles")]
    pub body_tally: &'a mut [Tally],
}

/// The body table's plane split into its head and its slots (M13); an
/// empty plane (no bodies) gives none.
#[cfg(feature = "obstacles")]
pub(crate) fn head_and_bodies(plane: &mut [u8]) -> (Option<&mut BodiesHead>, &mut [Body]) {
    if plane.len() < size_of::<BodiesHead>() {
        return (None, &mut []);
    }
    let (head, table) = plane.split_at_mut(size_of::<BodiesHead>());
    (view::<BodiesHead>(head).first_mut(), view(table))
}

/// Where a cell lives in the planes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Site {
    /// Dense index `x + nx (y + ny z)`.
    pub cell: usize,
    /// Bit index in a bit plane (rows padded to whole words).
    pub bit: usize,
    /// The cell's row `y + ny z`, its index in the row flags.
    pub row: usize,
    /// The cell's x.
    pub x: usize,
}

/// Writes stored component `i` of a velocity plane of `width`-byte
/// components (1, or 2 in the target's byte order) viewed as bytes: `q`,
/// in quanta, within the width's range. Callers that hold the plane as
/// bytes have one copy of their code for both widths: the bodies'
/// push-out (M13), which a build without `obstacles` does not have.
#[cfg(feature = "obstacles")]
#[inline(always)]
pub(crate) fn store(plane: &mut [u8], i: usize, width: usize, q: i32) {
    if width == 1 || !cfg!(feature = "q16") {
        plane[i] = q as i8 as u8;
    } else {
        plane[2 * i..2 * i + 2].copy_from_slice(&(q as i16).to_ne_bytes());
    }
}

/// Stored component `i` of a velocity plane of `width`-byte components,
/// viewed as bytes, in quanta: what [`store`] wrote.
#[inline(always)]
pub(crate) fn stored(plane: &[u8], i: usize, width: usize) -> i32 {
    if width == 1 || !cfg!(feature = "q16") {
        i32::from(plane[i] as i8)
    } else {
        i32::from(i16::from_ne_bytes([plane[2 * i], plane[2 * i + 1]]))
    }
}

/// Notes that cell `x` of row `row` now holds a particle: sets the row's
/// flag and its summary bit for the occupancy word holding the cell, so the
/// step does not skip them (M3). `summary_words` words per row.
///
/// With `small-step` nothing: that build's sweep reads neither
/// ([`crate::step::partition::Partition::sweep_band`]).
#[inline]
pub(crate) fn mark(rows: Cells<'_, u8>, words: Cells<'_, u64>, summary_words: usize, row: usize, x: usize) {
    if cfg!(feature = "small-step") {
        return;
    }
    rows.set(row, 1);
    let w = x >> 6;
    let at = row * summary_words + (w >> 6);
    words.set(at, words.get(at) | 1 << (w & 63));
}

/// 64-bit words per x-row of a bit plane of `nx` cells per row: rows are
/// padded to whole words.
#[inline]
pub(crate) const fn row_words(nx: usize) -> usize {
    nx.div_ceil(64)
}

#[inline]
pub(crate) fn test_bit(plane: &[u64], bit: usize) -> bool {
    plane.get(bit >> 6).is_some_and(|w| w >> (bit & 63) & 1 != 0)
}

#[inline]
pub(crate) fn put_bit(plane: Cells<'_, u64>, bit: usize, on: bool) {
    let at = bit >> 6;
    if at < plane.len() {
        let m = 1u64 << (bit & 63);
        let w = plane.get(at);
        plane.set(at, if on { w | m } else { w & !m });
    }
}

impl Layout {
    /// The site of in-range coordinates.
    #[inline]
    pub(crate) fn site(&self, x: usize, y: usize, z: usize) -> Site {
        self.grid().site(x, y, z)
    }

    /// What [`Layout::site`] reads, apart: a copy of three words where a
    /// caller must let go of the world (the emitters' placement).
    #[inline]
    pub(crate) fn grid(&self) -> Grid {
        Grid { n: self.n, row_words: self.row_words }
    }
}

/// The cells per axis and the words per bit-plane row of a [`Layout`].
#[derive(Clone, Copy)]
pub(crate) struct Grid {
    n: [usize; 3],
    row_words: usize,
}

impl Grid {
    /// The site of in-range coordinates.
    #[inline]
    pub(crate) fn site(&self, x: usize, y: usize, z: usize) -> Site {
        let row = y + self.n[1] * z;
        Site { cell: x + self.n[0] * row, bit: row * self.row_words * 64 + x, row, x }
    }
}
