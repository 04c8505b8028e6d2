//! Writes the seed corpus of the fuzz targets into fuzz/seeds/<target>/,
//! replacing what it wrote before (snapshot seeds kept by hand stay). From
//! the repository root:
//!
//!     cargo +nightly run --manifest-path fuzz/Cargo.toml --example seeds
//!
//! The seeds are valid inputs that reach deep: descriptions of every part,
//! call sequences on worlds that validate, and images of small worlds that
//! hold particles, obstacles, force planes, masses and emitters. Small (a
//! few KB a target) and the same on every run, so they are kept in the
//! repository.

use std::fs;
use std::path::Path;

use mpca_ffi::{mpca_desc, mpca_emitter, mpca_status};
use mpca_fuzz::{defaults, read_desc, scene, validate, write_desc, Input, World};

/// A fixed stream of bytes (xorshift64*), so the seeds never change.
struct Bytes(u64);

impl Bytes {
    fn next(&mut self) -> u8 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 56) as u8
    }

    fn take(&mut self, n: usize) -> Vec<u8> {
        (0..n).map(|_| self.next()).collect()
    }
}

/// Descriptions that use each part, for the desc target.
fn descriptions() -> Vec<mpca_desc> {
    let mut all = vec![defaults(2, 16, 16, 0), defaults(3, 4, 4, 4)];
    let mut d = defaults(2, 12, 8, 0);
    d.boundary = [[1, 1], [1, 2], [0, 0]];
    d.obstacles = 1;
    d.surface_capacity = 16;
    d.per_particle_mass = 1;
    d.mass_classes = 4;
    d.forces = 1 | 8;
    d.gravity = [0.0, -0.02, 0.0];
    d.vortex_centre = [6.0, 4.0];
    d.restitution = 0.8;
    d.method = 0;
    d.contacts = 1;
    all.push(d);
    let mut d = defaults(3, 6, 4, 2);
    d.quantization = 16;
    d.forces = 2 | 4;
    d.lifetimes = 1;
    d.emitter_capacity = 2;
    d.collisions = 1;
    d.energy_neutral = 1;
    d.drag_rate = 0.5;
    d.drag_wind = [0.1, 0.0, 0.0];
    d.drag_wind_field = 1;
    d.method = 2;
    all.push(d);
    all
}

/// A world with something of everything its description allows, stepped.
fn furnished(d: &mpca_desc, bytes: &mut Bytes) -> World {
    let mut w = World::create(d).expect("a seed description is valid");
    let n = w.desc().size;
    if d.obstacles == 1 {
        w.add_box([0.0, 0.0, 0.0], [n[0] as f32, 0.9, n[2] as f32], 0.5).expect("a floor");
    }
    for _ in 0..12 {
        let b = bytes.take(6);
        let pos = [u32::from(b[0]) % n[0], u32::from(b[1]) % n[1], u32::from(b[2]) % n[2]];
        let v = [f32::from(b[3] as i8) / 200.0, f32::from(b[4] as i8) / 200.0, f32::from(b[5] as i8) / 200.0];
        let _ = w.add_particle_mass(pos, v, if b[0] & 1 == 1 { d.mass } else { 2.0 });
    }
    if d.emitter_capacity > 0 {
        let e = mpca_emitter {
            struct_size: size_of::<mpca_emitter>() as u32,
            min: [0, n[1] - 2, 0],
            max: [2, n[1], n[2]],
            rate: 0.7,
            velocity: [0.3, -0.1, 0.0],
            spread: 0.2,
            mass: d.mass,
            lifetime: if d.lifetimes == 1 { 9 } else { 0 },
        };
        w.add_emitter(&e).expect("an emitter");
    }
    if d.forces & 2 != 0 {
        w.set_cell_force([1, 1, 0], [0.01, 0.02, 0.0]).expect("a field");
    }
    if d.forces & 4 != 0 {
        w.set_cell_potential([2, 1, 0], 0.05).expect("a potential");
    }
    if d.drag_wind_field == 1 {
        w.set_cell_wind([1, 0, 0], [0.0, 0.3, 0.0]).expect("a wind");
    }
    w.step(3).expect("steps");
    w
}

fn write(dir: &Path, name: &str, bytes: &[u8]) {
    fs::write(dir.join(name), bytes).unwrap_or_else(|e| panic!("writing {name}: {e}"));
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("seeds");
    let mut bytes = Bytes(0x6d70_6361_7365_6564);
    for target in ["desc", "ops"] {
        let dir = root.join(target);
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).expect("the seeds folder");
    }
    // The images it writes are replaced; the ones kept by hand (inputs the
    // fuzzer once found) stay.
    fs::create_dir_all(root.join("snapshot")).expect("the seeds folder");

    for (i, d) in descriptions().iter().enumerate() {
        assert_eq!(validate(d), mpca_status::Ok);
        let mut seed = vec![0u8];
        seed.extend(write_desc(d));
        assert_eq!(read_desc(&mut Input::new(&seed[1..])), *d, "read_desc does not read back what write_desc wrote");
        seed.extend(bytes.take(48));
        write(&root.join("desc"), &format!("desc-{i}"), &seed);
    }

    // Call sequences: the first fixed-stream inputs whose scene is valid,
    // half of them 3D (the scene's first byte picks).
    let mut kept = 0;
    while kept < 8 {
        let mut seed = bytes.take(300);
        seed[0] = (seed[0] & !1) | (kept & 1);
        if validate(&scene(&mut Input::new(&seed))) == mpca_status::Ok {
            write(&root.join("ops"), &format!("ops-{kept}"), &seed);
            kept += 1;
        }
    }

    // Images, with the flag byte in front: 1 (repair the framing) for half.
    for (i, d) in descriptions().iter().enumerate() {
        let w = furnished(d, &mut bytes);
        let mut seed = vec![(i & 1) as u8];
        seed.extend(w.save());
        write(&root.join("snapshot"), &format!("image-{i}"), &seed);
    }
    // An image of format version 1 (M12), which the library still reads:
    // the one the integration tests load.
    let mut seed = vec![0u8];
    seed.extend(include_bytes!("../../tests/data/small-world-20-v1.mpca"));
    write(&root.join("snapshot"), "version-1", &seed);
}
