//! Hooks for tests and tools that look inside the renderer: the software rasterizer alone
//! over given segments, the vertex pool and a character's texture read back. Each waits for
//! the frames in flight and runs its own small frame graph.

use ash::vk;

use super::core::graph::{FrameGraph, ImageState};
use super::core::shared::{FrameBlock, HairVertex, SoftSegment, TextureBinding};
use super::crowd::CharacterId;
use super::frame::Frames;
use super::passes::{FrameRes, FrameSources, FrameTransients, PassSets};
use super::settings::{FrameSettings, RenderPath};
use super::soft::StrandRaster;
use super::transparency::Transparency;
use super::world::World;
use crate::vk::{Access, Buffer, GpuError, GpuResult};

use super::core::readback::{read_device_buffer, readback};

/// Draw `segments` (screen space and shaded, as generation appends them) with the
/// software rasterizer alone, over a black image with nothing in front, keeping `k`
/// fragments per pixel sorted, each with opacity `opacity` times its coverage; returns
/// the image (RGBA8, sRGB). Waits for the frames in flight. For tests and tools that
/// check the rasterizer apart from generation (single-sample targets only).
pub(in crate::render) fn rasterize_segments(
    frames: &mut Frames,
    world: &mut World,
    segments: &[SoftSegment],
    k: u32,
    opacity: f32,
) -> GpuResult<Vec<u8>> {
    let raster = StrandRaster::Software { k };
    let kbuffer = Transparency::KBuffer { budget: k };
    let settings = FrameSettings {
        path: RenderPath::Compute,
        raster,
        transparency: kbuffer,
        msaa: frames.desc.msaa,
        light_raster: super::settings::LightRaster::Hardware,
    };
    settings
        .validate(&frames.caps())
        .map_err(GpuError::Unsupported)?;
    if segments.is_empty() || segments.len() as u64 > frames.soft_budget.segments as u64 {
        return Err(GpuError::Unsupported(format!(
            "rasterize_segments: 1..={} segments",
            frames.soft_budget.segments
        )));
    }
    if !(0.0..=1.0).contains(&opacity) {
        return Err(GpuError::Unsupported(format!(
            "rasterize_segments: opacity {opacity} outside 0..=1"
        )));
    }
    frames.finish(&mut world.crowd)?;
    let i = frames.next;
    let (width, height) = frames.targets.size();
    frames.prepare_workspace(world, i, RenderPath::Mesh)?;
    let transients = frames.frame_transients((kbuffer, raster), None, k, None)?;
    let mut block: FrameBlock = bytemuck::Zeroable::zeroed();
    block.viewport = [
        width as f32,
        height as f32,
        1.0 / width as f32,
        1.0 / height as f32,
    ];
    block.transparency = kbuffer.frame_fields(1);
    super::soft::frame_fields(&mut block, raster, opacity, frames.soft_tuning());
    frames.slots[i]
        .frame_ubo
        .write(0, bytemuck::bytes_of(&block))?;
    let upload = Buffer::with_data(
        &frames.ctx,
        "soft segments upload",
        vk::BufferUsageFlags::TRANSFER_SRC,
        bytemuck::cast_slice(segments),
    )?;
    let mut image = readback(
        &frames.ctx,
        "image readback",
        width as u64 * height as u64 * 4,
    )?;
    let counts = (segments.len() as u32, k);
    let result = run_debug_graph(frames, world, i, (&upload, &image), &transients, counts);
    // Nothing is in flight any more: replaced objects can go now.
    drop(frames.transients.take_released());
    result?;
    image.read()
}

/// The graph of [`rasterize_segments`]: upload, the soft passes, readback.
fn run_debug_graph(
    frames: &mut Frames,
    world: &World,
    i: usize,
    (upload, image): (&Buffer, &Buffer),
    transients: &FrameTransients,
    counts: (u32, u32),
) -> GpuResult<()> {
    let ctx = frames.ctx.clone();
    let slot = &mut frames.slots[i];
    let sets = PassSets {
        frame: &slot.set,
        textures: world.crowd.texture_set(),
    };
    let profiler = &mut slot.profiler;
    let sources = FrameSources {
        work: &frames.work,
        targets: &mut frames.targets,
        shadow: &mut frames.shadow,
        history: None,
        skinned: &slot.skinned,
    };
    let (passes, pool) = (&frames.passes, &mut frames.transients);
    let result = ctx.submit_and_wait(|rec| {
        profiler.reset(rec);
        let mut g = FrameGraph::new(false);
        let r = FrameRes::new(&mut g, sources, transients);
        g.bind_transients(sets.frame);
        let upload_res = g.host_input("segments upload");
        let segments = r.soft_segments;
        g.pass("upload segments")
            .read(upload_res, Access::TransferRead)
            .discard(segments, Access::TransferWrite)
            .record(move |rec, res| {
                rec.copy_buffer(upload, 0, res.buffer(segments)?, 0, upload.size);
                Ok(())
            });
        passes.add_soft_only(&mut g, &r, sets, counts)?;
        let out = super::passes::output::add_image_readback(&mut g, &r, image);
        g.pass("host reads").read(out, Access::HostRead).done();
        g.run(rec, profiler, pool).map(|_| ())
    });
    result?
}

/// The first `count` vertices of the compute path's pool, as the last frame wrote them
/// (waits for every frame in flight).
pub(in crate::render) fn read_vertices(
    frames: &mut Frames,
    world: &mut World,
    count: u32,
) -> GpuResult<Vec<HairVertex>> {
    frames.finish(&mut world.crowd)?;
    let Some(pool) = &frames.work.pool else {
        return Ok(Vec::new());
    };
    let bytes = (count as u64 * size_of::<HairVertex>() as u64).min(pool.size);
    if bytes == 0 {
        return Ok(Vec::new());
    }
    Ok(bytemuck::pod_collect_to_vec(&read_device_buffer(
        &frames.ctx,
        pool,
        bytes,
    )?))
}

/// Read back character `id`'s texture `binding` (tightly packed texels, as in the bake).
/// Waits for every frame in flight; for tests and tools.
pub(in crate::render) fn read_texture(
    frames: &mut Frames,
    world: &mut World,
    id: CharacterId,
    binding: TextureBinding,
) -> GpuResult<Vec<u8>> {
    frames.finish(&mut world.crowd)?;
    let image = world.crowd.texture(id, binding)?;
    let mut out = readback(&frames.ctx, "texture readback", image.byte_size())?;
    frames.ctx.submit_and_wait(|rec| {
        let mut g = FrameGraph::new(false);
        let src = g.import_image("texture", image, ImageState::Fixed(Access::SampledRead));
        let dst = g.import_buffer("texture readback", &out);
        g.pass("copy texture")
            .read(src, Access::TransferRead)
            .discard(dst, Access::TransferWrite)
            .record(|rec, _| {
                rec.copy_image_to_buffer(image, &out);
                Ok(())
            });
        g.pass("host reads").read(dst, Access::HostRead).done();
        g.run_untimed(rec).map(|_| ())
    })??;
    out.read()
}
