//! What the fuzz targets share: a reader that turns the fuzzer's bytes into
//! values, a scene description drawn from them, a safe wrapper over the C
//! ABI that fails the run on `MPCA_STATUS_PANIC`, and the image framing
//! (length field and CRC-32) the snapshot target repairs after mutating.

use core::ffi::c_void;
use core::ptr::{null, null_mut};

use mpca_ffi::*;

/// The fuzzer's bytes, read front to back; once they run out every read
/// gives zero, so any input decodes.
pub struct Input<'a> {
    data: &'a [u8],
}

impl<'a> Input<'a> {
    pub fn new(data: &'a [u8]) -> Self {
        Input { data }
    }

    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// The bytes not read yet.
    pub fn rest(&self) -> &'a [u8] {
        self.data
    }

    pub fn bytes<const N: usize>(&mut self) -> [u8; N] {
        let mut out = [0u8; N];
        let n = N.min(self.data.len());
        out[..n].copy_from_slice(&self.data[..n]);
        self.data = &self.data[n..];
        out
    }

    pub fn u8(&mut self) -> u8 {
        self.bytes::<1>()[0]
    }

    pub fn u16(&mut self) -> u16 {
        u16::from_le_bytes(self.bytes())
    }

    pub fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.bytes())
    }

    pub fn u64(&mut self) -> u64 {
        u64::from_le_bytes(self.bytes())
    }

    pub fn bit(&mut self) -> bool {
        self.u8() & 1 == 1
    }

    /// One of `0..n`.
    pub fn pick(&mut self, n: usize) -> usize {
        usize::from(self.u8()) % n
    }

    /// A float, mostly in [-1.28, 1.27] in steps of 0.01, sometimes one of
    /// the values that break careless checks (NaN, infinities, -0, values
    /// just past 1, subnormals), sometimes any bits at all.
    pub fn value(&mut self) -> f32 {
        let b = self.u8();
        if b < 0xf0 {
            return f32::from(b as i8) / 100.0;
        }
        match b {
            0xf1 => f32::NAN,
            0xf2 => f32::INFINITY,
            0xf3 => f32::NEG_INFINITY,
            0xf4 => 1.0f32.next_up(),
            0xf5 => core::f32::consts::FRAC_1_SQRT_2,
            0xf6 => -0.0,
            0xf7 => 1.0e30,
            0xf8 => f32::MIN_POSITIVE / 4.0,
            0xf9 => 1.0,
            0xfa => -1.0,
            _ => f32::from_bits(self.u32()),
        }
    }

    /// Three values.
    pub fn vector(&mut self) -> [f32; 3] {
        [self.value(), self.value(), self.value()]
    }

    /// A cell of a world of `n` cells per axis, or one past its end on an
    /// axis now and then (positions outside the world must be refused).
    pub fn position(&mut self, n: [u32; 3]) -> [u32; 3] {
        n.map(|n| u32::from(self.u8()) % (n + 1))
    }
}

