//! Bad descriptions (M1, M4, M9; STYLE.md practice 3): each kind is refused
//! with its own `ErrorKind` by `Description::validate`, `world_bytes` and
//! `World::init`, with a detail that names the field at fault, and
//! `World::init` refuses before touching a byte of the memory it was
//! handed. (Every feature is on in this crate, so `Q16Disabled`,
//! `Dim3Disabled` and `FeatureDisabled` cannot occur here.)

mod common;

use mpca::{Boundary, Description, Error, ErrorKind, World, WORLD_ALIGN};

/// A pattern init must not disturb.
const POISON: u8 = 0xAA;

/// Expects `desc` to be refused with `kind` everywhere, the detail naming
/// `field`, and `World::init` on a poisoned buffer (large enough for any
/// valid world here) to leave it untouched.
fn refused(desc: Description, kind: ErrorKind, field: &str, what: &str) {
    let want = Err((kind, field.to_string()));
    let seen = |r: Result<(), Error>| r.map_err(|e| (e.kind(), e.detail().to_string()));
    assert_eq!(seen(desc.validate()), want, "{what}: validate");
    assert_eq!(seen(mpca::world_bytes(&desc).map(drop)), want, "{what}: world_bytes");
    let mut memory = vec![POISON; 1 << 16];
    assert_eq!(seen(World::init(&desc, &mut memory).map(drop)), want, "{what}: init");
    assert!(memory.iter().all(|&b| b == POISON), "{what}: init wrote to the memory before refusing");
}

fn base() -> Description {
    Description::new_2d(16, 16)
}

/// M1: every size even and at least 2. Expected: a zero size is SizeZero,
/// an odd one SizeOdd, on every used axis, in 2D and 3D; the unused third
/// size of a 2D world is ignored.
#[test]
fn sizes_must_be_even_and_not_zero() {
    refused(Description::new_2d(0, 16), ErrorKind::SizeZero, "desc.size[0]", "2D nx = 0");
    refused(Description::new_2d(16, 0), ErrorKind::SizeZero, "desc.size[1]", "2D ny = 0");
    refused(Description::new_3d(16, 16, 0), ErrorKind::SizeZero, "desc.size[2]", "3D nz = 0");
    refused(Description::new_2d(15, 16), ErrorKind::SizeOdd, "desc.size[0]", "2D nx = 15");
    refused(Description::new_2d(16, 1), ErrorKind::SizeOdd, "desc.size[1]", "2D ny = 1");
    refused(Description::new_3d(16, 16, 3), ErrorKind::SizeOdd, "desc.size[2]", "3D nz = 3");
    refused(Description::new_3d(2, 2, u32::MAX), ErrorKind::SizeOdd, "desc.size[2]", "3D nz = 2^32 - 1");
    let mut d = base();
    d.size[2] = 7;
    assert_eq!(d.validate(), Ok(()), "the third size of a 2D world is unused");
    assert_eq!(Description::new_2d(2, 2).validate(), Ok(()), "the smallest world is one block");
}

/// Sizes whose cell count or byte count overflows are refused with
/// TooLarge, never wrapped around. Expected: 2^31 x 2^31 (2^62 cells, past
/// the u32 cell indices), 2^16 x 2^16 (2^32 cells, one past), and
/// 2^22 x 2^22 x 2^22 (2^66 cells, past usize) are TooLarge; one cell
/// fewer than the limit (2^16 x 2^15, 2^31 cells) is accepted by
/// world_bytes, which reports more than 2^31 bytes without overflowing.
#[test]
fn oversized_worlds_are_refused() {
    refused(Description::new_2d(1 << 31, 1 << 31), ErrorKind::TooLarge, "desc.size", "2^31 x 2^31");
    refused(Description::new_2d(1 << 16, 1 << 16), ErrorKind::TooLarge, "desc.size", "2^16 x 2^16");
    refused(Description::new_3d(1 << 22, 1 << 22, 1 << 22), ErrorKind::TooLarge, "desc.size", "2^22 cubed");
    refused(Description::new_3d(1 << 11, 1 << 11, 1 << 11), ErrorKind::TooLarge, "desc.size", "2^33 cells in 3D");
    // A capacity that alone overflows the bytes of its table is named.
    let mut d = base();
    d.emitter_capacity = u32::MAX;
    if usize::BITS == 32 {
        refused(d, ErrorKind::TooLarge, "desc.emitter_capacity", "2^32 - 1 emitters");
    }
    let big = Description::new_2d(1 << 16, 1 << 15);
    let bytes = mpca::world_bytes(&big).unwrap();
    assert!(bytes > 1 << 31, "{bytes}");
    // Not enough memory for it: refused as such, untouched.
    let mut memory = vec![POISON; 4096];
    let e = World::init(&big, &mut memory).err().map(|e| (e.kind(), e.detail()));
    assert_eq!(e, Some((ErrorKind::BufferTooSmall, "memory")));
    assert!(memory.iter().all(|&b| b == POISON));
}

