//! M12 snapshots: a world written out as a byte image, and read back.
//!
//! The image is defined byte for byte in `docs/model.md` (M12). Every
//! number in it is little-endian whatever the target, so an image written
//! on one target loads on any other, into a world that hashes the same
//! there. It holds the description, the step number, the counters and every
//! plane that holds state; the row flags and summary words the step skips
//! by (M3) are rebuilt from the occupancy instead of saved. A CRC-32 closes
//! it.
//!
//! Reading is all or nothing: the framing, the checksum and then every value
//! against the rules a live world keeps are checked before a byte of any
//! world is written, so a refused image changes nothing.
//!
//! ```
//! use mpca::{Description, World};
//!
//! let desc = Description::new_2d(16, 16);
//! let mut memory = vec![0u8; mpca::world_bytes(&desc).unwrap()];
//! let world = World::init(&desc, &mut memory).unwrap();
//! world.add_particle([3, 4, 0], [0.5, 0.0, 0.0]).unwrap();
//! world.step(5);
//!
//! let mut image = vec![0u8; world.snapshot_bytes()];
//! world.save(&mut image).unwrap();
//!
//! // Into fresh memory, sized from the image alone.
//! let mut other = vec![0u8; mpca::world_bytes(&mpca::image_description(&image).unwrap()).unwrap()];
//! let copy = World::init_from_image(&image, &mut other).unwrap();
//! assert_eq!(copy.state_hash(), world.state_hash());
//! copy.step(10);
//! world.step(10);
//! assert_eq!(copy.state_hash(), world.state_hash());
//!
//! // A damaged image is refused.
//! image[100] ^= 4;
//! assert_eq!(world.load(&image).unwrap_err().kind(), mpca::ErrorKind::ImageChecksum);
//! ```

use core::mem::size_of;

use core::ffi::CStr;

use crate::{Error, ErrorKind};
use crate::api::desc::{Boundary, Collisions, Description, Drag, Drift, Forces, Identity, Quantization, Turbulence, Vortex};
use crate::api::edit::storable;
use crate::rules::assign::Method;
use crate::rules::emitter::{checked, Emitter, EmitterStats, Slot};
use crate::rules::obstacle::Surface;
use crate::storage::cells::Cells;
use crate::storage::layout::{mark, view, Layout};
use crate::storage::world::{Counters, World};

/// The first eight bytes of every image.
const MAGIC: [u8; 8] = *b"MPCASNAP";

/// The newest version of the image format this library writes: 3 holds a
/// world with bodies (M13). A world without them is written as version 2,
/// which older libraries read too. It also reads version 1, whose emitters
/// carry no counts (they load as zero).
pub const IMAGE_VERSION: u32 = 3;

/// Magic, version, a reserved word and the image's length.
const HEAD: usize = 24;
/// The description.
const DESC: usize = 120;
/// The step number, the counters and the table counts.
const STATE: usize = 120;
/// Everything before the planes.
const FIXED: usize = HEAD + DESC + STATE;
/// The CRC-32 at the end.
const CHECKSUM: usize = 4;
/// One surface table entry: cell, normal, restitution, mask flag.
const SURFACE: usize = 24;
/// One emitter: region, rate, velocity, spread, mass, lifetime, mass index
/// and tag, then what it asked for and placed.
const EMITTER: usize = 72;
/// One emitter in an image of version 1: without the two counts.
const EMITTER_V1: usize = 56;
/// The bodies' head of an image of version 3, after the description: the
/// body and body surface capacities, the particles bodies crushed, the
/// redraws since the last step and a reserved word (M13).
const BODY_HEAD: usize = 24;
/// One slot of the body table: kind, restitution, the shape's two points
/// and radius, the velocity and a reserved word, then the tally of the
/// step under way and the last one (3 momenta, 3 counts and a reserved
/// word each).
const BODY: usize = 132;
/// The turbulence (M5.1c), after the description where the fourth of its
/// flag bytes says so: amplitude, scale, rate and a reserved word.
const TURBULENCE: usize = 16;

/// Whether a world of description `d` keeps turbulence settings in an
/// image: any of them not zero (from the bits, so that -0 comes back as
/// it was). Never in a build without `fields`, whose worlds have none.
fn turbulent(d: &Description) -> bool {
    cfg!(feature = "fields") && !all_zero(&d.drag.turbulence)
}

/// Whether every bit of the turbulence's settings is 0.
fn all_zero(t: &Turbulence) -> bool {
    t.amplitude.to_bits() | t.scale | t.rate.to_bits() == 0
}

/// The bytes a world of description `d` keeps of its bodies in an image:
/// the head and every slot of the table, or nothing without bodies.
fn body_bytes(d: &Description) -> usize {
    if d.obstacles && d.body_capacity > 0 { BODY_HEAD + d.body_capacity as usize * BODY } else { 0 }
}

/// CRC-32 as zlib, PNG and Ethernet compute it: the reflected polynomial
/// 0xEDB88320, register preset to all ones and inverted at the end. A table
/// of the remainders of every byte makes it one lookup a byte.
const fn crc_table() -> [u32; 256] {
    let mut table = [0u32; 256];
    let mut byte = 0;
    while byte < 256 {
        let mut r = byte as u32;
        let mut bit = 0;
        while bit < 8 {
            r = if r & 1 != 0 { (r >> 1) ^ 0xedb8_8320 } else { r >> 1 };
            bit += 1;
        }
        table[byte] = r;
        byte += 1;
    }
    table
}

static CRC_TABLE: [u32; 256] = crc_table();

/// Out of line: one copy for the writer and the reader.
#[inline(never)]
pub(crate) fn crc32(bytes: &[u8]) -> u32 {
    !bytes.iter().fold(!0u32, |r, &b| CRC_TABLE[((r ^ u32::from(b)) & 0xff) as usize] ^ (r >> 8))
}

/// Writes values little-endian into an image whose length was computed
/// beforehand ([`image_len`]), so nothing written can fall outside it.
struct Put<'a> {
    out: &'a mut [u8],
    at: usize,
}

impl Put<'_> {
    fn bytes(&mut self, b: &[u8]) {
        self.out[self.at..self.at + b.len()].copy_from_slice(b);
        self.at += b.len();
    }
    fn u8(&mut self, v: u8) {
        self.bytes(&[v]);
    }
    fn u32(&mut self, v: u32) {
        self.bytes(&v.to_le_bytes());
    }
    fn u64(&mut self, v: u64) {
        self.bytes(&v.to_le_bytes());
    }
    fn f32(&mut self, v: f32) {
        self.u32(v.to_bits());
    }
    /// Writes `N` bytes, those `f` writes, assembled in an array first:
    /// every write of `f` is then at an offset known when compiled, and
    /// none needs a check of its own (the image's fields are many, and
    /// each checked write made most of the writer's code).
    fn fixed<const N: usize>(&mut self, f: impl FnOnce(&mut Put<'_>)) {
        let mut a = [0; N];
        let mut q = Put { out: &mut a, at: 0 };
        f(&mut q);
        debug_assert_eq!(q.at, N);
        self.bytes(&a);
    }
    /// A plane of floats. Out of line: one copy serves every plane.
    #[inline(never)]
    fn f32s(&mut self, plane: &[f32]) {
        let out = &mut self.out[self.at..self.at + 4 * plane.len()];
        for (o, &f) in out.chunks_exact_mut(4).zip(plane) {
            o.copy_from_slice(&f.to_bits().to_le_bytes());
        }
        self.at += 4 * plane.len();
    }
    /// A bit plane, without the bits `clear` has set (none past its end).
    /// Out of line: one copy for the occupancy and the obstacles.
    #[inline(never)]
    fn words(&mut self, plane: &[u64], clear: &[u64]) {
        for (i, &w) in plane.iter().enumerate() {
            self.u64(w & !clear.get(i).copied().unwrap_or(0));
        }
    }
}

