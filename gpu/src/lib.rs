//! The block rule of `mpca` on the GPU: a [`GpuWorld`] steps a world in a
//! WGSL compute shader (`rule.wgsl`) and stays equal to the CPU's world
//! bit for bit (M8b in `docs/model.md`): the same hash, counters and
//! snapshot image after every step.
//!
//! The world lives in GPU buffers: the occupancy, one bit a cell as the CPU
//! keeps it, the stored velocities and what particles carry (lifetimes,
//! mass indices, ids, ages, tags), each in a pair of buffers that the
//! steps read and write in turn, and the planes a step only reads. A copy of the world on the CPU
//! (an [`mpca::World`]) keeps what does not change in a step (the
//! description) and what a step counts; [`GpuWorld::sync`] brings the
//! planes and the counters down into it, which checks them, and from there
//! come the hash, the statistics and the snapshot image.
//!
//! This version runs every part of the 2D rule: both velocity widths, one
//! mass or many (M9), every face, every force term (M5.1) and flow drag
//! (M5.1b), both collision rules (M5.2, M5.2b), both drift rules (M5.3),
//! reflection off walls and obstacles (M5.4, M7), every assignment method
//! (M5.6), contacts (M5.7), energy-neutral rounding (M1b), emitters and
//! lifetimes (M6), ids, ages and tags (M6b): the paper's aggregation,
//! cluster and smoke scenes, the smoke with flow drag and the benchmark's
//! gas. In 3D the same parts run with exact-fast or greedy assignment: the
//! paper's water scene among them. 3D exhaustive assignment is refused when
//! the world is made ([`mpca::ErrorKind::FeatureDisabled`], its detail
//! naming the field; [`unsupported`] names the part).
//!
//! ```
//! use mpca::{Description, WorldBox};
//!
//! # fn main() -> Result<(), mpca_gpu::Error> {
//! let mut world = WorldBox::new(&Description::new_2d(64, 64))?;
//! world.add_particle([3, 4, 0], [0.5, 0.25, 0.0])?;
//! world.add_particle([4, 4, 0], [-0.5, 0.0, 0.0])?;
//! let gpu = mpca_gpu::Gpu::new()?; // or Gpu::from_device(device, queue)
//! let mut on_gpu = mpca_gpu::GpuWorld::new(&gpu, &world)?; // a copy
//! on_gpu.step(100); // nothing read back
//! let mut encoder = gpu.device.create_command_encoder(&Default::default());
//! on_gpu.record(&mut encoder, 1); // or into an engine's frame
//! gpu.queue.submit([encoder.finish()]);
//! world.step(101);
//! let synced = on_gpu.sync()?; // an mpca::World: hash, stats, save
//! assert_eq!(synced.state_hash(), world.state_hash());
//! # Ok(())
//! # }
//! ```

mod export;

pub use export::Exports;

use std::ffi::CStr;

use mpca::port::{DragConstants, PortPlanes, StepConstants, StepCounts, TurbulenceConstants, VortexConstants};
use mpca::{Boundary, Collisions, Description, Drift, Method, Quantization, World, WorldBox};
use wgpu::util::DeviceExt;

/// Why a GPU world could not be made or stepped.
#[derive(Debug)]
pub enum Error {
    /// What the CPU world says: a bad description, or a part this backend
    /// does not run ([`mpca::ErrorKind::FeatureDisabled`]); its detail names
    /// the field or part at fault.
    World(mpca::Error),
    /// No adapter (a GPU, or a software one such as lavapipe) was found.
    NoAdapter(String),
    /// The adapter would not give a device.
    Device(String),
    /// [`GpuWorld::sync`] found fewer steps run than were recorded: an
    /// encoder that [`GpuWorld::record`] wrote to was not submitted.
    Unsubmitted,
}

impl core::fmt::Display for Error {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            // The kind's message and the detail (mpca::Error's Display).
            Error::World(e) => write!(f, "{e}"),
            Error::NoAdapter(why) => write!(f, "no GPU adapter: {why}"),
            Error::Device(why) => write!(f, "the GPU adapter gave no device: {why}"),
            Error::Unsubmitted => write!(f, "steps were recorded into an encoder that was not submitted"),
        }
    }
}

impl std::error::Error for Error {}

impl From<mpca::Error> for Error {
    fn from(e: mpca::Error) -> Self {
        Error::World(e)
    }
}

