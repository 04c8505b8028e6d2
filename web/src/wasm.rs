//! The exports of mpca_web.wasm, for web/mpca.js: one world per scene, in
//! a static buffer each (no allocator), and an RGBA image of each. The
//! browser runs one thread, and only these functions touch the buffers.

use core::cell::{Cell, UnsafeCell};

use mpca::{Error, World};

use crate::scene::{self, Kind, SIZE};

/// Bytes for one world: above `mpca::world_bytes` of either scene.
const WORLD_BYTES: usize = 96 * 1024;
const PIXELS: usize = (SIZE * SIZE * 4) as usize;

struct Slot {
    memory: [u8; WORLD_BYTES],
    pixels: [u8; PIXELS],
    /// The world `scene::build` made in `memory` (which it may start past
    /// `memory`'s first byte, to align it). `memory` is reached through
    /// it alone once built.
    world: Option<&'static mut World>,
}

struct Slots(UnsafeCell<[Slot; 2]>);

// SAFETY: wasm32-unknown-unknown without the atomics feature has one
// thread; nothing else reaches the slots.
unsafe impl Sync for Slots {}

static SLOTS: Slots = Slots(UnsafeCell::new(
    [const { Slot { memory: [0; WORLD_BYTES], pixels: [0; PIXELS], world: None } }; 2],
));

/// The slot of scene `kind` (0 smoke, 1 water).
fn slot(kind: u32) -> Option<(Kind, &'static mut Slot)> {
    let k = Kind::from_index(kind)?;
    // SAFETY: one thread, and each export takes the slot once, so no two
    // references to it live at a time.
    let slots = unsafe { &mut *SLOTS.0.get() };
    Some((k, &mut slots[kind as usize]))
}

/// The last refusal of an export, for the page to show (`mpca_web_error`).
struct Last(Cell<Option<Error>>);

// SAFETY: as for `Slots`: one thread.
unsafe impl Sync for Last {}

static LAST: Last = Last(Cell::new(None));

/// Keeps `e` as the last refusal and returns its code, what the exports
/// return for it.
fn refused(e: Error) -> u32 {
    LAST.0.set(Some(e));
    e.code()
}

/// The detail of the last refusal (the field or part at fault, beside
/// the code the export returned): the address of static, NUL-terminated
/// text in the module's memory, or 0 while no export was refused. The
/// kinds' messages are left out of the module: the code says the kind.
#[unsafe(no_mangle)]
pub extern "C" fn mpca_web_error() -> *const u8 {
    LAST.0.get().map_or(core::ptr::null(), |e| e.c_detail().as_ptr().cast())
}

/// The world of a slot, if built.
fn world(s: &mut Slot) -> Option<&mut World> {
    s.world.as_deref_mut()
}

/// Builds scene `kind` with `seed`; 0 on success, else the error's code
/// (its text: `mpca_web_error`).
#[unsafe(no_mangle)]
pub extern "C" fn mpca_web_init(kind: u32, seed: u32) -> u32 {
    let Some((k, s)) = slot(kind) else { return 1 };
    s.world = None;
    // SAFETY: the slot lives for ever, and its memory is reached through
    // the world built in it alone (the old world, if any, was dropped
    // above), so this is the only reference to it.
    let memory: &'static mut [u8] = unsafe { &mut *core::ptr::addr_of_mut!(s.memory) };
    match scene::build(k, u64::from(seed), memory) {
        Ok(w) => {
            s.world = Some(w);
            0
        }
        Err(e) => refused(e),
    }
}

/// Steps scene `kind` `steps` times.
#[unsafe(no_mangle)]
pub extern "C" fn mpca_web_step(kind: u32, steps: u32) {
    if let Some((k, s)) = slot(kind)
        && let Some(w) = world(s)
    {
        for _ in 0..steps {
            scene::step(k, w);
        }
    }
}

/// The world's hash (M8): a BigInt in JavaScript.
#[unsafe(no_mangle)]
pub extern "C" fn mpca_web_hash(kind: u32) -> u64 {
    slot(kind).and_then(|(_, s)| world(s)).map_or(0, |w| w.state_hash())
}

/// The particles in scene `kind`.
#[unsafe(no_mangle)]
pub extern "C" fn mpca_web_particles(kind: u32) -> u32 {
    slot(kind).and_then(|(_, s)| world(s)).map_or(0, |w| w.particle_count() as u32)
}

/// Draws scene `kind` into its image and returns the image's address in
/// the module's memory (`SIZE` x `SIZE` RGBA), or 0.
#[unsafe(no_mangle)]
pub extern "C" fn mpca_web_render(kind: u32) -> *const u8 {
    let Some((k, s)) = slot(kind) else { return core::ptr::null() };
    let Some(w) = s.world.as_deref() else { return core::ptr::null() };
    scene::render(k, w, &mut s.pixels);
    s.pixels.as_ptr()
}

/// An emitter at cell (x, y) of scene `kind`; 0 on success, else the
/// error's code (its text: `mpca_web_error`).
#[unsafe(no_mangle)]
pub extern "C" fn mpca_web_emit(kind: u32, x: u32, y: u32) -> u32 {
    let Some((k, s)) = slot(kind) else { return 1 };
    let Some(w) = world(s) else { return 1 };
    match scene::emit(k, w, x, y) {
        Ok(_) => 0,
        Err(e) => refused(e),
    }
}

/// Cells along a side of each scene.
#[unsafe(no_mangle)]
pub extern "C" fn mpca_web_size() -> u32 {
    SIZE
}

#[panic_handler]
fn on_panic(_: &core::panic::PanicInfo<'_>) -> ! {
    core::arch::wasm32::unreachable()
}
