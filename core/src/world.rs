//! A world in caller memory.
//!
//! [`World`] is an unsized type: a fixed header followed by the planes of
//! [`Layout`], all inside the byte slice the caller handed to
//! [`World::init`]. Being unsized, a `World` can only be reached through a
//! reference into that memory; it cannot be moved or swapped away from its
//! planes.

use core::mem::{align_of, size_of};

use crate::desc::{Description, Layout};
use crate::emitter::Slot;
use crate::obstacle::Surface;
use crate::quant::Quant;
use crate::Error;

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
unsafe impl Plain for u64 {}
unsafe impl Plain for f32 {}
// SAFETY: an array of plain values is plain: no padding between elements,
// and every element accepts every bit pattern.
unsafe impl<T: Plain, const N: usize> Plain for [T; N] {}

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
fn view<T: Plain>(bytes: &mut [u8]) -> &mut [T] {
    debug_assert_eq!(bytes.as_ptr() as usize % align_of::<T>(), 0);
    // SAFETY: the pointer is aligned for T (see above), the length is rounded
    // down to whole T, T accepts every bit pattern, and the borrow of `bytes`
    // is carried over to the result.
    unsafe { core::slice::from_raw_parts_mut(bytes.as_mut_ptr().cast::<T>(), bytes.len() / size_of::<T>()) }
}

/// Read-only twin of [`view`].
#[inline]
fn view_ref<T: Plain>(bytes: &[u8]) -> &[T] {
    debug_assert_eq!(bytes.as_ptr() as usize % align_of::<T>(), 0);
    // SAFETY: as in `view`.
    unsafe { core::slice::from_raw_parts(bytes.as_ptr().cast::<T>(), bytes.len() / size_of::<T>()) }
}

/// Counters the step keeps. All integers (clamped energy in 2^-32 units),
/// so they add up to the same bits in any block order (M8).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Counters {
    pub particles: u64,
    pub emitted: u64,
    pub exited: u64,
    pub expired: u64,
    pub shortfall: u64,
    pub collisions: u64,
    pub clamps: u64,
    pub clamp_energy: u128,
    pub displaced: u64,
    pub processed: u64,
    pub skipped: u64,
}

/// 2^32, the scale of the clamped-energy accumulator.
pub(crate) const ENERGY_SCALE: f64 = 4_294_967_296.0;

#[repr(C)]
pub(crate) struct Header {
    /// `TAG` xor the header's address: a live world at exactly this place.
    tag: u64,
    /// Bytes of planes after the header.
    len: usize,
    pub desc: Description,
    pub layout: Layout,
    pub step: u64,
    pub counters: Counters,
    pub masses: u32,
    pub surfaces: u32,
    pub emitters: u32,
    /// 1 when the library allocated the memory (`WorldBox`, feature `alloc`).
    pub owned: u32,
}

const TAG: u64 = 0x6d70_6361_776f_726c; // "mpcaworl"

/// A particle simulation of M1-M9 living in memory the caller owns.
///
/// ```
/// use mpca::{Description, World};
///
/// let desc = Description::new_2d(16, 16);
/// let mut memory = vec![0u8; mpca::world_bytes(&desc).unwrap()];
/// let world = World::init(&desc, &mut memory).unwrap();
/// world.add_particle([3, 4, 0], [0.5, 0.0, 0.0]).unwrap();
/// world.step(10);
/// assert_eq!(world.stats().particles, 1);
/// ```
#[repr(C)]
pub struct World {
    pub(crate) head: Header,
    mem: [u8],
}

/// Bytes a world built from `desc` needs, alignment slack included.
pub fn world_bytes(desc: &Description) -> Result<usize, Error> {
    let layout = Layout::of(desc)?;
    (align_of::<Header>() - 1 + size_of::<Header>()).checked_add(layout.total).ok_or(Error::TooLarge)
}

/// The alignment a world's memory is rounded up to inside the buffer.
pub const WORLD_ALIGN: usize = align_of::<Header>();

/// One particle as the queries report it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Particle {
    /// Cell coordinates; the third is 0 in 2D.
    pub pos: [u32; 3],
    /// Velocity in cells per step; the third is 0 in 2D.
    pub velocity: [f32; 3],
    /// Mass.
    pub mass: f32,
    /// Steps left to live, 0 for no limit.
    pub life: u16,
}

/// What one cell holds (M1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Cell {
    /// Nothing.
    Empty,
    /// An obstacle.
    Obstacle,
    /// A particle.
    Particle(Particle),
}

