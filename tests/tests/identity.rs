//! M6b: ids, ages and tags carried with the particles. What a world does
//! with them is what it does without them; each id stays with its
//! particle, is never given twice, and survives a snapshot; ages count
//! steps; running out of ids refuses adds and counts the emitters'
//! particles as shortfall.

mod common;

use std::collections::HashMap;

use mpca::{Description, Emitter, Error, ErrorKind, Identity, Method, Particle, World};
use mpca_tests::scenes::every_part_with;

/// What the world holds but for the identity planes.
fn motion(w: &World) -> Vec<([u32; 3], [f32; 3], f32, u16)> {
    w.particles().map(|p| (p.pos, p.velocity, p.mass, p.life)).collect()
}

/// Whether `a` and `b` lie in the same Margolus block of some partition:
/// at most one cell apart on each axis, across a periodic face too.
fn neighbours(a: [u32; 3], b: [u32; 3], n: [u32; 3]) -> bool {
    (0..3).all(|k| {
        let d = a[k].abs_diff(b[k]);
        d <= 1 || d == n[k] - 1
    })
}

#[test]
fn a_world_with_identity_moves_as_one_without() {
    // Expect: the every-part world (masses, lifetimes, an emitter, every
    // force, obstacles, open faces) with all three planes and without
    // them: the same particles, velocities, masses and lifetimes after
    // every step, under each method.
    for method in [Method::ExactFast, Method::Greedy] {
        let (mut with, mut without) = (Vec::new(), Vec::new());
        let a = every_part_with(&mut with, method, Identity::ALL);
        let b = every_part_with(&mut without, method, Identity::NONE);
        for step in 0..60 {
            assert_eq!(motion(a), motion(b), "{method:?}, step {step}");
            a.step(1);
            b.step(1);
        }
        let (sa, sb) = (a.stats(), b.stats());
        assert_eq!((sa.particles, sa.emitted, sa.exited, sa.expired), (sb.particles, sb.emitted, sb.exited, sb.expired));
        assert!(sa.emitted > 0 && sa.exited + sa.expired > 0, "the run must emit and lose particles: {sa:?}");
    }
}

#[test]
fn ids_follow_their_particles_and_ages_count_steps() {
    // Expect: after each step every particle that was there keeps its id
    // and tag, lies in a cell next to its last one (a Margolus move), and
    // is one step older; every new id is larger than every id given
    // before, new particles are emitted ones (age 1, the emitter's tag);
    // no id is held twice.
    let mut memory = Vec::new();
    let w = every_part_with(&mut memory, Method::ExactFast, Identity::ALL);
    w.set_emitter_tag(0, 7).unwrap();
    let n = w.description().size;
    let first: Vec<Particle> = w.particles().collect();
    assert!(first.iter().all(|p| p.age == 0 && p.tag == 0));
    let mut ids: Vec<u32> = first.iter().map(|p| p.id).collect();
    ids.sort_unstable();
    assert_eq!(ids, (1..=first.len() as u32).collect::<Vec<_>>(), "ids count up from 1 in the order of adding");
    w.set_tag(first[0].pos, 200).unwrap();
    let mut last: HashMap<u32, Particle> = w.particles().map(|p| (p.id, p)).collect();
    let mut highest = first.len() as u32;
    let (mut kept, mut born) = (0u64, 0u64);
    for step in 0..80 {
        w.step(1);
        let now: Vec<Particle> = w.particles().collect();
        let mut seen = HashMap::new();
        let mut newest = highest;
        for p in &now {
            assert!(seen.insert(p.id, p.pos).is_none(), "step {step}: id {} twice", p.id);
            match last.get(&p.id) {
                Some(before) => {
                    assert!(neighbours(before.pos, p.pos, n), "step {step}: id {} jumped {:?} -> {:?}", p.id, before.pos, p.pos);
                    assert_eq!((p.age, p.tag), (before.age + 1, before.tag), "step {step}: id {}", p.id);
                    kept += 1;
                }
                None => {
                    assert!(p.id > highest, "step {step}: id {} is new but not above {highest}", p.id);
                    assert_eq!((p.age, p.tag, p.life), (1, 7, 39), "step {step}: an emitted particle");
                    newest = newest.max(p.id);
                    born += 1;
                }
            }
        }
        highest = newest;
        last = now.into_iter().map(|p| (p.id, p)).collect();
    }
    assert!(kept > 1000 && born > 100, "kept {kept}, born {born}");
}