/// Expected: a dimension other than 2 or 3 is BadDimension.
#[test]
fn dimension_is_two_or_three() {
    for dim in [0u32, 1, 4, u32::MAX] {
        let mut d = base();
        d.dim = dim;
        refused(d, ErrorKind::BadDimension, "desc.dim", &format!("dim = {dim}"));
    }
}

/// M4: periodicity joins both faces of an axis. Expected: periodic on one
/// face only, with wall or open on the other, is PeriodicMismatch on every
/// used axis; wall with open is fine.
#[test]
fn periodic_faces_come_in_pairs() {
    for other in [Boundary::Wall, Boundary::Open] {
        for axis in 0..3 {
            for periodic_face in 0..2 {
                let mut d = Description::new_3d(8, 8, 8);
                d.boundary[axis][periodic_face] = Boundary::Periodic;
                d.boundary[axis][1 - periodic_face] = other;
                let field = format!("desc.boundary[{axis}]");
                refused(d, ErrorKind::PeriodicMismatch, &field, &format!("axis {axis} face {periodic_face} with {other:?}"));
            }
        }
    }
    let mut d = base().with_boundary(Boundary::Wall);
    d.boundary[0][1] = Boundary::Open;
    assert_eq!(d.validate(), Ok(()));
}

/// M1: every float the description holds is finite. Expected: NaN, +inf or
/// -inf in the mass, either restitution, dt, any gravity component or any
/// vortex parameter is NotFinite, the detail naming the field (the vortex
/// as a whole: one check takes its four floats).
#[test]
fn floats_must_be_finite() {
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let cases = common::description_floats();
        for (name, set) in cases {
            let mut d = base();
            d.forces.uniform = true;
            set(&mut d, bad);
            let field = match name.split(' ').next().unwrap_or("") {
                "vortex" => "desc.vortex".to_string(),
                first => format!("desc.{first}"),
            };
            refused(d, ErrorKind::NotFinite, &field, &format!("{name} = {bad}"));
        }
    }
    // The drag's floats too, apart from the others.
    let mut d = base();
    d.drag.rate = f32::NAN;
    refused(d, ErrorKind::NotFinite, "desc.drag.rate", "drag rate NaN");
    let mut d = base();
    d.drag.wind[1] = f32::INFINITY;
    refused(d, ErrorKind::NotFinite, "desc.drag.wind", "drag wind inf");
}