/// Statistics of a world (M10).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    /// Steps taken.
    pub step: u64,
    /// Particles now; always `added + emitted - exited - expired - removed`.
    pub particles: u64,
    /// Particles placed by emitters.
    pub emitted: u64,
    /// Particles that left by open faces.
    pub exited: u64,
    /// Particles whose lifetime ended.
    pub expired: u64,
    /// Particles emitters could not place for lack of room.
    pub emit_shortfall: u64,
    /// Total momentum `sum m v`.
    pub momentum: [f64; 3],
    /// Total kinetic energy `sum m |v|^2 / 2`.
    pub kinetic_energy: f64,
    /// Particle-particle collisions (M5.2), all steps.
    pub collisions: u64,
    /// Velocities scaled back to `|v| = 1` (M5.5), all steps.
    pub clamps: u64,
    /// Kinetic energy those clamps removed, all steps.
    pub clamp_energy: f64,
    /// Particles not placed in their desired cell (M5.6), all steps.
    pub displaced: u64,
    /// Blocks processed in the last step.
    pub blocks_processed: u64,
    /// Blocks skipped as empty in the last step (M3).
    pub blocks_skipped: u64,
    /// Bytes of the world's memory per cell.
    pub bytes_per_cell: f64,
}

/// Dispatches on the world's velocity storage type.
macro_rules! with_quant {
    ($q:expr, $t:ident => $body:expr) => {
        match $q {
            $crate::desc::Quantization::Bits8 => {
                type $t = i8;
                $body
            }
            #[cfg(feature = "q16")]
            $crate::desc::Quantization::Bits16 => {
                type $t = i16;
                $body
            }
            #[cfg(not(feature = "q16"))]
            $crate::desc::Quantization::Bits16 => unreachable!("refused by Layout::of"),
        }
    };
}
pub(crate) use with_quant;

/// Mutable views of every plane, borrowed together.
pub(crate) struct Planes<'a, Q> {
    pub occupancy: &'a mut [u64],
    pub rows: &'a mut [u8],
    pub words: &'a mut [u64],
    pub obstacle: &'a mut [u64],
    pub velocity: &'a mut [Q],
    pub mass_index: &'a mut [u8],
    pub life: &'a mut [u16],
    pub field: &'a mut [f32],
    pub potential: &'a mut [f32],
    pub mass_table: &'a mut [f32],
    pub surface: &'a mut [Surface],
    pub emitters: &'a mut [Slot],
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

/// Notes that cell `x` of row `row` now holds a particle: sets the row's
/// flag and its summary bit for the occupancy word holding the cell, so the
/// step does not skip them (M3). `summary_words` words per row.
#[inline]
pub(crate) fn mark(rows: &mut [u8], words: &mut [u64], summary_words: usize, row: usize, x: usize) {
    rows[row] = 1;
    let w = x >> 6;
    words[row * summary_words + (w >> 6)] |= 1 << (w & 63);
}

#[inline]
pub(crate) fn test_bit(plane: &[u64], bit: usize) -> bool {
    plane.get(bit >> 6).is_some_and(|w| w >> (bit & 63) & 1 != 0)
}

#[inline]
pub(crate) fn put_bit(plane: &mut [u64], bit: usize, on: bool) {
    if let Some(w) = plane.get_mut(bit >> 6) {
        let m = 1u64 << (bit & 63);
        if on { *w |= m } else { *w &= !m }
    }
}

impl Layout {
    /// The site of in-range coordinates.
    #[inline]
    pub(crate) fn site(&self, x: usize, y: usize, z: usize) -> Site {
        let row = y + self.n[1] * z;
        Site { cell: x + self.n[0] * row, bit: row * self.row_words * 64 + x, row, x }
    }
}

