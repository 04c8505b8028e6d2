//! M12 snapshots and region counters through the public API.
//!
//! - A world loaded from its image is the saved world: equal state hash and
//!   statistics, the same image when saved again, and the same worlds after
//!   stepping on; for the paper's four scenes and the every-part world
//!   under each assignment method, into fresh memory and into a live world.
//! - Refused images change nothing: every truncation and every single-bit
//!   flip of a small image, dense samples of the large ones, foreign
//!   versions and magics, images re-sealed with a valid checksum around
//!   content no world can hold, and worlds of another plan. After each, the
//!   target's hash, statistics, description and image are what they were.
//! - Region counters against a count of the particles by hand.

use mpca::{
    image_description, world_bytes, Boundary, Collisions, Description, Drag, Emitter, Error, ErrorKind, Forces, Method, Quantization,
    RegionStats, Shape, Stats, Vortex, World, IMAGE_VERSION,
};
use mpca_tests::scenes::{self, paper_scenes};

mod common;
use common::{crc32, reseal};

// Offsets of the documented format (docs/model.md, M12).
const VERSION_AT: usize = 8;
const RESERVED_AT: usize = 12;
const LENGTH_AT: usize = 16;
const DESC_AT: usize = 24;
const STATE_AT: usize = 144;
const PARTICLES_AT: usize = STATE_AT + 8;
const TABLES_AT: usize = STATE_AT + 104;
const PLANES_AT: usize = 264;

fn image(w: &World) -> Vec<u8> {
    let mut out = vec![0u8; w.snapshot_bytes()];
    assert_eq!(w.save(&mut out), Ok(out.len()));
    out
}

fn u32_at(image: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(image[at..at + 4].try_into().unwrap())
}

fn u64_at(image: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(image[at..at + 8].try_into().unwrap())
}

/// What a refused load must leave as it was.
#[derive(Debug, PartialEq)]
struct Fingerprint {
    hash: u64,
    stats: Stats,
    desc: Description,
    image: Vec<u8>,
}

fn fingerprint(w: &World) -> Fingerprint {
    Fingerprint { hash: w.state_hash(), stats: w.stats(), desc: *w.description(), image: image(w) }
}

/// A 2D world of 16 x 16 cells with every part a 2D world can have: 16-bit
/// velocities, per-particle masses, lifetimes, all four force terms,
/// obstacles from a disc and a mask, an emitter, every kind of face.
fn small_desc() -> Description {
    let mut d = Description::new_2d(16, 16);
    d.boundary = [[Boundary::Open; 2], [Boundary::Wall; 2], [Boundary::Periodic; 2]];
    d.per_particle_mass = true;
    d.mass_classes = 4;
    d.obstacles = true;
    d.surface_capacity = 64;
    d.forces = Forces { uniform: true, field: true, potential: true, vortex: true };
    d.gravity = [0.0, -0.01, 0.0];
    d.vortex = Vortex { centre: [8.0, 8.0], core_radius: 3.0, circulation: 0.3 };
    d.quantization = Quantization::Bits16;
    d.lifetimes = true;
    d.emitter_capacity = 2;
    d.restitution = 0.9;
    d.wall_restitution = 0.7;
    d.collisions = Collisions::SpeedLimited;
    d.contacts = true;
    d.seed = 1313;
    d
}

/// The small world with drag towards a wind plane too (M5.1b), and
/// resting contact (M5.7b).
fn windy_desc() -> Description {
    let mut d = small_desc();
    d.drag = Drag { rate: 0.05, wind: [0.0, 0.01, 0.0], field: true, vortex: false, ..Drag::OFF };
    d.rest = true;
    d
}

/// The windy world with turbulence in its flow too (M5.1c).
fn turbulent_desc() -> Description {
    let mut d = windy_desc();
    d.drag.turbulence = mpca::Turbulence { amplitude: 0.2, scale: 8, rate: 0.05 };
    d
}

fn small_world(memory: &mut Vec<u8>, steps: u64) -> &mut World {
    small_world_of(small_desc(), memory, steps)
}

fn small_world_of(d: Description, memory: &mut Vec<u8>, steps: u64) -> &mut World {
    *memory = vec![0u8; world_bytes(&d).unwrap()];
    let w = World::init(&d, memory).unwrap();
    let field: Vec<f32> = (0..256 * 2).map(|i| ((i % 5) as f32 - 2.0) * 0.002).collect();
    w.set_force_field(&field).unwrap();
    let potential: Vec<f32> = (0..256).map(|i| ((i % 16) as f32 - 8.0).abs() * 0.001).collect();
    w.set_potential(&potential).unwrap();
    if d.drag.field {
        let wind: Vec<f32> = (0..256 * 2).map(|i| ((i % 7) as f32 - 3.0) * 0.05).collect();
        w.set_wind_field(&wind).unwrap();
    }
    w.add_shape(Shape::Disc { centre: [5.0, 5.0], radius: 2.0 }, 0.8).unwrap();
    let mut mask = vec![0u8; 256];
    for (x, y) in [(12, 4), (13, 4), (12, 5), (13, 5)] {
        mask[x + 16 * y] = 1;
    }
    w.add_obstacle_mask(&mask, 0.6).unwrap();
    let emitter =
        Emitter { min: [9, 12, 0], max: [13, 14, 1], rate: 0.7, velocity: [0.0, -0.3, 0.0], spread: 0.1, mass: 2.0, lifetime: 30 };
    w.add_emitter(emitter).unwrap();
    let mut i = 7u32;
    for y in 0..16 {
        for x in 0..16 {
            i = i.wrapping_mul(1_103_515_245).wrapping_add(12345);
            if (i >> 16) % 6 == 0 && matches!(w.cell([x, y, 0]), Ok(mpca::Cell::Empty)) {
                let v = [((i >> 8) % 9) as f32 * 0.1 - 0.4, ((i >> 12) % 9) as f32 * 0.1 - 0.4, 0.0];
                w.add_particle_with_mass([x, y, 0], v, [1.0, 0.5, 3.0][(i % 3) as usize]).unwrap();
            }
        }
    }
    w.step(steps);
    w
}

