//! `embed`: a minimal engine with its own Vulkan device that draws a textured floor and the
//! Sintel head, then has the hair renderer record the hair of one hair mesh (`sintel.obj`) into
//! its own command buffer, hidden behind its own depth and composited over its own colour,
//! seen through its own matrices (right-handed, reversed depth, infinite far plane). Headless;
//! writes a PNG. The engine is raw `ash`, as a real one would be, and lends the renderer its
//! memory allocator.
//!
//! `cargo run --release --example embed -- [--out embed.png] [--size 640x480] [--no-validation]`
//!
//! It draws the frame three times (the engine alone, with the hair, and with the hair but
//! without the engine's depth) to count the hair pixels shown and hidden by the engine's
//! geometry, and fails when either is zero or a validation message was printed.

mod engine;

use std::path::PathBuf;
use std::sync::Arc;

use anyhow::{Context as _, Result, bail};
use ash::vk;
use clap::Parser;
use engine::{Buf, Engine, Img, Validation, barrier, copy};
use glam::{Mat4, Vec3, Vec4};
use gpu_allocator::MemoryLocation;
use hairmesh::render::{
    FrameOptions, FrameTicket, HostCamera, HostFrame, HostImage, Renderer, RendererDesc,
    StrandParams, View,
};
use hairmesh::vk::{Access, Context, Image, ImageDesc};

/// Embed the hair renderer in a minimal engine and draw one frame.
#[derive(Parser)]
struct Args {
    /// Output PNG.
    #[arg(long, default_value = "embed.png")]
    out: PathBuf,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "640x480")]
    size: String,
    /// Run without the Vulkan validation layer (on by default, installed by tools/setup.sh;
    /// any message fails the run).
    #[arg(long)]
    no_validation: bool,
}

const COLOR_FORMAT: vk::Format = vk::Format::B8G8R8A8_SRGB;
const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;
/// Floats per vertex: position, normal, uv.
const VERTEX_FLOATS: usize = 8;