/// A description drawn from the input with every field near its valid
/// range, so that most draws are worlds: sizes 2 to 32 (2D) or 2 to 8
/// (3D), every part and option possible. Some draws are still refused (a
/// drag wind too strong, a core radius of 0), which the targets skip.
pub fn scene(input: &mut Input<'_>) -> mpca_desc {
    let dim = if input.bit() { 3 } else { 2 };
    let n = |input: &mut Input<'_>| if dim == 2 { 2 * (1 + input.pick(16) as u32) } else { 2 * (1 + input.pick(4) as u32) };
    let (nx, ny, nz) = (n(input), n(input), n(input));
    let mut d = defaults(dim, nx, ny, nz);
    for axis in &mut d.boundary {
        // Periodic on both faces or on neither.
        *axis = [[0, 0], [1, 1], [2, 2], [1, 2], [2, 1]][input.pick(5)];
    }
    d.seed = input.u64();
    d.mass = [1.0, 0.5, 2.0, 3.0][input.pick(4)];
    let parts = input.u16();
    d.per_particle_mass = u32::from(parts & 1 != 0);
    d.mass_classes = 1 + input.pick(8) as u32;
    d.obstacles = u32::from(parts & 2 != 0);
    d.surface_capacity = input.pick(65) as u32;
    d.forces = u32::from(input.u8() & 15);
    d.gravity = input.vector().map(|g| g / 20.0);
    d.vortex_centre = [input.value() * nx as f32, input.value() * ny as f32];
    d.vortex_core_radius = [1.0, 0.5, 4.0, 1.0e-20, 0.0][input.pick(5)];
    d.vortex_circulation = input.value();
    d.restitution = f32::from(input.u8()) / 255.0;
    d.wall_restitution = f32::from(input.u8()) / 255.0;
    d.dt = [1.0, 0.5, 0.1, 0.0][input.pick(4)];
    d.quantization = if parts & 4 != 0 { 16 } else { 8 };
    d.drift = u32::from(parts & 8 != 0);
    // The exhaustive assignment tries every permutation of a block's cells:
    // 2D only, to keep a run's steps fast.
    d.method = if dim == 2 { input.pick(3) as u32 } else { 1 + input.pick(2) as u32 };
    d.emitter_capacity = input.pick(5) as u32;
    d.lifetimes = u32::from(parts & 16 != 0);
    d.collisions = u32::from(parts & 32 != 0);
    d.contacts = u32::from(parts & 64 != 0);
    d.energy_neutral = u32::from(parts & 128 != 0);
    d.drag_rate = [0.0, 0.0, 0.1, 1.0][input.pick(4)];
    d.drag_wind = input.vector().map(|w| w / 2.0);
    d.drag_vortex = u32::from(parts & 256 != 0);
    d.drag_wind_field = u32::from(parts & 512 != 0);
    // Bodies (M13), with obstacles: up to three, and room for a few cells.
    d.body_capacity = input.pick(4) as u32;
    d.body_surface_capacity = input.pick(129) as u32;
    d
}

/// The words of an `mpca_desc`, field by field in declaration order (the
/// seed as two, floats as their bits): what [`read_desc`] reads and
/// [`write_desc`] writes.
fn desc_words(d: &mut mpca_desc, each: &mut dyn FnMut(&mut u32)) {
    let mut seed = [d.seed as u32, (d.seed >> 32) as u32];
    fn float(f: &mut f32, each: &mut dyn FnMut(&mut u32)) {
        let mut bits = f.to_bits();
        each(&mut bits);
        *f = f32::from_bits(bits);
    }
    each(&mut d.struct_size);
    each(&mut d.dim);
    seed.iter_mut().for_each(&mut *each);
    d.seed = u64::from(seed[0]) | u64::from(seed[1]) << 32;
    d.size.iter_mut().for_each(&mut *each);
    d.boundary.iter_mut().flatten().for_each(&mut *each);
    float(&mut d.mass, each);
    for w in [&mut d.per_particle_mass, &mut d.mass_classes, &mut d.obstacles, &mut d.surface_capacity, &mut d.forces] {
        each(w);
    }
    for f in d.gravity.iter_mut().chain(d.vortex_centre.iter_mut()) {
        float(f, each);
    }
    for f in [&mut d.vortex_core_radius, &mut d.vortex_circulation, &mut d.restitution, &mut d.wall_restitution, &mut d.dt] {
        float(f, each);
    }
    for w in [
        &mut d.quantization,
        &mut d.drift,
        &mut d.method,
        &mut d.emitter_capacity,
        &mut d.lifetimes,
        &mut d.collisions,
        &mut d.contacts,
        &mut d.energy_neutral,
    ] {
        each(w);
    }
    float(&mut d.drag_rate, each);
    for f in d.drag_wind.iter_mut() {
        float(f, each);
    }
    each(&mut d.drag_vortex);
    each(&mut d.drag_wind_field);
    each(&mut d.identity);
    each(&mut d.body_capacity);
    each(&mut d.body_surface_capacity);
}