/// A device and its queue: made here ([`Gpu::new`]), or the caller's
/// ([`Gpu::from_device`]), as an engine that owns its device has them.
#[derive(Clone)]
pub struct Gpu {
    /// The device the worlds' buffers and shaders live on.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// The adapter's name and driver, where this made the device.
    pub adapter: String,
    /// The step's pipelines of each dimension (2D first), compiled for the
    /// first world of that dimension made on this device and shared by
    /// every other (clones of a `Gpu` share them).
    pipelines: std::sync::Arc<[std::sync::OnceLock<Pipelines>; 2]>,
}

/// The compute pipelines of the rule (`rule.wgsl`) in one dimension: the
/// sweep, the end of a step, the emitters.
struct Pipelines {
    step: wgpu::ComputePipeline,
    end: wgpu::ComputePipeline,
    emit: wgpu::ComputePipeline,
}

/// The shader of each dimension: what the dimension does its own way,
/// then the rule both share, written once.
const SHADERS: [(&str, &str); 2] = [
    ("step2d.wgsl, rule.wgsl", concat!(include_str!("step2d.wgsl"), include_str!("rule.wgsl"))),
    ("step3d.wgsl, rule.wgsl", concat!(include_str!("step3d.wgsl"), include_str!("rule.wgsl"))),
];

impl Pipelines {
    /// The pipelines of a world of `dim` dimensions.
    fn of(device: &wgpu::Device, dim: u32) -> Pipelines {
        let (label, source) = SHADERS[dim as usize - 2];
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some(label), source: wgpu::ShaderSource::Wgsl(source.into()) });
        let pipeline = |entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: None,
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        Pipelines { step: pipeline("sweep"), end: pipeline("end_step"), emit: pipeline("emit") }
    }
}

impl Gpu {
    /// A device on the first adapter wgpu finds (the `WGPU_BACKEND` and
    /// `WGPU_ADAPTER_NAME` variables of wgpu choose another).
    pub fn new() -> Result<Gpu, Error> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let options = wgpu::RequestAdapterOptions { power_preference: wgpu::PowerPreference::HighPerformance, ..Default::default() };
        let adapter = pollster::block_on(instance.request_adapter(&options)).map_err(|e| Error::NoAdapter(e.to_string()))?;
        let info = adapter.get_info();
        let descriptor = wgpu::DeviceDescriptor { label: Some("mpca"), required_limits: adapter.limits(), ..Default::default() };
        let (device, queue) = pollster::block_on(adapter.request_device(&descriptor)).map_err(|e| Error::Device(e.to_string()))?;
        Ok(Gpu { device, queue, adapter: format!("{} ({:?}, {})", info.name, info.backend, info.driver_info), pipelines: Default::default() })
    }

    /// The caller's device and queue.
    pub fn from_device(device: wgpu::Device, queue: wgpu::Queue) -> Gpu {
        Gpu { device, queue, adapter: String::from("the caller's device"), pipelines: Default::default() }
    }

    /// The contents of `buffer` (which needs `COPY_SRC`), read back after
    /// everything submitted before: a copy into a buffer the CPU maps.
    /// Waits for the GPU.
    pub fn read(&self, buffer: &wgpu::Buffer) -> Vec<u8> {
        let size = buffer.size();
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor { label: Some("read back"), size, usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST, mapped_at_creation: false });
        let mut encoder = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("read back") });
        encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
        self.queue.submit([encoder.finish()]);
        staging.slice(..).map_async(wgpu::MapMode::Read, |r| r.expect("mapping a read-back buffer"));
        self.device.poll(wgpu::PollType::Wait { submission_index: None, timeout: None }).expect("waiting for the GPU");
        let bytes = staging.slice(..).get_mapped_range().expect("a mapped read-back buffer").to_vec();
        staging.unmap();
        bytes
    }
}

/// Why this backend cannot run a description: `None` where it can.
pub fn unsupported(d: &Description) -> Option<&'static str> {
    refusal(d).map(|(_, part)| part)
}

/// What [`unsupported`] names, and the detail of the refusal: the field
/// that asks for it.
fn refusal(d: &Description) -> Option<(&'static CStr, &'static str)> {
    let checks: [(bool, &'static CStr, &'static str); 2] = [
        // Correct where loops are not limited, but a dense 3D block's search
        // (8! leaves) runs past the loop limit of Mesa's lavapipe, which
        // ends a shader's loops after 65,535 iterations in all: untested.
        (d.dim == 2 || d.method != Method::Exhaustive, c"desc.method: exhaustive assignment in 3D", "exhaustive assignment in 3D"),
        (!(d.obstacles && d.body_capacity > 0), c"desc.body_capacity: bodies, obstacles the caller moves (M13)", "bodies, obstacles the caller moves (M13)"),
    ];
    checks.iter().find(|(ok, ..)| !ok).map(|&(_, detail, part)| (detail, part))
}

