//! Snapshots (M12): a world's image saved into caller memory, loaded into a
//! world, or made into a new world in caller memory. The format is defined
//! byte for byte in docs/model.md; images are the same on every target.

use core::ffi::c_void;

use mpca_core::{ErrorKind, World};

use crate::{fits, guard, handle, mpca_desc, mpca_status, mpca_world, Refusal};

/// Whether `a_len` bytes at `a` and `b_len` bytes at `b` share a byte;
/// found from the addresses alone, before any slice is formed over either.
/// NULL and lengths no object can have are left to `Call::slice` to refuse.
/// Out of line: the export of particles asks it of every pair of columns.
#[inline(never)]
pub(crate) fn overlap(a: *const u8, a_len: usize, b: *const u8, b_len: usize) -> bool {
    if a.is_null() || b.is_null() || !fits::<u8>(a_len) || !fits::<u8>(b_len) {
        return false;
    }
    let (a, b) = (a as usize, b as usize);
    a_len != 0 && b_len != 0 && a < b.saturating_add(b_len) && b < a.saturating_add(a_len)
}

/// Where a world's memory lies: its start and its size.
fn span(w: &World) -> (*const u8, usize) {
    ((w as *const World).cast::<u8>(), w.size_in_bytes())
}

/// Writes to `out_bytes` the length of the image mpca_world_save would
/// write now. It changes as particles, surface cells and emitters come and
/// go, never beyond the size of the world's memory plus 252 bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_snapshot_bytes(world: *const mpca_world, out_bytes: *mut usize) -> mpca_status {
    guard(|c| {
        let w = c.world_ref(world)?;
        c.out(out_bytes)?.set(w.snapshot_bytes());
        Ok(())
    })
}

/// Writes the world's image (docs/model.md, M12) to `buf`, which has room
/// for `len` bytes, and its length to `out_written`. As with snprintf, `buf`
/// NULL with `len` 0 only asks for the length: `out_written` gets it and
/// the call succeeds. A `len` below the image's length writes nothing but
/// `out_written` and returns `MPCA_STATUS_OUTPUT_TOO_SMALL`. `buf` may not
/// overlap the world's memory (`MPCA_STATUS_OVERLAP`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_save(world: *const mpca_world, buf: *mut c_void, len: usize, out_written: *mut usize) -> mpca_status {
    guard(|c| {
        let w = c.world_ref(world)?;
        let written = c.out(out_written)?;
        let need = w.snapshot_bytes();
        if buf.is_null() && len == 0 {
            written.set(need);
            return Ok(());
        }
        let (at, size) = span(w);
        if overlap(buf.cast(), len, at, size) {
            return Err(Refusal::new(mpca_status::Overlap, c"buf"));
        }
        let out = c.slice_mut(buf.cast::<u8>(), len, mpca_status::BadLength)?;
        match w.save(out) {
            Ok(n) => {
                written.set(n);
                Ok(())
            }
            Err(e) if e.kind() == ErrorKind::OutputTooSmall => {
                written.set(need);
                Err(Refusal::new(mpca_status::OutputTooSmall, c"len"))
            }
            Err(e) => Err(e.into()),
        }
    })
}

/// Makes the world the one the image of `len` bytes at `image` holds: its
/// description, step, counters, particles, obstacles, force planes, masses
/// and emitters, so that it hashes equal to the saved world and steps on as
/// that world would have. The world must have the image's plan of memory
/// (sizes, velocity width, parts and capacities of its description; what
/// does not change the plan, such as the seed or the forces' values, comes
/// from the image): else `MPCA_STATUS_IMAGE_MISMATCH`. A world built from
/// mpca_desc_from_image always fits.
///
/// The whole image is checked before the world is written, and a refused
/// image changes nothing: `MPCA_STATUS_NOT_AN_IMAGE` (wrong magic),
/// `MPCA_STATUS_IMAGE_LENGTH` (cut short, or `len` beyond its end),
/// `MPCA_STATUS_IMAGE_VERSION`, `MPCA_STATUS_IMAGE_CHECKSUM` (damaged),
/// `MPCA_STATUS_IMAGE_INVALID` (well framed but not a consistent world),
/// or the status of a part this library was built without. The image may
/// not overlap the world's memory (`MPCA_STATUS_OVERLAP`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_load(world: *mut mpca_world, image: *const c_void, len: usize) -> mpca_status {
    guard(|c| {
        let w = c.world_to_end(world)?;
        let (at, size) = span(w);
        if overlap(image.cast(), len, at, size) {
            return Err(Refusal::new(mpca_status::Overlap, c"image"));
        }
        let image = c.slice(image.cast::<u8>(), len, mpca_status::BadLength)?;
        Ok(w.load(image)?)
    })
}

/// Writes to `out` the description of the world the image of `len` bytes
/// at `image` holds, after checking the whole image as mpca_world_load
/// does. mpca_world_bytes of it sizes the memory for
/// mpca_world_init_from_image; mpca_world_create of it makes a world that
/// mpca_world_load accepts the image into.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_desc_from_image(image: *const c_void, len: usize, out: *mut mpca_desc) -> mpca_status {
    guard(|c| {
        let image = c.slice(image.cast::<u8>(), len, mpca_status::BadLength)?;
        let out = c.out(out)?;
        out.set(mpca_desc::from_core(&mpca_core::image_description(image)?));
        Ok(())
    })
}

/// Builds the world the image of `image_len` bytes at `image` holds in
/// `memory` (`len` bytes, any alignment, at least mpca_world_bytes of
/// mpca_desc_from_image), as mpca_world_init builds an empty one, and
/// writes its handle to `out_world`. The image is checked in full first: a
/// refused image (see mpca_world_load) or too small a memory leaves
/// `memory` unwritten, and a live world in it alive. The image may not
/// overlap `memory` (`MPCA_STATUS_OVERLAP`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mpca_world_init_from_image(
    image: *const c_void,
    image_len: usize,
    memory: *mut c_void,
    len: usize,
    out_world: *mut *mut mpca_world,
) -> mpca_status {
    guard(|c| {
        let out = c.out(out_world)?;
        if overlap(image.cast(), image_len, memory.cast(), len) {
            return Err(Refusal::new(mpca_status::Overlap, c"image"));
        }
        let image = c.slice(image.cast::<u8>(), image_len, mpca_status::BadLength)?;
        let bytes = c.slice_mut(memory.cast::<u8>(), len, mpca_status::BadLength)?;
        let claim = handle::claim(memory.cast(), len)?;
        let number = handle::reserve()?;
        let world = World::init_from_image(image, bytes)?;
        out.set(handle::issue(number, claim, world));
        Ok(())
    })
}