fn main() -> std::process::ExitCode {
    let parsed = hairmesh::cli::parse::<Args>("embed");
    hairmesh::cli::clean_up_on_signals("embed");
    match run(parsed.args) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("embed: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}

fn run(args: Args) -> Result<()> {
    let (w, h) = parse_size(&args.size)?;
    // The output is checked (and refused where it cannot be written) before any work.
    let output = hairmesh::fsutil::RunFiles::new().output(&args.out, "--out")?;
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("hairmeshes");
    let head = hairmesh::model::obj_io::load_triangles(&root.join("sintel_head.obj"))?;
    let (baked, style) =
        hairmesh::render::scene::load_mesh(&root.join("sintel.obj"), None, Default::default())?;
    let validation = match args.no_validation {
        false => Validation::On,
        true => Validation::Off,
    };
    let engine = Engine::new(validation)?;
    // The renderer on the engine's device, queue and allocator.
    let ctx = Arc::new(Context::from_host(engine.lend(!args.no_validation, true))?);
    let mut renderer = Renderer::new(&ctx, &RendererDesc::default().size(w, h))?;
    let params = StrandParams {
        strands_per_bundle: 64,
        verts_log2: 5,
    };
    renderer.add_character(&baked, &style, params, Mat4::IDENTITY)?;
    let scene = Scene::new(&engine, &head, (w, h))?;
    let targets = Targets::new(&engine, &ctx, (w, h))?;
    let [host_only, with_depth, without_depth] = draw(&engine, (&scene, &targets), &mut renderer)?;
    let differ = |a: &[u8], b: &[u8]| a.chunks(4).zip(b.chunks(4)).filter(|(p, q)| p != q).count();
    let shown = differ(&host_only, &with_depth);
    let hidden = differ(&with_depth, &without_depth);
    let rgba: Vec<u8> = with_depth
        .chunks(4)
        .flat_map(|p| [p[2], p[1], p[0], 255])
        .collect();
    let png = hairmesh::fsutil::encode_png(&args.out.display().to_string(), w, h, rgba)?;
    output.write(&png)?;
    println!(
        "{}: {w}x{h}, the engine's floor and head, the hair of sintel.obj over them: {shown} hair pixels shown, {hidden} hidden by the engine's geometry ({})",
        args.out.display(),
        ctx.info.name
    );
    drop(targets);
    drop(renderer);
    let errors = ctx.validation_errors();
    if errors > 0 {
        bail!(
            "{errors} validation messages: {:#?}",
            ctx.validation_messages()
        );
    }
    check_shares(shown, hidden, (w, h))
}

/// Shares of the picture with hair shown over the engine's colour and hidden by its depth,
/// measured at 640x480 on lavapipe (18,591 and 5,961 pixels); a run passes within a factor 2
/// of each. Hair composited nowhere (no shown pixels), the engine's depth ignored (none
/// hidden) or misconverted (everything hidden, or nothing) all fail.
const SHOWN_SHARE: f64 = 18_591.0 / (640.0 * 480.0);
/// See [`SHOWN_SHARE`].
const HIDDEN_SHARE: f64 = 5_961.0 / (640.0 * 480.0);

/// Fail unless `shown` and `hidden` pixels of a `w x h` picture are within a factor 2 of the
/// measured shares.
fn check_shares(shown: usize, hidden: usize, (w, h): (u32, u32)) -> Result<()> {
    let pixels = (w as f64) * (h as f64);
    for (what, count, measured) in [
        ("shown", shown, SHOWN_SHARE),
        ("hidden", hidden, HIDDEN_SHARE),
    ] {
        let share = count as f64 / pixels;
        if !(measured / 2.0..=measured * 2.0).contains(&share) {
            bail!(
                "{count} hair pixels {what} ({:.2}% of the picture); expected {:.2}% within a factor 2",
                share * 100.0,
                measured * 100.0
            );
        }
    }
    Ok(())
}

/// `WIDTHxHEIGHT`, 16..=4096 each.
fn parse_size(size: &str) -> Result<(u32, u32)> {
    size.split_once('x')
        .and_then(|(a, b)| Some((a.parse::<u32>().ok()?, b.parse::<u32>().ok()?)))
        .filter(|&(a, b)| (16..=4096).contains(&a) && (16..=4096).contains(&b))
        .with_context(|| format!("--size {size}: expected WIDTHxHEIGHT, 16..=4096 each"))
}

/// Three engine frames: the engine alone, with the hair behind its depth (slot 0), with the
/// hair ignoring its depth (slot 1); their colours (BGRA). Prints the second one's timings.
fn draw(
    engine: &Engine,
    (scene, targets): (&Scene, &Targets),
    renderer: &mut Renderer,
) -> Result<[Vec<u8>; 3]> {
    // The crowd's look (Marschner, shadows, multiple scattering); its camera is the engine's.
    let look = View::crowd_look(hairmesh::render::Camera::look_at(Vec3::Z, Vec3::ZERO, 40.0));
    let opts = FrameOptions::default();
    let host_only = frame(engine, scene, targets, |_| Ok(None))?;
    let mut draw_hair = |with_depth: bool, slot: usize| {
        let mut ticket = None;
        let colour = frame(engine, scene, targets, |cmd| {
            let frame = HostFrame {
                cmd,
                slot,
                camera: scene.camera,
                color: HostImage {
                    image: &targets.color_image,
                    before: Access::ColorAttachment,
                    after: Access::TransferRead,
                },
                depth: with_depth.then_some(HostImage {
                    image: &targets.depth_image,
                    before: Access::DepthAttachment,
                    after: Access::DepthAttachment,
                }),
                depth_slack: 0.0,
            };
            let t = renderer.record_host_frame(&look, &opts, frame)?;
            ticket = Some(t);
            Ok(Some(t))
        })?;
        Ok::<_, anyhow::Error>((colour, ticket.context("no hair frame")?))
    };
    let (with_depth, first) = draw_hair(true, 0)?;
    let (without_depth, _) = draw_hair(false, 1)?;
    // The engine waited for both submissions: their reports are ready without waiting.
    let report = renderer.wait(first)?;
    let pass = |name: &str| -> f64 {
        let times = report.pass_ms.iter().filter(|p| p.0 == name);
        times.map(|p| p.1).sum()
    };
    println!(
        "the hair frame with the engine's depth: {} strands, GPU {:.1} ms (lavapipe: the first frame of a pipeline is slow), of which the engine's depth in {:.2} ms and the composite {:.2} ms",
        report.stats.strands_drawn,
        report.gpu_ms(),
        pass("host depth"),
        pass("host composite"),
    );
    Ok([host_only, with_depth, without_depth])
}

/// One engine frame: the scene, then `hair` into the same command buffer, the colour copied
/// out; submitted and waited for. The colour's bytes (BGRA). The hair hands the colour back in
/// transfer-read use; without hair the engine moves it there itself.
fn frame(
    engine: &Engine,
    scene: &Scene,
    targets: &Targets,
    hair: impl FnOnce(vk::CommandBuffer) -> Result<Option<FrameTicket>>,
) -> Result<Vec<u8>> {
    let d = &engine.device;
    engine.submit(|cmd| {
        // SAFETY: the engine's command buffer, recording; its objects outlive the submission.
        unsafe {
            scene.record(engine, targets, cmd);
            if hair(cmd)?.is_none() {
                let layouts = (
                    vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                );
                barrier(d, cmd, &targets.color, layouts);
            }
            copy(d, cmd, (&targets.color, &targets.readback), false);
        }
        Ok(())
    })?;
    let (w, h) = targets.size;
    let memory = targets.readback.memory.as_ref().context("readback")?;
    Ok(memory.mapped_slice().context("mapped")?[..(w * h * 4) as usize].to_vec())
}

/// The engine's colour and depth targets, the renderer's wrappers of them, a readback buffer.
struct Targets<'e> {
    engine: &'e Engine,
    size: (u32, u32),
    color: Img,
    depth: Img,
    readback: Buf,
    color_image: Image,
    depth_image: Image,
}

impl<'e> Targets<'e> {
    fn new(engine: &'e Engine, ctx: &Arc<Context>, size: (u32, u32)) -> Result<Self> {
        use vk::ImageUsageFlags as U;
        let color_usage = U::COLOR_ATTACHMENT | U::TRANSFER_SRC;
        // The renderer samples the engine's depth.
        let depth_usage = U::DEPTH_STENCIL_ATTACHMENT | U::SAMPLED;
        let color = engine.image(size, COLOR_FORMAT, color_usage)?;
        let depth = engine.image(size, DEPTH_FORMAT, depth_usage)?;
        let bytes = size.0 as u64 * size.1 as u64 * 4;
        let readback = engine.buffer(
            vk::BufferUsageFlags::TRANSFER_DST,
            (bytes, MemoryLocation::GpuToCpu),
            &[],
        )?;
        let desc =
            |name, format, usage| ImageDesc::new_2d(name, format, size.0, size.1).usage(usage);
        Ok(Targets {
            engine,
            size,
            color_image: Image::from_host(
                ctx,
                color.raw,
                &desc("engine colour", COLOR_FORMAT, color_usage),
            )?,
            depth_image: Image::from_host(
                ctx,
                depth.raw,
                &desc("engine depth", DEPTH_FORMAT, depth_usage),
            )?,
            color,
            depth,
            readback,
        })
    }
}

impl Drop for Targets<'_> {
    fn drop(&mut self) {
        // The frames that used them completed (each frame is waited for).
        let e = self.engine;
        for img in [&mut self.color, &mut self.depth] {
            e.destroy_image(std::mem::replace(img, Img::null()));
        }
        e.destroy_buffer(std::mem::replace(&mut self.readback, Buf::null()));
    }
}

