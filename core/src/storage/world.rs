//! A world in caller memory.
//!
//! [`World`] is an unsized type: a fixed header followed by the planes of
//! [`Layout`], all inside the byte slice the caller handed to
//! [`World::init`]. Being unsized, a `World` can only be reached through a
//! reference into that memory; it cannot be moved or swapped away from its
//! planes.

use core::mem::{align_of, size_of};

use crate::{Error, ErrorKind};
use crate::api::desc::Description;
use crate::rules::emitter::Slot;
use crate::storage::layout::{test_bit, view, view_counted, view_counted_ref, view_ref, Layout, Planes, Site, TOTAL};
use crate::storage::plain::Plain;

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
    pub clamp_energy: u64,
    pub displaced: u64,
    pub processed: u64,
    pub skipped: u64,
}

impl Counters {
    /// Nothing counted.
    pub const ZERO: Counters = Counters {
        particles: 0,
        emitted: 0,
        exited: 0,
        expired: 0,
        shortfall: 0,
        collisions: 0,
        clamps: 0,
        clamp_energy: 0,
        displaced: 0,
        processed: 0,
        skipped: 0,
    };

    /// Adds what a sweep of blocks counts (a task's share of a step). The
    /// running totals saturate: an image (M12) may carry any count.
    pub fn add_step(&mut self, c: &Counters) {
        add(&mut self.exited, c.exited);
        add(&mut self.expired, c.expired);
        add(&mut self.collisions, c.collisions);
        add(&mut self.clamps, c.clamps);
        add(&mut self.clamp_energy, c.clamp_energy);
        add(&mut self.displaced, c.displaced);
        add(&mut self.processed, c.processed);
    }
}

/// `total += more`, saturating. Out of line: one copy for every counter.
#[inline(never)]
fn add(total: &mut u64, more: u64) {
    *total = total.saturating_add(more);
}

/// 2^32, the scale of the clamped-energy accumulator (which saturates at
/// 2^32 energy units).
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
    /// How many ids were given (M6b): the next particle added or emitted
    /// takes this plus 1, and none is left at `u32::MAX`. 0 in a new world
    /// (the zeroed header) and in every world without ids.
    pub ids_given: u32,
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
    let layout = desc.plan()?;
    (align_of::<Header>() - 1 + size_of::<Header>()).checked_add(layout.total).ok_or(Error::new(ErrorKind::TooLarge, TOTAL))
}

/// The alignment a world's memory is rounded up to inside the buffer.
pub const WORLD_ALIGN: usize = align_of::<Header>();