/// M1: e in [0, 1], m > 0, dt >= 0, and the vortex core radius > 0 when the
/// vortex is on. Expected: RestitutionRange, MassRange, NegativeDt,
/// BadVortex respectively; the end points 0 and 1 of e are accepted.
#[test]
fn ranges_are_checked() {
    for e in [-0.1f32, 1.0001, 2.0, -f32::MIN_POSITIVE] {
        let mut d = base();
        d.restitution = e;
        refused(d, ErrorKind::RestitutionRange, "desc.restitution", &format!("restitution {e}"));
        let mut d = base();
        d.wall_restitution = e;
        refused(d, ErrorKind::RestitutionRange, "desc.wall_restitution", &format!("wall_restitution {e}"));
    }
    for e in [0.0f32, 1.0] {
        let mut d = base();
        d.restitution = e;
        d.wall_restitution = e;
        assert_eq!(d.validate(), Ok(()), "e = {e}");
    }
    for m in [0.0f32, -0.0, -1.0] {
        let mut d = base();
        d.mass = m;
        refused(d, ErrorKind::MassRange, "desc.mass", &format!("mass {m}"));
    }
    for dt in [-1.0f32, -f32::MIN_POSITIVE] {
        let mut d = base();
        d.dt = dt;
        refused(d, ErrorKind::NegativeDt, "desc.dt", &format!("dt {dt}"));
    }
    let mut d = base();
    d.dt = 0.0;
    assert_eq!(d.validate(), Ok(()), "dt = 0 is allowed");
    for r in [0.0f32, -1.0] {
        let mut d = base();
        d.forces.vortex = true;
        d.vortex.core_radius = r;
        refused(d, ErrorKind::BadVortex, "desc.vortex.core_radius", &format!("core radius {r}"));
    }
    // The drag reads the vortex as a flow too.
    let mut d = base();
    d.drag = mpca::Drag { rate: 0.1, vortex: true, ..d.drag };
    d.vortex.core_radius = 0.0;
    refused(d, ErrorKind::BadVortex, "desc.vortex.core_radius", "drag vortex, core radius 0");
    let mut d = base();
    d.drag.rate = -0.5;
    refused(d, ErrorKind::BadDrag, "desc.drag.rate", "drag rate -0.5");
    let mut d = base();
    d.drag.wind = [0.8, 0.8, 0.0];
    refused(d, ErrorKind::SpeedRange, "desc.drag.wind", "drag wind 1.13");
}

/// M9: the mass table holds 1 to 256 classes (a one-byte index). Expected:
/// 0 and 257 classes are CapacityRange with per-particle masses; 1 and 256
/// are accepted; the count is ignored without per-particle masses.
#[test]
fn mass_classes_in_range() {
    for classes in [0u16, 257, u16::MAX] {
        let mut d = base();
        d.per_particle_mass = true;
        d.mass_classes = classes;
        refused(d, ErrorKind::CapacityRange, "desc.mass_classes", &format!("{classes} mass classes"));
    }
    for classes in [1u16, 256] {
        let mut d = base();
        d.per_particle_mass = true;
        d.mass_classes = classes;
        assert_eq!(d.validate(), Ok(()));
    }
    let mut d = base();
    d.mass_classes = 0;
    assert_eq!(d.validate(), Ok(()));
}

/// The memory must hold world_bytes, which includes the slack to align the
/// world at any address. Expected, for every misalignment of the buffer:
/// exactly world_bytes bytes suffice; the exact need (world_bytes minus the
/// unused slack) suffices and one byte less is BufferTooSmall, with the
/// memory untouched.
#[test]
fn buffer_must_be_large_enough() {
    let mut desc = Description::new_3d(8, 8, 8);
    desc.obstacles = true;
    desc.surface_capacity = 10;
    desc.lifetimes = true;
    let bytes = mpca::world_bytes(&desc).unwrap();
    let mut backing = vec![POISON; bytes + 2 * WORLD_ALIGN];
    for shift in 0..WORLD_ALIGN {
        let slice = &mut backing[shift..shift + bytes];
        assert!(World::init(&desc, slice).is_ok(), "world_bytes at offset {shift}");
    }
    for shift in 0..WORLD_ALIGN {
        backing.fill(POISON);
        let base = &mut backing[shift..];
        let pad = (base.as_ptr() as usize).wrapping_neg() & (WORLD_ALIGN - 1);
        let need = bytes - (WORLD_ALIGN - 1) + pad;
        assert_eq!(World::init(&desc, &mut base[..need - 1]).err().map(Error::kind), Some(ErrorKind::BufferTooSmall), "offset {shift}");
        assert!(backing.iter().all(|&b| b == POISON), "offset {shift}: touched");
        assert!(World::init(&desc, &mut backing[shift..shift + need]).is_ok(), "offset {shift}: need {need}");
    }
    let mut empty: [u8; 0] = [];
    assert_eq!(World::init(&desc, &mut empty).err().map(Error::kind), Some(ErrorKind::BufferTooSmall));
}

