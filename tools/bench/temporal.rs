//! `bench temporal`: the flicker measure. Each scenario (a slow orbit and a slow dolly around
//! one head, an animated crowd in wind) is rendered frame after frame with temporal
//! accumulation off and on, and as a reference with many samples per pixel (rendered
//! `--supersample` times larger per side with full detail, box-filtered down). For each
//! consecutive pair the previous image is moved along the frame's true motion vectors and the
//! mean change of luminance over the hair's pixels is taken (`temporal::reprojected_change`);
//! the flicker ratio is ours over the reference's (the true change: shading, disocclusion).
//! Also FLIP mean of every frame against the reference, and the accumulation's GPU cost.

use std::sync::Arc;

use anyhow::{Result, bail};
use glam::{Mat4, Vec3};
use hairmesh::animate::{CharacterMotion, Collider, CrowdAnimation, Wind};
use hairmesh::bake::deform::DeformBasis;
use hairmesh::characters::preset::{self, Preset};
use hairmesh::outln;
use hairmesh::render::temporal::{PixelMotion, downsample, reprojected_change};
use hairmesh::render::{
    Camera, FrameOptions, FrameReport, LodSettings, Renderer, RendererDesc, StrandParams,
    StrandRaster, Temporal, View,
};
use hairmesh::vk::{Context, ContextDesc};

/// What `bench temporal` runs.
#[derive(clap::Args)]
pub struct TemporalArgs {
    /// Image size (the reference is rendered --supersample times larger per side).
    #[arg(long, default_value = "320x180", value_parser = parse_size)]
    size: (u32, u32),
    /// Frames per run.
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u32).range(3..=10000))]
    frames: u32,
    /// Frames left out of the measure at the start (accumulation converging).
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(0..=10000))]
    warmup: u32,
    /// Reference samples per pixel per side (1..=8).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=8))]
    supersample: u32,
    /// Scenarios: orbit, dolly, crowd.
    #[arg(long, value_delimiter = ',', default_value = "orbit,dolly,crowd", value_parser = ["orbit", "dolly", "crowd"])]
    scenarios: Vec<String>,
    /// How our frames' strands are rasterized: hw, soft, soft:K, auto or auto:K.
    #[arg(long, default_value = "hw")]
    draw: StrandRaster,
    /// Choose the GPU by name substring.
    #[arg(long)]
    device: Option<String>,
    /// Write the last frame of every scenario as a PNG strip: reference, off, taa side by
    /// side, one row per scenario.
    #[arg(long)]
    strip: Option<std::path::PathBuf>,
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    hairmesh::render::scene::parse_size(s)
}

/// A scenario: its characters, and what moves each frame.
trait Scenario {
    /// Set up frame `f` (move the camera, animate the characters); the camera.
    fn frame(&mut self, r: &mut Renderer, f: u32, height: u32) -> Result<Camera>;
}

/// One head seen from a camera that orbits it (0.25 degrees a frame) or moves away from it
/// (1% of the distance a frame).
struct Head {
    dolly: bool,
    base: Camera,
}

impl Scenario for Head {
    fn frame(&mut self, _: &mut Renderer, f: u32, _: u32) -> Result<Camera> {
        let offset = self.base.eye - self.base.target;
        let offset = match self.dolly {
            true => offset * (1.0 + 0.01 * f as f32),
            false => {
                Mat4::from_rotation_y(0.25f32.to_radians() * f as f32).transform_vector3(offset)
            }
        };
        Ok(Camera {
            eye: self.base.target + offset,
            ..self.base
        })
    }
}

/// Four people idling in wind (their hair simulated and re-textured every frame), seen from
/// a camera orbiting them by 0.25 degrees a frame.
struct Crowd {
    animation: CrowdAnimation,
}

impl Scenario for Crowd {
    fn frame(&mut self, r: &mut Renderer, f: u32, height: u32) -> Result<Camera> {
        let base = preset::orbit_camera(Preset::People, 4, 0);
        let turn = Mat4::from_rotation_y(0.25f32.to_radians() * f as f32);
        let camera = Camera {
            eye: base.target + turn.transform_vector3(base.eye - base.target),
            ..base
        };
        if f > 0 {
            self.animation.advance(r, 1.0 / 30.0, &camera, height)?;
        }
        Ok(camera)
    }
}