impl World {
    /// Builds an empty world for `desc` in `memory`, which must hold at least
    /// [`world_bytes`] bytes; any alignment is accepted (the world starts at
    /// the first [`WORLD_ALIGN`]-aligned byte). The description is checked in
    /// full before a byte of `memory` is written.
    pub fn init<'a>(desc: &Description, memory: &'a mut [u8]) -> Result<&'a mut World, Error> {
        let layout = Layout::of(desc)?;
        let pad = (memory.as_ptr() as usize).wrapping_neg() & (WORLD_ALIGN - 1);
        let need = pad.checked_add(size_of::<Header>()).and_then(|n| n.checked_add(layout.total)).ok_or(Error::TooLarge)?;
        if memory.len() < need {
            return Err(Error::BufferTooSmall);
        }
        let region = &mut memory[pad..need];
        region.fill(0);
        let base = region.as_mut_ptr();
        let mut desc = *desc;
        if desc.dim == 2 {
            desc.size[2] = 1;
        }
        let head = Header {
            tag: TAG ^ base as u64,
            len: layout.total,
            desc,
            layout,
            step: 0,
            counters: Counters::default(),
            masses: 0,
            surfaces: 0,
            emitters: 0,
            owned: 0,
        };
        // SAFETY: `base` is aligned for Header (pad above) and the region
        // holds size_of::<Header>() + layout.total bytes, borrowed for 'a.
        // The fat pointer's metadata is the length of the trailing [u8].
        unsafe {
            base.cast::<Header>().write(head);
            let world = core::ptr::slice_from_raw_parts_mut(base, layout.total) as *mut World;
            let world = &mut *world;
            if desc.per_particle_mass {
                // Class 0 is the description's mass, for particles added without one.
                world.planes::<i8>().1.mass_table[0] = desc.mass;
                world.head.masses = 1;
            }
            Ok(world)
        }
    }

    /// Recovers a world from the address [`World::as_ptr`] gave, after
    /// checking its tag.
    ///
    /// # Safety
    /// `ptr` must be null or point to at least `size_of` of the header of
    /// readable memory aligned to [`WORLD_ALIGN`]; if the tag matches, the
    /// memory must be the live world it claims to be, not aliased elsewhere for
    /// `'a`. A retired world, or memory that never held one, is refused by its
    /// tag.
    pub unsafe fn from_ptr<'a>(ptr: *mut u8) -> Result<&'a mut World, Error> {
        if ptr.is_null() || (ptr as usize) % WORLD_ALIGN != 0 {
            return Err(Error::NotAWorld);
        }
        // SAFETY: the caller promises a readable, aligned header's worth.
        let (tag, len) = unsafe {
            let h = ptr.cast::<Header>();
            (core::ptr::addr_of!((*h).tag).read(), core::ptr::addr_of!((*h).len).read())
        };
        if tag != TAG ^ ptr as u64 {
            return Err(Error::NotAWorld);
        }
        // SAFETY: the tag says a world was built here with `len` plane bytes.
        Ok(unsafe { &mut *(core::ptr::slice_from_raw_parts_mut(ptr, len) as *mut World) })
    }

    /// The address [`World::from_ptr`] takes back.
    pub fn as_ptr(&mut self) -> *mut u8 {
        (self as *mut World).cast::<u8>()
    }

    /// Marks the memory as no longer holding a world, so a later
    /// [`World::from_ptr`] on it is refused.
    pub fn retire(&mut self) {
        self.head.tag = 0;
    }

    /// Whether the library allocated this world's memory (a
    /// `WorldBox`, feature `alloc`), so that it, not the caller, must free it.
    pub fn is_owned(&self) -> bool {
        self.head.owned != 0
    }

    /// Bytes from the world's start to the end of its planes.
    pub fn size_in_bytes(&self) -> usize {
        size_of::<Header>() + self.head.len
    }

    /// The description the world was built from.
    pub fn description(&self) -> &Description {
        &self.head.desc
    }

    pub(crate) fn layout(&self) -> &Layout {
        &self.head.layout
    }

    pub(crate) fn dim(&self) -> usize {
        self.head.desc.dim as usize
    }

    /// The header and every plane, borrowed apart.
    pub(crate) fn planes<Q: Plain>(&mut self) -> (&mut Header, Planes<'_, Q>) {
        let l = self.head.layout;
        let mut rest: &mut [u8] = &mut self.mem;
        let mut at = 0usize;
        let mut take = |p: crate::desc::Plane| -> &mut [u8] {
            let r = core::mem::take(&mut rest);
            let (_, r) = r.split_at_mut(p.off - at);
            let (mine, r) = r.split_at_mut(p.len);
            at = p.off + p.len;
            rest = r;
            mine
        };
        let planes = Planes {
            occupancy: view(take(l.occupancy)),
            rows: take(l.rows),
            words: view(take(l.words)),
            obstacle: view(take(l.obstacle)),
            velocity: view(take(l.velocity)),
            mass_index: take(l.mass_index),
            life: view(take(l.life)),
            field: view(take(l.field)),
            potential: view(take(l.potential)),
            mass_table: view(take(l.mass_table)),
            surface: view(take(l.surface)),
            emitters: view(take(l.emitters)),
        };
        (&mut self.head, planes)
    }

    pub(crate) fn plane<T: Plain>(&self, p: crate::desc::Plane) -> &[T] {
        view_ref(&self.mem[p.off..p.off + p.len])
    }

    /// The site of `pos`, or `OutOfBounds`.
    pub(crate) fn locate(&self, pos: [u32; 3]) -> Result<Site, Error> {
        let l = self.layout();
        let mut c = [0usize; 3];
        for k in 0..3 {
            let v = pos[k] as usize;
            if v >= l.n[k] {
                return Err(Error::OutOfBounds);
            }
            c[k] = v;
        }
        Ok(l.site(c[0], c[1], c[2]))
    }

    pub(crate) fn occupied(&self, s: Site) -> bool {
        test_bit(self.plane(self.layout().occupancy), s.bit)
    }

    pub(crate) fn is_obstacle(&self, s: Site) -> bool {
        test_bit(self.plane(self.layout().obstacle), s.bit)
    }

    fn velocity_at(&self, cell: usize) -> [f32; 3] {
        let d = self.dim();
        let mut v = [0.0f32; 3];
        with_quant!(self.head.desc.quantization, Q => {
            let plane: &[Q] = self.plane(self.layout().velocity);
            for (k, out) in v.iter_mut().enumerate().take(d) {
                *out = plane[cell * d + k].get();
            }
        });
        v
    }

    pub(crate) fn mass_at(&self, cell: usize) -> f32 {
        if self.head.desc.per_particle_mass {
            let idx: &[u8] = self.plane(self.layout().mass_index);
            let table: &[f32] = self.plane(self.layout().mass_table);
            table[usize::from(idx[cell])]
        } else {
            self.head.desc.mass
        }
    }

    fn particle_at(&self, pos: [u32; 3], cell: usize) -> Particle {
        let life = if self.head.desc.lifetimes { self.plane::<u16>(self.layout().life)[cell] } else { 0 };
        Particle { pos, velocity: self.velocity_at(cell), mass: self.mass_at(cell), life }
    }

    /// What the cell at `pos` holds.
    pub fn cell(&self, pos: [u32; 3]) -> Result<Cell, Error> {
        let s = self.locate(pos)?;
        Ok(if self.occupied(s) {
            Cell::Particle(self.particle_at(pos, s.cell))
        } else if self.is_obstacle(s) {
            Cell::Obstacle
        } else {
            Cell::Empty
        })
    }

    /// Checks a velocity a caller hands in: finite, `|v| <= 1`, and zero on
    /// the unused axis of 2D.
    pub(crate) fn check_velocity(&self, v: [f32; 3]) -> Result<[f32; 3], Error> {
        crate::desc::finite(&v)?;
        let mut v = v;
        if self.dim() == 2 {
            v[2] = 0.0;
        }
        if v[0] * v[0] + v[1] * v[1] + v[2] * v[2] > 1.0 {
            return Err(Error::SpeedRange);
        }
        Ok(v)
    }

    /// The mass table index of `m`, adding it if new. Nothing is changed on
    /// error.
    pub(crate) fn mass_class(&mut self, m: f32) -> Result<u8, Error> {
        crate::desc::mass(m)?;
        if !self.head.desc.per_particle_mass {
            return if m == self.head.desc.mass { Ok(0) } else { Err(Error::NotEnabled) };
        }
        let used = self.head.masses as usize;
        let (head, p) = self.planes::<u8>();
        if let Some(i) = p.mass_table[..used].iter().position(|&t| t.to_bits() == m.to_bits()) {
            return Ok(i as u8);
        }
        if used >= p.mass_table.len() {
            return Err(Error::MassTableFull);
        }
        p.mass_table[used] = m;
        head.masses += 1;
        Ok(used as u8)
    }

    /// Adds a particle of the world's mass at `pos` with velocity `v`
    /// (rounded to the nearest stored value).
    pub fn add_particle(&mut self, pos: [u32; 3], v: [f32; 3]) -> Result<(), Error> {
        let m = self.head.desc.mass;
        self.add_particle_with_mass(pos, v, m)
    }

    /// Adds a particle of mass `m`. Worlds without per-particle masses accept
    /// only their own mass.
    pub fn add_particle_with_mass(&mut self, pos: [u32; 3], v: [f32; 3], m: f32) -> Result<(), Error> {
        let s = self.locate(pos)?;
        let v = self.check_velocity(v)?;
        if self.occupied(s) {
            return Err(Error::CellOccupied);
        }
        if self.is_obstacle(s) {
            return Err(Error::CellObstacle);
        }
        crate::desc::mass(m)?;
        // Last fallible step; it changes the world only when it succeeds.
        let class = self.mass_class(m)?;
        self.place(s, v, class, 0, None);
        self.head.counters.particles += 1;
        Ok(())
    }

    /// Writes a particle into a free cell. Components are rounded
    /// stochastically from `stream` when one is given (M1), else to nearest.
    pub(crate) fn place(&mut self, s: Site, v: [f32; 3], class: u8, life: u16, stream: Option<&mut crate::rng::Stream>) {
        let d = self.dim();
        let summary_words = self.layout().summary_words;
        let per_mass = self.head.desc.per_particle_mass;
        let lifetimes = self.head.desc.lifetimes;
        with_quant!(self.head.desc.quantization, Q => {
            let (_, p) = self.planes::<Q>();
            put_bit(p.occupancy, s.bit, true);
            mark(p.rows, p.words, summary_words, s.row, s.x);
            let r = stream.map(|rng| rng.next_u64());
            for k in 0..d {
                p.velocity[s.cell * d + k] = match r {
                    Some(r) => Q::from_int(Q::stochastic(v[k] * Q::SCALE, (r >> (16 * k)) as u32)),
                    None => Q::nearest(v[k]),
                };
            }
            if per_mass {
                p.mass_index[s.cell] = class;
            }
            if lifetimes {
                p.life[s.cell] = life;
            }
        });
    }

    /// Removes the particle at `pos` and returns it.
    pub fn remove_particle(&mut self, pos: [u32; 3]) -> Result<Particle, Error> {
        let s = self.locate(pos)?;
        if !self.occupied(s) {
            return Err(Error::NoParticle);
        }
        let p = self.particle_at(pos, s.cell);
        let (head, planes) = self.planes::<u8>();
        put_bit(planes.occupancy, s.bit, false);
        head.counters.particles -= 1;
        Ok(p)
    }

    /// Every particle, in cell order (x fastest).
    pub fn particles(&self) -> Particles<'_> {
        Particles { world: self, word: 0, bits: 0, words: self.plane::<u64>(self.layout().occupancy) }
    }

    /// Fills `out` with the share of cells holding a particle in each of
    /// `res` bins per axis (x fastest; the third is 1 in 2D). Bin `i` along
    /// an axis of `n` cells covers cells `i n / r .. (i+1) n / r`.
    pub fn density(&self, res: [u32; 3], out: &mut [f32]) -> Result<(), Error> {
        self.bin(res, out.len(), |i, hit, total| out[i] = hit as f32 / total as f32)
    }

    /// As [`World::density`], scaled to `0..=255` for a texture upload.
    pub fn density_u8(&self, res: [u32; 3], out: &mut [u8]) -> Result<(), Error> {
        // In u64: hit * 255 can overflow a 32-bit usize.
        self.bin(res, out.len(), |i, hit, total| {
            out[i] = ((hit as u64 * 255 + total as u64 / 2) / total as u64) as u8
        })
    }

    fn bin(&self, res: [u32; 3], len: usize, mut put: impl FnMut(usize, usize, usize)) -> Result<(), Error> {
        let l = *self.layout();
        let mut r = [1usize; 3];
        for k in 0..3 {
            r[k] = res[k] as usize;
            let used = k < self.dim();
            if r[k] == 0 || r[k] > l.n[k] || (!used && r[k] != 1) {
                return Err(Error::BadResolution);
            }
        }
        if r[0].checked_mul(r[1]).and_then(|v| v.checked_mul(r[2])) != Some(len) {
            return Err(Error::BadResolution);
        }
        let occ: &[u64] = self.plane(l.occupancy);
        // In u64: i * n can overflow a 32-bit usize; the result is <= n.
        let edge = |k: usize, i: usize| (i as u64 * l.n[k] as u64 / r[k] as u64) as usize;
        let mut i = 0;
        for bz in 0..r[2] {
            for by in 0..r[1] {
                for bx in 0..r[0] {
                    let (x0, x1) = (edge(0, bx), edge(0, bx + 1));
                    let (y0, y1) = (edge(1, by), edge(1, by + 1));
                    let (z0, z1) = (edge(2, bz), edge(2, bz + 1));
                    let mut hit = 0;
                    for z in z0..z1 {
                        for y in y0..y1 {
                            hit += count_bits(occ, l.site(x0, y, z).bit, x1 - x0);
                        }
                    }
                    put(i, hit, (x1 - x0) * (y1 - y0) * (z1 - z0));
                    i += 1;
                }
            }
        }
        Ok(())
    }

    /// Statistics now; momentum and energy are summed over the particles.
    pub fn stats(&self) -> Stats {
        let c = self.head.counters;
        let mut momentum = [0.0f64; 3];
        let mut kinetic_energy = 0.0f64;
        for p in self.particles() {
            let m = f64::from(p.mass);
            let mut v2 = 0.0;
            for k in 0..3 {
                let v = f64::from(p.velocity[k]);
                momentum[k] += m * v;
                v2 += v * v;
            }
            kinetic_energy += 0.5 * m * v2;
        }
        Stats {
            step: self.head.step,
            particles: c.particles,
            emitted: c.emitted,
            exited: c.exited,
            expired: c.expired,
            emit_shortfall: c.shortfall,
            momentum,
            kinetic_energy,
            collisions: c.collisions,
            clamps: c.clamps,
            clamp_energy: c.clamp_energy as f64 / ENERGY_SCALE,
            displaced: c.displaced,
            blocks_processed: c.processed,
            blocks_skipped: c.skipped,
            bytes_per_cell: self.bytes_per_cell(),
        }
    }

    /// Blocks processed and skipped in the last step; cheap, unlike
    /// [`World::stats`], which sums over every particle.
    pub fn last_step_blocks(&self) -> (u64, u64) {
        (self.head.counters.processed, self.head.counters.skipped)
    }

    /// Particles in the world now; cheap.
    pub fn particle_count(&self) -> u64 {
        self.head.counters.particles
    }

    /// Bytes of this world's memory (header and planes) per cell.
    pub fn bytes_per_cell(&self) -> f64 {
        (size_of::<Header>() + self.head.len) as f64 / self.layout().cells as f64
    }

    /// A 64-bit FNV-1a hash over every particle's cell, stored velocity,
    /// mass and lifetime, in cell order. Equal worlds hash equal on every
    /// target.
    pub fn state_hash(&self) -> u64 {
        let mut h = Fnv(0xcbf2_9ce4_8422_2325);
        let d = self.dim();
        let l = *self.layout();
        h.eat(&(self.head.desc.dim).to_le_bytes());
        for k in 0..3 {
            h.eat(&(l.n[k] as u64).to_le_bytes());
        }
        for p in self.particles() {
            let cell = l.site(p.pos[0] as usize, p.pos[1] as usize, p.pos[2] as usize).cell;
            h.eat(&(cell as u64).to_le_bytes());
            with_quant!(self.head.desc.quantization, Q => {
                let plane: &[Q] = self.plane(l.velocity);
                for k in 0..d {
                    h.eat(&plane[cell * d + k].to_int().to_le_bytes());
                }
            });
            h.eat(&p.mass.to_bits().to_le_bytes());
            h.eat(&p.life.to_le_bytes());
        }
        h.0
    }
}