/// Every refusal above has its own message (Display). Expected: the
/// messages of the description errors are distinct and not empty.
#[test]
fn errors_have_distinct_messages() {
    let errors = [
        ErrorKind::BadDimension,
        ErrorKind::SizeZero,
        ErrorKind::SizeOdd,
        ErrorKind::TooLarge,
        ErrorKind::PeriodicMismatch,
        ErrorKind::NotFinite,
        ErrorKind::NegativeDt,
        ErrorKind::BadVortex,
        ErrorKind::RestitutionRange,
        ErrorKind::MassRange,
        ErrorKind::CapacityRange,
        ErrorKind::BufferTooSmall,
    ];
    let messages: Vec<String> = errors.iter().map(|e| e.to_string()).collect();
    for (i, m) in messages.iter().enumerate() {
        assert!(!m.is_empty());
        assert!(!messages[..i].contains(m), "{m} repeated");
    }
}

/// A refused call after init changes nothing (error.rs: "Nothing was
/// changed"). Expected: each bad call returns its own error and the state
/// hash, the statistics and the cell it aimed at are as before.
#[test]
fn refused_calls_change_nothing() {
    let mut desc = Description::new_2d(16, 16);
    desc.emitter_capacity = 1;
    let mut mem = common::memory(&desc);
    let world = World::init(&desc, &mut mem).unwrap();
    world.add_particle([1, 1, 0], [0.5, 0.0, 0.0]).unwrap();
    world.step(3);
    let (hash, stats) = (world.state_hash(), world.stats());
    let at = world.particles().next().unwrap().pos;
    // Each refusal's kind, and the detail naming the argument or field.
    let seen = |r: Result<(), Error>| r.map_err(|e| (e.kind(), e.detail()));
    assert_eq!(seen(world.add_particle([16, 0, 0], [0.0; 3])), Err((ErrorKind::OutOfBounds, "pos")));
    assert_eq!(seen(world.add_particle(at, [0.0; 3])), Err((ErrorKind::CellOccupied, "pos")));
    assert_eq!(seen(world.add_particle([5, 5, 0], [0.8, 0.8, 0.0])), Err((ErrorKind::SpeedRange, "velocity")));
    assert_eq!(seen(world.add_particle([5, 5, 0], [f32::NAN, 0.0, 0.0])), Err((ErrorKind::NotFinite, "velocity")));
    let one_mass = "mass is not desc.mass (desc.per_particle_mass is off)";
    assert_eq!(seen(world.add_particle_with_mass([5, 5, 0], [0.0; 3], 2.0)), Err((ErrorKind::NotEnabled, one_mass)));
    assert_eq!(seen(world.add_particle_with_mass([5, 5, 0], [0.0; 3], -1.0)), Err((ErrorKind::MassRange, "mass")));
    assert_eq!(seen(world.remove_particle([5, 5, 0]).map(drop)), Err((ErrorKind::NoParticle, "pos")));
    assert_eq!(seen(world.set_gravity([0.0, -1.0, 0.0])), Err((ErrorKind::NotEnabled, "desc.forces.uniform")));
    assert_eq!(seen(world.add_obstacle([5, 5, 0], [0.0, 1.0, 0.0], 1.0)), Err((ErrorKind::NotEnabled, "desc.obstacles")));
    let e = mpca::Emitter { min: [4, 4, 0], max: [4, 6, 1], rate: 1.0, mass: 1.0, ..Default::default() };
    assert_eq!(seen(world.add_emitter(e).map(drop)), Err((ErrorKind::BadEmitter, "emitter.min is not below max")));
    let e = mpca::Emitter { max: [6, 6, 1], velocity: [0.9, 0.0, 0.0], spread: 0.2, ..e };
    assert_eq!(seen(world.add_emitter(e).map(drop)), Err((ErrorKind::SpeedRange, "emitter.velocity and spread")));
    // BadEmitter's other fields, each named.
    let far = mpca::Emitter { min: [4, 4, 0], max: [17, 6, 1], rate: 1.0, mass: 1.0, ..Default::default() };
    assert_eq!(seen(world.add_emitter(far).map(drop)), Err((ErrorKind::BadEmitter, "emitter.max is past the world")));
    let negative = mpca::Emitter { max: [6, 6, 1], rate: -1.0, ..far };
    assert_eq!(seen(world.add_emitter(negative).map(drop)), Err((ErrorKind::BadEmitter, "emitter.rate is negative")));
    let spread = mpca::Emitter { rate: 1.0, spread: -0.1, ..negative };
    assert_eq!(seen(world.add_emitter(spread).map(drop)), Err((ErrorKind::BadEmitter, "emitter.spread is negative")));
    assert_eq!(world.state_hash(), hash);
    assert_eq!(world.stats(), stats);
    assert_eq!(world.cell([5, 5, 0]), Ok(mpca::Cell::Empty));
}