/// Reads values little-endian from an image, front to back.
struct Get<'a> {
    rest: &'a [u8],
}

impl<'a> Get<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], Error> {
        if n > self.rest.len() {
            return Err(invalid(c"a part past the end"));
        }
        let (head, rest) = self.rest.split_at(n);
        self.rest = rest;
        Ok(head)
    }
    fn array<const N: usize>(&mut self) -> Result<[u8; N], Error> {
        let mut a = [0; N];
        a.copy_from_slice(self.take(N)?);
        Ok(a)
    }
    fn u8(&mut self) -> Result<u8, Error> {
        Ok(self.array::<1>()?[0])
    }
    fn u32(&mut self) -> Result<u32, Error> {
        Ok(u32::from_le_bytes(self.array()?))
    }
    fn u64(&mut self) -> Result<u64, Error> {
        Ok(u64::from_le_bytes(self.array()?))
    }
    fn f32(&mut self) -> Result<f32, Error> {
        Ok(f32::from_bits(self.u32()?))
    }
    /// `n` reserved bytes, which must be zero.
    fn zeros(&mut self, n: usize) -> Result<(), Error> {
        if self.take(n)?.iter().all(|&b| b == 0) { Ok(()) } else { Err(invalid(RESERVED)) }
    }
}

/// The first `N` bytes of `b`: checked once, so that the reads at fixed
/// offsets in it that follow need no check of their own.
fn first<const N: usize>(b: &[u8]) -> &[u8; N] {
    b.first_chunk().unwrap()
}

/// Word `i` of a plane of little-endian `u32` in an image.
fn le_u32(bytes: &[u8], i: usize) -> u32 {
    let mut a = [0; 4];
    a.copy_from_slice(&bytes[4 * i..4 * i + 4]);
    u32::from_le_bytes(a)
}

/// Word `i` of a plane of little-endian `u64` in an image.
fn le_u64(bytes: &[u8], i: usize) -> u64 {
    let mut a = [0; 8];
    a.copy_from_slice(&bytes[8 * i..8 * i + 8]);
    u64::from_le_bytes(a)
}

/// A stored velocity component of `width` bytes (1 or 2) at the start of
/// `bytes`.
fn component(bytes: &[u8], width: usize) -> i32 {
    if width == 1 { i32::from(bytes[0] as i8) } else { i32::from(i16::from_le_bytes([bytes[0], bytes[1]])) }
}

/// Bytes of a stored velocity component, and stored steps per unit speed.
fn width_and_scale(q: Quantization) -> (usize, i32) {
    match q {
        Quantization::Bits8 => (1, 127),
        Quantization::Bits16 => (2, 32767),
    }
}

/// Calls `f(row, x)` for every set bit of a bit plane laid out as `l`
/// plans it, whose word `i` is `word(i)`, in cell order (x fastest).
fn each_bit(l: &Layout, word: impl Fn(usize) -> u64, mut f: impl FnMut(usize, usize)) {
    for i in 0..l.occupancy().len / 8 {
        let mut bits = word(i);
        let (row, x0) = (i / l.row_words, (i % l.row_words) * 64);
        while bits != 0 {
            let b = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            f(row, x0 + b);
        }
    }
}

/// Calls `f(cell)` with the dense index of every cell set in the
/// occupancy plane `occupancy` of a world planned as `l`, in cell order.
/// Out of line, `f` dynamic: one copy serves every plane an image holds
/// per particle.
#[inline(never)]
fn each_cell(l: &Layout, occupancy: &[u64], f: &mut dyn FnMut(usize)) {
    each_bit(l, |i| occupancy[i], |row, x| f(x + l.n[0] * row));
}

