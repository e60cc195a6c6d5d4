//! `bench animate`: one hair mesh in wind, simulated and re-textured every frame: CPU ms of
//! the hair dynamics, GPU ms of the texture rebuild, GPU ms of the frame, per frame (medians);
//! optionally a strip of frames side by side.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Result, bail};
use glam::{Mat4, Vec3};
use hairmesh::animate::{CharacterMotion, Collider, DynamicsSettings, HairDynamics, Wind};
use hairmesh::bake::deform::DeformBasis;
use hairmesh::fsutil::OutputPath;
use hairmesh::model::obj_io::load_hair_mesh_obj;
use hairmesh::outln;
use hairmesh::render::{
    Camera, FrameOptions, LodSettings, Renderer, RendererDesc, ShadowMode, StrandParams,
    Transparency, View,
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
    pub strip: Option<PathBuf>,
    pub strip_frames: u32,
    pub device: Option<String>,
}

pub fn bench_animate(a: AnimateArgs) -> Result<()> {
    if !(0.0..=100.0).contains(&a.wind) {
        bail!("--wind {}: must be 0..=100", a.wind);
    }
    let strip = a
        .strip
        .as_ref()
        .map(|p| OutputPath::check(p, &[a.mesh.as_path()]))
        .transpose()?;
    let mesh = load_hair_mesh_obj(&a.mesh)?;
    let style = match HairStyle::beside(&a.mesh) {
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
    let ctx = Arc::new(Context::new(
        &ContextDesc::default().device(a.device.clone()),
    )?);
    let (w, h) = a.size;
    let mut renderer = Renderer::new(&ctx, &RendererDesc::default().size(w, h))?;
    let params = StrandParams {
        strands_per_bundle: a.strands_per_bundle,
        verts_log2: 5,
    };
    let id = renderer.add_character(&baked, &style, params, Mat4::IDENTITY)?;
    renderer.make_deformable(id, DeformBasis::new(&mesh, &baked, options)?)?;
    let settings = DynamicsSettings {
        wind: Wind {
            direction: Vec3::new(1.0, 0.1, 0.6),
            strength: a.wind,
            gustiness: 0.7,
        },
        ..Default::default()
    };
    let mut dynamics = HairDynamics::new(
        &mesh,
        vec![Collider::fit_scalp(&mesh)],
        settings,
        Mat4::IDENTITY,
    );
    let motion = CharacterMotion {
        turn: 0.5,
        turn_rate: 0.25,
        sway: 0.04,
        ..CharacterMotion::still(Mat4::IDENTITY)
    };
    let centre = (lo + hi) * 0.5;
    let camera = Camera::look_at(
        centre + Vec3::new(0.9, 0.25, 1.4) * size * 0.75,
        centre + Vec3::Y * 0.12 * size,
        40.0,
    );
    let strip_every = (a.frames / a.strip_frames.max(1)).max(1);
    let (mut sim_ms, mut update_ms, mut gpu_ms) = (Vec::new(), Vec::new(), Vec::new());
    let mut strip_images = Vec::new();
    for f in 0..a.frames {
        let t = (f + 1) as f32 / 30.0;
        let model = motion.model(t);
        let start = Instant::now();
        dynamics.step(1.0 / 30.0, model);
        let pose = dynamics.pose();
        sim_ms.push(start.elapsed().as_secs_f64() * 1e3);
        renderer.set_model(id, model)?;
        renderer.set_hair_mesh_pose(id, &pose)?;
        let view = View {
            light_dir: Vec3::new(-0.6, 0.8, 0.4),
            lod: LodSettings::off(),
            shading: hairmesh::shade::ShadingModel::Marschner,
            shadows: ShadowMode::DeepOpacity,
            transparency: Transparency::KBuffer { budget: 8 },
            ..View::new(camera)
        };
        let wants_image = strip.is_some() && (f + 1) % strip_every == 0;
        let report = renderer.render_one(
            &view,
            &FrameOptions {
                read_image: wants_image,
                ..Default::default()
            },
        )?;
        update_ms.push(
            report
                .pass_ms
                .iter()
                .filter(|(n, _)| *n == "hair mesh update")
                .map(|p| p.1)
                .sum::<f64>(),
        );
        gpu_ms.push(report.gpu_ms());
        if let Some(rgba) = report.rgba
            && strip_images.len() < a.strip_frames as usize
        {
            strip_images.push(rgba);
        }
    }
    outln!(
        "{}: {} layer vertices ({} columns x {} layers), {} frames at 30 Hz, wind {} m/s^2",
        a.mesh.display(),
        dynamics.vertex_count(),
        mesh.vertices_per_layer(),
        mesh.layer_count(),
        a.frames,
        a.wind
    )?;
    outln!(
        "median per frame: hair dynamics {:.2} ms CPU, texture rebuild {:.2} ms GPU, frame {:.1} ms GPU ({})",
        super::median(sim_ms),
        super::median(update_ms),
        super::median(gpu_ms),
        ctx.info.name
    )?;
    if let (Some(out), false) = (strip, strip_images.is_empty()) {
        let n = strip_images.len() as u32;
        let mut img = image::RgbaImage::new(w * n, h);
        for (k, rgba) in strip_images.into_iter().enumerate() {
            let frame = image::RgbaImage::from_raw(w, h, rgba)
                .ok_or_else(|| anyhow::anyhow!("frame {k}: wrong size"))?;
            image::imageops::replace(&mut img, &frame, k as i64 * w as i64, 0);
        }
        let png = hairmesh::fsutil::encode_png(
            &out.path().display().to_string(),
            w * n,
            h,
            img.into_raw(),
        )?;
        out.write(&png)?;
        outln!("wrote {} frames side by side", n)?;
    }
    Ok(())
}