/// The engine's scene: a checker-textured floor and the head, one pipeline, the camera.
struct Scene<'e> {
    engine: &'e Engine,
    vertices: Buf,
    /// Floor vertices, then head vertices.
    counts: (u32, u32),
    texture: Img,
    sampler: vk::Sampler,
    set_layout: vk::DescriptorSetLayout,
    descriptor_pool: vk::DescriptorPool,
    set: vk::DescriptorSet,
    layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
    view_proj: Mat4,
    camera: HostCamera,
}

/// Push constants of the scene's shaders: the view-projection and a tint (w: textured).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Push {
    view_proj: [[f32; 4]; 4],
    tint: [f32; 4],
}

const SCENE_VERT: &str = r#"#version 450
layout(location = 0) in vec3 pos;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec2 uv;
layout(push_constant) uniform Push { mat4 view_proj; vec4 tint; } push;
layout(location = 0) out vec3 v_normal;
layout(location = 1) out vec2 v_uv;
void main() {
    gl_Position = push.view_proj * vec4(pos, 1.0);
    v_normal = normal;
    v_uv = uv;
}
"#;

const SCENE_FRAG: &str = r#"#version 450
layout(set = 0, binding = 0) uniform sampler2D checker;
layout(push_constant) uniform Push { mat4 view_proj; vec4 tint; } push;
layout(location = 0) in vec3 v_normal;
layout(location = 1) in vec2 v_uv;
layout(location = 0) out vec4 color;
void main() {
    vec3 l = normalize(vec3(0.4, 1.0, 0.3));
    float lit = 0.3 + 0.7 * abs(dot(normalize(v_normal), l));
    vec3 base = push.tint.w > 0.5 ? texture(checker, v_uv).rgb : push.tint.rgb;
    color = vec4(base * lit, 1.0);
}
"#;