#[test]
fn snapshots_keep_ids_ages_tags_and_the_next_id() {
    // Expect: an image of a world with the planes loads into a world that
    // reports the same particles (ids, ages, tags included), hashes the
    // same, saves to the same bytes, and gives the same ids to what it
    // adds and emits afterwards.
    let mut memory = Vec::new();
    let w = every_part_with(&mut memory, Method::ExactFast, Identity::ALL);
    w.set_emitter_tag(0, 9).unwrap();
    w.step(15);
    let mut image = vec![0u8; w.snapshot_bytes()];
    w.save(&mut image).unwrap();
    let desc = mpca::image_description(&image).unwrap();
    assert_eq!(desc.identity, Identity::ALL);
    let mut other = vec![0u8; mpca::world_bytes(&desc).unwrap()];
    let copy = World::init_from_image(&image, &mut other).unwrap();
    assert_eq!(copy.particles().collect::<Vec<_>>(), w.particles().collect::<Vec<_>>());
    assert_eq!(copy.state_hash(), w.state_hash());
    let mut again = vec![0u8; image.len()];
    copy.save(&mut again).unwrap();
    assert_eq!(again, image, "saved again, the same bytes");
    for world in [&mut *w, &mut *copy] {
        world.step(10);
        let free = (0..16).map(|x| [x, 8, 1]).find(|&p| matches!(world.cell(p), Ok(mpca::Cell::Empty))).unwrap();
        world.add_particle(free, [0.0; 3]).unwrap();
    }
    assert_eq!(copy.particles().collect::<Vec<_>>(), w.particles().collect::<Vec<_>>());
    assert_eq!(copy.state_hash(), w.state_hash());
}

#[test]
fn without_ids_left_adds_are_refused_and_emissions_fall_short() {
    // Expect: a world whose image says every id but one was given takes
    // one more particle (id u32::MAX), then refuses the next add with
    // IdsExhausted, changing nothing; its emitter places nothing and its
    // whole asked count goes to the shortfall, so the count stays exact.
    let mut d = Description::new_2d(16, 16);
    d.identity = Identity::IDS;
    d.emitter_capacity = 1;
    let mut memory = common::memory(&d);
    let w = World::init(&d, &mut memory).unwrap();
    w.add_particle([1, 1, 0], [0.0; 3]).unwrap();
    let mut image = vec![0u8; w.snapshot_bytes()];
    w.save(&mut image).unwrap();
    // The ids given: the state's last word, before the planes.
    const IDS_GIVEN_AT: usize = 24 + 120 + 116;
    assert_eq!(u32::from_le_bytes(image[IDS_GIVEN_AT..IDS_GIVEN_AT + 4].try_into().unwrap()), 1);
    image[IDS_GIVEN_AT..IDS_GIVEN_AT + 4].copy_from_slice(&(u32::MAX - 1).to_le_bytes());
    common::reseal(&mut image);
    w.load(&image).unwrap();
    w.add_particle([2, 2, 0], [0.0; 3]).unwrap();
    assert_eq!(common::particle(w, [2, 2, 0]).id, u32::MAX);
    let hash = w.state_hash();
    assert_eq!(w.add_particle([3, 3, 0], [0.0; 3]).map_err(Error::kind), Err(ErrorKind::IdsExhausted));
    assert_eq!((w.state_hash(), w.particle_count()), (hash, 2));
    w.add_emitter(Emitter { min: [4, 4, 0], max: [12, 12, 1], rate: 3.0, mass: 1.0, ..Emitter::default() }).unwrap();
    w.step(5);
    let s = w.stats();
    assert_eq!((s.particles, s.emitted, s.emit_shortfall), (2, 0, 15));
    // An image whose particle holds an id above those given is refused.
    image[IDS_GIVEN_AT..IDS_GIVEN_AT + 4].copy_from_slice(&0u32.to_le_bytes());
    common::reseal(&mut image);
    assert_eq!(w.load(&image).map_err(Error::kind), Err(ErrorKind::ImageInvalid));
}

#[test]
fn the_planes_are_refused_where_the_world_has_none() {
    let mut d = Description::new_2d(8, 8);
    d.emitter_capacity = 1;
    let mut memory = common::memory(&d);
    let w = World::init(&d, &mut memory).unwrap();
    w.add_particle([1, 1, 0], [0.0; 3]).unwrap();
    w.add_emitter(Emitter { min: [0, 0, 0], max: [2, 2, 1], rate: 0.0, mass: 1.0, ..Emitter::default() }).unwrap();
    assert_eq!(w.set_tag([1, 1, 0], 3).map_err(Error::kind), Err(ErrorKind::NotEnabled));
    assert_eq!(w.set_emitter_tag(0, 3).map_err(Error::kind), Err(ErrorKind::NotEnabled));
    let p = common::particle(w, [1, 1, 0]);
    assert_eq!((p.id, p.age, p.tag), (0, 0, 0));
    // Each plane costs its bytes a cell and nothing more.
    let base = mpca::world_bytes(&d).unwrap();
    for (identity, per_cell) in [
        (Identity::IDS, 4),
        (Identity::AGES, 4),
        (Identity::TAGS, 1),
        (Identity::ALL, 9),
    ] {
        let mut e = d;
        e.identity = identity;
        assert_eq!(mpca::world_bytes(&e).unwrap(), base + 64 * per_cell, "{identity:?}");
    }
}