/// M9: planes a scene does not use are not allocated. Expected: each part
/// adds at least its payload (cells times its bytes per cell, plus its
/// table) and at most 8 bytes of alignment more; parts that need no storage
/// (a uniform force, the analytic vortex) and capacities of parts that are
/// off (mass classes without per-particle masses, surfaces without
/// obstacles) add nothing.
#[test]
fn memory_follows_the_scene() {
    for dim in [2u32, 3] {
        let base = if dim == 2 { Description::new_2d(64, 64) } else { Description::new_3d(16, 16, 16) };
        let cells = 4096usize;
        let d = dim as usize;
        let bytes = |desc: &Description| mpca::world_bytes(desc).unwrap();
        let b0 = bytes(&base);
        let adds = |what: &str, change: fn(&mut Description), payload: usize| {
            let mut desc = base;
            change(&mut desc);
            let extra = bytes(&desc) - b0;
            assert!(
                (payload..=payload + 8).contains(&extra),
                "{dim}D {what}: {extra} bytes for a payload of {payload}"
            );
        };
        adds("lifetimes", |d| d.lifetimes = true, 2 * cells);
        adds("16-bit velocities", |d| d.quantization = mpca::Quantization::Bits16, d * cells);
        adds(
            "per-particle masses",
            |d| {
                d.per_particle_mass = true;
                d.mass_classes = 16;
            },
            // The index plane, the table, and the step's conversion of each
            // class (M1c).
            cells + 16 * 4 + 16 * 24,
        );
        adds("force field", |d| d.forces.field = true, 4 * d * cells);
        adds("potential", |d| d.forces.potential = true, 4 * cells);
        adds("uniform force", |d| d.forces.uniform = true, 0);
        adds("vortex", |d| d.forces.vortex = true, 0);
        adds("mass classes, masses off", |d| d.mass_classes = 200, 0);
        adds("surfaces, obstacles off", |d| d.surface_capacity = 1000, 0);
        // Obstacles: a bit per cell (rows padded to 64 bits) and the table.
        let surface = std::mem::size_of::<mpca::Surface>();
        let mut desc = base;
        desc.obstacles = true;
        desc.surface_capacity = 100;
        let rows = (base.size[1] * if dim == 3 { base.size[2] } else { 1 }) as usize;
        let bit_plane = (base.size[0] as usize).div_ceil(64) * 8 * rows;
        let payload = bit_plane + 100 * surface;
        let extra = bytes(&desc) - b0;
        assert!((payload..=payload + 16).contains(&extra), "{dim}D obstacles: {extra} bytes for {payload}");
        // Emitters: at least an Emitter each, linear in the capacity.
        let per = |cap: u32| {
            let mut desc = base;
            desc.emitter_capacity = cap;
            bytes(&desc) - b0
        };
        assert!(per(8) >= 8 * std::mem::size_of::<mpca::Emitter>() && per(16) - per(8) <= per(8) + 8);
    }
}