impl<'e> Scene<'e> {
    fn new(engine: &'e Engine, head: &[[Vec3; 3]], (w, h): (u32, u32)) -> Result<Self> {
        let (lo, hi) = head
            .iter()
            .flatten()
            .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            });
        let (centre, size) = ((lo + hi) * 0.5, (hi - lo).length());
        let mut data: Vec<f32> = Vec::new();
        // The floor under the head, 20 tiles across.
        let y = lo.y;
        let r = size * 2.0;
        let corner = |x: f32, z: f32| {
            [
                centre.x + x * r,
                y,
                centre.z + z * r,
                0.0,
                1.0,
                0.0,
                (x + 1.0) * 10.0,
                (z + 1.0) * 10.0,
            ]
        };
        for (x, z) in [
            (-1.0, -1.0),
            (1.0, -1.0),
            (1.0, 1.0),
            (-1.0, -1.0),
            (1.0, 1.0),
            (-1.0, 1.0),
        ] {
            data.extend(corner(x, z));
        }
        for t in head {
            let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or(Vec3::Y);
            for p in t {
                data.extend([p.x, p.y, p.z, n.x, n.y, n.z, 0.0, 0.0]);
            }
        }
        let counts = (6, (head.len() * 3) as u32);
        let bytes: &[u8] = bytemuck::cast_slice(&data);
        let place = (bytes.len() as u64, MemoryLocation::CpuToGpu);
        let vertices = engine.buffer(vk::BufferUsageFlags::VERTEX_BUFFER, place, bytes)?;
        // A front three-quarter view from above: the head hides the hair behind it.
        let eye = centre + Vec3::new(0.8, 0.35, 1.0).normalize() * size * 1.6;
        let view = look_at(eye, centre);
        // Reversed depth, infinite far plane, Vulkan clip space (y down).
        let g = 1.0 / 20f32.to_radians().tan();
        let near = size * 0.01;
        let proj = Mat4::from_cols(
            Vec4::new(g * h as f32 / w as f32, 0.0, 0.0, 0.0),
            Vec4::new(0.0, -g, 0.0, 0.0),
            Vec4::new(0.0, 0.0, 0.0, -1.0),
            Vec4::new(0.0, 0.0, near, 0.0),
        );
        let texture = checker_texture(engine)?;
        let (set_layout, descriptor_pool, set, sampler) = texture_set(engine, &texture)?;
        let (layout, pipeline) = scene_pipeline(engine, set_layout)?;
        Ok(Scene {
            engine,
            vertices,
            counts,
            texture,
            sampler,
            set_layout,
            descriptor_pool,
            set,
            layout,
            pipeline,
            view_proj: proj * view,
            camera: HostCamera { view, proj },
        })
    }

    /// Draw the floor and the head into the targets (cleared; depth reversed, so cleared to 0).
    ///
    /// # Safety
    /// `cmd` is recording on the engine's device.
    unsafe fn record(&self, engine: &Engine, t: &Targets, cmd: vk::CommandBuffer) {
        let d = &engine.device;
        // SAFETY: per the caller; the targets and scene outlive the submission.
        unsafe {
            barrier(
                d,
                cmd,
                &t.color,
                (
                    vk::ImageLayout::UNDEFINED,
                    vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                ),
            );
            barrier(
                d,
                cmd,
                &t.depth,
                (
                    vk::ImageLayout::UNDEFINED,
                    vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
                ),
            );
            let (color, depth) = attachments(t);
            let area = vk::Rect2D {
                offset: vk::Offset2D::default(),
                extent: vk::Extent2D {
                    width: t.size.0,
                    height: t.size.1,
                },
            };
            let info = vk::RenderingInfo::default()
                .render_area(area)
                .layer_count(1)
                .color_attachments(&color)
                .depth_attachment(&depth);
            d.cmd_begin_rendering(cmd, &info);
            let viewport = vk::Viewport {
                x: 0.0,
                y: 0.0,
                width: t.size.0 as f32,
                height: t.size.1 as f32,
                min_depth: 0.0,
                max_depth: 1.0,
            };
            d.cmd_set_viewport(cmd, 0, &[viewport]);
            d.cmd_set_scissor(cmd, 0, &[area]);
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline);
            d.cmd_bind_descriptor_sets(
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                self.layout,
                0,
                &[self.set],
                &[],
            );
            d.cmd_bind_vertex_buffers(cmd, 0, &[self.vertices.raw], &[0]);
            for (first, count, tint) in [
                (0, self.counts.0, [1.0, 1.0, 1.0, 1.0]),
                (self.counts.0, self.counts.1, [0.8, 0.6, 0.5, 0.0]),
            ] {
                let push = Push {
                    view_proj: self.view_proj.to_cols_array_2d(),
                    tint,
                };
                d.cmd_push_constants(
                    cmd,
                    self.layout,
                    vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                    0,
                    bytemuck::bytes_of(&push),
                );
                d.cmd_draw(cmd, count, 1, first, 0);
            }
            d.cmd_end_rendering(cmd);
        }
    }
}

