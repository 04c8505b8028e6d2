//! What a renderer reads of a GPU world, kept on the GPU (`export2d.wgsl`):
//! the particles as instanced vertices, their count as an indirect draw, and
//! the density and mean velocity per tile of cells as a texture.

use wgpu::util::DeviceExt;

use crate::{Error, GpuWorld};

/// The buffers and the texture a render pass reads, refreshed by
/// [`Exports::record`] from the world's state where the encoder runs.
pub struct Exports {
    /// Per particle, in the CPU's cell order (`mpca::World::particles`),
    /// four `f32`: x and y of its cell's centre (cells), its velocity
    /// (cells a step). Usable as an instanced vertex buffer
    /// (`Float32x4`, `VertexStepMode::Instance`) and as a storage buffer.
    pub particles: wgpu::Buffer,
    /// An indirect draw's arguments (`draw_indirect`): 6 vertices (two
    /// triangles) a particle, the particles as instances.
    pub draw: wgpu::Buffer,
    /// `Rgba16Float`, a texel per `tile x tile` cells: red the share of the
    /// tile's cells holding a particle, green and blue their mean velocity
    /// (cells a step), alpha 1. Filterable, so a sampler smooths it.
    pub density: wgpu::Texture,
    /// The particles `particles` holds room for: the world's count when
    /// the exports were made. Particles beyond it (emitters add them) are
    /// left out of `particles` and the draw; exports made again take them.
    pub capacity: u64,
    /// Cells along a side of a texel of `density`.
    pub tile: u32,
    pipelines: [wgpu::ComputePipeline; 4],
    /// Per member of the world's pairs of buffers, the passes' bindings
    /// (which keep the buffers they bind).
    groups: [[wgpu::BindGroup; 4]; 2],
    /// Workgroups of the passes that take a row an invocation.
    row_groups: u32,
}

impl Exports {
    /// The exports of `world`, with a texel of `density` for each `tile x
    /// tile` cells (a power of two; the texture is rounded up to whole
    /// texels). Refused with `BadResolution` for another tile, or one that
    /// leaves the texture larger than the device allows, and with
    /// `FeatureDisabled` for a 3D world (the passes read 2D planes).
    pub fn new(world: &GpuWorld, tile: u32) -> Result<Exports, Error> {
        // The exports read the 2D planes' layout.
        if world.host.description().dim != 2 {
            return Err(Error::World(mpca::Error::new(mpca::ErrorKind::FeatureDisabled, c"desc.dim: the exports read 2D planes")));
        }
        let device = &world.gpu.device;
        let [nx, ny, _] = world.host.description().size;
        let size = [nx.div_ceil(tile.max(1)), ny.div_ceil(tile.max(1))];
        let largest = device.limits().max_texture_dimension_2d;
        if !tile.is_power_of_two() || size[0] > largest || size[1] > largest {
            let why = if tile.is_power_of_two() { c"tile: the texture exceeds the device's largest" } else { c"tile is not a power of two" };
            return Err(Error::World(mpca::Error::new(mpca::ErrorKind::BadResolution, why)));
        }
        let capacity = world.host.particle_count().max(1);
        let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let particles = device.create_buffer(&wgpu::BufferDescriptor { label: Some("particles"), size: 16 * capacity, usage: storage | wgpu::BufferUsages::VERTEX, mapped_at_creation: false });
        let draw = device.create_buffer(&wgpu::BufferDescriptor { label: Some("draw"), size: 16, usage: storage | wgpu::BufferUsages::INDIRECT, mapped_at_creation: false });
        let rows = device.create_buffer(&wgpu::BufferDescriptor { label: Some("rows"), size: 4 * u64::from(ny), usage: storage, mapped_at_creation: false });
        let density = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("density"),
            size: wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba16Float,
            usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let wide = world.host.description().quantization == mpca::Quantization::Bits16;
        let info = [nx, ny, 2 * nx.div_ceil(64), tile, capacity as u32, if wide { 32767 } else { 127 }, u32::from(wide)];
        let info = device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some("export info"), contents: bytemuck::cast_slice(&info), usage: wgpu::BufferUsages::STORAGE });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some("export2d.wgsl"), source: wgpu::ShaderSource::Wgsl(include_str!("export2d.wgsl").into()) });
        let entries = ["count_rows", "scan_rows", "write_particles", "write_density"];
        let pipelines = entries.map(|entry| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor { label: Some(entry), layout: None, module: &module, entry_point: Some(entry), compilation_options: Default::default(), cache: None })
        });
        let view = density.create_view(&wgpu::TextureViewDescriptor::default());
        // Each pass's layout holds the bindings it uses (wgpu derives it).
        let uses: [&[u32]; 4] = [&[0, 1, 3], &[0, 3, 5], &[0, 1, 2, 3, 4], &[0, 1, 2, 6]];
        let group = |member: usize, pass: usize| {
            let resource = |binding: u32| match binding {
                0 => info.as_entire_binding(),
                1 => world.occupancy[member].as_entire_binding(),
                2 => world.velocity[member].as_entire_binding(),
                3 => rows.as_entire_binding(),
                4 => particles.as_entire_binding(),
                5 => draw.as_entire_binding(),
                _ => wgpu::BindingResource::TextureView(&view),
            };
            let entries: Vec<wgpu::BindGroupEntry<'_>> = uses[pass].iter().map(|&binding| wgpu::BindGroupEntry { binding, resource: resource(binding) }).collect();
            device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(entries_label(pass)), layout: &pipelines[pass].get_bind_group_layout(0), entries: &entries })
        };
        let groups = [0, 1].map(|member| [0, 1, 2, 3].map(|pass| group(member, pass)));
        Ok(Exports { particles, draw, density, capacity, tile, pipelines, groups, row_groups: ny.div_ceil(64) })
    }

    /// Records the passes that refresh the exports from `world` as it
    /// stands after the steps recorded before them, into `encoder` (an
    /// engine's frame, before its render pass).
    pub fn record(&self, world: &GpuWorld, encoder: &mut wgpu::CommandEncoder) {
        let groups = &self.groups[world.current];
        let size = self.density.size();
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("mpca exports"), timestamp_writes: None });
        let work = [[self.row_groups, 1], [1, 1], [self.row_groups, 1], [size.width.div_ceil(8), size.height.div_ceil(8)]];
        for (i, [x, y]) in work.into_iter().enumerate() {
            pass.set_pipeline(&self.pipelines[i]);
            pass.set_bind_group(0, &groups[i], &[]);
            pass.dispatch_workgroups(x, y, 1);
        }
    }
}

/// A label for pass `i`'s bindings.
fn entries_label(pass: usize) -> &'static str {
    ["count rows", "scan rows", "write particles", "write density"][pass]
}