/// Saves `w`, makes two copies (into fresh memory sized from the image, and
/// into a live world of `w`'s description), checks them against `w`, steps
/// all three `more` steps and checks again. Returns the image's length.
fn round_trip(name: &str, w: &mut World, more: u64) -> usize {
    let img = image(w);
    assert!(img.len() <= w.size_in_bytes() + 252, "{name}: {} image bytes for {} world bytes", img.len(), w.size_in_bytes());
    assert_eq!(image_description(&img).as_ref(), Ok(w.description()), "{name}");

    let mut fresh = vec![0u8; world_bytes(&image_description(&img).unwrap()).unwrap()];
    let a = World::init_from_image(&img, &mut fresh).unwrap();
    let mut other = vec![0u8; world_bytes(w.description()).unwrap()];
    let b = World::init(w.description(), &mut other).unwrap();
    b.add_particle([0, 0, 0], [0.1, 0.0, 0.0]).ok(); // something to overwrite
    b.load(&img).unwrap();

    for (how, copy) in [("init_from_image", &*a), ("load", &*b)] {
        assert_eq!(copy.state_hash(), w.state_hash(), "{name} {how}: hash");
        assert_eq!(copy.stats(), w.stats(), "{name} {how}: stats");
        assert_eq!(copy.description(), w.description(), "{name} {how}: description");
        assert!(image(copy) == img, "{name} {how}: saved again, the image differs");
    }
    w.step(more);
    a.step(more);
    b.step(more);
    for (how, copy) in [("init_from_image", &*a), ("load", &*b)] {
        assert_eq!(copy.state_hash(), w.state_hash(), "{name} {how}: hash after {more} more steps");
        assert_eq!(copy.stats(), w.stats(), "{name} {how}: stats after {more} more steps");
    }
    img.len()
}

#[test]
fn paper_scenes_load_bit_identical_and_step_on_alike() {
    let mut memory = Vec::new();
    for scene in paper_scenes() {
        let w = scenes::build(&scene, &mut memory).unwrap();
        w.step(scene.steps / 2);
        let cells: u64 = scene.desc.size.iter().take(scene.desc.dim as usize).map(|&s| u64::from(s)).product();
        let particles = w.particle_count();
        let crc = u32_at(&image(w), w.snapshot_bytes() - 4);
        let bytes = round_trip(scene.name, w, 20);
        // The CRC names the image: equal on every target (M8, M12).
        println!(
            "{}: {particles} particles after {} steps, image {bytes} bytes (crc {crc:08x}), {:.3} bytes per cell (world {:.3})",
            scene.name,
            scene.steps / 2,
            bytes as f64 / cells as f64,
            w.bytes_per_cell()
        );
    }
}

#[test]
fn every_part_worlds_load_bit_identical_and_step_on_alike() {
    let mut memory = Vec::new();
    for method in [Method::Exhaustive, Method::ExactFast, Method::Greedy] {
        let w = scenes::every_part(&mut memory, method);
        w.step(30);
        let crc = u32_at(&image(w), w.snapshot_bytes() - 4);
        let bytes = round_trip(&format!("every-part-{method:?}"), w, 30);
        println!("every-part-{method:?}: image {bytes} bytes (crc {crc:08x}), {:.3} bytes per cell", bytes as f64 / 4096.0);
    }
    let mut memory = Vec::new();
    let w = small_world(&mut memory, 25);
    assert!(w.stats().emitted > 0 && w.stats().collisions > 0, "{:?}", w.stats());
    round_trip("small", w, 40);
    let w = small_world_of(windy_desc(), &mut memory, 25);
    round_trip("small, wind plane", w, 40);
    let w = small_world_of(turbulent_desc(), &mut memory, 25);
    round_trip("small, turbulence", w, 40);
}

/// An image saved from the small world at step 25, and a different world of
/// the same plan to load into: the small world before it stepped.
fn small_image_and_target(memory: &mut Vec<u8>) -> (Vec<u8>, &mut World) {
    let mut source = Vec::new();
    let img = image(small_world(&mut source, 25));
    (img, small_world(memory, 0))
}

#[test]
fn every_truncation_of_a_small_image_is_refused_and_changes_nothing() {
    let mut memory = Vec::new();
    let (img, target) = small_image_and_target(&mut memory);
    let before = fingerprint(target);
    let desc = image_description(&img).unwrap();
    let room = world_bytes(&desc).unwrap();
    println!("small image: {} bytes, every truncation tried", img.len());
    for len in 0..img.len() {
        let cut = &img[..len];
        assert_eq!(target.load(cut).map_err(Error::kind), Err(ErrorKind::ImageLength), "cut to {len}");
        assert_eq!(fingerprint(target), before, "cut to {len}");
        assert_eq!(image_description(cut).map_err(Error::kind), Err(ErrorKind::ImageLength), "cut to {len}");
        let mut fresh = vec![0xa5u8; room];
        assert_eq!(World::init_from_image(cut, &mut fresh).err().map(Error::kind), Some(ErrorKind::ImageLength), "cut to {len}");
        assert!(fresh.iter().all(|&b| b == 0xa5), "cut to {len}: the memory was written");
    }
    // Bytes after the end are refused too.
    let mut longer = img.clone();
    longer.push(0);
    assert_eq!(target.load(&longer).map_err(Error::kind), Err(ErrorKind::ImageLength));
    assert_eq!(fingerprint(target), before);
    // The whole image loads.
    target.load(&img).unwrap();
    assert!(image(target) == img);
}

#[test]
fn truncations_of_the_scene_images_are_refused_and_change_nothing() {
    let mut memory = Vec::new();
    let mut source = Vec::new();
    let mut tried = 0;
    for scene in paper_scenes() {
        let w = scenes::build(&scene, &mut source).unwrap();
        w.step(scene.steps / 4);
        let img = image(w);
        let target = scenes::build(&scene, &mut memory).unwrap();
        let before = fingerprint(target);
        // Every length near the ends, every 61st between.
        let lens = (0..600.min(img.len())).chain((600..img.len()).step_by(61)).chain(img.len().saturating_sub(600)..img.len());
        for len in lens {
            assert_eq!(target.load(&img[..len]).map_err(Error::kind), Err(ErrorKind::ImageLength), "{} cut to {len}", scene.name);
            assert_eq!((target.state_hash(), target.stats()), (before.hash, before.stats), "{} cut to {len}", scene.name);
            tried += 1;
        }
        assert_eq!(fingerprint(target), before, "{}", scene.name);
    }
    println!("scene images: {tried} truncations tried");
}