/// The refusal of a description this backend does not run, if it is one.
fn check_supported(d: &Description) -> Result<(), Error> {
    match refusal(d) {
        Some((detail, _)) => Err(Error::World(mpca::Error::new(mpca::ErrorKind::FeatureDisabled, detail))),
        None => Ok(()),
    }
}

/// Where the tables lie in the shader's table buffer (`step2d.wgsl`).
const TURNS_AT: usize = 256;
const KEYS_AT: usize = 2304;
const LISTS_AT: usize = 3600;
const KEYS_2D: usize = 1296;

/// The rule's tables as the shader reads them: M5.3's move limits, M5.2's
/// turns and M5.6's 2D assignments, from the core crate.
fn tables(moves: &[u16; 256]) -> Vec<u32> {
    let mut t = vec![0u32; LISTS_AT];
    for (i, &m) in moves.iter().enumerate() {
        t[i] = u32::from(m);
    }
    for j in 0..1024u32 {
        let (c, s) = mpca::port::turn(j);
        t[TURNS_AT + 2 * j as usize] = c as u32;
        t[TURNS_AT + 2 * j as usize + 1] = s as u32;
    }
    for key in 0..KEYS_2D {
        if let Some(list) = mpca::port::optimal_moves_2d(key) {
            let start = t.len() - LISTS_AT;
            t[KEYS_AT + key] = start as u32 | (list.len() as u32) << 16;
            t.extend(list.iter().map(|&m| u32::from(m)));
        }
    }
    t
}

/// The counters buffer: pairs (low, high) of collisions, clamps, clamp
/// energy, displaced, exited; the blocks processed in the step; a flag for
/// a saturated clamp energy; the blocks processed in the last step; the
/// number of the step the world takes next (low, high); pairs of the
/// particles emitted, the emitters' shortfall and the particles whose
/// lifetime ended; the last id given (M6b), which a sync does not clear.
const COUNTERS: usize = 22;
/// Where the last id given lies in the counters.
const IDS_GIVEN: usize = 21;
/// Words a surface entry takes in the shader's surface table.
const SURFACE: usize = 5;
/// Words an emitter takes in the shader's emitter table.
const EMITTER: usize = 16;
/// The counters a sync takes into the CPU copy and clears: all but the
/// step number.
const COUNTED: usize = 13;
/// Where the emitted particles, the shortfall and the expired lie in the
/// counters.
const EMITTED: usize = 15;

/// A world stepped on the GPU, equal to the CPU's bit for bit.
pub struct GpuWorld {
    gpu: Gpu,
    /// The world's copy on the CPU: its description, and its planes and
    /// counters as of the last [`GpuWorld::sync`].
    host: WorldBox,
    /// Steps run on the GPU since the last sync.
    pending: u64,
    pipeline: wgpu::ComputePipeline,
    /// The world's integers and the rule's tables (`rule.wgsl`), written
    /// again when an image brings another description.
    params: wgpu::Buffer,
    tables: wgpu::Buffer,
    /// `emit` (M6) with its bindings, where the world has emitters: per
    /// member of the pairs, the one it writes (the next step's input).
    emit: Option<(wgpu::ComputePipeline, [wgpu::BindGroup; 2])>,
    emitters: wgpu::Buffer,
    emitter_stats: wgpu::Buffer,
    /// `end_step`: the last step's processed blocks, the step number.
    end: wgpu::ComputePipeline,
    end_group: wgpu::BindGroup,
    occupancy: [wgpu::Buffer; 2],
    velocity: [wgpu::Buffer; 2],
    /// The lifetimes (M6), where the world has them (a word otherwise).
    life: [wgpu::Buffer; 2],
    /// The force field, potential and wind planes (M5.1, M5.1b), as the
    /// world had them when made or loaded.
    fields: [wgpu::Buffer; 3],
    /// The obstacle cells and their surface entries (M7), as the world had
    /// them when made or loaded.
    obstacles: [wgpu::Buffer; 2],
    /// The mass indices (M9) and tags (M6b), 16 bits a cell, where the
    /// world has either (a word otherwise), and the classes the indices
    /// stand for.
    mass: [wgpu::Buffer; 2],
    /// M6b's ids and ages, two words a cell, where the world keeps either.
    ident: [wgpu::Buffer; 2],
    classes: wgpu::Buffer,
    counters: wgpu::Buffer,
    /// `groups[i]` reads pair member `i` and writes the other.
    groups: [wgpu::BindGroup; 2],
    /// The member of each pair that holds the world now.
    current: usize,
    /// Workgroups along x (occupancy words) and y (rows of blocks).
    dispatch: [u32; 2],
}