/// A value of a plane of one or more values per particle, as an image
/// holds it: little-endian.
trait Le: Copy {
    /// The value in the first bytes of `b`.
    fn le(b: &[u8]) -> Self;
    /// Writes the value.
    fn put(self, p: &mut Put<'_>);
}

impl Le for u8 {
    fn le(b: &[u8]) -> u8 {
        b[0]
    }
    fn put(self, p: &mut Put<'_>) {
        p.u8(self);
    }
}

impl Le for u16 {
    fn le(b: &[u8]) -> u16 {
        u16::from_le_bytes([b[0], b[1]])
    }
    fn put(self, p: &mut Put<'_>) {
        p.bytes(&self.to_le_bytes());
    }
}

impl Le for u32 {
    fn le(b: &[u8]) -> u32 {
        le_u32(b, 0)
    }
    fn put(self, p: &mut Put<'_>) {
        p.u32(self);
    }
}

/// Writes the world's plane `plane` of `per` values a cell as an image
/// holds it: the values of the cells set in the occupancy plane
/// `occupancy` of a world planned as `l`, in cell order. An empty plane
/// (one the world does not keep) writes nothing. Out of line: one copy
/// for every plane of a width.
#[inline(never)]
fn gather<T: Le>(p: &mut Put<'_>, l: &Layout, occupancy: &[u64], plane: &[T], per: usize) {
    if plane.is_empty() {
        return;
    }
    each_cell(l, occupancy, &mut |cell| {
        for k in 0..per {
            plane[cell * per + k].put(p);
        }
    });
}

/// Writes a plane of an image of `per` values a particle, `from`, into the
/// world's plane `to`: the particles' values in cell order, each where the
/// occupancy plane `occupancy` of a world planned as `l` has it. A plane
/// the image does not hold is empty there, and writes nothing. Out of
/// line: one copy for every plane of a width.
#[inline(never)]
fn scatter<T: Le>(l: &Layout, occupancy: &[u64], from: &[u8], per: usize, to: &mut [T]) {
    let mut from = from.chunks_exact(per * size_of::<T>());
    each_cell(l, occupancy, &mut |cell| {
        if let Some(values) = from.next() {
            for (k, b) in values.chunks_exact(size_of::<T>()).enumerate() {
                to[cell * per + k] = T::le(b);
            }
        }
    });
}

/// Bytes of the image of a world described by `d`, planned as `l`, with
/// these counts of particles and used table entries.
/// `emitter` is the bytes of one emitter in the image's version.
fn image_len(d: &Description, l: &Layout, particles: usize, masses: usize, surfaces: usize, (emitters, emitter): (usize, usize)) -> Option<usize> {
    let (width, _) = width_and_scale(d.quantization);
    let ids = d.identity;
    let per_particle = d.dim as usize * width
        + usize::from(d.per_particle_mass)
        + 2 * usize::from(d.lifetimes)
        + 4 * usize::from(ids.ids())
        + 4 * usize::from(ids.ages())
        + usize::from(ids.tags());
    [
        FIXED,
        if turbulent(d) { TURBULENCE } else { 0 },
        body_bytes(d),
        l.occupancy().len,
        l.obstacle().len,
        particles.checked_mul(per_particle)?,
        l.field().len,
        l.potential().len,
        l.wind().len,
        masses.checked_mul(4)?,
        surfaces.checked_mul(SURFACE)?,
        emitters.checked_mul(emitter)?,
        CHECKSUM,
    ]
    .iter()
    .try_fold(0usize, |sum, &n| sum.checked_add(n))
}

fn put_desc(p: &mut Put<'_>, d: &Description) {
    // Taken apart whole, so that a field added to Description does not
    // compile here until the image holds it (under a new IMAGE_VERSION).
    let Description {
        dim,
        size,
        boundary,
        mass,
        per_particle_mass,
        mass_classes,
        obstacles,
        surface_capacity,
        // In the bodies' head of version 3 (M13).
        body_capacity: _,
        body_surface_capacity: _,
        forces,
        gravity,
        vortex,
        restitution,
        wall_restitution,
        dt,
        seed,
        quantization,
        drift,
        method,
        collisions,
        contacts,
        rest,
        energy_neutral,
        drag,
        emitter_capacity,
        lifetimes,
        identity,
    } = *d;
    let Forces { uniform, field, potential, vortex: swirl } = forces;
    let Vortex { centre, core_radius, circulation } = vortex;
    // The turbulence, where on, is written in its own section (`save`).
    let Drag { rate, wind, field: wind_plane, vortex: flow, turbulence: _ } = drag;
    p.u32(dim);
    size.iter().for_each(|&s| p.u32(s));
    p.u64(seed);
    boundary.iter().flatten().for_each(|&b| p.u8(b as u8));
    p.u8(quantization as u8);
    p.u8(drift as u8);
    p.u8(method as u8);
    p.u8(collisions as u8);
    for on in [per_particle_mass, obstacles, lifetimes, contacts, uniform, field, potential, swirl] {
        p.u8(u8::from(on));
    }
    p.u8(u8::from(energy_neutral));
    p.u8(u8::from(flow));
    p.f32(mass);
    p.u32(u32::from(mass_classes));
    p.u32(surface_capacity);
    p.u32(emitter_capacity);
    gravity.iter().for_each(|&g| p.f32(g));
    centre.iter().for_each(|&c| p.f32(c));
    p.f32(core_radius);
    p.f32(circulation);
    p.f32(restitution);
    p.f32(wall_restitution);
    p.f32(dt);
    p.f32(rate);
    wind.iter().for_each(|&w| p.f32(w));
    // The first of what were four reserved zero bytes: an image of a world
    // without a wind plane is the one an older library wrote, and an older
    // library refuses an image with one.
    p.u8(u8::from(wind_plane));
    // The second, likewise: the identity planes (M6b), a bit each.
    p.u8(identity.bits() as u8);
    // The third, likewise: resting contact (M5.7b).
    p.u8(u8::from(rest));
    // The fourth, likewise: the turbulence's settings follow the
    // description (M5.1c).
    p.u8(u8::from(turbulent(d)));
}

/// The description, and whether the turbulence's settings follow it
/// (which the description then lacks).
fn get_desc(g: &mut Get<'_>) -> Result<(Description, bool), Error> {
    let bad = invalid(c"desc (a value)");
    // Taken whole, then read from the copy: every read below is at an
    // offset known when compiled, so none needs a check of its own.
    let fixed: [u8; DESC] = g.array()?;
    let g = &mut Get { rest: &fixed };
    let dim = g.u32()?;
    let size = [g.u32()?, g.u32()?, g.u32()?];
    let seed = g.u64()?;
    let faces: [u8; 6] = g.array()?;
    let mut boundary = [[Boundary::Periodic; 2]; 3];
    for (face, &b) in boundary.iter_mut().flatten().zip(&faces) {
        *face = match b {
            0 => Boundary::Periodic,
            1 => Boundary::Wall,
            2 => Boundary::Open,
            _ => return Err(bad),
        };
    }
    let quantization = match g.u8()? {
        8 => Quantization::Bits8,
        16 => Quantization::Bits16,
        _ => return Err(bad),
    };
    // The flags, and the enumerations of two values, are converted as
    // read and checked together at the end: valid when none is above 1,
    // that is when they or'ed together are at most 1 (as `mpca_desc`'s
    // conversion in the C library checks its own).
    let mut ones = 0;
    let mut one = |v: u8| {
        ones |= v;
        v & 1 != 0
    };
    let drift = if one(g.u8()?) { Drift::Calibrated } else { Drift::Paper };
    let method = match g.u8()? {
        0 => Method::Exhaustive,
        1 => Method::ExactFast,
        2 => Method::Greedy,
        _ => return Err(bad),
    };
    let collisions = if one(g.u8()?) { Collisions::SpeedLimited } else { Collisions::Paper };
    let flags: [u8; 10] = g.array()?;
    let [per_particle_mass, obstacles, lifetimes, contacts, uniform, field, potential, vortex, energy_neutral, flow] = flags.map(&mut one);
    let forces = Forces { uniform, field, potential, vortex };
    let mass = g.f32()?;
    // The description keeps 16 bits (no world has more): an image with
    // more is refused, not read back changed.
    let mass_classes = u16::try_from(g.u32()?).map_err(|_| invalid(c"desc.mass_classes"))?;
    let (surface_capacity, emitter_capacity) = (g.u32()?, g.u32()?);
    let gravity = [g.f32()?, g.f32()?, g.f32()?];
    let vortex = Vortex { centre: [g.f32()?, g.f32()?], core_radius: g.f32()?, circulation: g.f32()? };
    let (restitution, wall_restitution, dt) = (g.f32()?, g.f32()?, g.f32()?);
    let (rate, wind) = (g.f32()?, [g.f32()?, g.f32()?, g.f32()?]);
    // The turbulence, where on, is read from its section after this.
    let drag = Drag { rate, wind, field: one(g.u8()?), vortex: flow, turbulence: Turbulence::OFF };
    let identity = Identity::from_bits(u32::from(g.u8()?)).ok_or(bad)?;
    let rest = one(g.u8()?);
    let turbulence = one(g.u8()?);
    if ones > 1 {
        return Err(invalid(c"desc (a flag)"));
    }
    let desc = Description {
        dim,
        size,
        boundary,
        mass,
        per_particle_mass,
        mass_classes,
        obstacles,
        surface_capacity,
        body_capacity: 0,
        body_surface_capacity: 0,
        forces,
        gravity,
        vortex,
        restitution,
        wall_restitution,
        dt,
        seed,
        quantization,
        drift,
        method,
        collisions,
        contacts,
        rest,
        energy_neutral,
        drag,
        emitter_capacity,
        lifetimes,
        identity,
    };
    Ok((desc, turbulence))
}

fn put_surface(p: &mut Put<'_>, s: &Surface) {
    p.u32(s.cell);
    s.normal.iter().for_each(|&c| p.f32(c));
    p.f32(s.restitution);
    p.u32(s.from_mask);
}

fn get_surface(b: &[u8]) -> Surface {
    let b = first::<SURFACE>(b);
    let f = |i| f32::from_bits(le_u32(b, i));
    Surface { cell: le_u32(b, 0), normal: [f(1), f(2), f(3)], restitution: f(4), from_mask: le_u32(b, 5) }
}

fn put_slot(p: &mut Put<'_>, s: &Slot) {
    let e = &s.emitter;
    e.min.iter().chain(&e.max).for_each(|&c| p.u32(c));
    p.f32(e.rate);
    e.velocity.iter().for_each(|&c| p.f32(c));
    p.f32(e.spread);
    p.f32(e.mass);
    p.u32(e.lifetime);
    p.u32(s.class);
    p.u64(s.stats.requested);
    p.u64(s.stats.delivered);
}

/// The emitter of `b`, an image's entry of either version: one of version
/// 1 is shorter, without the counts, which start from zero.
fn get_slot(b: &[u8]) -> Slot {
    // The words and counts as arrays: no index below needs a check.
    let w: [u32; EMITTER_V1 / 4] = core::array::from_fn(|i| le_u32(&b[..EMITTER_V1], i));
    let f = |i: usize| f32::from_bits(w[i]);
    let emitter = Emitter {
        min: [w[0], w[1], w[2]],
        max: [w[3], w[4], w[5]],
        rate: f(6),
        velocity: [f(7), f(8), f(9)],
        spread: f(10),
        mass: f(11),
        lifetime: w[12],
    };
    let counts = &b[EMITTER_V1..];
    let count = |i| if counts.len() == EMITTER - EMITTER_V1 { le_u64(counts, i) } else { 0 };
    Slot { emitter, class: w[13], stats: EmitterStats { requested: count(0), delivered: count(1) } }
}

/// An image checked in full; its planes are still the image's bytes.
struct Image<'a> {
    desc: Description,
    layout: Layout,
    step: u64,
    counters: Counters,
    masses: usize,
    surfaces: usize,
    emitters: usize,
    /// Bytes of one emitter: [`EMITTER`], or [`EMITTER_V1`] in an image
    /// of version 1.
    emitter_len: usize,
    occupancy: &'a [u8],
    obstacle: &'a [u8],
    velocity: &'a [u8],
    mass_index: &'a [u8],
    life: &'a [u8],
    id: &'a [u8],
    // Written into a world only where the build has the planes; without
    // them `read` refuses an image that holds any.
    #[cfg_attr(not(feature = "identity"), allow(dead_code))]
    age: &'a [u8],
    #[cfg_attr(not(feature = "identity"), allow(dead_code))]
    tag: &'a [u8],
    ids_given: u32,
    field: &'a [u8],
    potential: &'a [u8],
    wind: &'a [u8],
    mass_table: &'a [u8],
    surface: &'a [u8],
    emitter: &'a [u8],
    /// M13: the bodies' head, and the body table's slots.
    #[cfg_attr(not(feature = "obstacles"), allow(dead_code))]
    crushed: u64,
    #[cfg_attr(not(feature = "obstacles"), allow(dead_code))]
    redraws: u32,
    #[cfg_attr(not(feature = "obstacles"), allow(dead_code))]
    body: &'a [u8],
}