/// The engine's colour (cleared to sky blue) and depth (cleared to 0) attachments.
fn attachments(
    t: &Targets,
) -> (
    [vk::RenderingAttachmentInfo<'static>; 1],
    vk::RenderingAttachmentInfo<'static>,
) {
    let color = [vk::RenderingAttachmentInfo::default()
        .image_view(t.color.view)
        .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
        .load_op(vk::AttachmentLoadOp::CLEAR)
        .store_op(vk::AttachmentStoreOp::STORE)
        .clear_value(vk::ClearValue {
            color: vk::ClearColorValue {
                float32: [0.45, 0.55, 0.7, 1.0],
            },
        })];
    let depth = vk::RenderingAttachmentInfo::default()
        .image_view(t.depth.view)
        .image_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL)
        .load_op(vk::AttachmentLoadOp::CLEAR)
        .store_op(vk::AttachmentStoreOp::STORE)
        .clear_value(vk::ClearValue {
            depth_stencil: vk::ClearDepthStencilValue {
                depth: 0.0,
                stencil: 0,
            },
        });
    (color, depth)
}

impl Drop for Scene<'_> {
    fn drop(&mut self) {
        let d = &self.engine.device;
        // SAFETY: the frames that used them completed.
        unsafe {
            d.destroy_pipeline(self.pipeline, None);
            d.destroy_pipeline_layout(self.layout, None);
            d.destroy_descriptor_pool(self.descriptor_pool, None);
            d.destroy_descriptor_set_layout(self.set_layout, None);
            d.destroy_sampler(self.sampler, None);
        }
        let e = self.engine;
        e.destroy_image(std::mem::replace(&mut self.texture, Img::null()));
        e.destroy_buffer(std::mem::replace(&mut self.vertices, Buf::null()));
    }
}

/// A right-handed look-at view matrix (view space looks down -z, y up).
fn look_at(eye: Vec3, target: Vec3) -> Mat4 {
    let f = (target - eye).normalize();
    let s = f.cross(Vec3::Y).normalize();
    let u = s.cross(f);
    Mat4::from_cols(
        s.extend(0.0),
        u.extend(0.0),
        (-f).extend(0.0),
        eye.extend(1.0),
    )
    .inverse()
}

