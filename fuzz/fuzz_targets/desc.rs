//! Description validation, by both doors: the input's first bytes as a
//! C `mpca_desc` (any field any value), and the same bytes read into the
//! core's `Description`, each field brought near its range so validation
//! runs deep. Checked: nothing panics; the C door refuses exactly what the
//! core refuses, with the status of the core's error; a world whose
//! description is accepted is built, in library and in caller memory at
//! any alignment, reports the description back, takes particles and
//! steps; too small a memory is refused and left unwritten.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mpca::{Boundary, Collisions, Description, Drift, Method, Quantization};
use mpca_ffi::{mpca_desc, mpca_status};
use mpca_fuzz::{read_desc, validate, world_bytes, Input, World};

/// Worlds larger than this are validated but not built.
const MAX_BYTES: usize = 1 << 20;

/// The same fields, as the core's description: enumerations and flags
/// taken modulo their range, sizes and capacities kept small.
fn core_desc(c: &mpca_desc) -> Description {
    let mut d = if c.dim % 2 == 1 { Description::new_3d(1, 1, 1) } else { Description::new_2d(1, 1) };
    // Now and then an impossible dimension.
    d.dim = if c.dim % 97 == 5 { c.dim } else { d.dim };
    d.seed = c.seed;
    d.size = c.size.map(|n| if n & 0x8000_0000 != 0 { n } else { n % 40 });
    let b = [Boundary::Periodic, Boundary::Wall, Boundary::Open];
    d.boundary = c.boundary.map(|a| a.map(|v| b[v as usize % 3]));
    d.mass = c.mass;
    d.per_particle_mass = c.per_particle_mass & 1 == 1;
    d.mass_classes = (c.mass_classes % 300) as u16;
    d.obstacles = c.obstacles & 1 == 1;
    d.surface_capacity = c.surface_capacity % 100;
    d.body_capacity = c.body_capacity % 5;
    d.body_surface_capacity = c.body_surface_capacity % 100;
    d.forces.uniform = c.forces & 1 != 0;
    d.forces.field = c.forces & 2 != 0;
    d.forces.potential = c.forces & 4 != 0;
    d.forces.vortex = c.forces & 8 != 0;
    d.gravity = c.gravity;
    d.vortex.centre = c.vortex_centre;
    d.vortex.core_radius = c.vortex_core_radius;
    d.vortex.circulation = c.vortex_circulation;
    d.restitution = c.restitution;
    d.wall_restitution = c.wall_restitution;
    d.dt = c.dt;
    d.quantization = if c.quantization & 1 == 1 { Quantization::Bits16 } else { Quantization::Bits8 };
    d.drift = if c.drift & 1 == 1 { Drift::Paper } else { Drift::Calibrated };
    d.method = [Method::Exhaustive, Method::ExactFast, Method::Greedy][c.method as usize % 3];
    d.emitter_capacity = c.emitter_capacity % 10;
    d.lifetimes = c.lifetimes & 1 == 1;
    d.collisions = if c.collisions & 1 == 1 { Collisions::SpeedLimited } else { Collisions::Paper };
    d.contacts = c.contacts & 1 == 1;
    d.rest = c.rest & 1 == 1;
    d.energy_neutral = c.energy_neutral & 1 == 1;
    d.drag.rate = c.drag_rate;
    d.drag.wind = c.drag_wind;
    d.drag.vortex = c.drag_vortex & 1 == 1;
    d.drag.field = c.drag_wind_field & 1 == 1;
    // Now and then a power of two, so that turbulence passes its checks.
    let scale = c.drag_turbulence_scale;
    d.drag.turbulence = mpca::Turbulence {
        amplitude: c.drag_turbulence_amplitude,
        scale: if scale & 3 == 0 { 1 << (scale >> 2) % 12 } else { scale },
        rate: c.drag_turbulence_rate,
    };
    d
}

/// The core's description as C writes it.
fn to_c(d: &Description) -> mpca_desc {
    let mut c = mpca_fuzz::defaults(2, 2, 2, 0);
    c.dim = d.dim;
    c.seed = d.seed;
    c.size = d.size;
    c.boundary = d.boundary.map(|a| a.map(|b| b as u32));
    c.mass = d.mass;
    c.per_particle_mass = u32::from(d.per_particle_mass);
    c.mass_classes = u32::from(d.mass_classes);
    c.obstacles = u32::from(d.obstacles);
    c.surface_capacity = d.surface_capacity;
    c.body_capacity = d.body_capacity;
    c.body_surface_capacity = d.body_surface_capacity;
    let f = d.forces;
    c.forces = u32::from(f.uniform) | u32::from(f.field) << 1 | u32::from(f.potential) << 2 | u32::from(f.vortex) << 3;
    c.gravity = d.gravity;
    c.vortex_centre = d.vortex.centre;
    c.vortex_core_radius = d.vortex.core_radius;
    c.vortex_circulation = d.vortex.circulation;
    c.restitution = d.restitution;
    c.wall_restitution = d.wall_restitution;
    c.dt = d.dt;
    c.quantization = d.quantization as u32;
    c.drift = d.drift as u32;
    c.method = d.method as u32;
    c.emitter_capacity = d.emitter_capacity;
    c.lifetimes = u32::from(d.lifetimes);
    c.collisions = d.collisions as u32;
    c.contacts = u32::from(d.contacts);
    c.rest = u32::from(d.rest);
    c.energy_neutral = u32::from(d.energy_neutral);
    c.drag_rate = d.drag.rate;
    c.drag_wind = d.drag.wind;
    c.drag_vortex = u32::from(d.drag.vortex);
    c.drag_wind_field = u32::from(d.drag.field);
    c.drag_turbulence_amplitude = d.drag.turbulence.amplitude;
    c.drag_turbulence_scale = d.drag.turbulence.scale;
    c.drag_turbulence_rate = d.drag.turbulence.rate;
    c
}