/// The error a flip of bit `bit` of byte `at` of `img` must give: the
/// framing fields are checked before the checksum, everything else by it;
/// a flipped version the library reads (1 to 3) goes on to the checksum.
fn flip_error(img: &[u8], at: usize, bit: u32) -> ErrorKind {
    match at {
        0..VERSION_AT => ErrorKind::NotAnImage,
        VERSION_AT..RESERVED_AT => {
            let version = u32_at(img, VERSION_AT) ^ 1 << (8 * (at - VERSION_AT) as u32 + bit);
            if (1..=IMAGE_VERSION).contains(&version) { ErrorKind::ImageChecksum } else { ErrorKind::ImageVersion }
        }
        LENGTH_AT..DESC_AT => ErrorKind::ImageLength,
        _ => ErrorKind::ImageChecksum,
    }
}

#[test]
fn every_single_bit_flip_of_a_small_image_is_refused_and_changes_nothing() {
    let mut memory = Vec::new();
    let (img, target) = small_image_and_target(&mut memory);
    let before = fingerprint(target);
    let mut damaged = img.clone();
    for at in 0..img.len() {
        for bit in 0..8 {
            damaged[at] ^= 1 << bit;
            assert_eq!(target.load(&damaged).map_err(Error::kind), Err(flip_error(&img, at, bit)), "byte {at} bit {bit}");
            assert_eq!(fingerprint(target), before, "byte {at} bit {bit}");
            damaged[at] ^= 1 << bit;
        }
    }
    println!("small image: {} single-bit flips refused", img.len() * 8);
}

#[test]
fn bit_flips_in_a_large_image_are_refused() {
    let mut memory = Vec::new();
    let w = scenes::every_part(&mut memory, Method::ExactFast);
    w.step(20);
    let img = image(w);
    let mut other = Vec::new();
    let target = scenes::every_part(&mut other, Method::ExactFast);
    let before = fingerprint(target);
    let mut damaged = img.clone();
    // Every bit of the fixed part and the first planes, of the end, and of
    // 2,000 bytes spread over the rest.
    let spread = (0..2000).map(|i| PLANES_AT + 512 + i * (img.len() - PLANES_AT - 1024) / 2000);
    let bytes: Vec<usize> = (0..PLANES_AT + 512).chain(spread).chain(img.len() - 512..img.len()).collect();
    for &at in &bytes {
        for bit in 0..8 {
            damaged[at] ^= 1 << bit;
            assert_eq!(target.load(&damaged).map_err(Error::kind), Err(flip_error(&img, at, bit)), "byte {at} bit {bit}");
            assert_eq!(target.state_hash(), before.hash, "byte {at} bit {bit}");
            damaged[at] ^= 1 << bit;
        }
    }
    assert_eq!(fingerprint(target), before);
    println!("every-part image: {} bytes, {} single-bit flips refused", img.len(), bytes.len() * 8);
}

#[test]
fn the_image_head_is_little_endian_and_the_checksum_is_crc32() {
    let mut memory = Vec::new();
    let w = small_world(&mut memory, 25);
    let img = image(w);
    assert_eq!(&img[..8], b"MPCASNAP");
    // Version 2: a world without bodies is written as before they existed
    // (version 3 is a world with bodies, M13).
    assert_eq!(u32_at(&img, VERSION_AT), 2);
    assert_eq!(IMAGE_VERSION, 3);
    assert_eq!(u32_at(&img, RESERVED_AT), 0);
    assert_eq!(u64_at(&img, LENGTH_AT), img.len() as u64);
    let n = img.len() - 4;
    assert_eq!(u32_at(&img, n), crc32(&img[..n]));
    // The description: dimension, sizes, seed.
    assert_eq!(u32_at(&img, DESC_AT), 2);
    assert_eq!([u32_at(&img, DESC_AT + 4), u32_at(&img, DESC_AT + 8), u32_at(&img, DESC_AT + 12)], [16, 16, 1]);
    assert_eq!(u64_at(&img, DESC_AT + 16), 1313);
    // The state: step, particles, table counts.
    assert_eq!(u64_at(&img, STATE_AT), 25);
    assert_eq!(u64_at(&img, PARTICLES_AT), w.particle_count());
    assert_eq!(u32_at(&img, TABLES_AT), 4, "mass classes used: 1, the emitter's 2, 0.5 and 3");
    // The occupancy plane: bit x of row y's word is cell (x, y).
    for y in 0..16u32 {
        let word = u64_at(&img, PLANES_AT + 8 * y as usize);
        for x in 0..16u32 {
            let occupied = matches!(w.cell([x, y, 0]), Ok(mpca::Cell::Particle(_)));
            assert_eq!(word >> x & 1 == 1, occupied, "({x}, {y})");
        }
    }
}

/// Where the small world's planes lie in its image.
#[derive(Clone, Copy)]
struct Planes {
    particles: usize,
    occupancy: usize,
    obstacle: usize,
    velocity: usize,
    mass_index: usize,
    life: usize,
    field: usize,
    potential: usize,
    mass_table: usize,
    surface: usize,
    emitter: usize,
}

fn small_planes(img: &[u8]) -> Planes {
    let particles = u64_at(img, PARTICLES_AT) as usize;
    let masses = u32_at(img, TABLES_AT) as usize;
    let surfaces = u32_at(img, TABLES_AT + 4) as usize;
    let occupancy = PLANES_AT;
    let obstacle = occupancy + 16 * 8;
    let velocity = obstacle + 16 * 8;
    let mass_index = velocity + particles * 2 * 2;
    let life = mass_index + particles;
    let field = life + 2 * particles;
    let potential = field + 256 * 2 * 4;
    let mass_table = potential + 256 * 4;
    let surface = mass_table + 4 * masses;
    let emitter = surface + 24 * surfaces;
    assert_eq!(emitter + 72 * u32_at(img, TABLES_AT + 8) as usize + 4, img.len());
    Planes { particles, occupancy, obstacle, velocity, mass_index, life, field, potential, mass_table, surface, emitter }
}

