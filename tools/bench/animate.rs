//! `bench animate`: copies of one hair mesh in wind, each simulated and re-textured every
//! frame, for each character count and dynamics path (GPU: `Renderer::step_hair`, one
//! dispatch; CPU: `HairDynamics` on all cores, poses uploaded): CPU and GPU ms of the hair
//! dynamics, GPU ms of the texture rebuild, GPU ms of the frame, per frame (medians);
//! optionally a strip of frames of the first run side by side.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Result, bail};
use glam::{Mat4, Vec3};
use hairmesh::animate::{
    CharacterMotion, Collider, DynamicsPath, DynamicsSettings, HairDynamics, Wind,
};
use hairmesh::bake::BakedHairMesh;
use hairmesh::bake::deform::DeformBasis;
use hairmesh::fsutil::OutputPath;
use hairmesh::model::hair_mesh::HairMesh;
use hairmesh::model::obj_io::load_hair_mesh_obj;
use hairmesh::outln;
use hairmesh::reference::volume::VolumeSampling;
use hairmesh::render::{
    Camera, CharacterId, FrameOptions, LodSettings, Renderer, RendererDesc, ShadowMode,
    StrandParams, Transparency, View,
};
use hairmesh::vk::{Context, ContextDesc};
use hairmesh::{BakeOptions, HairStyle, bake};

/// What `bench animate` runs.
pub struct AnimateArgs {
    pub mesh: PathBuf,
    pub frames: u32,
    pub wind: f32,
    pub size: (u32, u32),
    pub strands_per_bundle: u32,
    pub counts: Vec<u32>,
    pub dynamics: Vec<DynamicsPath>,
    pub strip: Option<PathBuf>,
    pub strip_frames: u32,
    pub device: Option<String>,
    /// Rebuild every character's strand density volume every frame (`--volumes`).
    pub volumes: bool,
}

/// Most characters one run animates (the renderer's default room).
const MOST_CHARACTERS: u32 = 1024;

/// The hair mesh, its style and bake, and its size.
struct Sample {
    mesh: HairMesh,
    style: HairStyle,
    baked: BakedHairMesh,
    options: BakeOptions,
    centre: Vec3,
    size: f32,
}

fn load(path: &std::path::Path) -> Result<Sample> {
    let mesh = load_hair_mesh_obj(path)?;
    let style = match HairStyle::beside(path) {
        Some(p) => HairStyle::load(&p)?,
        None => HairStyle::default(),
    };
    let (lo, hi) = hairmesh::model::hair_mesh::bounds(mesh.layers.iter().flatten().copied());
    let size = (hi - lo).length();
    let options = BakeOptions {
        motion_margin: 0.5 * size,
        ..Default::default()
    };
    let baked = bake(&mesh, &style, options, |_, _| {})?;
    Ok(Sample {
        mesh,
        style,
        baked,
        options,
        centre: (lo + hi) * 0.5,
        size,
    })
}

/// `count` animated copies of the sample on a square grid, and a camera that sees them all.
struct Herd {
    renderer: Renderer,
    ids: Vec<CharacterId>,
    dynamics: Vec<HairDynamics>,
    motions: Vec<CharacterMotion>,
    camera: Camera,
    path: DynamicsPath,
    settings: DynamicsSettings,
}