/// An `mpca_desc` from the input, every field any value.
pub fn read_desc(input: &mut Input<'_>) -> mpca_desc {
    let mut d = defaults(2, 2, 2, 0);
    desc_words(&mut d, &mut |w| *w = input.u32());
    d
}

/// The bytes [`read_desc`] reads back as `d`.
pub fn write_desc(d: &mpca_desc) -> Vec<u8> {
    let mut out = Vec::new();
    desc_words(&mut d.clone(), &mut |w| out.extend_from_slice(&w.to_le_bytes()));
    out
}

/// Fails the run on a status that only a bug can give.
#[track_caller]
pub fn check(s: mpca_status) -> mpca_status {
    assert_ne!(s, mpca_status::Panic, "the library panicked");
    s
}

/// The defaults of mpca_desc_defaults.
pub fn defaults(dim: u32, nx: u32, ny: u32, nz: u32) -> mpca_desc {
    let mut d = core::mem::MaybeUninit::<mpca_desc>::uninit();
    // SAFETY: `d` has room for one mpca_desc, which the call fills.
    assert_eq!(check(unsafe { mpca_desc_defaults(d.as_mut_ptr(), dim, nx, ny, nz) }), mpca_status::Ok);
    // SAFETY: written in full by the call above.
    unsafe { d.assume_init() }
}

/// mpca_desc_validate.
pub fn validate(d: &mpca_desc) -> mpca_status {
    // SAFETY: a live description.
    check(unsafe { mpca_desc_validate(d) })
}

/// mpca_world_bytes.
pub fn world_bytes(d: &mpca_desc) -> Result<usize, mpca_status> {
    let mut n = 0usize;
    // SAFETY: a live description and a live out-parameter.
    match check(unsafe { mpca_world_bytes(d, &mut n) }) {
        mpca_status::Ok => Ok(n),
        s => Err(s),
    }
}

/// mpca_desc_from_image.
pub fn desc_from_image(image: &[u8]) -> Result<mpca_desc, mpca_status> {
    let mut d = defaults(2, 2, 2, 0);
    // SAFETY: the image's bytes and a live out-parameter.
    match check(unsafe { mpca_desc_from_image(image.as_ptr().cast(), image.len(), &mut d) }) {
        mpca_status::Ok => Ok(d),
        s => Err(s),
    }
}

/// Turns a status into a result.
pub fn status(s: mpca_status) -> Result<(), mpca_status> {
    match check(s) {
        mpca_status::Ok => Ok(()),
        s => Err(s),
    }
}

/// A world behind its C handle, in library memory (mpca_world_create) or
/// in a buffer of ours (mpca_world_init), ended when dropped. Every method
/// is one call of the C ABI with pointers to live values of the sizes the
/// header asks for, which is what each `unsafe` below relies on.
pub struct World {
    handle: *mut mpca_world,
    memory: Option<Vec<u8>>,
}

impl World {
    /// mpca_world_create.
    pub fn create(d: &mpca_desc) -> Result<World, mpca_status> {
        let mut handle = null_mut();
        // SAFETY: a live description and out-parameter.
        status(unsafe { mpca_world_create(d, &mut handle) })?;
        Ok(World { handle, memory: None })
    }

    /// mpca_world_init in `memory` from byte `at` on; a refusal hands the
    /// memory back to be inspected.
    pub fn init(d: &mpca_desc, mut memory: Vec<u8>, at: usize) -> Result<World, (mpca_status, Vec<u8>)> {
        let mut handle = null_mut();
        let len = memory.len() - at;
        // SAFETY: `len` bytes of `memory` from `at`, which stays where it is
        // (a Vec's buffer does not move with the Vec) until deinit.
        let s = check(unsafe { mpca_world_init(d, memory.as_mut_ptr().add(at).cast(), len, &mut handle) });
        if s != mpca_status::Ok {
            return Err((s, memory));
        }
        Ok(World { handle, memory: Some(memory) })
    }