/// The description as the world reports it back: 2D worlds have one layer.
fn as_stored(mut d: mpca_desc) -> mpca_desc {
    if d.dim == 2 {
        d.size[2] = 1;
    }
    d
}

/// Builds the world of an accepted description in both kinds of memory,
/// checks what it reports, adds particles and steps.
fn exercise(d: &mpca_desc, input: &mut Input<'_>) {
    let bytes = world_bytes(d).expect("a valid description has a size");
    if bytes > MAX_BYTES {
        return;
    }
    // mpca_world_bytes counts the worst alignment; at this address the
    // world needs `need`. One byte less is refused without a byte written,
    // and `need` itself is enough.
    let at = input.pick(8);
    let mut memory = vec![0xa5u8; at + bytes];
    let pad = (memory.as_ptr() as usize + at).wrapping_neg() & (mpca::WORLD_ALIGN - 1);
    let need = bytes - (mpca::WORLD_ALIGN - 1) + pad;
    // Shortening and then lengthening within the capacity keeps the buffer
    // where it is.
    memory.truncate(at + need - 1);
    let mut memory = match World::init(d, memory, at) {
        Ok(_) => panic!("mpca_world_init took {} bytes where the world needs {need}", need - 1),
        Err((s, m)) => {
            assert_eq!(s, mpca_status::BufferTooSmall);
            assert!(m.iter().all(|&b| b == 0xa5), "a refused mpca_world_init wrote to the memory");
            m
        }
    };
    memory.push(0xa5);
    let mut owned = World::create(d).expect("create takes a valid description");
    let mut placed = World::init(d, memory, at).map_err(|e| e.0).expect("init takes the memory it needs");
    for w in [&owned, &placed] {
        assert_eq!(as_stored(w.desc()), as_stored(*d), "the world reports another description");
        assert_eq!(w.count(), 0);
    }
    let n = as_stored(*d).size;
    let mut added = 0;
    for _ in 0..input.pick(16) {
        let (pos, v) = (input.position(n), input.vector());
        let a = owned.add_particle(pos, v);
        assert_eq!(a, placed.add_particle(pos, v), "the two worlds disagree");
        added += u64::from(a.is_ok());
    }
    let steps = input.pick(4) as u64;
    owned.step(steps).unwrap();
    placed.step(steps).unwrap();
    assert_eq!(owned.hash(), placed.hash(), "a world in caller memory steps otherwise than one in library memory");
    let s = owned.stats();
    assert_eq!(s.step, steps);
    assert_eq!(s.particles + s.exited + s.expired, added + s.emitted, "particles not accounted for");
    assert_eq!(owned.count() as u64, s.particles);
}

fuzz_target!(|data: &[u8]| {
    let mut input = Input::new(data);
    let mode = input.u8();
    let mut c = read_desc(&mut input);
    if mode & 1 == 0 {
        // Mostly the right size, so the fields behind it are read.
        c.struct_size = size_of::<mpca_desc>() as u32;
    }
    // The C door: anything at all.
    let s = validate(&c);
    match world_bytes(&c) {
        Ok(_) => assert_eq!(s, mpca_status::Ok, "mpca_world_bytes took a description mpca_desc_validate refuses"),
        Err(e) => assert!(s != mpca_status::Ok || e == mpca_status::TooLarge, "mpca_world_bytes refused {e:?} a valid description"),
    }
    if s == mpca_status::Ok {
        exercise(&c, &mut input);
    }

    // The core's door, with the same fields brought near their ranges.
    let d = core_desc(&c);
    let core = d.validate();
    let through_c = validate(&to_c(&d));
    let want = match core {
        Ok(()) => mpca_status::Ok,
        Err(e) => mpca_status::from(e),
    };
    assert_eq!(through_c, want, "the C door and the core disagree on {d:?}");
    if let Ok(bytes) = mpca::world_bytes(&d) {
        assert!(core.is_ok(), "world_bytes took a description validate refuses");
        if bytes <= MAX_BYTES {
            let mut memory = vec![0u8; bytes];
            let w = mpca::World::init(&d, &mut memory).expect("init takes a valid description");
            assert_eq!(w.description().size[..d.dim as usize], d.size[..d.dim as usize]);
            let n = w.description().size;
            for _ in 0..input.pick(8) {
                let _ = w.add_particle(input.position(n), input.vector());
            }
            w.step(1 + input.pick(3) as u64);
            let s = w.stats();
            assert_eq!(s.particles, w.particles().count() as u64);
        }
    }
});