impl GpuWorld {
    /// A GPU world holding `world`'s state (a copy: `world` is not
    /// changed). Refused with [`mpca::ErrorKind::FeatureDisabled`] where
    /// the description needs a part this backend does not run
    /// ([`unsupported`]).
    pub fn new(gpu: &Gpu, world: &World) -> Result<GpuWorld, Error> {
        check_supported(world.description())?;
        let mut image = vec![0u8; world.snapshot_bytes()];
        world.save(&mut image)?;
        let mut host = WorldBox::new(world.description())?;
        host.load(&image)?;
        let device = &gpu.device;
        let desc = *host.description();
        let [nx, ny, nz] = desc.size;
        let c = Contents::of(&host);
        let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let buffer = |label: &str, bytes: &[u8]| device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents: bytes, usage: storage });
        let pair = |label: &str, bytes: &[u8]| [buffer(label, bytes), buffer(label, bytes)];
        let [occupancy, velocity, life, mass, ident] = [("occupancy", 0), ("velocity", 1), ("life", 2), ("mass index and tag", 3), ("ids and ages", 4)].map(|(label, i)| pair(label, &c.planes[i]));
        let classes = buffer("classes", &c.classes);
        let fields = [("force field", 0), ("potential", 1), ("wind", 2)].map(|(label, i)| buffer(label, &c.fields[i]));
        let obstacles = [buffer("obstacles", &c.obstacles), buffer("surfaces", &c.surfaces)];
        let counters = buffer("counters", &c.counters);
        let params = buffer("params", &c.params);
        let tables = buffer("tables", &c.tables);
        let shared = gpu.pipelines[desc.dim as usize - 2].get_or_init(|| Pipelines::of(device, desc.dim));
        let (pipeline, end) = (shared.step.clone(), shared.end.clone());
        let emitters = buffer("emitters", &c.emitters);
        let emitter_stats = buffer("emitter stats", &c.emitter_stats);
        let emit = (desc.emitter_capacity > 0).then(|| {
            let pipeline = shared.emit.clone();
            let layout = pipeline.get_bind_group_layout(0);
            let group = |member: usize| {
                let entries = [(0, &params), (6, &counters), (7, &occupancy[member]), (8, &velocity[member]), (9, &emitters), (10, &emitter_stats), (13, &life[member]), (17, &obstacles[0]), (22, &mass[member]), (25, &ident[member])];
                let entries: Vec<wgpu::BindGroupEntry<'_>> = entries.iter().map(|&(binding, b)| wgpu::BindGroupEntry { binding, resource: b.as_entire_binding() }).collect();
                device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some("emit"), layout: &layout, entries: &entries })
            };
            (pipeline, [group(0), group(1)])
        });
        let end_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("end of step"),
            layout: &end.get_bind_group_layout(0),
            entries: &[wgpu::BindGroupEntry { binding: 6, resource: counters.as_entire_binding() }],
        });
        let layout = pipeline.get_bind_group_layout(0);
        let group = |from: usize| {
            let to = 1 - from;
            let entries = [(0, &params), (1, &tables), (2, &occupancy[from]), (3, &velocity[from]), (4, &occupancy[to]), (5, &velocity[to]), (6, &counters), (11, &life[from]), (12, &life[to]), (14, &fields[0]), (15, &fields[1]), (16, &fields[2]), (17, &obstacles[0]), (18, &obstacles[1]), (19, &classes), (20, &mass[from]), (21, &mass[to]), (23, &ident[from]), (24, &ident[to])];
            let entries: Vec<wgpu::BindGroupEntry<'_>> = entries.iter().map(|&(binding, b)| wgpu::BindGroupEntry { binding, resource: b.as_entire_binding() }).collect();
            device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some("step"), layout: &layout, entries: &entries })
        };
        let groups = [group(0), group(1)];
        let words = nx.div_ceil(32);
        Ok(GpuWorld {
            gpu: gpu.clone(),
            host,
            pending: 0,
            pipeline,
            params,
            tables,
            emit,
            emitters,
            emitter_stats,
            end,
            end_group,
            occupancy,
            velocity,
            life,
            fields,
            obstacles,
            mass,
            ident,
            classes,
            counters,
            groups,
            current: 0,
            // At offset 1 a face that is not periodic has a half block
            // more (the shader skips the row where it has not); rows of
            // blocks along y, then z.
            dispatch: [words.div_ceil(64), (ny / 2 + 1) * if desc.dim == 3 { nz / 2 + 1 } else { 1 }],
        })
    }

    /// Replaces the world with the one `image` holds (a snapshot, M12),
    /// mid-run: its state, counters, step number and settings. The image
    /// must be of a world of this size that this backend runs; otherwise
    /// it is refused (as [`mpca::World::load`] refuses it, `ImageMismatch`
    /// for another size, `FeatureDisabled` for a part not run here) and
    /// nothing changes. Steps run since the last sync are dropped with the
    /// old world. The new world is written through the queue, after what
    /// was submitted before.
    pub fn load(&mut self, image: &[u8]) -> Result<(), Error> {
        let desc = mpca::image_description(image)?;
        if desc.size != self.host.description().size || desc.dim != self.host.description().dim {
            return Err(Error::World(mpca::Error::new(mpca::ErrorKind::ImageMismatch, c"desc.size")));
        }
        check_supported(&desc)?;
        let mut host = WorldBox::new(&desc)?;
        host.load(image)?;
        // The same plan as the world's (checked by the load): every buffer
        // keeps its size.
        let c = Contents::of(&host);
        let now = self.current;
        let planes = [&self.occupancy[now], &self.velocity[now], &self.life[now], &self.mass[now], &self.ident[now]].into_iter().zip(&c.planes);
        let fields = self.fields.iter().zip(&c.fields);
        let rest = [(&self.classes, &c.classes), (&self.obstacles[0], &c.obstacles), (&self.obstacles[1], &c.surfaces), (&self.counters, &c.counters), (&self.params, &c.params), (&self.tables, &c.tables), (&self.emitters, &c.emitters), (&self.emitter_stats, &c.emitter_stats)];
        for (buffer, bytes) in planes.chain(fields).chain(rest) {
            self.gpu.queue.write_buffer(buffer, 0, bytes);
        }
        self.host = host;
        self.pending = 0;
        Ok(())
    }

    /// Runs `n` steps on the GPU: [`GpuWorld::record`] into an encoder of
    /// its own, submitted. Nothing is read back: [`GpuWorld::sync`] does
    /// that.
    pub fn step(&mut self, n: u64) {
        let mut encoder = self.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("mpca steps") });
        self.record(&mut encoder, n);
        self.gpu.queue.submit([encoder.finish()]);
    }

    /// Records `n` steps into the caller's `encoder` (an engine's frame),
    /// as one compute pass: the steps run where the caller submits it, in
    /// order with the rest of its work. Everything a step reads is on the
    /// GPU already (the step number too), so recording writes nothing
    /// through the queue. The encoder must be submitted before the next
    /// [`GpuWorld::sync`], which otherwise says so
    /// ([`Error::Unsubmitted`]).
    pub fn record(&mut self, encoder: &mut wgpu::CommandEncoder, n: u64) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("mpca steps"), timestamp_writes: None });
        for _ in 0..n {
            if let Some((emit, groups)) = &self.emit {
                pass.set_pipeline(emit);
                pass.set_bind_group(0, &groups[self.current], &[]);
                pass.dispatch_workgroups(1, 1, 1);
            }
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.groups[self.current], &[]);
            pass.dispatch_workgroups(self.dispatch[0], self.dispatch[1], 1);
            pass.set_pipeline(&self.end);
            pass.set_bind_group(0, &self.end_group, &[]);
            pass.dispatch_workgroups(1, 1, 1);
            self.current = 1 - self.current;
        }
        self.pending += n;
    }

    /// Brings the world down from the GPU into its CPU copy, and returns
    /// that: its hash, statistics and snapshot image are the GPU world's.
    /// The CPU copy checks what it takes (`mpca::World::port_finish_steps`):
    /// an error here is a fault of this backend, and leaves the copy as it
    /// was at the last sync.
    pub fn sync(&mut self) -> Result<&World, Error> {
        if self.pending > 0 {
            let occupancy: Vec<u64> = self.gpu.read(&self.occupancy[self.current]).chunks_exact(8).map(|b| u64::from_le_bytes(b.try_into().expect("8 bytes"))).collect();
            let velocity = self.gpu.read(&self.velocity[self.current]);
            let mut life = self.gpu.read(&self.life[self.current]);
            let mass = self.gpu.read(&self.mass[self.current]);
            let ident = self.gpu.read(&self.ident[self.current]);
            let counters: Vec<u32> = bytemuck::cast_slice(&self.gpu.read(&self.counters)).to_vec();
            let stats: Vec<u64> = bytemuck::cast_slice::<u8, u32>(&self.gpu.read(&self.emitter_stats)).chunks_exact(2).map(|w| u64::from(w[0]) | u64::from(w[1]) << 32).collect();
            let emitters = emitter_count(&self.host);
            let emitted: Vec<mpca::EmitterStats> = (0..emitters).map(|i| mpca::EmitterStats { requested: stats[2 * i], delivered: stats[2 * i + 1] }).collect();
            // The buffers are padded to whole words.
            let planes = self.host.port_planes();
            let velocity = from_gpu_velocity(self.host.description(), &velocity, planes.velocity.len());
            life.truncate(planes.life.len());
            // 16 bits a cell on the GPU, a byte each in the world; ids and
            // ages interleaved on the GPU.
            let mass_index: Vec<u8> = mass.chunks_exact(2).take(planes.mass_index.len()).map(|h| h[0]).collect();
            let tag: Vec<u8> = mass.chunks_exact(2).take(planes.tag.len()).map(|h| h[1]).collect();
            let id: Vec<u8> = ident.chunks_exact(8).take(planes.id.len() / 4).flat_map(|w| [w[0], w[1], w[2], w[3]]).collect();
            let age: Vec<u8> = ident.chunks_exact(8).take(planes.age.len() / 4).flat_map(|w| [w[4], w[5], w[6], w[7]]).collect();
            let row_words = planes.row_words;
            let wide = |i: usize| u64::from(counters[i]) | u64::from(counters[i + 1]) << 32;
            if wide(13) != self.host.stats().step.wrapping_add(self.pending) {
                return Err(Error::Unsubmitted);
            }
            let counts = StepCounts {
                steps: self.pending,
                collisions: wide(0),
                clamps: wide(2),
                clamp_energy: if counters[11] != 0 { u64::MAX } else { wide(4) },
                displaced: wide(6),
                exited: wide(8),
                blocks_processed: u64::from(counters[12]),
                emitted: wide(EMITTED),
                shortfall: wide(EMITTED + 2),
                expired: wide(EMITTED + 4),
                ids_given: counters[IDS_GIVEN],
            };
            let planes = PortPlanes { occupancy: &occupancy, row_words, velocity: &velocity, life: &life, mass_index: &mass_index, id: &id, age: &age, tag: &tag };
            self.host.port_finish_steps(&planes, &counts, &emitted)?;
            // Counted into the CPU copy: the GPU's start again from zero.
            self.gpu.queue.write_buffer(&self.counters, 0, &[0u8; 4 * COUNTED]);
            self.gpu.queue.write_buffer(&self.counters, 4 * EMITTED as u64, &[0u8; 24]);
            self.gpu.queue.write_buffer(&self.emitter_stats, 0, &vec![0u8; self.emitter_stats.size() as usize]);
            self.pending = 0;
        }
        Ok(&self.host)
    }

}