/// A 64x64 two-tone checker, uploaded and left in shader-read layout.
fn checker_texture(engine: &Engine) -> Result<Img> {
    let n = 64u32;
    let texels: Vec<u8> = (0..n * n)
        .flat_map(|i| match ((i % n) / 32 + (i / n) / 32) % 2 {
            0 => [200, 190, 170, 255],
            _ => [90, 80, 70, 255],
        })
        .collect();
    let usage = vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST;
    let image = engine.image((n, n), vk::Format::R8G8B8A8_SRGB, usage)?;
    let place = (texels.len() as u64, MemoryLocation::CpuToGpu);
    let staging = engine.buffer(vk::BufferUsageFlags::TRANSFER_SRC, place, &texels)?;
    let d = &engine.device;
    let uploaded = engine.submit(|cmd| {
        use vk::ImageLayout as L;
        // SAFETY: the engine's command buffer, recording; waited for before the staging
        // buffer goes.
        unsafe {
            barrier(d, cmd, &image, (L::UNDEFINED, L::TRANSFER_DST_OPTIMAL));
            copy(d, cmd, (&image, &staging), true);
            let layouts = (L::TRANSFER_DST_OPTIMAL, L::SHADER_READ_ONLY_OPTIMAL);
            barrier(d, cmd, &image, layouts);
        }
        Ok(())
    });
    engine.destroy_buffer(staging);
    uploaded?;
    Ok(image)
}

/// The texture's set: layout, pool, set and a repeating linear sampler.
fn texture_set(
    engine: &Engine,
    texture: &Img,
) -> Result<(
    vk::DescriptorSetLayout,
    vk::DescriptorPool,
    vk::DescriptorSet,
    vk::Sampler,
)> {
    let d = &engine.device;
    // SAFETY: the engine's device; destroyed with the scene.
    unsafe {
        let binding = [vk::DescriptorSetLayoutBinding::default()
            .binding(0)
            .descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
            .descriptor_count(1)
            .stage_flags(vk::ShaderStageFlags::FRAGMENT)];
        let layout = d.create_descriptor_set_layout(
            &vk::DescriptorSetLayoutCreateInfo::default().bindings(&binding),
            None,
        )?;
        let sizes = [vk::DescriptorPoolSize {
            ty: vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
            descriptor_count: 1,
        }];
        let pool = d.create_descriptor_pool(
            &vk::DescriptorPoolCreateInfo::default()
                .max_sets(1)
                .pool_sizes(&sizes),
            None,
        )?;
        let layouts = [layout];
        let set = d.allocate_descriptor_sets(
            &vk::DescriptorSetAllocateInfo::default()
                .descriptor_pool(pool)
                .set_layouts(&layouts),
        )?[0];
        let sampler_info = vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::LINEAR)
            .min_filter(vk::Filter::LINEAR)
            .address_mode_u(vk::SamplerAddressMode::REPEAT)
            .address_mode_v(vk::SamplerAddressMode::REPEAT);
        let sampler = d.create_sampler(&sampler_info, None)?;
        let image_info = [vk::DescriptorImageInfo {
            sampler,
            image_view: texture.view,
            image_layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
        }];
        let write = vk::WriteDescriptorSet::default()
            .dst_set(set)
            .dst_binding(0)
            .descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
            .image_info(&image_info);
        d.update_descriptor_sets(&[write], &[]);
        Ok((layout, pool, set, sampler))
    }
}

/// The scene pipelines' layout: the texture's set and the push constants.
fn scene_layout(
    d: &ash::Device,
    set_layout: vk::DescriptorSetLayout,
) -> Result<vk::PipelineLayout> {
    let push = [vk::PushConstantRange {
        stage_flags: vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
        offset: 0,
        size: size_of::<Push>() as u32,
    }];
    let sets = [set_layout];
    let info = vk::PipelineLayoutCreateInfo::default()
        .set_layouts(&sets)
        .push_constant_ranges(&push);
    // SAFETY: the engine's device; destroyed with the scene.
    Ok(unsafe { d.create_pipeline_layout(&info, None) }?)
}