/// Checks an image in full and returns it, or the first reason it is
/// refused. In this order: the magic (`NotAnImage`), enough bytes for the
/// head (`ImageLength`), the version (`ImageVersion`), the length the head
/// states (`ImageLength`), the checksum (`ImageChecksum`); then the
/// description, which this build may not hold (`Dim3Disabled`,
/// `Q16Disabled`, `FeatureDisabled`, `TooLarge`), and everything else
/// (`ImageInvalid`).
fn read(image: &[u8]) -> Result<Image<'_>, Error> {
    let m = image.len().min(MAGIC.len());
    if image[..m] != MAGIC[..m] {
        return Err(Error::new(ErrorKind::NotAnImage, c"header: magic"));
    }
    if image.len() < HEAD {
        return Err(Error::new(ErrorKind::ImageLength, c"header"));
    }
    let mut g = Get { rest: &image[MAGIC.len()..] };
    let version = g.u32()?;
    let emitter_len = match version {
        1 => EMITTER_V1,
        2 | 3 => EMITTER,
        _ => return Err(Error::new(ErrorKind::ImageVersion, c"header: version")),
    };
    let reserved = g.u32()?;
    if g.u64()? != image.len() as u64 {
        return Err(Error::new(ErrorKind::ImageLength, c"header: length"));
    }
    let (body, sum) = image.split_at(image.len() - CHECKSUM);
    if crc32(body) != le_u32(sum, 0) {
        return Err(Error::new(ErrorKind::ImageChecksum, c"checksum"));
    }
    // From here on the bytes are what the writer wrote; a refusal means the
    // writer was not this library (or a build with other parts).
    if reserved != 0 {
        return Err(invalid(RESERVED));
    }
    if image.len() < FIXED + CHECKSUM {
        return Err(invalid(c"length"));
    }
    let (mut desc, turbulence) = get_desc(&mut g)?;
    if turbulence {
        let section: [u8; TURBULENCE] = g.array()?;
        let g = &mut Get { rest: &section };
        desc.drag.turbulence = Turbulence { amplitude: g.f32()?, scale: g.u32()?, rate: g.f32()? };
        g.zeros(4)?;
        if all_zero(&desc.drag.turbulence) {
            return Err(invalid(c"desc.drag.turbulence (flagged, but all zero)"));
        }
    }
    // M13: version 3 is a world with bodies, and only such a world.
    let (mut crushed, mut redraws) = (0, 0);
    if version == 3 {
        let head: [u8; BODY_HEAD] = g.array()?;
        let g = &mut Get { rest: &head };
        (desc.body_capacity, desc.body_surface_capacity, crushed, redraws) = (g.u32()?, g.u32()?, g.u64()?, g.u32()?);
        g.zeros(4)?;
        if !desc.obstacles || desc.body_capacity == 0 {
            return Err(invalid(c"version 3 without bodies"));
        }
    }
    // A description the world would refuse: the field at fault named.
    let layout = desc.plan().map_err(|e| match e.kind() {
        ErrorKind::Dim3Disabled | ErrorKind::Q16Disabled | ErrorKind::FeatureDisabled | ErrorKind::TooLarge => e,
        _ => invalid(e.c_detail()),
    })?;
    // A 2D world keeps 1 as its third size (World::init).
    if desc.dim == 2 && desc.size[2] != 1 {
        return Err(invalid(c"desc.size[2]"));
    }
    // Read from a copy, as the description is.
    let state: [u8; STATE] = g.array()?;
    let s = &mut Get { rest: &state };
    let step = s.u64()?;
    let [particles, emitted, exited, expired, shortfall, collisions, clamps] =
        [s.u64()?, s.u64()?, s.u64()?, s.u64()?, s.u64()?, s.u64()?, s.u64()?];
    // 16 bytes in the image; the world counts in a u64.
    let clamp_energy = u64::try_from(u128::from_le_bytes(s.array()?)).map_err(|_| invalid(c"clamp energy"))?;
    let [displaced, processed, skipped] = [s.u64()?, s.u64()?, s.u64()?];
    let counters =
        Counters { particles, emitted, exited, expired, shortfall, collisions, clamps, clamp_energy, displaced, processed, skipped };
    let [masses, surfaces, emitters] = [s.u32()?, s.u32()?, s.u32()?].map(|c| c as usize);
    // What was a reserved zero word: a world without ids gives none.
    let ids_given = s.u32()?;
    if !desc.identity.ids() && ids_given != 0 {
        return Err(invalid(c"ids given"));
    }
    let mass_room = if desc.per_particle_mass { 1..=desc.mass_classes as usize } else { 0..=0 };
    if !mass_room.contains(&masses) {
        return Err(invalid(c"mass count"));
    }
    if surfaces > layout.surface().len / size_of::<Surface>() {
        return Err(invalid(c"surface count"));
    }
    if emitters > layout.emitters().len / size_of::<Slot>() {
        return Err(invalid(c"emitter count"));
    }
    if particles > layout.cells as u64 {
        return Err(invalid(c"particle count"));
    }
    if image_len(&desc, &layout, particles as usize, masses, surfaces, (emitters, emitter_len)) != Some(image.len()) {
        return Err(invalid(c"length"));
    }
    let (width, _) = width_and_scale(desc.quantization);
    let n = particles as usize;
    let dim = desc.dim as usize;
    // The parts' lengths in the image's order, taken in one loop.
    let ids = desc.identity;
    let lens = [
        layout.occupancy().len,
        layout.obstacle().len,
        n * dim * width,
        if desc.per_particle_mass { n } else { 0 },
        if desc.lifetimes { 2 * n } else { 0 },
        if ids.ids() { 4 * n } else { 0 },
        if ids.ages() { 4 * n } else { 0 },
        if ids.tags() { n } else { 0 },
        layout.field().len,
        layout.potential().len,
        layout.wind().len,
        4 * masses,
        SURFACE * surfaces,
        emitter_len * emitters,
        body_bytes(&desc).saturating_sub(BODY_HEAD),
    ];
    let mut parts: [&[u8]; 15] = [&[]; 15];
    for (part, &len) in parts.iter_mut().zip(&lens) {
        *part = g.take(len)?;
    }
    let [occupancy, obstacle, velocity, mass_index, life, id, age, tag, field, potential, wind, mass_table, surface, emitter, body] = parts;
    let img = Image {
        desc,
        layout,
        step,
        counters,
        masses,
        surfaces,
        emitters,
        emitter_len,
        occupancy,
        obstacle,
        velocity,
        mass_index,
        life,
        id,
        age,
        tag,
        ids_given,
        field,
        potential,
        wind,
        mass_table,
        surface,
        emitter,
        crushed,
        redraws,
        body,
    };
    check(&img)?;
    Ok(img)
}