/// The bytes every buffer of a GPU world starts from, made from the world's
/// CPU copy, each padded to a buffer's size: what [`GpuWorld::new`] fills
/// its buffers with and [`GpuWorld::load`] writes into them.
struct Contents {
    /// The planes of a pair: occupancy, velocities, lifetimes, mass indices
    /// and tags, ids and ages.
    planes: [Vec<u8>; 5],
    classes: Vec<u8>,
    /// The force field, potential and wind planes.
    fields: [Vec<u8>; 3],
    obstacles: Vec<u8>,
    /// With room for every entry the description allows (an image may
    /// bring more than the world has).
    surfaces: Vec<u8>,
    counters: Vec<u8>,
    params: Vec<u8>,
    tables: Vec<u8>,
    /// With room for every emitter the description allows.
    emitters: Vec<u8>,
    emitter_stats: Vec<u8>,
}

impl Contents {
    fn of(host: &World) -> Contents {
        let desc = host.description();
        let p = host.port_planes();
        let f = host.port_fields();
        let words = |w: &[u32]| padded(bytemuck::cast_slice(w));
        let mut surfaces = surface_table(host);
        let count = surfaces.len() / SURFACE;
        surfaces.resize(SURFACE * (desc.surface_capacity as usize).max(1), 0);
        let capacity = desc.emitter_capacity as usize;
        Contents {
            planes: [padded(bytemuck::cast_slice(p.occupancy)), padded(&to_gpu_velocity(desc, p.velocity)), padded(p.life), padded(&carried(&p)), padded(&identities(&p))],
            classes: words(&class_table(host)),
            fields: [f.force, f.potential, f.wind].map(padded),
            obstacles: padded(bytemuck::cast_slice(host.port_obstacles())),
            surfaces: words(&surfaces),
            counters: words(&counters_of(host)),
            params: words(&params(&host.port_constants(), desc, emitter_count(host) as u32, count as u32)),
            tables: words(&tables(mpca::port::move_table_8(desc.drift))),
            emitters: words(&emitter_table(host, capacity)),
            emitter_stats: padded(&vec![0u8; 16 * capacity]),
        }
    }
}