#[test]
fn images_resealed_around_content_no_world_holds_are_refused() {
    let mut memory = Vec::new();
    let (img, target) = small_image_and_target(&mut memory);
    let before = fingerprint(target);
    let p = small_planes(&img);
    assert!(p.particles > 10);
    let occ = move |img: &[u8], y: usize| u64_at(img, p.occupancy + 8 * y);
    let obs = move |img: &[u8], y: usize| u64_at(img, p.obstacle + 8 * y);
    let set_u64 = |img: &mut Vec<u8>, at: usize, v: u64| img[at..at + 8].copy_from_slice(&v.to_le_bytes());
    // A row holding a particle, and one holding an obstacle cell free of particles.
    let row = (0..16).find(|&y| occ(&img, y) != 0).unwrap();
    let obstacle_row = (0..16).find(|&y| obs(&img, y) & !occ(&img, y) != 0).unwrap();

    // Each with the kind and the detail naming the part at fault.
    let cases: Vec<(&str, ErrorKind, &str, Edit)> = vec![
        ("version 4", ErrorKind::ImageVersion, "header: version", Box::new(move |i| set_u32(i, VERSION_AT, 4))),
        ("version 3 without bodies", ErrorKind::ImageInvalid, "clamp energy", Box::new(move |i| set_u32(i, VERSION_AT, 3))),
        ("version 0", ErrorKind::ImageVersion, "header: version", Box::new(move |i| set_u32(i, VERSION_AT, 0))),
        // Version 1's emitters are shorter: these do not add up.
        ("version 1", ErrorKind::ImageInvalid, "length", Box::new(move |i| set_u32(i, VERSION_AT, 1))),
        ("reserved word", ErrorKind::ImageInvalid, "reserved bytes", Box::new(move |i| set_u32(i, RESERVED_AT, 1))),
        ("dimension 4", ErrorKind::ImageInvalid, "desc.dim", Box::new(move |i| set_u32(i, DESC_AT, 4))),
        ("odd size", ErrorKind::ImageInvalid, "desc.size[0]", Box::new(move |i| set_u32(i, DESC_AT + 4, 15))),
        ("boundary 3", ErrorKind::ImageInvalid, "desc (a value)", Box::new(move |i| i[DESC_AT + 24] = 3)),
        ("quantization 12", ErrorKind::ImageInvalid, "desc (a value)", Box::new(move |i| i[DESC_AT + 30] = 12)),
        ("flag 2", ErrorKind::ImageInvalid, "desc (a flag)", Box::new(move |i| i[DESC_AT + 34] = 2)),
        ("reserved description byte", ErrorKind::ImageInvalid, "length", Box::new(move |i| i[DESC_AT + 117] = 1)),
        ("wind-plane flag 2", ErrorKind::ImageInvalid, "desc (a flag)", Box::new(move |i| i[DESC_AT + 116] = 2)),
        ("wind-plane flag without the plane", ErrorKind::ImageInvalid, "length", Box::new(move |i| i[DESC_AT + 116] = 1)),
        ("drag-vortex flag 2", ErrorKind::ImageInvalid, "desc (a flag)", Box::new(move |i| i[DESC_AT + 43] = 2)),
        ("NaN restitution", ErrorKind::ImageInvalid, "desc.restitution", Box::new(move |i| set_u32(i, DESC_AT + 88, f32::NAN.to_bits()))),
        ("particle count + 1", ErrorKind::ImageInvalid, "length", Box::new(move |i| set_u64(i, PARTICLES_AT, p.particles as u64 + 1))),
        ("mass classes used 0", ErrorKind::ImageInvalid, "mass count", Box::new(move |i| set_u32(i, TABLES_AT, 0))),
        ("mass classes used 5 of 4", ErrorKind::ImageInvalid, "mass count", Box::new(move |i| set_u32(i, TABLES_AT, 5))),
        ("particle moved into a row's padding", ErrorKind::ImageInvalid, "occupancy: a bit past a row", Box::new(move |i| {
            let w = occ(i, row);
            set_u64(i, p.occupancy + 8 * row, (w & (w - 1)) | 1 << 40);
        })),
        ("particle moved onto an obstacle", ErrorKind::ImageInvalid, "occupancy: a particle on an obstacle", Box::new(move |i| {
            let w = occ(i, row);
            set_u64(i, p.occupancy + 8 * row, w & (w - 1));
            let free = obs(i, obstacle_row) & !occ(i, obstacle_row);
            let o = occ(i, obstacle_row);
            set_u64(i, p.occupancy + 8 * obstacle_row, o | (free & free.wrapping_neg()));
        })),
        ("velocity -32768", ErrorKind::ImageInvalid, "velocities", Box::new(move |i| i[p.velocity..p.velocity + 2].copy_from_slice(&i16::MIN.to_le_bytes()))),
        ("speed 1.4", ErrorKind::ImageInvalid, "velocities", Box::new(move |i| {
            i[p.velocity..p.velocity + 4].copy_from_slice(&[0xff, 0x7f, 0xff, 0x7f]);
        })),
        ("mass class 4 of 4", ErrorKind::ImageInvalid, "mass classes", Box::new(move |i| i[p.mass_index] = 4)),
        ("infinite force", ErrorKind::ImageInvalid, "force, potential or wind planes", Box::new(move |i| set_u32(i, p.field + 40, f32::INFINITY.to_bits()))),
        ("NaN potential", ErrorKind::ImageInvalid, "force, potential or wind planes", Box::new(move |i| set_u32(i, p.potential + 4, f32::NAN.to_bits()))),
        ("mass 0", ErrorKind::ImageInvalid, "mass table", Box::new(move |i| set_u32(i, p.mass_table + 4, 0))),
        ("mass twice", ErrorKind::ImageInvalid, "mass table", Box::new(move |i| {
            let m = u32_at(i, p.mass_table);
            set_u32(i, p.mass_table + 8, m);
        })),
        ("class 0 not the description's mass", ErrorKind::ImageInvalid, "mass table", Box::new(move |i| set_u32(i, p.mass_table, 7.0f32.to_bits()))),
        ("surfaces out of order", ErrorKind::ImageInvalid, "surface table", Box::new(move |i| {
            let first: Vec<u8> = i[p.surface..p.surface + 24].to_vec();
            i.copy_within(p.surface + 24..p.surface + 48, p.surface);
            i[p.surface + 24..p.surface + 48].copy_from_slice(&first);
        })),
        ("surface on a free cell", ErrorKind::ImageInvalid, "surface table", Box::new(move |i| set_u32(i, p.surface, 0))),
        ("surface normal of length 2", ErrorKind::ImageInvalid, "surface table", Box::new(move |i| {
            for k in 0..2 {
                let c = f32::from_bits(u32_at(i, p.surface + 4 + 4 * k));
                set_u32(i, p.surface + 4 + 4 * k, (2.0 * c).to_bits());
            }
        })),
        ("surface normal with z in 2D", ErrorKind::ImageInvalid, "surface table", Box::new(move |i| set_u32(i, p.surface + 12, 0.5f32.to_bits()))),
        ("surface restitution 2", ErrorKind::ImageInvalid, "surface table", Box::new(move |i| set_u32(i, p.surface + 16, 2.0f32.to_bits()))),
        ("surface mask flag 2", ErrorKind::ImageInvalid, "surface table", Box::new(move |i| set_u32(i, p.surface + 20, 2))),
        ("emitter rate -1", ErrorKind::ImageInvalid, "emitter.rate is negative", Box::new(move |i| set_u32(i, p.emitter + 24, (-1.0f32).to_bits()))),
        ("emitter beyond the world", ErrorKind::ImageInvalid, "emitter.max is past the world", Box::new(move |i| set_u32(i, p.emitter + 12, 17))),
        ("emitter lifetime 70000", ErrorKind::ImageInvalid, "emitter.lifetime", Box::new(move |i| set_u32(i, p.emitter + 48, 70_000))),
        ("emitter mass class not its mass", ErrorKind::ImageInvalid, "emitter table", Box::new(move |i| set_u32(i, p.emitter + 52, 0))),
        // What an emitter placed exceeds what it asked for (the low word
        // of the delivered count, at 64, past the requested's 56).
        ("emitter placed more than it asked for", ErrorKind::ImageInvalid, "emitter counts", Box::new(move |i| set_u32(i, p.emitter + 64, u32::MAX))),
    ];
    assert!(p.life > p.mass_index);
    let n = cases.len();
    let mut misnamed = Vec::new();
    for (what, kind, detail, edit) in cases {
        let mut bad = img.clone();
        edit(&mut bad);
        assert_ne!(bad, img, "{what}: the edit changed nothing");
        reseal(&mut bad);
        let seen = |e: Error| (e.kind(), e.detail());
        let got = target.load(&bad).map_err(seen);
        if got != Err((kind, detail)) {
            misnamed.push(format!("{what}: {got:?}, expected {:?}", (kind, detail)));
        }
        assert_eq!(fingerprint(target), before, "{what}");
        let mut fresh = vec![0x5au8; world_bytes(&small_desc()).unwrap()];
        assert_eq!(World::init_from_image(&bad, &mut fresh).err().map(seen), got.err(), "{what}: as load");
        assert!(fresh.iter().all(|&b| b == 0x5a), "{what}: the memory was written");
    }
    assert!(misnamed.is_empty(), "refused otherwise than expected:\n  {}", misnamed.join("\n  "));
    // A foreign magic needs no new checksum to be refused.
    let mut bad = img.clone();
    bad[..8].copy_from_slice(b"MPCAsnap");
    assert_eq!(target.load(&bad).map_err(Error::kind), Err(ErrorKind::NotAnImage));
    assert_eq!(target.load(b"PK\x03\x04").map_err(Error::kind), Err(ErrorKind::NotAnImage));
    assert_eq!(fingerprint(target), before);
    // The unedited image, resealed, still loads: the cases above failed for their edits.
    let mut same = img.clone();
    reseal(&mut same);
    target.load(&same).unwrap();
    println!("{n} re-sealed images refused");
}