/// Whether every value of an image's plane of `f32` is finite. Out of
/// line: one copy for every plane.
#[inline(never)]
fn finite_plane(plane: &[u8]) -> bool {
    plane.chunks_exact(4).all(|b| f32::from_bits(le_u32(b, 0)).is_finite())
}

/// Whether every velocity of an image's plane `velocity` of `dim`
/// components a particle is one the step could have stored (M1). Out of
/// line, the width a value: one loop for both widths.
#[inline(never)]
fn velocities_ok(velocity: &[u8], dim: usize, quantization: Quantization) -> bool {
    let (width, scale) = width_and_scale(quantization);
    velocity.chunks_exact(dim * width).all(|v| {
        let mut q = [0i32; 3];
        for k in 0..dim {
            q[k] = component(&v[k * width..], width);
        }
        q.iter().all(|c| c.abs() <= scale) && storable(q, scale)
    })
}

/// The rules a live world keeps, held against an image's content.
fn check(img: &Image<'_>) -> Result<(), Error> {
    let bad = |detail| Err(invalid(detail));
    let (d, l) = (&img.desc, &img.layout);
    let dim = d.dim as usize;

    // The bit planes: nothing in the padding after a row's last cell, no
    // particle on an obstacle, as many particles as the counter says.
    let tail = if l.n[0] % 64 == 0 { 0 } else { u64::MAX << (l.n[0] % 64) };
    let mut count = 0u64;
    for i in 0..l.occupancy().len / 8 {
        let occ = le_u64(img.occupancy, i);
        let obs = if d.obstacles { le_u64(img.obstacle, i) } else { 0 };
        if i % l.row_words == l.row_words - 1 && (occ | obs) & tail != 0 {
            return bad(c"occupancy: a bit past a row");
        }
        if occ & obs != 0 {
            return bad(c"occupancy: a particle on an obstacle");
        }
        count += u64::from(occ.count_ones());
    }
    if count != img.counters.particles {
        return bad(c"particle count");
    }

    // Velocities the step could have stored (M1), mass classes in use.
    if !velocities_ok(img.velocity, dim, d.quantization) {
        return bad(c"velocities");
    }
    if img.mass_index.iter().any(|&i| usize::from(i) >= img.masses) {
        return bad(c"mass classes");
    }
    // Ids that were given (M6b): from 1 to the count given. (That no two
    // are equal is not checked: it would take memory or time a load does
    // not have.)
    if (0..img.id.len() / 4).any(|i| !(1..=img.ids_given).contains(&le_u32(img.id, i))) {
        return bad(c"ids");
    }

    // Force and wind planes: finite, as the set functions require, and no
    // cell's wind faster than 1.
    let float = |plane: &[u8], i: usize| f32::from_bits(le_u32(plane, i));
    if ![img.field, img.potential, img.wind].into_iter().all(finite_plane) {
        return bad(c"force, potential or wind planes");
    }
    let wind_cell = |i: usize| -> [f32; 3] { core::array::from_fn(|k| if k < dim { float(img.wind, i + k) } else { 0.0 }) };
    // Cell by cell, `dim` values each.
    for c in 0..img.wind.len() / 4 / dim {
        if !crate::api::speed::slow(&wind_cell(c * dim)[..dim]) {
            return bad(c"wind plane");
        }
    }

    // The mass table: distinct valid masses, class 0 the description's.
    let table = |i: usize| f32::from_bits(le_u32(img.mass_table, i));
    for i in 0..img.masses {
        let detail = c"mass table";
        if crate::api::checks::mass(table(i), detail).is_err() || (0..i).any(|j| table(j).to_bits() == table(i).to_bits()) {
            return bad(detail);
        }
    }
    if img.masses > 0 && table(0).to_bits() != d.mass.to_bits() {
        return bad(c"mass table");
    }

    // The surface table: obstacle cells in increasing order, unit normals
    // in the world's plane, restitutions in [0, 1].
    let mut last = None;
    for b in img.surface.chunks_exact(SURFACE) {
        let s = get_surface(b);
        let cell = s.cell as usize;
        if cell >= l.cells || last.is_some_and(|c| c >= s.cell) {
            return bad(c"surface table");
        }
        last = Some(s.cell);
        let (row, x) = (cell / l.n[0], cell % l.n[0]);
        let bit = row * l.row_words * 64 + x;
        if le_u64(img.obstacle, bit / 64) >> (bit % 64) & 1 == 0 {
            return bad(c"surface table");
        }
        // normalise() leaves |N|^2 within a few 1e-7 of 1; NaN is not unit.
        let unit = (crate::rules::vector::dot(s.normal, s.normal) - 1.0).abs() <= 1e-4;
        if !unit || (dim == 2 && s.normal[2] != 0.0) {
            return bad(c"surface table");
        }
        let detail = c"surface table";
        if crate::api::checks::restitution(s.restitution, detail).is_err() || s.from_mask > 1 {
            return bad(detail);
        }
    }

    #[cfg(feature = "obstacles")]
    check_bodies(img)?;

    // Emitters: what add_emitter accepts, stored as it stores them.
    for b in img.emitter.chunks_exact(img.emitter_len) {
        let s = get_slot(b);
        let e = s.emitter;
        // Nothing is placed that was not asked for.
        if s.stats.delivered > s.stats.requested {
            return bad(c"emitter counts");
        }
        let mut stored = e;
        // What add_emitter would refuse, named.
        checked(&mut stored, dim, l.n, d.lifetimes).map_err(|e| invalid(e.c_detail()))?;
        if stored != e {
            return bad(c"emitter table");
        }
        // The word of the mass class and the tag: two zero bytes above, and
        // no tag where the world has none.
        if s.class >> 16 != 0 || (s.tag() != 0 && !d.identity.tags()) {
            return bad(c"emitter table");
        }
        let class = usize::from(s.mass_index());
        let known = if d.per_particle_mass { class < img.masses && table(class).to_bits() == e.mass.to_bits() } else { class == 0 && e.mass.to_bits() == d.mass.to_bits() };
        if !known {
            return bad(c"emitter table");
        }
    }
    Ok(())
}