/// `bytes` padded to a buffer's size: a multiple of 4 bytes, at least 4.
fn padded(bytes: &[u8]) -> Vec<u8> {
    let mut contents = bytes.to_vec();
    contents.resize(bytes.len().next_multiple_of(4).max(4), 0);
    contents
}

/// The surface entries of `host`'s obstacles as the shader reads them
/// (`rule.wgsl`): cell, normal x, y and z in Q30, restitution in Q16.
fn surface_table(host: &World) -> Vec<u32> {
    (0..).map_while(|i| host.port_surface(i)).flat_map(|e| [e.cell, e.normal[0] as u32, e.normal[1] as u32, e.normal[2] as u32, e.restitution as u32]).collect()
}

/// Bytes a cell's stored velocity takes in the world's plane (`dim`
/// components of one or two bytes) and in the shader's: the same in 2D; a
/// word (8-bit) or two (16-bit) in 3D (`rule.wgsl`).
fn velocity_strides(d: &Description) -> (usize, usize) {
    let bytes = if d.quantization == Quantization::Bits16 { 2 } else { 1 };
    let cpu = d.dim as usize * bytes;
    (cpu, if d.dim == 3 { 4 * bytes } else { cpu })
}

/// The world's velocity plane as the shader keeps it.
fn to_gpu_velocity(d: &Description, plane: &[u8]) -> Vec<u8> {
    let (cpu, gpu) = velocity_strides(d);
    plane.chunks_exact(cpu).flat_map(|cell| {
        let mut out = [0u8; 8];
        out[..cpu].copy_from_slice(cell);
        out.into_iter().take(gpu)
    }).collect()
}