/// A renderer of `size` holding the scenario's characters, and the scenario.
fn scene(
    ctx: &Arc<Context>,
    name: &str,
    size: (u32, u32),
) -> Result<(Renderer, Box<dyn Scenario>)> {
    let mut r = Renderer::new(ctx, &RendererDesc::default().size(size.0, size.1))?;
    match name {
        "orbit" | "dolly" => {
            let path = std::path::Path::new("hairmeshes/head_long.obj");
            let (baked, style) =
                hairmesh::render::scene::load_mesh(path, None, Default::default())?;
            let params = StrandParams {
                strands_per_bundle: 64,
                verts_log2: 5,
            };
            r.add_character(&baked, &style, params, Mat4::IDENTITY)?;
            let o = Vec3::from_slice(&baked.info.pos_origin[..3]);
            let e = Vec3::from_slice(&baked.info.pos_extent[..3]);
            let base = Camera::framing(o, o + e, hairmesh::render::DEFAULT_VIEW_DIR, 40.0);
            let dolly = name == "dolly";
            Ok((r, Box::new(Head { dolly, base })))
        }
        "crowd" => {
            let animation = crowd(&mut r)?;
            Ok((r, Box::new(Crowd { animation })))
        }
        _ => bail!("--scenarios {name:?}: orbit, dolly or crowd"),
    }
}

/// Four people with props and hair dynamics in wind.
fn crowd(r: &mut Renderer) -> Result<CrowdAnimation> {
    let characters = preset::build(Preset::People, 4, 7)?;
    r.set_prop_meshes(&preset::prop_meshes()?)?;
    let skinned = hairmesh::characters::people::skinned_meshes()?;
    r.set_skinned_meshes(&skinned)?;
    r.set_skinned_lods(&hairmesh::characters::people::skinned_lods(&skinned))?;
    r.set_prop_instances(&preset::world_props())?;
    let mut animation = CrowdAnimation::new();
    animation.wind = Wind {
        direction: Vec3::new(1.0, 0.0, 0.3),
        strength: 20.0,
        gustiness: 0.6,
    };
    let params = StrandParams {
        strands_per_bundle: 32,
        verts_log2: 4,
    };
    for (k, c) in characters.iter().enumerate() {
        let options = hairmesh::BakeOptions {
            motion_margin: 0.3,
            ..Default::default()
        };
        let baked = hairmesh::bake(&c.hair.mesh, &c.hair.style, options, |_, _| {})?;
        let id = r.add_character(&baked, &c.hair.style, c.strand_params(params), c.model)?;
        preset::dress(r, id, c)?;
        let colliders: Vec<Collider> = c.colliders()?.unwrap_or_default();
        r.make_deformable(id, DeformBasis::new(&c.hair.mesh, &baked, options)?)?;
        let motion = CharacterMotion::idle(c.model, 11 ^ k as u32);
        match &c.walker {
            Some(w) => animation.add_person(id, w.clone(), Some((&c.hair.mesh, colliders)))?,
            None => animation.add(id, motion, Some((&c.hair.mesh, colliders))),
        }
    }
    Ok(animation)
}

/// The frames of one run of a scenario: images, motion vectors, GPU ms and temporal ms.
struct Run {
    images: Vec<Vec<u8>>,
    motion: Vec<Vec<PixelMotion>>,
    gpu_ms: Vec<f64>,
    temporal_ms: Vec<f64>,
}

/// Render `frames` frames of scenario `name` at `size` (`scale` times larger per side for
/// the reference, box-filtered down) with `temporal`.
fn run(
    ctx: &Arc<Context>,
    name: &str,
    (size, scale): ((u32, u32), u32),
    (temporal, draw, lod): (Temporal, StrandRaster, bool),
    frames: u32,
) -> Result<Run> {
    let big = (size.0 * scale, size.1 * scale);
    let (mut r, mut scenario) = scene(ctx, name, big)?;
    let mut out = Run {
        images: Vec::new(),
        motion: Vec::new(),
        gpu_ms: Vec::new(),
        temporal_ms: Vec::new(),
    };
    for f in 0..frames {
        // Every run simulates on the same schedule: the one of the measured size.
        let camera = scenario.frame(&mut r, f, size.1)?;
        let view = View {
            lod: if lod {
                LodSettings::default()
            } else {
                LodSettings::off()
            },
            temporal,
            ..View::new(camera)
        };
        let opts = FrameOptions {
            read_image: true,
            read_motion: scale == 1,
            raster: draw,
            ..Default::default()
        };
        let report: FrameReport = r.render_one(&view, &opts)?;
        let rgba = report.rgba.clone().unwrap_or_default();
        out.images.push(match scale {
            1 => rgba,
            _ => downsample(&rgba, big, scale),
        });
        out.motion.push(report.motion.clone().unwrap_or_default());
        out.gpu_ms.push(report.gpu_ms());
        let temporal = report
            .pass_ms
            .iter()
            .filter(|(n, _)| n.starts_with("temporal"));
        let t: f64 = temporal.map(|p| p.1).sum();
        out.temporal_ms.push(t);
    }
    Ok(out)
}