/// The body table of an image (M13): every slot a body `add_body` could
/// have made, or zeros; no particle in a cell a body covers, and room in
/// the body surface table for the bodies' entries.
#[cfg(feature = "obstacles")]
fn check_bodies(img: &Image<'_>) -> Result<(), Error> {
    let bad = |detail| Err(invalid(detail));
    let (d, l) = (&img.desc, &img.layout);
    let dim = d.dim as usize;
    let slots = img.body.len() / BODY;
    for b in img.body.chunks_exact(BODY) {
        let body = get_body(b);
        let Some(shape) = body.shape() else {
            if b.iter().any(|&x| x != 0) {
                return bad(c"body table");
            }
            continue;
        };
        // As the library stores a body it accepts: the same bits.
        // What add_body would refuse, named.
        let stored = crate::rules::body::Body::new(shape, body.velocity, body.restitution, dim).map_err(|e| invalid(e.c_detail()))?;
        let same = |x: &[f32], y: &[f32]| x.iter().zip(y).all(|(a, b)| a.to_bits() == b.to_bits());
        let fields = |b: &crate::rules::body::Body| [b.a, b.b, b.velocity, [b.radius, b.restitution, 0.0]];
        // The reserved words: after the velocity and after each tally.
        let reserved = [12, 22, 32].iter().any(|&w| le_u32(b, w) != 0);
        if stored.kind != body.kind || !fields(&stored).iter().zip(&fields(&body)).all(|(x, y)| same(x, y)) || reserved {
            return bad(c"body table");
        }
    }
    let obstacle = |c: [usize; 3]| {
        let bit = (c[1] + l.n[1] * c[2]) * l.row_words * 64 + c[0];
        le_u64(img.obstacle, bit / 64) >> (bit % 64) & 1 != 0
    };
    let body = |i: usize| get_body(&img.body[i * BODY..]);
    let frame = crate::api::obstacles::Frame { n: l.n, boundary: d.boundary, dim };
    let draw = crate::api::bodies::Draw { frame, count: slots, body: &body, is_static: &obstacle };
    let mut inside = false;
    each_bit(l, |k| le_u64(img.occupancy, k), |row, x| inside |= draw.owner([x, row % l.n[1], row / l.n[1]]).is_some());
    if inside {
        return bad(c"occupancy: a particle in a body");
    }
    if draw.entries() > d.body_surface_capacity as usize {
        return bad(c"desc.body_surface_capacity");
    }
    Ok(())
}