struct Fnv(u64);

impl Fnv {
    fn eat(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
}

/// Set bits of `plane` in `bit .. bit + len`.
fn count_bits(plane: &[u64], bit: usize, len: usize) -> usize {
    let mut n = 0;
    let mut at = bit;
    let end = bit + len;
    while at < end {
        let take = (64 - (at & 63)).min(end - at);
        let w = plane[at >> 6] >> (at & 63);
        let mask = if take == 64 { u64::MAX } else { (1u64 << take) - 1 };
        n += (w & mask).count_ones() as usize;
        at += take;
    }
    n
}

/// Iterator over a world's particles, from [`World::particles`].
pub struct Particles<'a> {
    world: &'a World,
    words: &'a [u64],
    word: usize,
    bits: u64,
}

impl Iterator for Particles<'_> {
    type Item = Particle;

    fn next(&mut self) -> Option<Particle> {
        while self.bits == 0 {
            let w = *self.words.get(self.word)?;
            self.bits = w;
            self.word += 1;
        }
        let b = self.bits.trailing_zeros() as usize;
        self.bits &= self.bits - 1;
        let l = self.world.layout();
        let w = self.word - 1;
        let row = w / l.row_words;
        let x = (w % l.row_words) * 64 + b;
        let (y, z) = (row % l.n[1], row / l.n[1]);
        let pos = [x as u32, y as u32, z as u32];
        Some(self.world.particle_at(pos, l.site(x, y, z).cell))
    }
}