    /// mpca_world_init_from_image, as [`World::init`].
    pub fn init_from_image(image: &[u8], mut memory: Vec<u8>) -> Result<World, (mpca_status, Vec<u8>)> {
        let mut handle = null_mut();
        // SAFETY: as in `init`, and the image's bytes.
        let s = check(unsafe {
            mpca_world_init_from_image(image.as_ptr().cast(), image.len(), memory.as_mut_ptr().cast(), memory.len(), &mut handle)
        });
        if s != mpca_status::Ok {
            return Err((s, memory));
        }
        Ok(World { handle, memory: Some(memory) })
    }

    /// The buffer a world built by `init` lives in.
    pub fn memory(&self) -> Option<&[u8]> {
        self.memory.as_deref()
    }

    pub fn handle(&self) -> *mut mpca_world {
        self.handle
    }

    pub fn step(&mut self, n: u64) -> Result<(), mpca_status> {
        // SAFETY: a live handle.
        status(unsafe { mpca_world_step(self.handle, n) })
    }

    pub fn hash(&self) -> u64 {
        let mut h = 0;
        // SAFETY: a live handle and out-parameter.
        assert_eq!(check(unsafe { mpca_world_hash(self.handle, &mut h) }), mpca_status::Ok);
        h
    }

    pub fn stats(&self) -> mpca_stats {
        let mut s = mpca_stats { struct_size: size_of::<mpca_stats>() as u32, ..Default::default() };
        // SAFETY: a live handle and out-parameter.
        assert_eq!(check(unsafe { mpca_world_stats(self.handle, &mut s) }), mpca_status::Ok);
        s
    }

    pub fn desc(&self) -> mpca_desc {
        let mut d = defaults(2, 2, 2, 0);
        // SAFETY: a live handle and out-parameter.
        assert_eq!(check(unsafe { mpca_world_desc(self.handle, &mut d) }), mpca_status::Ok);
        d
    }

    pub fn cell(&self, pos: [u32; 3]) -> Result<mpca_cell, mpca_status> {
        let mut c = mpca_cell::default();
        // SAFETY: a live handle, 3 coordinates, an out-parameter.
        status(unsafe { mpca_world_cell(self.handle, pos.as_ptr(), &mut c) }).map(|()| c)
    }

    pub fn add_particle(&mut self, pos: [u32; 3], v: [f32; 3]) -> Result<(), mpca_status> {
        // SAFETY: a live handle and two arrays of 3.
        status(unsafe { mpca_world_add_particle(self.handle, pos.as_ptr(), v.as_ptr()) })
    }

    pub fn add_particle_mass(&mut self, pos: [u32; 3], v: [f32; 3], m: f32) -> Result<(), mpca_status> {
        // SAFETY: as in `add_particle`.
        status(unsafe { mpca_world_add_particle_mass(self.handle, pos.as_ptr(), v.as_ptr(), m) })
    }

    pub fn remove_particle(&mut self, pos: [u32; 3]) -> Result<mpca_particle, mpca_status> {
        let mut p = mpca_particle::default();
        // SAFETY: a live handle, 3 coordinates, an out-parameter.
        status(unsafe { mpca_world_remove_particle(self.handle, pos.as_ptr(), &mut p) }).map(|()| p)
    }

    pub fn add_emitter(&mut self, e: &mpca_emitter) -> Result<u32, mpca_status> {
        let mut i = 0;
        // SAFETY: a live handle, emitter and out-parameter.
        status(unsafe { mpca_world_add_emitter(self.handle, e, &mut i) }).map(|()| i)
    }

    pub fn set_emitter_rate(&mut self, index: u32, rate: f32) -> Result<(), mpca_status> {
        // SAFETY: a live handle.
        status(unsafe { mpca_world_set_emitter_rate(self.handle, index, rate) })
    }