/// Writes a checked image into `w`, whose plan is the image's. Nothing here
/// can fail.
fn apply(w: &mut World, img: &Image<'_>) {
    let (d, l) = (img.desc, img.layout);
    let dim = d.dim as usize;
    w.head.desc = d;
    w.head.step = img.step;
    w.head.counters = img.counters;
    w.head.masses = img.masses as u32;
    w.head.surfaces = img.surfaces as u32;
    w.head.emitters = img.emitters as u32;
    w.head.ids_given = img.ids_given;
    // The velocities as bytes, written component by component in the
    // world's width (`store`): one copy of this for both widths.
    {
        let p = &mut w.byte_planes().1;
        for (i, word) in p.occupancy.iter_mut().enumerate() {
            *word = le_u64(img.occupancy, i);
        }
        for (i, word) in p.obstacle.iter_mut().enumerate() {
            *word = le_u64(img.obstacle, i);
        }
        // Values in empty cells are never read; zero, so that equal images
        // make equal memory.
        p.velocity.fill(0);
        p.mass_index.fill(0);
        p.life.fill(0);
        #[cfg(feature = "identity")]
        {
            p.id.fill(0);
            p.age.fill(0);
            p.tag.fill(0);
        }
        // The skip summaries (M3), exact: flagged where a particle is,
        // every word holding one.
        p.rows.fill(0);
        p.words.fill(0);
        let (rows, words) = (Cells::new(&mut *p.rows), Cells::new(&mut *p.words));
        for (i, &word) in p.occupancy.iter().enumerate() {
            if word != 0 {
                mark(rows, words, l.summary_words, i / l.row_words, i % l.row_words * 64);
            }
        }
        // Plane by plane, the particles' values in cell order. The
        // velocities as the image holds them: `check` refused any
        // component beyond the width's scale.
        let occupancy = &*p.occupancy;
        if width_and_scale(d.quantization).0 == 1 {
            scatter::<u8>(&l, occupancy, img.velocity, dim, p.velocity);
        } else {
            scatter::<u16>(&l, occupancy, img.velocity, dim, view(p.velocity));
        }
        scatter::<u8>(&l, occupancy, img.mass_index, 1, p.mass_index);
        scatter::<u16>(&l, occupancy, img.life, 1, p.life);
        // M6b: an image with these planes reads only where they are
        // built (`read` refuses others).
        #[cfg(feature = "identity")]
        {
            scatter::<u32>(&l, occupancy, img.id, 1, p.id);
            scatter::<u32>(&l, occupancy, img.age, 1, p.age);
            scatter::<u8>(&l, occupancy, img.tag, 1, p.tag);
        }
        for (plane, bytes) in [(&mut *p.field, img.field), (&mut *p.potential, img.potential), (&mut *p.wind, img.wind)] {
            for (k, f) in plane.iter_mut().enumerate() {
                *f = f32::from_bits(le_u32(bytes, k));
            }
        }
        p.mass_table.fill(0.0);
        for (k, m) in p.mass_table.iter_mut().take(img.masses).enumerate() {
            *m = f32::from_bits(le_u32(img.mass_table, k));
        }
        p.surface.fill(Surface::default());
        for (s, b) in p.surface.iter_mut().zip(img.surface.chunks_exact(SURFACE)) {
            *s = get_surface(b);
        }
        p.emitters.fill(Slot::default());
        for (s, b) in p.emitters.iter_mut().zip(img.emitter.chunks_exact(img.emitter_len)) {
            *s = get_slot(b);
        }
    }
    // M13: the bodies, drawn again over the static obstacles the image
    // holds (the cells and entries they had).
    #[cfg(feature = "obstacles")]
    w.set_bodies(img.crushed, img.redraws, &|i| get_body(&img.body[i * BODY..]));
}

/// Writes a body table slot (M13) as [`BODY`] bytes.
#[cfg(feature = "obstacles")]
fn put_body(p: &mut Put<'_>, b: &crate::rules::body::Body) {
    p.u32(b.kind);
    p.f32(b.restitution);
    b.a.iter().chain(&b.b).for_each(|&c| p.f32(c));
    p.f32(b.radius);
    b.velocity.iter().for_each(|&c| p.f32(c));
    p.u32(0);
    for t in [&b.current, &b.last] {
        t.momentum.iter().for_each(|&m| p.u64(m as u64));
        for c in [t.reflected, t.pushed, t.crushed, 0] {
            p.u32(c);
        }
    }
}

/// Reads a body table slot written by [`put_body`] (its velocity in fine
/// units is the world's to convert).
#[cfg(feature = "obstacles")]
fn get_body(b: &[u8]) -> crate::rules::body::Body {
    use crate::rules::body::{Body, Tally};
    let b = first::<BODY>(b);
    let f = |i| f32::from_bits(le_u32(b, i));
    let tally = |w: usize| Tally {
        momentum: [0, 1, 2].map(|k| le_u64(&b[4 * w..], k) as i64),
        reflected: le_u32(b, w + 6),
        pushed: le_u32(b, w + 7),
        crushed: le_u32(b, w + 8),
        spare: 0,
    };
    Body {
        kind: le_u32(b, 0),
        restitution: f(1),
        a: [f(2), f(3), f(4)],
        b: [f(5), f(6), f(7)],
        radius: f(8),
        velocity: [f(9), f(10), f(11)],
        current: tally(13),
        last: tally(23),
        ..Body::ZERO
    }
}

/// The set bits of `words`: the particles of an occupancy plane. Out of
/// line: on targets without a population count instruction the sum is
/// unrolled into much code, which every caller of
/// [`World::snapshot_bytes`] would hold.
#[inline(never)]
fn ones(words: &[u64]) -> usize {
    words.iter().map(|w| w.count_ones() as usize).sum()
}



/// An `ImageInvalid` naming the part of the image at fault.
fn invalid(detail: &'static CStr) -> Error {
    Error::new(ErrorKind::ImageInvalid, detail)
}

/// The detail of reserved bytes that are not zero.
const RESERVED: &CStr = c"reserved bytes";

/// The part of the plan of memory in which an image's description `image`
/// and a world's `world` differ, for [`World::load`]'s refusal: the sizes,
/// the velocity width, a plane one has and the other not, or a capacity.
#[cold]
#[inline(never)]
fn mismatch(image: &Description, world: &Description) -> &'static CStr {
    let (a, b) = (image, world);
    if a.dim != b.dim || a.size != b.size {
        c"desc.size"
    } else if a.quantization != b.quantization {
        c"desc.quantization"
    } else if a.obstacles != b.obstacles {
        c"desc.obstacles"
    } else if a.per_particle_mass != b.per_particle_mass {
        c"desc.per_particle_mass"
    } else if a.lifetimes != b.lifetimes {
        c"desc.lifetimes"
    } else if a.forces.field != b.forces.field || a.forces.potential != b.forces.potential {
        c"desc.forces"
    } else if a.drag.field != b.drag.field {
        c"desc.drag.field"
    } else if a.identity != b.identity {
        c"desc.identity"
    } else if a.mass_classes != b.mass_classes {
        c"desc.mass_classes"
    } else if a.surface_capacity != b.surface_capacity {
        c"desc.surface_capacity"
    } else if a.emitter_capacity != b.emitter_capacity {
        c"desc.emitter_capacity"
    } else if a.body_capacity != b.body_capacity {
        c"desc.body_capacity"
    } else {
        c"desc.body_surface_capacity"
    }
}

/// The description of the world `image` holds, after checking the whole
/// image as [`World::load`] does. [`crate::world_bytes`] of it is the memory
/// [`World::init_from_image`] needs.
pub fn image_description(image: &[u8]) -> Result<Description, Error> {
    read(image).map(|img| img.desc)
}

impl World {
    /// Bytes of the image [`World::save`] writes now: a fixed head and state,
    /// the occupancy and obstacle bit planes, a few bytes per particle,
    /// the force and wind planes, and the used entries of the tables (M12).
    // Out of line: one copy for the writer and the C library's exports.
    #[inline(never)]
    pub fn snapshot_bytes(&self) -> usize {
        let h = &self.head;
        let occupancy: &[u64] = self.plane(h.layout.occupancy());
        let particles = ones(occupancy);
        image_len(&self.saved_desc(), &h.layout, particles, h.masses as usize, h.surfaces as usize, (h.emitters as usize, EMITTER)).unwrap_or(usize::MAX)
    }

