//! Inputs that must be refused without changing anything (issue #5):
//! non-finite floats everywhere a float is taken, and worlds too large for
//! the target.

mod common;
mod stability;

use common::{cells, memory};
use mpca::{Cell, Description, Emitter, Error, ErrorKind, Quantization, Shape, Vortex, World};
use stability::*;

// ------------------------------------------------------------- non-finite

const NON_FINITE: [f32; 3] = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY];

/// M1, STYLE practice 3: NaN, +inf and -inf are refused with NotFinite in
/// every float input, and a refused call changes nothing. Expected for the
/// description's floats: validate, world_bytes and init say NotFinite and
/// init leaves the memory untouched; for every call taking a float
/// (add_particle velocity, add_particle_with_mass velocity and mass,
/// add_obstacle normal and restitution, every field of every Shape and its
/// restitution, add_obstacle_mask's restitution, set_gravity, set_force_field,
/// set_cell_force, set_potential, set_cell_potential, set_vortex, every float
/// of add_emitter, set_emitter_rate), in 2D and 3D, every component
/// including the third of a 2D world: NotFinite, with state_hash, stats and
/// description as before.
#[test]
fn non_finite_inputs_are_refused_and_change_nothing() {
        let fields = common::description_floats();
    for dim in [2u32, 3] {
        for bad in NON_FINITE {
            for (name, set) in fields {
                let mut d = busy_desc(dim);
                set(&mut d, bad);
                assert_eq!(d.validate().map_err(Error::kind), Err(ErrorKind::NotFinite), "{dim}D description {name} = {bad}");
                assert_eq!(mpca::world_bytes(&d).map_err(Error::kind), Err(ErrorKind::NotFinite), "{dim}D world_bytes {name} = {bad}");
                let mut poison = vec![0xa5u8; 1 << 16];
                assert_eq!(World::init(&d, &mut poison).err().map(Error::kind), Some(ErrorKind::NotFinite), "{dim}D init {name}");
                assert!(poison.iter().all(|&b| b == 0xa5), "{dim}D init {name} wrote memory");
            }
        }
    }

    for dim in [2u32, 3] {
        let desc = busy_desc(dim);
        let mut mem = memory(&desc);
        let world = World::init(&desc, &mut mem).unwrap();
        make_busy(world);
        let before = (world.state_hash(), world.stats(), *world.description());
        let free = cells(&desc).find(|&p| world.cell(p) == Ok(Cell::Empty)).expect("an empty cell");
        let n = cells(&desc).count();
        let d = dim as usize;
        for bad in NON_FINITE {
            let mut calls: Vec<(String, Result<(), Error>)> = vec![];
            for k in 0..3 {
                let mut v = [0.1f32, 0.1, 0.0];
                v[k] = bad;
                calls.push((format!("add_particle v[{k}]"), world.add_particle(free, v)));
                calls.push((format!("add_particle_with_mass v[{k}]"), world.add_particle_with_mass(free, v, 1.0)));
                let mut nrm = [0.0f32, 1.0, 0.0];
                nrm[k] = bad;
                calls.push((format!("add_obstacle normal[{k}]"), world.add_obstacle(free, nrm, 1.0)));
                let mut g = [0.0f32, -0.01, 0.0];
                g[k] = bad;
                calls.push((format!("set_gravity[{k}]"), world.set_gravity(g)));
                calls.push((format!("set_cell_force[{k}]"), world.set_cell_force(free, g)));
                let mut p3 = [4.0f32, 4.0, 4.0];
                p3[k] = bad;
                let shapes = [
                    ("half-space point", Shape::HalfSpace { point: p3, normal: [0.0, 1.0, 0.0] }),
                    ("half-space normal", Shape::HalfSpace { point: [0.0, 1.0, 0.0], normal: g }),
                    ("box min", Shape::Box { min: p3, max: [5.0, 5.0, 5.0] }),
                    ("box max", Shape::Box { min: [3.0, 3.0, 3.0], max: p3.map(|c| if c.is_finite() { c + 1.0 } else { c }) }),
                ];
                for (sname, shape) in shapes {
                    calls.push((format!("add_shape {sname}[{k}]"), world.add_shape(shape, 1.0)));
                }
                if dim == 3 {
                    calls.push((format!("add_shape sphere centre[{k}]"), world.add_shape(Shape::Sphere { centre: p3, radius: 1.0 }, 1.0)));
                } else if k < 2 {
                    let c = [p3[0], p3[1]];
                    calls.push((format!("add_shape disc centre[{k}]"), world.add_shape(Shape::Disc { centre: c, radius: 1.0 }, 1.0)));
                }
                let e = Emitter { min: [0, 0, 0], max: [2, 2, 2], rate: 1.0, velocity: v, mass: 1.0, ..Emitter::default() };
                calls.push((format!("add_emitter velocity[{k}]"), world.add_emitter(e).map(|_| ())));
            }
            let radius_shape = if dim == 3 { Shape::Sphere { centre: [4.0; 3], radius: bad } } else { Shape::Disc { centre: [4.0; 2], radius: bad } };
            calls.push(("add_shape radius".into(), world.add_shape(radius_shape, 1.0)));
            calls.push(("add_particle_with_mass mass".into(), world.add_particle_with_mass(free, [0.0; 3], bad)));
            calls.push(("add_obstacle restitution".into(), world.add_obstacle(free, [0.0, 1.0, 0.0], bad)));
            calls.push(("add_shape restitution".into(), world.add_shape(Shape::Box { min: [3.0; 3], max: [4.0; 3] }, bad)));
            calls.push(("add_obstacle_mask restitution".into(), world.add_obstacle_mask(&vec![0u8; n], bad)));
            for at in [0, n * d / 2, n * d - 1] {
                let mut f = vec![0.0f32; n * d];
                f[at] = bad;
                calls.push((format!("set_force_field[{at}]"), world.set_force_field(&f)));
            }
            for at in [0, n / 2, n - 1] {
                let mut u = vec![0.0f32; n];
                u[at] = bad;
                calls.push((format!("set_potential[{at}]"), world.set_potential(&u)));
            }
            calls.push(("set_cell_potential".into(), world.set_cell_potential(free, bad)));
            let v = Vortex { centre: [4.0, 4.0], core_radius: 1.0, circulation: 0.5 };
            calls.push(("set_vortex centre x".into(), world.set_vortex(Vortex { centre: [bad, 4.0], ..v })));
            calls.push(("set_vortex centre y".into(), world.set_vortex(Vortex { centre: [4.0, bad], ..v })));
            calls.push(("set_vortex core".into(), world.set_vortex(Vortex { core_radius: bad, ..v })));
            calls.push(("set_vortex circulation".into(), world.set_vortex(Vortex { circulation: bad, ..v })));
            let e = Emitter { min: [0, 0, 0], max: [2, 2, 2], rate: 1.0, mass: 1.0, ..Emitter::default() };
            calls.push(("add_emitter rate".into(), world.add_emitter(Emitter { rate: bad, ..e }).map(|_| ())));
            calls.push(("add_emitter spread".into(), world.add_emitter(Emitter { spread: bad, ..e }).map(|_| ())));
            calls.push(("add_emitter mass".into(), world.add_emitter(Emitter { mass: bad, ..e }).map(|_| ())));
            calls.push(("set_emitter_rate".into(), world.set_emitter_rate(0, bad)));
            let mut failures = vec![];
            for (call, result) in calls {
                if result.map_err(Error::kind) != Err(ErrorKind::NotFinite) {
                    failures.push(format!("{call} = {bad}: {result:?}"));
                }
            }
            assert!(failures.is_empty(), "{dim}D: not refused as NotFinite:\n  {}", failures.join("\n  "));
            assert_eq!((world.state_hash(), world.stats(), *world.description()), before, "{dim}D {bad}: a refused call changed the world");
            assert_eq!(world.cell(free), Ok(Cell::Empty), "{dim}D {bad}");
        }
    }
}

