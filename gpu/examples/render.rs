//! A large 2D world stepped on the GPU and drawn from the backend's exports
//! with no read-back of particles: `cargo run --release -p mpca-gpu
//! --example render [-- OUT.png [STEPS [SIZE [PIXELS]]]]`.
//!
//! The world is the aggregation gas over a whole periodic `SIZE x SIZE`
//! world (default 1024; `mpca_tests::scenes::full_gas`). It takes `STEPS`
//! steps (default 400) recorded into command encoders, the exports are
//! recorded after them, and a render pass draws the density texture as a
//! glow and every particle as an instanced quad from the particles buffer,
//! with an indirect draw whose count the GPU wrote. Only the finished
//! picture is read back, to write the PNG (default
//! `target/gpu/gas-SIZE.png`, `PIXELS` square, default one pixel a cell; a
//! particle is drawn at least a pixel wide). The same world is then
//! stepped on the CPU, and both hashes are printed: they are equal.

use std::time::Instant;

use mpca_gpu::{Exports, Gpu, GpuWorld};
use mpca_tests::scenes::{build, full_gas};

/// The picture's format: 8-bit sRGB, as PNG stores it.
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let size: u32 = 1024;
    let out = args.next();
    let steps: u64 = args.next().map_or(Ok(400), |s| s.parse())?;
    let size: u32 = args.next().map_or(Ok(size), |s| s.parse())?;
    let pixels: u32 = args.next().map_or(Ok(size), |s| s.parse())?;
    let out = out.unwrap_or_else(|| format!("target/gpu/gas-{size}.png"));
    let gpu = Gpu::new()?;
    println!("adapter: {}", gpu.adapter);
    let scene = full_gas("gas", size, steps);
    let mut memory = Vec::new();
    let world = build(&scene, &mut memory)?;
    let mut on_gpu = GpuWorld::new(&gpu, world)?;
    // A texel of the glow for each 8 x 8 cells.
    let exports = Exports::new(&on_gpu, 8)?;
    let device = &gpu.device;

    let start = Instant::now();
    let mut done = 0;
    while done < steps {
        let n = (steps - done).min(50);
        let mut encoder = device.create_command_encoder(&Default::default());
        on_gpu.record(&mut encoder, n);
        gpu.queue.submit([encoder.finish()]);
        done += n;
    }

    let target = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("picture"),
        size: wgpu::Extent3d { width: pixels, height: pixels, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: FORMAT,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some("render2d.wgsl"), source: wgpu::ShaderSource::Wgsl(include_str!("render2d.wgsl").into()) });
    let pipeline = |vs: &str, fs: &str, buffers: &[Option<wgpu::VertexBufferLayout<'_>>]| {
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(vs),
            layout: None,
            vertex: wgpu::VertexState { module: &module, entry_point: Some(vs), compilation_options: Default::default(), buffers },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState { module: &module, entry_point: Some(fs), compilation_options: Default::default(), targets: &[Some(FORMAT.into())] }),
            multiview_mask: None,
            cache: None,
        })
    };
    let glow = pipeline("glow_vs", "glow_fs", &[]);
    // The particles buffer as it is: four floats a particle, one instance
    // each.
    let particle = wgpu::VertexBufferLayout { array_stride: 16, step_mode: wgpu::VertexStepMode::Instance, attributes: &wgpu::vertex_attr_array![0 => Float32x4] };
    let dots = pipeline("dot_vs", "dot_fs", &[Some(particle)]);
    // The world's size in cells, and a particle's width: a cell, or a
    // pixel where a pixel is wider.
    let world_size = [size as f32, size as f32, (size as f32 / pixels as f32).max(1.0), 0.0];
    let uniform = wgpu::util::DeviceExt::create_buffer_init(device, &wgpu::util::BufferInitDescriptor { label: Some("world"), contents: bytemuck::cast_slice(&world_size), usage: wgpu::BufferUsages::UNIFORM });
    let smooth = device.create_sampler(&wgpu::SamplerDescriptor { mag_filter: wgpu::FilterMode::Linear, min_filter: wgpu::FilterMode::Linear, ..Default::default() });
    let density = exports.density.create_view(&Default::default());
    let glow_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("glow"),
        layout: &glow.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&density) },
            wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::Sampler(&smooth) },
        ],
    });
    let dots_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("dots"),
        layout: &dots.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() }],
    });

    let mut encoder = device.create_command_encoder(&Default::default());
    exports.record(&on_gpu, &mut encoder);
    {
        let view = target.create_view(&Default::default());
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("picture"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::BLACK), store: wgpu::StoreOp::Store },
            })],
            ..Default::default()
        });
        pass.set_pipeline(&glow);
        pass.set_bind_group(0, &glow_group, &[]);
        pass.draw(0..3, 0..1);
        pass.set_pipeline(&dots);
        pass.set_bind_group(0, &dots_group, &[]);
        pass.set_vertex_buffer(0, exports.particles.slice(..));
        pass.draw_indirect(&exports.draw, 0);
    }
    // The picture alone comes back, its rows padded as a copy to a buffer
    // needs.
    let row = (4 * pixels).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let picture = device.create_buffer(&wgpu::BufferDescriptor { label: Some("picture"), size: u64::from(row) * u64::from(pixels), usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ, mapped_at_creation: false });
    encoder.copy_texture_to_buffer(
        target.as_image_copy(),
        wgpu::TexelCopyBufferInfo { buffer: &picture, layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: None } },
        target.size(),
    );
    gpu.queue.submit([encoder.finish()]);
    picture.slice(..).map_async(wgpu::MapMode::Read, |r| r.expect("the picture maps"));
    device.poll(wgpu::PollType::Wait { submission_index: None, timeout: None })?;
    let took = start.elapsed();
    let bytes = picture.slice(..).get_mapped_range()?.to_vec();
    let mut rgb = Vec::with_capacity(3 * (pixels * pixels) as usize);
    for y in 0..pixels as usize {
        for px in bytes[y * row as usize..][..4 * pixels as usize].chunks_exact(4) {
            rgb.extend_from_slice(&px[..3]);
        }
    }
    if let Some(dir) = std::path::Path::new(&out).parent() {
        std::fs::create_dir_all(dir)?;
    }
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(std::fs::File::create(&out)?), pixels, pixels);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_compression(png::Compression::High);
    encoder.write_header()?.write_image_data(&rgb)?;

    let gpu_hash = on_gpu.sync()?.state_hash();
    println!("{size}x{size} cells, {} particles, {steps} steps and the picture in {:.2} s on the GPU", world.particle_count(), took.as_secs_f64());
    world.step(steps);
    println!("hash on the GPU {gpu_hash:016x}, on the CPU {:016x}: {}", world.state_hash(), if gpu_hash == world.state_hash() { "equal" } else { "DIFFERENT" });
    println!("wrote {out}");
    if gpu_hash != world.state_hash() {
        return Err("the GPU's world differs from the CPU's".into());
    }
    Ok(())
}