fn herd(
    ctx: &Arc<Context>,
    s: &Sample,
    count: u32,
    path: DynamicsPath,
    a: &AnimateArgs,
) -> Result<Herd> {
    let (w, h) = a.size;
    let mut renderer = Renderer::new(ctx, &RendererDesc::default().size(w, h))?;
    let params = StrandParams {
        strands_per_bundle: a.strands_per_bundle,
        verts_log2: 5,
    };
    let settings = DynamicsSettings {
        wind: Wind {
            direction: Vec3::new(1.0, 0.1, 0.6),
            strength: a.wind,
            gustiness: 0.7,
        },
        ..Default::default()
    };
    let side = (count as f32).sqrt().ceil() as u32;
    let spacing = 1.5 * s.size;
    let (mut ids, mut dynamics, mut motions) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..count {
        let offset = Vec3::new((k % side) as f32, 0.0, (k / side) as f32) * spacing;
        let home = Mat4::from_translation(offset);
        let id = renderer.add_character(&s.baked, &s.style, params, home)?;
        renderer.make_deformable(id, DeformBasis::new(&s.mesh, &s.baked, s.options)?)?;
        let collider = vec![Collider::fit_scalp(&s.mesh)];
        let sim = HairDynamics::new(&s.mesh, collider, settings, home);
        if path == DynamicsPath::Gpu {
            renderer.simulate_hair(id, &sim)?;
        }
        dynamics.push(sim);
        // Each turns on its own phase, so the herd is not in lockstep.
        motions.push(CharacterMotion {
            turn: 0.5,
            turn_rate: 0.25 + 0.01 * (k % 7) as f32,
            sway: 0.04,
            ..CharacterMotion::still(home)
        });
        ids.push(id);
    }
    let middle = s.centre + Vec3::new(1.0, 0.0, 1.0) * spacing * (side - 1) as f32 * 0.5;
    let reach = (0.75 + 0.9 * (side - 1) as f32) * s.size;
    let camera = Camera::look_at(
        middle + Vec3::new(0.9, 0.25 + 0.3 * (side > 1) as u32 as f32, 1.4) * reach,
        middle + Vec3::Y * 0.12 * s.size,
        40.0,
    );
    Ok(Herd {
        renderer,
        ids,
        dynamics,
        motions,
        camera,
        path,
        settings,
    })
}

/// Step every character by `dt` to its model, on all cores (characters are independent, as in
/// `animate::CrowdAnimation`); their poses, in order.
fn step_all(dynamics: &mut [HairDynamics], models: &[Mat4], dt: f32) -> Vec<Vec<Vec3>> {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let chunk = dynamics.len().div_ceil(threads).max(1);
    let mut poses = vec![Vec::new(); dynamics.len()];
    std::thread::scope(|scope| {
        for ((part, m), out) in dynamics
            .chunks_mut(chunk)
            .zip(models.chunks(chunk))
            .zip(poses.chunks_mut(chunk))
        {
            scope.spawn(move || {
                for ((d, model), pose) in part.iter_mut().zip(m).zip(out) {
                    d.step(dt, *model);
                    *pose = d.pose();
                }
            });
        }
    });
    poses
}

/// Per-frame figures of one run.
#[derive(Default)]
struct Timings {
    sim_ms: Vec<f64>,
    sim_gpu_ms: Vec<f64>,
    update_ms: Vec<f64>,
    gpu_ms: Vec<f64>,
    volume_ms: Vec<f64>,
    strip: Vec<Vec<u8>>,
}

fn run_frames(herd: &mut Herd, a: &AnimateArgs, strip: bool) -> Result<Timings> {
    let strip_every = (a.frames / a.strip_frames.max(1)).max(1);
    let mut t = Timings::default();
    for f in 0..a.frames {
        let time = (f + 1) as f32 / 30.0;
        let models: Vec<Mat4> = herd.motions.iter().map(|m| m.model(time)).collect();
        let start = Instant::now();
        match herd.path {
            DynamicsPath::Cpu => {
                let poses = step_all(&mut herd.dynamics, &models, 1.0 / 30.0);
                for (id, pose) in herd.ids.iter().zip(&poses) {
                    herd.renderer.set_hair_mesh_pose(*id, pose)?;
                }
            }
            DynamicsPath::Gpu => {
                for (id, model) in herd.ids.iter().zip(&models) {
                    herd.renderer
                        .step_hair(*id, 1.0 / 30.0, *model, &herd.settings)?;
                }
            }
        }
        t.sim_ms.push(start.elapsed().as_secs_f64() * 1e3);
        for (id, model) in herd.ids.iter().zip(&models) {
            herd.renderer.set_model(*id, *model)?;
            if a.volumes {
                herd.renderer
                    .request_density_volume(*id, VolumeSampling::default())?;
            }
        }
        let view = View {
            light_dir: Vec3::new(-0.6, 0.8, 0.4),
            // One character at full detail (the strip); a herd with LoD, as a crowd is drawn.
            lod: match herd.ids.len() {
                1 => LodSettings::off(),
                _ => LodSettings::default(),
            },
            shading: hairmesh::shade::ShadingModel::Marschner,
            shadows: ShadowMode::DeepOpacity,
            transparency: Transparency::KBuffer { budget: 8 },
            ..View::new(herd.camera)
        };
        let wants_image = strip && (f + 1) % strip_every == 0;
        let opts = FrameOptions {
            read_image: wants_image,
            ..Default::default()
        };
        let report = herd.renderer.render_one(&view, &opts)?;
        let update = report
            .pass_ms
            .iter()
            .filter(|(n, _)| *n == "hair mesh update");
        t.update_ms.push(update.map(|p| p.1).sum::<f64>());
        let pass = |name: &str| {
            report
                .pass_ms
                .iter()
                .filter(|(n, _)| *n == name)
                .map(|p| p.1)
                .sum::<f64>()
        };
        t.sim_gpu_ms.push(pass("hair dynamics"));
        t.volume_ms.push(pass("density volume"));
        t.gpu_ms.push(report.gpu_ms());
        if let Some(rgba) = report.rgba
            && t.strip.len() < a.strip_frames as usize
        {
            t.strip.push(rgba);
        }
    }
    Ok(t)
}