/// The scene's pipeline: lit or textured triangles, reversed depth (GREATER), two-sided.
fn scene_pipeline(
    engine: &Engine,
    set_layout: vk::DescriptorSetLayout,
) -> Result<(vk::PipelineLayout, vk::Pipeline)> {
    let compiler = shaderc::Compiler::new().context("shaderc")?;
    let spirv = |src: &str, kind, name| -> Result<Vec<u32>> {
        Ok(compiler
            .compile_into_spirv(src, kind, name, "main", None)?
            .as_binary()
            .to_vec())
    };
    let vert = spirv(SCENE_VERT, shaderc::ShaderKind::Vertex, "scene.vert")?;
    let frag = spirv(SCENE_FRAG, shaderc::ShaderKind::Fragment, "scene.frag")?;
    let d = &engine.device;
    let layout = scene_layout(d, set_layout)?;
    // SAFETY: the engine's device; the modules are destroyed once the pipeline is made.
    unsafe {
        let vm =
            d.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&vert), None)?;
        let fm =
            d.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&frag), None)?;
        let stages = [
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::VERTEX)
                .module(vm)
                .name(c"main"),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::FRAGMENT)
                .module(fm)
                .name(c"main"),
        ];
        let pipeline = graphics_pipeline(d, layout, &stages);
        d.destroy_shader_module(vm, None);
        d.destroy_shader_module(fm, None);
        Ok((layout, pipeline?))
    }
}

/// A pipeline of `stages` for the engine's targets: position, normal and uv vertices, reversed
/// depth (GREATER, written), two-sided, dynamic viewport and scissor.
fn graphics_pipeline(
    d: &ash::Device,
    layout: vk::PipelineLayout,
    stages: &[vk::PipelineShaderStageCreateInfo],
) -> Result<vk::Pipeline> {
    let bindings = [vk::VertexInputBindingDescription {
        binding: 0,
        stride: (VERTEX_FLOATS * 4) as u32,
        input_rate: vk::VertexInputRate::VERTEX,
    }];
    let attributes =
        [(0, 0), (1, 12), (2, 24)].map(|(location, offset)| vk::VertexInputAttributeDescription {
            location,
            binding: 0,
            format: if location == 2 {
                vk::Format::R32G32_SFLOAT
            } else {
                vk::Format::R32G32B32_SFLOAT
            },
            offset,
        });
    let vertex = vk::PipelineVertexInputStateCreateInfo::default()
        .vertex_binding_descriptions(&bindings)
        .vertex_attribute_descriptions(&attributes);
    let assembly = vk::PipelineInputAssemblyStateCreateInfo::default()
        .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
    let viewport = vk::PipelineViewportStateCreateInfo::default()
        .viewport_count(1)
        .scissor_count(1);
    let raster = vk::PipelineRasterizationStateCreateInfo::default()
        .polygon_mode(vk::PolygonMode::FILL)
        .cull_mode(vk::CullModeFlags::NONE)
        .line_width(1.0);
    let multisample = vk::PipelineMultisampleStateCreateInfo::default()
        .rasterization_samples(vk::SampleCountFlags::TYPE_1);
    let depth = vk::PipelineDepthStencilStateCreateInfo::default()
        .depth_test_enable(true)
        .depth_write_enable(true)
        .depth_compare_op(vk::CompareOp::GREATER);
    let blend_attachments = [vk::PipelineColorBlendAttachmentState::default()
        .color_write_mask(vk::ColorComponentFlags::RGBA)];
    let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachments);
    let dynamic = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
    let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic);
    let formats = [COLOR_FORMAT];
    let mut rendering = vk::PipelineRenderingCreateInfo::default()
        .color_attachment_formats(&formats)
        .depth_attachment_format(DEPTH_FORMAT);
    let info = [vk::GraphicsPipelineCreateInfo::default()
        .stages(stages)
        .vertex_input_state(&vertex)
        .input_assembly_state(&assembly)
        .viewport_state(&viewport)
        .rasterization_state(&raster)
        .multisample_state(&multisample)
        .depth_stencil_state(&depth)
        .color_blend_state(&blend)
        .dynamic_state(&dynamic)
        .layout(layout)
        .push_next(&mut rendering)];
    // SAFETY: the engine's device; every create info lives for the call.
    let made = unsafe { d.create_graphics_pipelines(vk::PipelineCache::null(), &info, None) };
    Ok(made.map_err(|(_, e)| e)?[0])
}