/// Mean flicker of the frame pairs after `warmup` frames, moved along `motion`.
fn flicker(images: &[Vec<u8>], motion: &[Vec<PixelMotion>], size: (u32, u32), warmup: u32) -> f64 {
    let mut sum = 0.0;
    let mut n = 0;
    for f in (warmup as usize).max(1)..images.len() {
        let mask: Vec<bool> = motion[f].iter().map(PixelMotion::is_hair).collect();
        let (change, pixels) =
            reprojected_change(&images[f - 1], &images[f], &motion[f], &mask, size);
        if pixels > 0 {
            sum += change;
            n += 1;
        }
    }
    if n > 0 { sum / n as f64 } else { 0.0 }
}

/// Mean FLIP of the frames after `warmup` against the reference's.
fn flip_mean(images: &[Vec<u8>], reference: &[Vec<u8>], size: (u32, u32), warmup: u32) -> f64 {
    let rgb = |v: &[u8]| -> Vec<u8> { v.chunks(4).flat_map(|p| [p[0], p[1], p[2]]).collect() };
    let frames = (warmup as usize)..images.len();
    let n = frames.len().max(1) as f64;
    frames
        .map(|f| {
            let err = nv_flip::flip(
                nv_flip::FlipImageRgb8::with_data(size.0, size.1, &rgb(&reference[f])),
                nv_flip::FlipImageRgb8::with_data(size.0, size.1, &rgb(&images[f])),
                nv_flip::DEFAULT_PIXELS_PER_DEGREE,
            );
            nv_flip::FlipPool::from_image(&err).mean() as f64
        })
        .sum::<f64>()
        / n
}

pub fn bench_temporal(a: TemporalArgs) -> Result<()> {
    if a.frames <= a.warmup + 1 {
        bail!(
            "--frames {} must exceed --warmup {} by 2 or more",
            a.frames,
            a.warmup
        );
    }
    if !(1..=8).contains(&a.supersample) {
        bail!("--supersample {}: 1..=8", a.supersample);
    }
    let strip = a
        .strip
        .as_ref()
        .map(|p| hairmesh::fsutil::OutputPath::check(p, &[]))
        .transpose()?;
    let ctx = Arc::new(Context::new(
        &ContextDesc::default().device(a.device.clone()),
    )?);
    let mut rows = Vec::new();
    outln!(
        "{}: {}x{}, {} frames ({} warm-up), reference {}x{} samples per pixel, full detail",
        ctx.info.name,
        a.size.0,
        a.size.1,
        a.frames,
        a.warmup,
        a.supersample,
        a.supersample
    )?;
    outln!(
        "| scenario | temporal | flicker | reference flicker | ratio | FLIP mean | frame ms | temporal ms |"
    )?;
    outln!("|---|---|---|---|---|---|---|---|")?;
    for name in &a.scenarios {
        let soft = StrandRaster::Software { k: 8 };
        let reference = run(
            &ctx,
            name,
            (a.size, a.supersample),
            (Temporal::Off, soft, false),
            a.frames,
        )?;
        let mut motion = Vec::new();
        let mut row = vec![reference.images.last().cloned().unwrap_or_default()];
        for temporal in Temporal::ALL {
            let ours = run(&ctx, name, (a.size, 1), (temporal, a.draw, true), a.frames)?;
            if temporal == Temporal::Off {
                motion = ours.motion.clone();
            }
            let mine = flicker(&ours.images, &ours.motion, a.size, a.warmup);
            let truth = flicker(&reference.images, &motion, a.size, a.warmup);
            let flip = flip_mean(&ours.images, &reference.images, a.size, a.warmup);
            let skip = a.warmup as usize;
            outln!(
                "| {name} | {temporal} | {mine:.4} | {truth:.4} | {:.2} | {flip:.4} | {:.1} | {:.2} |",
                mine / truth.max(1e-9),
                super::median(ours.gpu_ms[skip..].to_vec()),
                super::median(ours.temporal_ms[skip..].to_vec())
            )?;
            row.push(ours.images.last().cloned().unwrap_or_default());
        }
        rows.push(row);
    }
    if let Some(out) = strip {
        let picture = super::side_by_side(&rows, a.size)?;
        let (w, h) = picture.dimensions();
        super::write_png(&out, picture.into_raw(), w, h)?;
    }
    Ok(())
}