fn write_strip(out: &OutputPath, images: Vec<Vec<u8>>, size: (u32, u32)) -> Result<()> {
    let n = images.len();
    let img = super::side_by_side(&[images], size)?;
    let (w, h) = img.dimensions();
    let path = out.path().display().to_string();
    out.write(&hairmesh::fsutil::encode_png(&path, w, h, img.into_raw())?)?;
    outln!("wrote {n} frames side by side")?;
    Ok(())
}

pub fn bench_animate(a: AnimateArgs) -> Result<()> {
    if !(0.0..=100.0).contains(&a.wind) {
        bail!("--wind {}: must be 0..=100", a.wind);
    }
    if let Some(&n) = a.counts.iter().find(|&&n| n == 0 || n > MOST_CHARACTERS) {
        bail!("--counts {n}: each must be 1..={MOST_CHARACTERS}");
    }
    let strip = a
        .strip
        .as_ref()
        .map(|p| OutputPath::check(p, &[a.mesh.as_path()]))
        .transpose()?;
    let sample = load(&a.mesh)?;
    let ctx = Arc::new(Context::new(
        &ContextDesc::default().device(a.device.clone()),
    )?);
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    outln!(
        "{}: {} layer vertices ({} columns x {} layers) per character, {} frames at 30 Hz, wind {} m/s^2; {}, {threads} CPU threads",
        a.mesh.display(),
        sample.mesh.vertices_per_layer() * sample.mesh.layer_count(),
        sample.mesh.vertices_per_layer(),
        sample.mesh.layer_count(),
        a.frames,
        a.wind,
        ctx.info.name
    )?;
    let volume_column = match a.volumes {
        true => (" density volumes ms GPU |", "---|"),
        false => ("", ""),
    };
    outln!(
        "| characters | dynamics | dynamics ms CPU | dynamics ms GPU | per character ms | texture rebuild ms GPU | frame ms GPU |{}",
        volume_column.0
    )?;
    outln!("|---|---|---|---|---|---|---|{}", volume_column.1)?;
    let mut strip_images = Vec::new();
    let runs = a
        .counts
        .iter()
        .flat_map(|&c| a.dynamics.iter().map(move |&p| (c, p)));
    for (k, (count, path)) in runs.enumerate() {
        let mut h = herd(&ctx, &sample, count, path, &a)?;
        let t = run_frames(&mut h, &a, k == 0 && strip.is_some())?;
        let (cpu, gpu) = (super::median(t.sim_ms), super::median(t.sim_gpu_ms));
        // What the dynamics cost: the CPU's wall time, or the GPU's pass.
        let cost = match path {
            DynamicsPath::Cpu => cpu,
            DynamicsPath::Gpu => gpu,
        };
        let gpu_text = match path {
            DynamicsPath::Gpu => format!("{gpu:.2}"),
            DynamicsPath::Cpu => "-".into(),
        };
        let volumes = match a.volumes {
            true => format!(" {:.2} |", super::median(t.volume_ms)),
            false => String::new(),
        };
        outln!(
            "| {count} | {path} | {cpu:.2} | {gpu_text} | {:.3} | {:.2} | {:.1} |{volumes}",
            cost / count as f64,
            super::median(t.update_ms),
            super::median(t.gpu_ms)
        )?;
        if k == 0 {
            strip_images = t.strip;
        }
    }
    if let (Some(out), false) = (strip, strip_images.is_empty()) {
        write_strip(&out, strip_images, a.size)?;
    }
    Ok(())
}
