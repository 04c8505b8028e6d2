//! Snapshot loading (M12) on mutated images. The input is a flag byte and
//! an image; the seeds are real images, which the fuzzer mutates. With the
//! flag's low bit set the length field and CRC-32 are repaired first, so
//! that mutations reach the checks behind the checksum.
//!
//! Checked: nothing panics; mpca_desc_from_image, mpca_world_load and
//! mpca_world_init_from_image (World::load and World::init_from_image
//! beneath) agree on whether the image is a world and why not; a refused
//! load leaves every byte of the world's memory as it was, and a refused
//! init_from_image leaves every byte of the memory it was given; an
//! accepted image loads into a world built from its description, saves
//! back byte for byte (an image of version 1 as version 2, which then
//! does), and steps on as a world built from it in fresh memory does.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mpca_ffi::mpca_status;
use mpca_fuzz::{defaults, desc_from_image, image, world_bytes, World};

/// Worlds larger than this are not built.
const MAX_BYTES: usize = 1 << 20;

/// A world in caller memory that no image of the seeds fits (its plan
/// differs), holding a particle, to load refused images into.
fn bystander() -> World {
    let d = defaults(2, 6, 4, 0);
    let bytes = world_bytes(&d).expect("valid");
    let mut w = World::init(&d, vec![0u8; bytes], 0).map_err(|e| e.0).expect("builds");
    w.add_particle([1, 2, 0], [0.25, -0.5, 0.0]).expect("an empty cell");
    w
}

/// Loads `image` into `w` and checks that a refusal left its memory alone.
fn load(w: &mut World, image: &[u8]) -> Result<(), mpca_status> {
    let before = w.memory().map(<[u8]>::to_vec);
    let hash = w.hash();
    let r = w.load(image);
    if r.is_err() {
        assert_eq!(w.memory().map(<[u8]>::to_vec), before, "a refused load ({r:?}) wrote to the world's memory");
        assert_eq!(w.hash(), hash);
    }
    r
}

fuzz_target!(|data: &[u8]| {
    let Some((&flags, rest)) = data.split_first() else { return };
    let mut img = rest.to_vec();
    if flags & 1 == 1 {
        image::reframe(&mut img);
    }
    let desc = desc_from_image(&img);
    let core = mpca::image_description(&img);
    assert_eq!(desc.err(), core.err().map(mpca_status::from), "the C and Rust readers disagree");

    // Into a world of another plan: refused, nothing written.
    let mut other = bystander();
    let r = load(&mut other, &img);
    match desc {
        Err(e) => assert_eq!(r, Err(e), "load and desc_from_image refuse differently"),
        Ok(_) => assert!(r.is_ok() || r == Err(mpca_status::ImageMismatch), "{r:?}"),
    }

    // Into fresh memory, sized by the image's own description when it has
    // one; a refusal must not write a byte of it.
    let bytes = match desc {
        Ok(d) => match world_bytes(&d) {
            Ok(n) if n <= MAX_BYTES => n,
            Ok(_) => return,
            Err(e) => panic!("the description of an accepted image is refused: {e:?}"),
        },
        Err(_) => 4096,
    };
    let fresh = World::init_from_image(&img, vec![0x5au8; bytes]);
    let fresh = match (desc, fresh) {
        (Err(e), Err((s, memory))) => {
            assert_eq!(s, e, "init_from_image and desc_from_image refuse differently");
            assert!(memory.iter().all(|&b| b == 0x5a), "a refused init_from_image wrote to the memory");
            return;
        }
        (Ok(_), Ok(w)) => w,
        (Err(e), Ok(_)) => panic!("init_from_image took an image desc_from_image refuses ({e:?})"),
        (Ok(_), Err((s, _))) => panic!("init_from_image refused ({s:?}) an image desc_from_image takes"),
    };

    // Accepted: into a world built from the description, in library memory.
    let d = desc.expect("accepted");
    let mut w = World::create(&d).expect("the description of an accepted image builds");
    load(&mut w, &img).expect("an accepted image loads into a world built from its description");
    assert_eq!(w.hash(), fresh.hash(), "load and init_from_image give different worlds");
    let saved = w.save();
    if img[8..12] == 1u32.to_le_bytes() {
        // Version 1 (M12) is read and saved as the version this library
        // writes: the same world, whose image then saves back as it is.
        let mut again = World::create(&d).expect("builds");
        load(&mut again, &saved).expect("a saved image loads");
        assert_eq!(again.hash(), w.hash(), "a version 1 image saved again is another world");
        assert_eq!(again.save(), saved, "a version 1 image saved again does not save back byte for byte");
    } else {
        assert_eq!(saved, img, "a loaded image does not save back byte for byte");
    }
    let mut fresh = fresh;
    w.step(2).expect("steps");
    fresh.step(2).expect("steps");
    assert_eq!(w.hash(), fresh.hash(), "worlds from one image step apart");
});