/// An edit of an image's bytes.
type Edit = Box<dyn Fn(&mut Vec<u8>)>;

/// Writes `v` little-endian at `at`.
fn set_u32(img: &mut [u8], at: usize, v: u32) {
    img[at..at + 4].copy_from_slice(&v.to_le_bytes());
}

/// Each edit of `img`, resealed, is refused by `target` as `ImageInvalid`
/// and leaves it as `before`.
fn refused_as_invalid(img: &[u8], target: &mut World, before: &Fingerprint, cases: Vec<(&str, Edit)>) {
    for (what, edit) in cases {
        let mut bad = img.to_vec();
        edit(&mut bad);
        reseal(&mut bad);
        assert_eq!(target.load(&bad).map_err(Error::kind), Err(ErrorKind::ImageInvalid), "{what}");
        assert_eq!(&fingerprint(target), before, "{what}");
    }
}

/// M5.1b's wind plane in an image (M12): after the force planes, `dim`
/// floats a cell, flagged in the description's byte 116. A world without
/// the plane writes the image it wrote before the plane existed (the
/// pinned format test), so the flag set there, a flag of 2, a NaN wind
/// and a cell faster than 1 are refused, and change nothing.
#[test]
fn images_with_a_wind_plane_no_world_could_hold_are_refused() {
    let mut memory = Vec::new();
    let img = image(small_world_of(windy_desc(), &mut memory, 7));
    let mut other = Vec::new();
    let target = small_world_of(windy_desc(), &mut other, 0);
    let before = fingerprint(target);
    let dry = image(small_world_of(small_desc(), &mut Vec::new(), 0));
    let wet = image(small_world_of(windy_desc(), &mut Vec::new(), 0));
    assert_eq!((img[DESC_AT + 116], dry[DESC_AT + 116]), (1, 0));
    // The wind plane lies after the potential, 256 cells of 2 floats,
    // before the mass table and the other tables.
    let tables = 4 * u32_at(&img, TABLES_AT) as usize + 24 * u32_at(&img, TABLES_AT + 4) as usize + 72 * u32_at(&img, TABLES_AT + 8) as usize;
    let wind = img.len() - 4 - tables - 256 * 2 * 4;
    assert_eq!(wet.len() - dry.len(), 256 * 2 * 4, "the plane is what the image gains");
    let cases: Vec<(&str, Edit)> = vec![
        ("wind-plane flag 2", Box::new(|i| i[DESC_AT + 116] = 2)),
        ("NaN wind", Box::new(move |i| set_u32(i, wind + 12, f32::NAN.to_bits()))),
        ("infinite wind", Box::new(move |i| set_u32(i, wind, f32::NEG_INFINITY.to_bits()))),
        ("a cell of speed 1.2", Box::new(move |i| {
            set_u32(i, wind + 8, 0.6f32.to_bits());
            set_u32(i, wind + 12, (-1.04f32).to_bits());
        })),
    ];
    refused_as_invalid(&img, target, &before, cases);
    // Read back as written: a wind of speed exactly within 1 is taken.
    let mut fine = img.clone();
    set_u32(&mut fine, wind + 8, 0.6f32.to_bits());
    set_u32(&mut fine, wind + 12, (-0.79f32).to_bits());
    reseal(&mut fine);
    target.load(&fine).unwrap();
    assert_eq!(image(target), fine);
}