    pub fn add_body(&mut self, shape: &mpca_shape, u: [f32; 3], e: f32) -> Result<u32, mpca_status> {
        let mut id = u32::MAX;
        // SAFETY: a live handle, a shape, an array of 3 and an out value.
        status(unsafe { mpca_world_add_body(self.handle, shape, u.as_ptr(), e, &mut id) }).map(|()| id)
    }

    pub fn move_body(&mut self, id: u32, shape: &mpca_shape, u: [f32; 3]) -> Result<(), mpca_status> {
        // SAFETY: a live handle, a shape and an array of 3.
        status(unsafe { mpca_world_move_body(self.handle, id, shape, u.as_ptr()) })
    }

    pub fn remove_body(&mut self, id: u32) -> Result<(), mpca_status> {
        // SAFETY: a live handle.
        status(unsafe { mpca_world_remove_body(self.handle, id) })
    }

    pub fn add_obstacle(&mut self, pos: [u32; 3], normal: [f32; 3], e: f32) -> Result<(), mpca_status> {
        // SAFETY: a live handle and two arrays of 3.
        status(unsafe { mpca_world_add_obstacle(self.handle, pos.as_ptr(), normal.as_ptr(), e) })
    }

    pub fn add_half_space(&mut self, point: [f32; 3], normal: [f32; 3], e: f32) -> Result<(), mpca_status> {
        // SAFETY: a live handle and two arrays of 3.
        status(unsafe { mpca_world_add_half_space(self.handle, point.as_ptr(), normal.as_ptr(), e) })
    }

    pub fn add_box(&mut self, min: [f32; 3], max: [f32; 3], e: f32) -> Result<(), mpca_status> {
        // SAFETY: a live handle and two arrays of 3.
        status(unsafe { mpca_world_add_box(self.handle, min.as_ptr(), max.as_ptr(), e) })
    }

    pub fn add_disc(&mut self, c: [f32; 2], r: f32, e: f32) -> Result<(), mpca_status> {
        // SAFETY: a live handle.
        status(unsafe { mpca_world_add_disc(self.handle, c[0], c[1], r, e) })
    }

    pub fn add_sphere(&mut self, c: [f32; 3], r: f32, e: f32) -> Result<(), mpca_status> {
        // SAFETY: a live handle and an array of 3.
        status(unsafe { mpca_world_add_sphere(self.handle, c.as_ptr(), r, e) })
    }

    pub fn add_obstacle_mask(&mut self, mask: &[u8], e: f32) -> Result<(), mpca_status> {
        // SAFETY: a live handle and the mask's bytes.
        status(unsafe { mpca_world_add_obstacle_mask(self.handle, mask.as_ptr(), mask.len(), e) })
    }

    pub fn surface(&self, pos: [u32; 3]) -> Result<([f32; 3], f32), mpca_status> {
        let (mut n, mut e) = ([0.0f32; 3], 0.0f32);
        // SAFETY: a live handle, 3 coordinates, room for 3 floats and 1.
        status(unsafe { mpca_world_surface(self.handle, pos.as_ptr(), n.as_mut_ptr(), &mut e) }).map(|()| (n, e))
    }

    pub fn set_gravity(&mut self, g: [f32; 3]) -> Result<(), mpca_status> {
        // SAFETY: a live handle and an array of 3.
        status(unsafe { mpca_world_set_gravity(self.handle, g.as_ptr()) })
    }

    pub fn set_force_field(&mut self, f: &[f32]) -> Result<(), mpca_status> {
        // SAFETY: a live handle and the slice's floats.
        status(unsafe { mpca_world_set_force_field(self.handle, f.as_ptr(), f.len()) })
    }

    pub fn set_cell_force(&mut self, pos: [u32; 3], f: [f32; 3]) -> Result<(), mpca_status> {
        // SAFETY: a live handle and two arrays of 3.
        status(unsafe { mpca_world_set_cell_force(self.handle, pos.as_ptr(), f.as_ptr()) })
    }