/// The shader's velocity plane (padded) as the world keeps it, `len` bytes.
fn from_gpu_velocity(d: &Description, plane: &[u8], len: usize) -> Vec<u8> {
    let (cpu, gpu) = velocity_strides(d);
    plane.chunks_exact(gpu).flat_map(|cell| cell[..cpu].iter().copied()).take(len).collect()
}

/// What the shader keeps of a world's mass indices and tags: 16 bits a
/// cell (two cells a word: rows of an even width start on a word), the
/// index in the low byte and the tag in the high; empty where the world
/// has neither.
fn carried(p: &PortPlanes<'_>) -> Vec<u8> {
    let cells = p.mass_index.len().max(p.tag.len());
    (0..cells).flat_map(|i| [p.mass_index.get(i).copied().unwrap_or(0), p.tag.get(i).copied().unwrap_or(0)]).collect()
}

/// What the shader keeps of a world's ids and ages: two words a cell (id,
/// age); empty where the world keeps neither.
fn identities(p: &PortPlanes<'_>) -> Vec<u8> {
    let cells = p.id.len().max(p.age.len()) / 4;
    let word = |plane: &[u8], i: usize| plane.get(4 * i..4 * i + 4).map_or([0; 4], |w| [w[0], w[1], w[2], w[3]]);
    (0..cells).flat_map(|i| [word(p.id, i), word(p.age, i)].concat()).collect()
}

/// The shader's class table (`rule.wgsl`): for each of the 256 mass
/// indices its class (M1c) as 8 words.
fn class_table(host: &World) -> Vec<u32> {
    (0..=255u8)
        .flat_map(|i| {
            let c = host.port_class(i);
            let (g, e) = c.swirl.unwrap_or_default();
            [c.relative, c.energy.0, c.energy.1 as u32, c.push, g as u32, e as u32, 0, 0]
        })
        .collect()
}

/// The emitters `host` has.
fn emitter_count(host: &World) -> usize {
    (0..).take_while(|&i| host.port_emitter(i).is_some()).count()
}