/// M5.1c's settings in an image (M12): 16 bytes after the description
/// (amplitude, scale, rate, a reserved word), flagged in the description's
/// last byte. A world without turbulence writes the image it wrote before
/// (the pinned format test); a flag of 2, a flagged section of zeros, a
/// reserved word set, and settings the description's check refuses are
/// refused, and change nothing.
#[test]
fn images_with_turbulence_no_world_could_hold_are_refused() {
    let mut memory = Vec::new();
    let img = image(small_world_of(turbulent_desc(), &mut memory, 7));
    let mut other = Vec::new();
    let target = small_world_of(turbulent_desc(), &mut other, 0);
    let before = fingerprint(target);
    let calm = image(small_world_of(windy_desc(), &mut Vec::new(), 0));
    let stirred = image(small_world_of(turbulent_desc(), &mut Vec::new(), 0));
    assert_eq!((img[DESC_AT + 119], calm[DESC_AT + 119]), (1, 0));
    assert_eq!(stirred.len() - calm.len(), 16, "the section is what the image gains");
    let at = DESC_AT + 120;
    assert_eq!(f32::from_bits(u32_at(&img, at)), 0.2);
    assert_eq!(u32_at(&img, at + 4), 8);
    assert_eq!(f32::from_bits(u32_at(&img, at + 8)), 0.05);
    let cases: Vec<(&str, Edit)> = vec![
        ("turbulence flag 2", Box::new(|i| i[DESC_AT + 119] = 2)),
        ("a flagged section of zeros", Box::new(move |i| (0..12).for_each(|k| i[at + k] = 0))),
        ("the reserved word", Box::new(move |i| set_u32(i, at + 12, 1))),
        ("NaN amplitude", Box::new(move |i| set_u32(i, at, f32::NAN.to_bits()))),
        ("amplitude 1.5", Box::new(move |i| set_u32(i, at, 1.5f32.to_bits()))),
        ("scale 3", Box::new(move |i| set_u32(i, at + 4, 3))),
        ("rate -0.1", Box::new(move |i| set_u32(i, at + 8, (-0.1f32).to_bits()))),
    ];
    refused_as_invalid(&img, target, &before, cases);
    target.load(&img).unwrap();
    assert_eq!(image(target), img);
}