    /// Writes the world's image (M12) to the start of `out` and returns its
    /// length, [`World::snapshot_bytes`]. An `out` shorter than that is
    /// refused with `OutputTooSmall`, and nothing is written.
    pub fn save(&self, out: &mut [u8]) -> Result<usize, Error> {
        let len = self.snapshot_bytes();
        let out = out.get_mut(..len).ok_or(Error::new(ErrorKind::OutputTooSmall, c"out"))?;
        let h = &self.head;
        let l = h.layout;
        let dim = self.dim();
        let mut p = Put { out, at: 0 };
        let bodies = body_bytes(&self.saved_desc()) > 0;
        p.fixed::<HEAD>(|p| {
            p.bytes(&MAGIC);
            p.u32(if bodies { 3 } else { 2 });
            p.u32(0);
            p.u64(len as u64);
        });
        p.fixed::<DESC>(|p| put_desc(p, &h.desc));
        if turbulent(&h.desc) {
            let t = h.desc.drag.turbulence;
            p.fixed::<TURBULENCE>(|p| {
                p.f32(t.amplitude);
                p.u32(t.scale);
                p.f32(t.rate);
                p.u32(0);
            });
        }
        #[cfg(feature = "obstacles")]
        if let Some((crushed, redraws)) = self.body_head() {
            p.fixed::<BODY_HEAD>(|p| {
                p.u32(h.desc.body_capacity);
                p.u32(h.desc.body_surface_capacity);
                p.u64(crushed);
                p.u32(redraws);
                p.u32(0);
            });
        }
        p.fixed::<STATE>(|p| {
            p.u64(h.step);
            let Counters { particles, emitted, exited, expired, shortfall, collisions, clamps, clamp_energy, displaced, processed, skipped } =
                h.counters;
            for c in [particles, emitted, exited, expired, shortfall, collisions, clamps] {
                p.u64(c);
            }
            p.bytes(&u128::from(clamp_energy).to_le_bytes());
            for c in [displaced, processed, skipped] {
                p.u64(c);
            }
            for c in [h.masses, h.surfaces, h.emitters, h.ids_given] {
                p.u32(c);
            }
        });
        let occupancy: &[u64] = self.plane(l.occupancy());
        p.words(occupancy, &[]);
        // The static obstacles: bodies are drawn again from their table
        // when the image is loaded (M13).
        p.words(self.plane(l.obstacle()), self.body_cells());
        // Per particle, in cell order: velocities, mass classes, lifetimes,
        // then ids, ages and tags. The velocities as stored: an 8-bit
        // component is its byte, a 16-bit one its two.
        if width_and_scale(h.desc.quantization).0 == 1 {
            gather::<u8>(&mut p, &l, occupancy, self.plane(l.velocity()), dim);
        } else {
            gather::<u16>(&mut p, &l, occupancy, self.plane(l.velocity()), dim);
        }
        gather::<u8>(&mut p, &l, occupancy, self.plane(l.mass_index()), 1);
        gather::<u16>(&mut p, &l, occupancy, self.plane(l.life()), 1);
        // M6b: ids, ages, tags.
        gather::<u32>(&mut p, &l, occupancy, self.plane(l.id()), 1);
        gather::<u32>(&mut p, &l, occupancy, self.plane(l.age()), 1);
        gather::<u8>(&mut p, &l, occupancy, self.plane(l.tag()), 1);
        for plane in [l.field(), l.potential(), l.wind()] {
            p.f32s(self.plane(plane));
        }
        p.f32s(&self.plane::<f32>(l.mass_table())[..h.masses as usize]);
        self.plane::<Surface>(l.surface())[..h.surfaces as usize].iter().for_each(|s| p.fixed::<SURFACE>(|p| put_surface(p, s)));
        self.plane::<Slot>(l.emitters())[..h.emitters as usize].iter().for_each(|s| p.fixed::<EMITTER>(|p| put_slot(p, s)));
        #[cfg(feature = "obstacles")]
        self.body_table().iter().for_each(|b| p.fixed::<BODY>(|p| put_body(p, b)));
        let crc = crc32(&p.out[..len - CHECKSUM]);
        p.u32(crc);
        debug_assert_eq!(p.at, len);
        Ok(len)
    }

    /// The description as an image keeps it: without body capacities
    /// where the build has no bodies.
    fn saved_desc(&self) -> Description {
        let mut d = self.head.desc;
        if !cfg!(feature = "obstacles") {
            (d.body_capacity, d.body_surface_capacity) = (0, 0);
        }
        d
    }

    /// Makes this world the one `image` holds (M12): its description,
    /// step number, counters, particles, obstacles, force and wind planes
    /// and tables,
    /// so that it hashes equal to the saved world and steps on exactly as
    /// that world would have.
    ///
    /// This world must have the image's plan of memory: the same sizes,
    /// velocity width and parts (obstacles, per-particle masses, lifetimes,
    /// force field, potential, wind plane) and the same capacities (mass classes,
    /// surface, emitter, body and body surface tables); anything else is refused with
    /// `ImageMismatch`. What does not change the plan (seed, forces,
    /// restitutions, method, faces...) is taken from the image. A world built
    /// from [`image_description`] always fits.
    ///
    /// The whole image is checked before anything is written, and a refused
    /// image leaves the world as it was: `NotAnImage` (wrong magic),
    /// `ImageLength` (cut short, or bytes after its end), `ImageVersion`,
    /// `ImageChecksum` (damaged), `ImageInvalid` (well framed, but not a
    /// world this library could have written), or the error of a part this
    /// build left out (`Dim3Disabled`, `Q16Disabled`, `FeatureDisabled`).
    pub fn load(&mut self, image: &[u8]) -> Result<(), Error> {
        let img = read(image)?;
        if !img.layout.same(&self.head.layout) {
            return Err(Error::computed(ErrorKind::ImageMismatch, || mismatch(&img.desc, &self.head.desc)));
        }
        apply(self, &img);
        Ok(())
    }

    /// Builds the world `image` holds in `memory`, as [`World::init`]
    /// builds an empty one: `memory` must hold at least
    /// [`crate::world_bytes`] of [`image_description`]. The image is
    /// checked in full before a byte of `memory` is written.
    pub fn init_from_image<'a>(image: &[u8], memory: &'a mut [u8]) -> Result<&'a mut World, Error> {
        let img = read(image)?;
        let world = World::init(&img.desc, memory)?;
        apply(world, &img);
        Ok(world)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc32_is_the_zlib_one() {
        // The check value of the CRC catalogue for CRC-32/ISO-HDLC.
        assert_eq!(crc32(b"123456789"), 0xcbf4_3926);
        assert_eq!(crc32(b""), 0);
    }

    #[test]
    fn the_fixed_part_has_the_sizes_the_format_states() {
        let mut out = [0u8; FIXED];
        let mut p = Put { out: &mut out, at: HEAD };
        put_desc(&mut p, &Description::new_3d(4, 4, 4));
        assert_eq!(p.at, HEAD + DESC);
        assert_eq!(size_of::<Surface>(), SURFACE);
        assert_eq!(size_of::<Slot>(), EMITTER);
        let mut g = Get { rest: &out[HEAD..HEAD + DESC] };
        assert_eq!(get_desc(&mut g), Ok((Description::new_3d(4, 4, 4), false)));
        assert!(g.rest.is_empty());
    }
}