/// The shader's emitter table (`rule.wgsl`, M6) for `capacity`
/// emitters, those of `host` first.
fn emitter_table(host: &World, capacity: usize) -> Vec<u32> {
    let mut table = vec![0u32; EMITTER * capacity];
    for (i, entry) in table.chunks_exact_mut(EMITTER).enumerate() {
        let Some(e) = host.port_emitter(i) else { break };
        entry.copy_from_slice(&[e.min[0], e.min[1], e.min[2], e.max[0], e.max[1], e.max[2], e.whole as u32, (e.whole >> 32) as u32, e.threshold, e.velocity[0] as u32, e.velocity[1] as u32, e.velocity[2] as u32, e.radius as u32, e.lifetime, u32::from(e.mass_index), u32::from(e.tag)]);
    }
    table
}

/// The counters buffer of a world as `host` holds it: nothing counted yet
/// on the GPU, and the number of the step it takes next.
fn counters_of(host: &World) -> [u32; COUNTERS] {
    let mut counters = [0u32; COUNTERS];
    let step = host.stats().step;
    (counters[13], counters[14]) = (step as u32, (step >> 32) as u32);
    counters[IDS_GIVEN] = host.port_ids_given();
    counters
}

/// The shader's parameters (`rule.wgsl`).
const PARAMS: usize = 67;

/// A face as the shader reads it: 0 periodic, 1 wall, 2 open.
fn face(b: Boundary) -> u32 {
    match b {
        Boundary::Periodic => 0,
        Boundary::Wall => 1,
        Boundary::Open => 2,
    }
}

/// The shader's parameters, the same every step (`rule.wgsl`), from
/// the world's constants `c`; what depends on the mass is in the class
/// table ([`class_table`]).
fn params(c: &StepConstants, d: &Description, d_emitters: u32, surfaces: u32) -> [u32; PARAMS] {
    let lo = |x: u64| x as u32;
    let hi = |x: u64| (x >> 32) as u32;
    let [nx, ny, nz] = d.size;
    let faces = (0..d.dim as usize).map(|k| (face(d.boundary[k][0]) | face(d.boundary[k][1]) << 2) << (4 * k)).fold(0, |all, f| all | f);
    let g = c.push.map(|g| g as u64);
    let v = c.vortex.unwrap_or(VortexConstants { centre: [0; 2], core: 0, flow: None });
    let flow = v.flow.unwrap_or_default();
    let drag = c.drag.unwrap_or(DragConstants { keep: 0, wind: [0; 3], field: false, turbulence: None });
    let eddies = drag.turbulence.unwrap_or(TurbulenceConstants { rate: 0, base: 0, t: 0, shift: 0, lambda: 0 });
    let rest = c.rest;
    let on = |x: bool| u32::from(x);
    [
        lo(d.seed),
        hi(d.seed),
        nz,
        0,
        0,
        0,
        nx,
        ny,
        2 * nx.div_ceil(64),
        u32::from(d.quantization == Quantization::Bits16),
        c.restitution as u32,
        c.unit as u32,
        drag.wind[2] as u32,
        0,
        faces,
        c.wall_restitution as u32,
        lo(g[0]),
        hi(g[0]),
        lo(g[1]),
        hi(g[1]),
        lo(g[2]),
        hi(g[2]),
        on(c.push != [0; 3] || d.forces.vortex || d.forces.field || d.forces.potential),
        u32::from(d.drift == Drift::Calibrated),
        u32::from(d.collisions == Collisions::SpeedLimited),
        c.speed_limit as u32,
        u32::from(d.contacts),
        on(d.forces.vortex),
        lo(v.centre[0] as u64),
        hi(v.centre[0] as u64),
        lo(v.centre[1] as u64),
        hi(v.centre[1] as u64),
        v.core,
        0,
        0,
        d_emitters,
        on(d.lifetimes),
        0,
        on(d.forces.potential),
        on(d.forces.field),
        surfaces,
        flow.0 as u32,
        flow.1 as u32,
        on(c.drag.is_some()),
        drag.keep as u32,
        drag.wind[0] as u32,
        drag.wind[1] as u32,
        on(drag.field),
        on(v.flow.is_some()),
        (c.unit >> c.fine) as u32,
        on(d.obstacles),
        on(d.energy_neutral),
        on(d.per_particle_mass),
        d.identity.bits(),
        d.method as u32,
        on(drag.turbulence.is_some()),
        eddies.rate,
        lo(eddies.base),
        hi(eddies.base),
        eddies.t as u32,
        eddies.shift as u32,
        eddies.lambda,
        on(rest.is_some()),
        rest.map_or(0, |r| r.axis),
        on(rest.is_some_and(|r| r.up)),
        rest.map_or(0, |r| r.lower),
        rest.map_or(0, |r| r.slow as u32),
    ]
}