    pub fn set_wind_field(&mut self, u: &[f32]) -> Result<(), mpca_status> {
        // SAFETY: a live handle and the slice's floats.
        status(unsafe { mpca_world_set_wind_field(self.handle, u.as_ptr(), u.len()) })
    }

    pub fn set_cell_wind(&mut self, pos: [u32; 3], u: [f32; 3]) -> Result<(), mpca_status> {
        // SAFETY: a live handle and two arrays of 3.
        status(unsafe { mpca_world_set_cell_wind(self.handle, pos.as_ptr(), u.as_ptr()) })
    }

    pub fn set_potential(&mut self, u: &[f32]) -> Result<(), mpca_status> {
        // SAFETY: a live handle and the slice's floats.
        status(unsafe { mpca_world_set_potential(self.handle, u.as_ptr(), u.len()) })
    }

    pub fn set_cell_potential(&mut self, pos: [u32; 3], u: f32) -> Result<(), mpca_status> {
        // SAFETY: a live handle and an array of 3.
        status(unsafe { mpca_world_set_cell_potential(self.handle, pos.as_ptr(), u) })
    }

    pub fn set_vortex(&mut self, c: [f32; 2], r: f32, g: f32) -> Result<(), mpca_status> {
        // SAFETY: a live handle.
        status(unsafe { mpca_world_set_vortex(self.handle, c[0], c[1], r, g) })
    }

    /// One of the exports (`which`: positions, velocities, masses) into a
    /// buffer for `capacity` particles: the status, the count written and
    /// the floats.
    pub fn export(&self, which: usize, capacity: usize) -> (mpca_status, usize, Vec<f32>) {
        let per = if which == 2 { 1 } else { 3 };
        // A marker value, so that writes past what is promised show.
        let mut out = vec![-7.0f32; capacity * per];
        let mut count = usize::MAX;
        let f = [mpca_world_export_positions, mpca_world_export_velocities, mpca_world_export_masses][which];
        // SAFETY: a live handle, room for `capacity` particles, an out-parameter.
        let s = check(unsafe { f(self.handle, out.as_mut_ptr(), capacity, &mut count) });
        (s, count, out)
    }

    /// The particle count by the export's size query.
    pub fn count(&self) -> usize {
        let mut n = usize::MAX;
        // SAFETY: a live handle; NULL with capacity 0 is the size query.
        assert_eq!(check(unsafe { mpca_world_export_positions(self.handle, null_mut(), 0, &mut n) }), mpca_status::Ok);
        let mut m = usize::MAX;
        // SAFETY: a live handle and an out-parameter.
        assert_eq!(check(unsafe { mpca_world_particle_count(self.handle, &mut m) }), mpca_status::Ok);
        assert_eq!(n, m, "the size query and mpca_world_particle_count disagree");
        n
    }

    pub fn density(&self, res: [u32; 3], len: usize) -> Result<Vec<f32>, mpca_status> {
        let mut out = vec![-7.0f32; len];
        // SAFETY: a live handle, 3 values, `len` floats.
        status(unsafe { mpca_world_density(self.handle, res.as_ptr(), out.as_mut_ptr(), len) }).map(|()| out)
    }

    pub fn region_stats(&self, min: [u32; 3], max: [u32; 3]) -> Result<mpca_region_stats, mpca_status> {
        let mut r = mpca_region_stats { struct_size: size_of::<mpca_region_stats>() as u32, ..Default::default() };
        // SAFETY: a live handle, two arrays of 3, an out-parameter.
        status(unsafe { mpca_world_region_stats(self.handle, min.as_ptr(), max.as_ptr(), &mut r) }).map(|()| r)
    }