impl World {
    /// Builds an empty world for `desc` in `memory`, which must hold at least
    /// [`world_bytes`] bytes; any alignment is accepted (the world starts at
    /// the first [`WORLD_ALIGN`]-aligned byte). The description is checked in
    /// full before a byte of `memory` is written.
    pub fn init<'a>(desc: &Description, memory: &'a mut [u8]) -> Result<&'a mut World, Error> {
        // Read inside the result: moved out, the layout would be copied
        // once more before its copy into the header.
        let layout = desc.plan();
        let layout = layout.as_ref().map_err(|&e| e)?;
        let pad = (memory.as_ptr() as usize).wrapping_neg() & (WORLD_ALIGN - 1);
        let need = pad.checked_add(size_of::<Header>()).and_then(|n| n.checked_add(layout.total)).ok_or(Error::new(ErrorKind::TooLarge, TOTAL))?;
        if memory.len() < need {
            return Err(Error::new(ErrorKind::BufferTooSmall, c"memory"));
        }
        let region = &mut memory[pad..need];
        // Cleared as 64-bit words, which it is made of: `pad` aligns its
        // start, and the header and every plane are multiples of 8 bytes
        // (`Layout`), so the aligned clear covers it all.
        debug_assert_eq!(region.len() % 8, 0);
        view::<u64>(region).fill(0);
        let base = region.as_mut_ptr();
        let h = base.cast::<Header>();
        // SAFETY: `base` is aligned for Header (pad above) and the region
        // holds size_of::<Header>() + layout.total bytes, borrowed for 'a
        // and all 0. The fields are written in place (a Header built on the
        // stack and copied over would be a `memcpy` of the whole header);
        // those not written (the step, the counters and the table counts)
        // are integers, for which the zero bytes are the value 0. The fat
        // pointer's metadata is the length of the trailing [u8].
        unsafe {
            core::ptr::addr_of_mut!((*h).tag).write(TAG ^ base as u64);
            core::ptr::addr_of_mut!((*h).len).write(layout.total);
            core::ptr::addr_of_mut!((*h).desc).write(*desc);
            core::ptr::addr_of_mut!((*h).layout).write(*layout);
            let world = core::ptr::slice_from_raw_parts_mut(base, layout.total) as *mut World;
            let world = &mut *world;
            if world.head.desc.dim == 2 {
                world.head.desc.size[2] = 1;
            }
            if world.head.desc.has_masses() {
                // Class 0 is the description's mass, for particles added without one.
                world.planes::<i8>().1.mass_table[0] = world.head.desc.mass;
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
        // SAFETY: the caller's promise, passed on.
        Ok(unsafe { &mut *Self::from_ptr_raw(ptr)? })
    }

    /// [`World::from_ptr`] without forming a reference: the caller decides
    /// whether to read only (a shared reference, where other calls may read
    /// the world at the same time, as mpca-ffi lets them) or to write.
    ///
    /// # Safety
    /// As for [`World::from_ptr`], for the header's check; what the caller
    /// then does through the pointer is its own to justify.
    pub unsafe fn from_ptr_raw(ptr: *mut u8) -> Result<*mut World, Error> {
        if ptr.is_null() || (ptr as usize) % WORLD_ALIGN != 0 {
            return Err(Error::new(ErrorKind::NotAWorld, c"world"));
        }
        // SAFETY: the caller promises a readable, aligned header's worth.
        let (tag, len) = unsafe {
            let h = ptr.cast::<Header>();
            (core::ptr::addr_of!((*h).tag).read(), core::ptr::addr_of!((*h).len).read())
        };
        if tag != TAG ^ ptr as u64 {
            return Err(Error::new(ErrorKind::NotAWorld, c"world"));
        }
        // The tag says a world was built here with `len` plane bytes.
        Ok(core::ptr::slice_from_raw_parts_mut(ptr, len) as *mut World)
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

    /// 2 or 3; 2 in a build without `dim3`, whose worlds are all 2D.
    pub(crate) fn dim(&self) -> usize {
        if cfg!(feature = "dim3") { self.head.desc.dim as usize } else { 2 }
    }

    /// The header and every plane, borrowed apart, the velocities as `Q`.
    /// Hosted builds split the memory in one routine for every velocity
    /// type ([`World::split`] with bytes) and view the velocities after;
    /// firmware, which has one width and calls this from few places, splits
    /// in place: a call, and the planes handed back through memory, take
    /// more flash there than the copies.
    #[inline]
    pub(crate) fn planes<Q: Plain>(&mut self) -> (&mut Header, Planes<'_, Q>) {
        if cfg!(feature = "small-step") {
            return self.split::<Q>();
        }
        let (head, p) = self.split::<u8>();
        let planes = Planes {
            occupancy: p.occupancy,
            rows: p.rows,
            words: p.words,
            obstacle: p.obstacle,
            velocity: view(p.velocity),
            mass_index: p.mass_index,
            life: p.life,
            field: p.field,
            potential: p.potential,
            wind: p.wind,
            mass_table: p.mass_table,
            surface: p.surface,
            emitters: p.emitters,
            #[cfg(feature = "identity")]
            id: p.id,
            #[cfg(feature = "identity")]
            age: p.age,
            #[cfg(feature = "identity")]
            tag: p.tag,
            #[cfg(feature = "obstacles")]
            body_cells: p.body_cells,
            #[cfg(feature = "obstacles")]
            bodies: p.bodies,
            #[cfg(feature = "obstacles")]
            body_surface: p.body_surface,
            #[cfg(feature = "obstacles")]
            body_tally: p.body_tally,
        };
        (head, planes)
    }

    /// The planes with the velocities as bytes, as [`World::split`] hands
    /// them back: for the API's calls outside the step, which take them
    /// so. Not through [`World::planes`], whose move of every plane into a
    /// new `Planes` each of its inlined callers would hold; callers borrow
    /// the result where it lies (`&mut self.byte_planes()`) for the same
    /// reason, as taking it apart moves every plane again.
    #[inline]
    pub(crate) fn byte_planes(&mut self) -> (&mut Header, Planes<'_, u8>) {
        self.split::<u8>()
    }

    /// [`World::planes`]' split of the memory.
    #[cfg_attr(not(feature = "small-step"), inline(never))]
    fn split<Q: Plain>(&mut self) -> (&mut Header, Planes<'_, Q>) {
        let l = self.head.layout;
        let mut rest: &mut [u8] = &mut self.mem;
        let mut at = 0usize;
        let mut take = |p: crate::storage::layout::Plane| -> &mut [u8] {
            let r = core::mem::take(&mut rest);
            let (_, r) = r.split_at_mut(p.off - at);
            let (mine, r) = r.split_at_mut(p.len);
            at = p.off + p.len;
            rest = r;
            mine
        };
        // A plane of a part the build leaves out is empty in every layout
        // (`Description::check` refuses a description that would need it): no
        // split, and no code, for it; an empty slice of its own type
        // stands for it.
        let (obstacles, mass, fields) = (cfg!(feature = "obstacles"), cfg!(feature = "mass"), cfg!(feature = "fields"));
        let planes = Planes {
            occupancy: view(take(l.occupancy())),
            rows: take(l.rows()),
            words: view(take(l.words())),
            obstacle: if obstacles { view(take(l.obstacle())) } else { &mut [] },
            velocity: view(take(l.velocity())),
            mass_index: if mass { take(l.mass_index()) } else { &mut [] },
            life: view(take(l.life())),
            field: if fields { view(take(l.field())) } else { &mut [] },
            potential: if fields { view(take(l.potential())) } else { &mut [] },
            wind: if fields { view(take(l.wind())) } else { &mut [] },
            mass_table: if mass { view(take(l.mass_table())) } else { &mut [] },
            surface: if obstacles { view(take(l.surface())) } else { &mut [] },
            emitters: view_counted(take(l.emitters()), self.head.desc.emitter_capacity as usize),
            // M6b's planes lie last (`Layout::of`), and are taken in that
            // order.
            #[cfg(feature = "identity")]
            id: view(take(l.id())),
            #[cfg(feature = "identity")]
            age: view(take(l.age())),
            #[cfg(feature = "identity")]
            tag: take(l.tag()),
            // M13's, after them.
            #[cfg(feature = "obstacles")]
            body_cells: view(take(l.body_cells())),
            #[cfg(feature = "obstacles")]
            bodies: take(l.bodies()),
            #[cfg(feature = "obstacles")]
            body_surface: view(take(l.body_surface())),
            #[cfg(feature = "obstacles")]
            body_tally: view(take(l.body_tally())),
        };
        (&mut self.head, planes)
    }

    pub(crate) fn plane<T: Plain>(&self, p: crate::storage::layout::Plane) -> &[T] {
        view_ref(self.plane_bytes(p))
    }

    /// The bytes of plane `p`: the part of [`World::plane`] that does not
    /// depend on the type, so that it exists once.
    pub(crate) fn plane_bytes(&self, p: crate::storage::layout::Plane) -> &[u8] {
        &self.mem[p.off..p.off + p.len]
    }

    /// The site of `pos`, or `OutOfBounds`.
    pub(crate) fn locate(&self, pos: [u32; 3]) -> Result<Site, Error> {
        let l = self.layout();
        let mut c = [0usize; 3];
        for k in 0..3 {
            let v = pos[k] as usize;
            if v >= l.n[k] {
                return Err(Error::new(ErrorKind::OutOfBounds, c"pos"));
            }
            c[k] = v;
        }
        Ok(l.site(c[0], c[1], c[2]))
    }

    pub(crate) fn occupied(&self, s: Site) -> bool {
        test_bit(self.plane(self.layout().occupancy()), s.bit)
    }

    /// Whether cell `s` is an obstacle: never in a build without obstacles.
    pub(crate) fn is_obstacle(&self, s: Site) -> bool {
        cfg!(feature = "obstacles") && test_bit(self.plane(self.layout().obstacle()), s.bit)
    }

    /// Whether a body covers cell `s` (M13): never without bodies.
    pub(crate) fn is_body(&self, s: Site) -> bool {
        #[cfg(feature = "obstacles")]
        if self.head.desc.has_bodies() {
            return test_bit(self.plane(self.layout().body_cells()), s.bit);
        }
        let _ = s;
        false
    }

    /// Particles bodies crushed (M13): none without bodies.
    pub(crate) fn crushed(&self) -> u64 {
        #[cfg(feature = "obstacles")]
        return self.crushed_count();
        #[cfg(not(feature = "obstacles"))]
        0
    }

    /// The plane of cells bodies cover (M13): empty without bodies.
    pub(crate) fn body_cells(&self) -> &[u64] {
        #[cfg(feature = "obstacles")]
        return self.plane(self.layout().body_cells());
        #[cfg(not(feature = "obstacles"))]
        &[]
    }

    /// Whether cell `s` is a static obstacle (M7), not a body's (M13).
    pub(crate) fn is_static(&self, s: Site) -> bool {
        self.is_obstacle(s) && !self.is_body(s)
    }

    /// The emitter table, as long as its capacity.
    pub(crate) fn slots(&self) -> &[Slot] {
        view_counted_ref(self.plane_bytes(self.layout().emitters()), self.head.desc.emitter_capacity as usize)
    }
}