// ------------------------------------------------------------- sizes

/// M1/M9: a world whose cell count does not fit the u32 cell index, or
/// whose byte count overflows the target, is refused with TooLarge by
/// validate and world_bytes, and nothing is allocated (only the
/// descriptions are checked here). Expected: TooLarge for 2^32 cells and
/// beyond, in 2D and 3D, with and without every part; the largest world
/// with fewer cells and every part is either refused with TooLarge (when
/// its payload, computed here in u128, exceeds usize) or gets a byte count
/// at least that payload.
#[test]
fn oversized_worlds_are_refused_without_allocating() {
    let every_part = |mut d: Description| {
        d.per_particle_mass = true;
        d.mass_classes = 256;
        d.obstacles = true;
        d.surface_capacity = u32::MAX;
        d.forces = mpca::Forces { uniform: true, field: true, potential: true, vortex: true };
        d.lifetimes = true;
        d.emitter_capacity = u32::MAX;
        d.quantization = Quantization::Bits16;
        d
    };
    let big = u32::MAX - 1; // the largest even size
    let too_many = [
        Description::new_2d(1 << 16, 1 << 16),
        Description::new_2d(1 << 31, 2),
        Description::new_2d(2, 1 << 31),
        Description::new_2d(big, big),
        Description::new_3d(1 << 11, 1 << 11, 1 << 10),
        Description::new_3d(2, 2, 1 << 30),
        Description::new_3d(1 << 22, 1 << 22, 1 << 22),
        Description::new_3d(big, big, big),
    ];
    for d in too_many {
        for desc in [d, every_part(d)] {
            assert_eq!(desc.validate().map_err(Error::kind), Err(ErrorKind::TooLarge), "{:?}", desc.size);
            assert_eq!(mpca::world_bytes(&desc).map_err(Error::kind), Err(ErrorKind::TooLarge), "{:?}", desc.size);
        }
    }
    for d in [Description::new_2d(1 << 16, 1 << 15), Description::new_3d(1 << 11, 1 << 11, 1 << 9)] {
        let desc = every_part(d);
        let cells: u128 = desc.size[..desc.dim as usize].iter().map(|&s| u128::from(s)).product();
        let dim = u128::from(desc.dim);
        // Velocity 2 dim, mass index 1, lifetime 2, field 4 dim, potential
        // 4 bytes per cell, two bit planes; the tables on top.
        let payload = cells * (2 * dim + 1 + 2 + 4 * dim + 4) + 2 * cells / 8
            + u128::from(u32::MAX) * std::mem::size_of::<mpca::Surface>() as u128
            + u128::from(u32::MAX) * std::mem::size_of::<Emitter>() as u128;
        match mpca::world_bytes(&desc) {
            Ok(bytes) => assert!(bytes as u128 >= payload && payload <= usize::MAX as u128, "{bytes} < {payload}"),
            Err(e) => assert!(e == ErrorKind::TooLarge && payload > usize::MAX as u128 / 2, "{e:?} for a payload of {payload}"),
        }
    }
}