/// M1: the paper spent 25 bytes per cell in 2D and 33 in 3D, the ceiling.
/// Expected: each of the paper's scenes stays below it; the aggregation
/// scene, which uses nothing but 8-bit velocities, needs 2 bytes of
/// velocity and 1/8 of occupancy per cell plus a header far below 2 KiB
/// (1/8 byte per cell of its 16384): under 2.25 bytes per cell.
#[test]
fn paper_scenes_stay_under_the_papers_memory() {
    for scene in mpca_tests::scenes::paper_scenes() {
        let mut memory = vec![];
        let world = mpca_tests::scenes::build(&scene, &mut memory).unwrap();
        let per_cell = world.bytes_per_cell();
        let ceiling = if scene.desc.dim == 2 { 25.0 } else { 33.0 };
        assert!(per_cell < ceiling, "{}: {per_cell} bytes per cell", scene.name);
        assert_eq!(world.stats().bytes_per_cell, per_cell);
        if scene.name == "aggregation" {
            assert!(per_cell < 2.25, "aggregation: {per_cell} bytes per cell");
        }
    }
}

/// A world handed out as an address (the C boundary's handle) is checked
/// by its tag. Expected: the address `as_ptr` gives comes back as the same
/// world; after `retire` it is NotAWorld; so are null, a misaligned
/// address, zeroed memory, and a byte-for-byte copy of a live world at
/// another address (the tag includes the address, so copies are forgeries).
#[test]
fn world_handles_are_checked() {
    let desc = Description::new_2d(16, 16);
    let bytes = mpca::world_bytes(&desc).unwrap();
    let mut memory = vec![0u64; bytes / 8 + 2];
    let mut copy = vec![0u64; bytes / 8 + 2];
    let ptr = {
        // SAFETY: viewing the u64 buffer as bytes; u8 has no alignment.
        let raw = unsafe { std::slice::from_raw_parts_mut(memory.as_mut_ptr().cast::<u8>(), memory.len() * 8) };
        let world = World::init(&desc, raw).unwrap();
        world.add_particle([3, 4, 0], [0.5, -0.25, 0.0]).unwrap();
        world.step(5);
        world.as_ptr()
    };
    let offset = ptr as usize - memory.as_ptr() as usize;
    // SAFETY: `ptr` came from as_ptr of a world whose borrow has ended; the
    // buffer outlives every use below and nothing else aliases it.
    let world = unsafe { World::from_ptr(ptr) }.unwrap();
    assert_eq!(world.particle_count(), 1);
    let hash = world.state_hash();
    assert_eq!(world.stats().step, 5);

    // A copy at another address carries a tag for the original address.
    // SAFETY: both buffers have the same length; they do not overlap.
    unsafe { std::ptr::copy_nonoverlapping(memory.as_ptr(), copy.as_mut_ptr(), memory.len()) };
    let forged = unsafe { copy.as_mut_ptr().cast::<u8>().add(offset) };
    // SAFETY: aligned (same offset in an 8-aligned buffer) and readable.
    assert_eq!(unsafe { World::from_ptr(forged) }.err().map(Error::kind), Some(ErrorKind::NotAWorld));
    assert_eq!(unsafe { World::from_ptr(std::ptr::null_mut()) }.err().map(Error::kind), Some(ErrorKind::NotAWorld));
    assert_eq!(unsafe { World::from_ptr(ptr.add(1)) }.err().map(Error::kind), Some(ErrorKind::NotAWorld));
    let mut zeros = vec![0u64; 64];
    assert_eq!(unsafe { World::from_ptr(zeros.as_mut_ptr().cast()) }.err().map(Error::kind), Some(ErrorKind::NotAWorld));

    // SAFETY: as above.
    let world = unsafe { World::from_ptr(ptr) }.unwrap();
    assert_eq!(world.state_hash(), hash, "the failed look-ups changed nothing");
    world.retire();
    assert_eq!(unsafe { World::from_ptr(ptr) }.err().map(Error::kind), Some(ErrorKind::NotAWorld));
}