#[test]
fn a_world_of_another_plan_refuses_the_image_and_one_of_the_same_plan_takes_it_whole() {
    let mut source = Vec::new();
    let img = image(small_world(&mut source, 25));
    type Edit = (&'static str, fn(&mut Description));
    let edits: [Edit; 8] = [
        ("32 x 16", |d| d.size[0] = 32),
        ("16 x 18", |d| d.size[1] = 18),
        ("8-bit velocities", |d| d.quantization = Quantization::Bits8),
        ("no lifetimes", |d| d.lifetimes = false),
        ("another surface capacity", |d| d.surface_capacity = 65),
        ("another emitter capacity", |d| d.emitter_capacity = 1),
        ("no potential", |d| d.forces.potential = false),
        ("3D", |d| {
            d.dim = 3;
            d.size[2] = 2;
        }),
    ];
    for (what, edit) in edits {
        let mut d = small_desc();
        edit(&mut d);
        let mut memory = vec![0u8; world_bytes(&d).unwrap()];
        let w = World::init(&d, &mut memory).unwrap();
        w.add_particle([1, 1, 0], [0.2, 0.1, 0.0]).unwrap();
        w.step(3);
        let before = fingerprint(w);
        assert_eq!(w.load(&img).map_err(Error::kind), Err(ErrorKind::ImageMismatch), "{what}");
        assert_eq!(fingerprint(w), before, "{what}");
    }
    // The same plan with another seed, forces, method and faces: the world
    // takes the image's description with everything else.
    let mut d = small_desc();
    d.seed = 1;
    d.gravity = [0.0, 0.05, 0.0];
    d.method = Method::Greedy;
    d.boundary = [[Boundary::Periodic; 2]; 3];
    d.forces.vortex = false;
    let mut memory = vec![0u8; world_bytes(&d).unwrap()];
    let w = World::init(&d, &mut memory).unwrap();
    w.load(&img).unwrap();
    assert_eq!(*w.description(), small_desc());
    assert!(image(w) == img);
}

#[test]
fn save_refuses_a_short_buffer_and_writes_nothing() {
    let mut memory = Vec::new();
    let w = small_world(&mut memory, 10);
    let len = w.snapshot_bytes();
    for short in [0, 1, 24, 247, len / 2, len - 1] {
        let mut out = vec![0x77u8; short];
        assert_eq!(w.save(&mut out).map_err(Error::kind), Err(ErrorKind::OutputTooSmall), "{short} bytes");
        assert!(out.iter().all(|&b| b == 0x77), "{short} bytes: written");
    }
    let mut out = vec![0x77u8; len + 100];
    assert_eq!(w.save(&mut out), Ok(len));
    assert!(out[len..].iter().all(|&b| b == 0x77));
    assert!(out[..len] == image(w));
}

#[test]
fn init_from_image_into_too_little_memory_writes_nothing() {
    let mut memory = Vec::new();
    let img = image(small_world(&mut memory, 10));
    let need = world_bytes(&image_description(&img).unwrap()).unwrap();
    for short in [0, 100, need - mpca::WORLD_ALIGN] {
        let mut fresh = vec![0x33u8; short];
        assert_eq!(World::init_from_image(&img, &mut fresh).err().map(Error::kind), Some(ErrorKind::BufferTooSmall), "{short} bytes");
        assert!(fresh.iter().all(|&b| b == 0x33));
    }
    // Any alignment: the world starts at the first aligned byte.
    let mut fresh = vec![0u8; need + 3];
    let w = World::init_from_image(&img, &mut fresh[3..]).unwrap();
    assert!(image(w) == img);
}

/// Brute force: every particle the world reports, filtered by the box, in
/// cell order (the order region_stats sums in).
fn by_hand(w: &World, min: [u32; 3], max: [u32; 3]) -> RegionStats {
    let dim = w.description().dim as usize;
    let mut r = RegionStats::default();
    for p in w.particles().filter(|p| (0..dim).all(|k| min[k] <= p.pos[k] && p.pos[k] < max[k])) {
        let m = f64::from(p.mass);
        let mut v2 = 0.0;
        for k in 0..3 {
            let v = f64::from(p.velocity[k]);
            r.momentum[k] += m * v;
            v2 += v * v;
        }
        r.kinetic_energy += 0.5 * m * v2;
        r.particles += 1;
    }
    r
}

#[test]
fn region_counters_count_known_particles() {
    let mut d = Description::new_2d(192, 8);
    d.per_particle_mass = true;
    d.mass_classes = 3;
    let mut memory = vec![0u8; world_bytes(&d).unwrap()];
    let w = World::init(&d, &mut memory).unwrap();
    // On both sides of the word boundaries at x = 64 and 128; velocities in
    // whole quanta (k / 127), so the sums are known exactly.
    let q = |k: i32| k as f32 / 127.0;
    let placed = [
        ([0, 0, 0], [q(127), 0.0, 0.0], 1.0),
        ([63, 1, 0], [0.0, q(-64), 0.0], 2.0),
        ([64, 1, 0], [q(32), q(32), 0.0], 1.0),
        ([127, 5, 0], [q(-100), 0.0, 0.0], 0.5),
        ([128, 5, 0], [0.0, 0.0, 0.0], 2.0),
        ([191, 7, 0], [q(10), q(-10), 0.0], 1.0),
    ];
    for (pos, v, m) in placed {
        w.add_particle_with_mass(pos, v, m).unwrap();
    }
    let region = |min: [u32; 3], max: [u32; 3]| w.region_stats(min, max).unwrap();
    let count = |min, max| region(min, max).particles;
    assert_eq!(count([0, 0, 0], [192, 8, 1]), 6);
    assert_eq!(count([63, 0, 0], [65, 8, 1]), 2, "across the first word boundary");
    assert_eq!(count([64, 0, 0], [128, 8, 1]), 2, "one whole word");
    assert_eq!(count([127, 5, 0], [129, 6, 1]), 2, "across the second");
    assert_eq!(count([1, 0, 0], [63, 8, 1]), 0);
    assert_eq!(count([191, 7, 0], [192, 8, 1]), 1, "the last cell");
    assert_eq!(count([0, 2, 0], [192, 5, 1]), 0, "rows without particles");
    // The third axis is ignored in 2D.
    assert_eq!(count([0, 0, 9], [192, 8, 0]), 6);

    // (63, 1), (64, 1), (127, 5), (128, 5), against the sums in quanta.
    let r = region([60, 0, 0], [130, 8, 1]);
    assert_eq!(r.particles, 4);
    let momentum = [(32.0 - 0.5 * 100.0) / 127.0, (-2.0 * 64.0 + 32.0) / 127.0, 0.0];
    let energy = 0.5 * (2.0 * 64.0f64.powi(2) + 2.0 * 32.0f64.powi(2) + 0.5 * 100.0f64.powi(2)) / 127.0f64.powi(2);
    for k in 0..3 {
        assert!((r.momentum[k] - momentum[k]).abs() < 1e-6, "{:?} vs {momentum:?}", r.momentum);
    }
    assert!((r.kinetic_energy - energy).abs() < 1e-6, "{} vs {energy}", r.kinetic_energy);

    // The whole world gives the statistics to the bit.
    let all = region([0, 0, 0], [192, 8, 1]);
    let s = w.stats();
    assert_eq!((all.particles, all.momentum, all.kinetic_energy), (s.particles, s.momentum, s.kinetic_energy));

    // Refused: empty or reversed, and beyond the world. Nothing changes.
    let before = w.state_hash();
    for (min, max) in [([5, 0, 0], [5, 8, 1]), ([6, 0, 0], [5, 8, 1]), ([0, 4, 0], [192, 3, 1])] {
        assert_eq!(w.region_stats(min, max).map_err(Error::kind), Err(ErrorKind::BadShape), "{min:?} {max:?}");
    }
    for (min, max) in [([0, 0, 0], [193, 8, 1]), ([0, 0, 0], [192, 9, 1]), ([190, 0, 0], [u32::MAX, 8, 1])] {
        assert_eq!(w.region_stats(min, max).map_err(Error::kind), Err(ErrorKind::OutOfBounds), "{min:?} {max:?}");
    }
    assert_eq!(w.state_hash(), before);
}

#[test]
fn region_counters_agree_with_a_count_by_hand_on_stepped_worlds() {
    let mut memory = Vec::new();
    let w = scenes::every_part(&mut memory, Method::ExactFast);
    w.step(25);
    let mut i = 99u64;
    let mut next = |n: u32| {
        i = i.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        ((i >> 33) % u64::from(n)) as u32
    };
    let mut boxes = 0;
    for _ in 0..300 {
        let (a, b) = ([next(16), next(16), next(16)], [next(16), next(16), next(16)]);
        let min = [0, 1, 2].map(|k| a[k].min(b[k]));
        let max = [0, 1, 2].map(|k| a[k].max(b[k]) + 1);
        assert_eq!(w.region_stats(min, max), Ok(by_hand(w, min, max)), "{min:?} {max:?}");
        boxes += 1;
    }
    let all = w.region_stats([0; 3], [16; 3]).unwrap();
    let s = w.stats();
    assert_eq!((all.particles, all.momentum, all.kinetic_energy), (s.particles, s.momentum, s.kinetic_energy));
    assert_eq!(w.region_stats([0, 0, 3], [16, 16, 3]).map_err(Error::kind), Err(ErrorKind::BadShape), "empty along z in 3D");
    assert_eq!(w.region_stats([0, 0, 0], [16, 16, 17]).map_err(Error::kind), Err(ErrorKind::OutOfBounds));

    let mut memory = Vec::new();
    let scene = scenes::aggregation();
    let w = scenes::build(&scene, &mut memory).unwrap();
    w.step(50);
    for _ in 0..300 {
        let (a, b) = ([next(128), next(128), 0], [next(128), next(128), 0]);
        let min = [a[0].min(b[0]), a[1].min(b[1]), 0];
        let max = [a[0].max(b[0]) + 1, a[1].max(b[1]) + 1, 1];
        assert_eq!(w.region_stats(min, max), Ok(by_hand(w, min, max)), "{min:?} {max:?}");
        boxes += 1;
    }
    println!("{boxes} boxes against the count by hand");
}

/// The bytes of format version 2 for a world that has not stepped (so only
/// the setup, not the step, decides them): a change here is a change of the
/// format, which must come with a new IMAGE_VERSION. Equal on x86-64 and
/// 32-bit Arm.
#[test]
fn the_format_of_version_2_is_pinned() {
    let mut memory = Vec::new();
    let img = image(small_world(&mut memory, 0));
    let crc = u32_at(&img, img.len() - 4);
    println!("small world at step 0: image {} bytes, crc {crc:08x}", img.len());
    assert_eq!((img.len(), crc), (4334, 0x25bd_d1d8));
}

/// Images of version 1 (written before emitters kept counts) still load.
/// `data/small-world-20-v1.mpca` is the small world after 20 steps, saved
/// by the library of version 1. Expected: it loads into a world of its
/// description as the same world (hash, counters) with emitter counts of
/// zero, and steps on as the world it was saved from; saved again it is
/// an image of version 2, longer by its one emitter's two counts.
#[test]
fn images_of_version_1_still_load() {
    let v1 = include_bytes!("../data/small-world-20-v1.mpca");
    assert_eq!(u32_at(v1, VERSION_AT), 1);
    let mut memory = Vec::new();
    let original = small_world(&mut memory, 20);
    let mut other = Vec::new();
    let loaded = small_world_of(small_desc(), &mut other, 0);
    loaded.load(v1).unwrap();
    assert_eq!(loaded.state_hash(), 0x4248_d3cd_276e_18eb, "the hash version 1's library printed");
    assert_eq!(loaded.state_hash(), original.state_hash());
    assert_eq!(loaded.stats(), original.stats());
    assert_eq!(loaded.emitter_stats(0), Ok(mpca::EmitterStats::default()));
    let again = image(loaded);
    assert_eq!((u32_at(&again, VERSION_AT), again.len()), (2, v1.len() + 16));
    // The two count on from where each stands: by the same amounts.
    let at_20 = original.emitter_stats(0).unwrap();
    original.step(15);
    loaded.step(15);
    assert_eq!(loaded.state_hash(), original.state_hash());
    assert_eq!(loaded.stats(), original.stats());
    let (a, b) = (original.emitter_stats(0).unwrap(), loaded.emitter_stats(0).unwrap());
    assert_eq!((a.requested - at_20.requested, a.delivered - at_20.delivered), (b.requested, b.delivered));
    assert!(b.requested > 0 && b.delivered <= b.requested, "{b:?}");
}

#[test]
fn a_world_loaded_at_the_last_step_number_steps_on_to_step_zero() {
    // Found by the snapshot fuzzer: an image may carry any step number, and
    // stepping a world loaded at u64::MAX overflowed the count. It wraps.
    let desc = Description::new_2d(16, 16);
    let mut memory = vec![0u8; world_bytes(&desc).unwrap()];
    let w = World::init(&desc, &mut memory).unwrap();
    w.add_particle([3, 4, 0], [0.5, 0.0, 0.0]).unwrap();
    let mut img = image(w);
    assert_eq!(u64_at(&img, STATE_AT), 0, "the state starts with the step number");
    img[STATE_AT..STATE_AT + 8].copy_from_slice(&u64::MAX.to_le_bytes());
    reseal(&mut img);
    w.load(&img).unwrap();
    assert_eq!(w.stats().step, u64::MAX);
    w.step(2);
    assert_eq!((w.stats().step, w.stats().particles), (1, 1));
}

#[test]
fn counts_loaded_at_their_largest_saturate_as_the_world_steps() {
    // Found by the snapshot fuzzer: an image may carry any running count,
    // and adding a step's collisions to u64::MAX overflowed. Every count
    // of the image's state (emitted ... clamps) set to u64::MAX; a dense
    // emitting gas then collides, exits and emits on.
    let mut desc = Description::new_2d(16, 16).with_boundary(Boundary::Open);
    desc.emitter_capacity = 1;
    let mut memory = vec![0u8; world_bytes(&desc).unwrap()];
    let w = World::init(&desc, &mut memory).unwrap();
    w.add_emitter(Emitter { min: [0, 0, 0], max: [16, 16, 1], rate: 100.0, velocity: [0.5, 0.0, 0.0], spread: 0.3, mass: 1.0, lifetime: 0 })
        .unwrap();
    w.step(3);
    let mut img = image(w);
    // After the particle count: emitted, exited, expired, shortfall,
    // collisions, clamps.
    for k in 1..7 {
        img[PARTICLES_AT + 8 * k..PARTICLES_AT + 8 * k + 8].copy_from_slice(&u64::MAX.to_le_bytes());
    }
    reseal(&mut img);
    w.load(&img).unwrap();
    w.step(5);
    let s = w.stats();
    assert!(s.collisions == u64::MAX && s.emitted == u64::MAX && s.exited == u64::MAX, "{s:?}");
}