    /// The world's image, by the size query and a second call.
    pub fn save(&self) -> Vec<u8> {
        let mut need = 0usize;
        // SAFETY: a live handle; NULL with length 0 asks for the length.
        assert_eq!(check(unsafe { mpca_world_save(self.handle, null_mut(), 0, &mut need) }), mpca_status::Ok);
        let mut bytes = 0usize;
        // SAFETY: a live handle and an out-parameter.
        assert_eq!(check(unsafe { mpca_world_snapshot_bytes(self.handle, &mut bytes) }), mpca_status::Ok);
        assert_eq!(need, bytes, "mpca_world_save's size query and mpca_world_snapshot_bytes disagree");
        let mut image = vec![0u8; need];
        let mut written = 0usize;
        // SAFETY: a live handle, `need` bytes, an out-parameter.
        assert_eq!(check(unsafe { mpca_world_save(self.handle, image.as_mut_ptr().cast(), need, &mut written) }), mpca_status::Ok);
        assert_eq!(written, need);
        image
    }

    pub fn load(&mut self, image: &[u8]) -> Result<(), mpca_status> {
        // SAFETY: a live handle and the image's bytes.
        status(unsafe { mpca_world_load(self.handle, image.as_ptr().cast::<c_void>(), image.len()) })
    }

    /// Calls that must be refused whatever the world holds: NULL pointers,
    /// a wrong `struct_size`, a handle that is not one. Each must give its
    /// status and change nothing (the caller compares).
    pub fn refused_calls(&mut self, which: usize) -> mpca_status {
        let pos = [0u32; 3];
        let v = [0.0f32; 3];
        // SAFETY: every pointer is NULL or a live local; the forged handle
        // is refused by the registry before anything is read.
        let (s, want) = unsafe {
            match which % 7 {
                0 => (mpca_world_add_particle(self.handle, null(), v.as_ptr()), mpca_status::NullPointer),
                1 => (mpca_world_add_particle(self.handle, pos.as_ptr(), null()), mpca_status::NullPointer),
                2 => {
                    let mut st = mpca_stats { struct_size: 8, ..Default::default() };
                    (mpca_world_stats(self.handle, &mut st), mpca_status::BadStructSize)
                }
                3 => (mpca_world_step(self.handle.wrapping_byte_add(8), 1), mpca_status::BadHandle),
                4 => (mpca_world_set_force_field(self.handle, null(), 0), mpca_status::NullPointer),
                5 => (mpca_world_set_wind_field(self.handle, null(), 0), mpca_status::NullPointer),
                _ => (mpca_world_remove_particle(self.handle, pos.as_ptr(), null_mut()), mpca_status::NullPointer),
            }
        };
        assert_eq!(check(s), want, "refused call {which}");
        s
    }
}

impl Drop for World {
    fn drop(&mut self) {
        // SAFETY: a live handle, ended once.
        let s = unsafe { if self.memory.is_some() { mpca_world_deinit(self.handle) } else { mpca_world_destroy(self.handle) } };
        // Not while unwinding from a failed check: that would abort with
        // a second panic and hide the first.
        if !std::thread::panicking() {
            assert_eq!(check(s), mpca_status::Ok);
        }
    }
}

/// The image format's framing (docs/model.md, M12): bytes 16..24 hold the
/// image's length, the last four a CRC-32 of everything before them.
pub mod image {
    /// CRC-32 (the reflected polynomial 0xEDB88320, preset and inverted),
    /// a bit at a time: slow and obviously right.
    pub fn crc32(bytes: &[u8]) -> u32 {
        let mut crc = !0u32;
        for &b in bytes {
            crc ^= u32::from(b);
            for _ in 0..8 {
                crc = if crc & 1 == 1 { (crc >> 1) ^ 0xedb8_8320 } else { crc >> 1 };
            }
        }
        !crc
    }

    /// Makes the length field and the checksum agree with the bytes, so a
    /// mutation reaches the checks behind them.
    pub fn reframe(image: &mut [u8]) {
        if image.len() < 28 {
            return;
        }
        let len = image.len();
        image[16..24].copy_from_slice(&(len as u64).to_le_bytes());
        let crc = crc32(&image[..len - 4]);
        image[len - 4..].copy_from_slice(&crc.to_le_bytes());
    }
}
