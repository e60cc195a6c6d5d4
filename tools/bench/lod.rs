//! `bench lod`: one hair mesh at near / mid / far distances (multiples of its framing
//! distance), LoD on and off on both paths: strands, triangles, segments, GPU ms, and FLIP of
//! the LoD frame against the full-detail one (the picture the LoD must hold). `--look crowd`
//! draws with the crowd's LoD (its alpha, area term and pixel cap) and look (Marschner, deep
//! opacity shadows, the fastest rasterizers), as a crowd's character is drawn.

use std::path::PathBuf;
use std::sync::Arc;

use anyhow::{Context as _, Result};
use glam::{Mat4, Vec3};
use hairmesh::fsutil::OutputPath;
use hairmesh::outln;
use hairmesh::render::scene::load_mesh;
use hairmesh::render::{
    FrameOptions, FrameSettings, LodSettings, RenderPath, Renderer, RendererDesc, StrandParams,
    View,
};
use hairmesh::vk::{Context, ContextDesc};

/// Arguments of `bench lod`.
#[derive(clap::Args)]
pub struct LodArgs {
    /// Hair mesh (.obj or .hmb).
    #[arg(long, default_value = "hairmeshes/head_long.obj")]
    mesh: PathBuf,
    /// Image width.
    #[arg(long, default_value_t = 1280, value_parser = clap::value_parser!(u32).range(1..=8192))]
    width: u32,
    /// Image height.
    #[arg(long, default_value_t = 720, value_parser = clap::value_parser!(u32).range(1..=8192))]
    height: u32,
    /// Strands per bundle.
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..=16384))]
    strands_per_bundle: u32,
    /// Distances, multiples of the mesh's framing distance, one row each (near, mid, far).
    #[arg(long, value_delimiter = ',', default_value = "0.6,2.5,8")]
    distances: Vec<f32>,
    /// The look: paper (eq. 7 alone at alpha 0.1, the placeholder shading, hardware strips)
    /// or crowd (the crowd's LoD and default look).
    #[arg(long, default_value = "paper", value_parser = ["paper", "crowd"])]
    look: String,
    /// Timed runs per configuration (after one warm-up).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u16).range(1..=1000))]
    runs: u16,
    /// Choose the GPU by name substring.
    #[arg(long)]
    device: Option<String>,
    /// Write the LoD frames of the first path side by side here.
    #[arg(long)]
    picture: Option<PathBuf>,
}

impl LodArgs {
    /// The view of `camera` with LoD on or off, in the look asked for.
    fn view(&self, camera: hairmesh::render::Camera, lod_on: bool) -> View {
        let crowd = self.look == "crowd";
        let lod = match (lod_on, crowd) {
            (false, _) => LodSettings::off(),
            (true, true) => LodSettings::crowd(),
            (true, false) => LodSettings::default(),
        };
        match crowd {
            true => View {
                lod,
                volumes: hairmesh::render::VolumeTier::OFF,
                ..View::crowd_look(camera)
            },
            false => View {
                light_dir: Vec3::new(0.4, 1.0, 0.6),
                lod,
                ..View::new(camera)
            },
        }
    }
}

/// Run `bench lod`.
pub fn bench_lod(args: LodArgs) -> Result<()> {
    let picture = args
        .picture
        .as_ref()
        .map(|p| OutputPath::check(p, &[args.mesh.as_path()]))
        .transpose()?;
    let (baked, style) = load_mesh(&args.mesh, None, Default::default())?;
    let ctx = Arc::new(Context::new(
        &ContextDesc::default().device(args.device.clone()),
    )?);
    let (width, height) = (args.width, args.height);
    let mut renderer = Renderer::new(&ctx, &RendererDesc::default().size(width, height))?;
    let params = StrandParams {
        strands_per_bundle: args.strands_per_bundle,
        verts_log2: 5,
    };
    renderer.add_character(&baked, &style, params, Mat4::IDENTITY)?;
    let at = super::dolly(&baked);
    outln!(
        "device: {} ({}), {width}x{height}, {} strands/bundle, 33 vertices at full detail, {} look",
        ctx.info.name,
        ctx.info.driver,
        args.strands_per_bundle,
        args.look
    )?;
    outln!(
        "| distance | path | LoD | strands | triangles | segments | GPU ms (median of {}) | FLIP on vs off (mean / p99) |",
        args.runs
    )?;
    outln!("|---|---|---|---|---|---|---|---|")?;
    let mut paths = vec![RenderPath::Compute];
    if renderer.has_mesh_path() {
        paths.insert(0, RenderPath::Mesh);
    }
    let mut pics = Vec::new();
    for &k in &args.distances {
        for &path in &paths {
            let settings = FrameSettings {
                path,
                raster: Default::default(),
                transparency: Default::default(),
                msaa: 1,
                light_raster: Default::default(),
            };
            let settings = match args.look == "crowd" {
                true => settings.with_fastest((None, None), &renderer.caps()),
                false => settings,
            };
            let opts = FrameOptions {
                path: Some(path),
                read_image: true,
                raster: settings.raster,
                light_raster: settings.light_raster,
                ..Default::default()
            };
            let mut frames = Vec::new();
            for lod_on in [true, false] {
                let view = args.view(at(k), lod_on);
                let first = renderer.render_one(&view, &opts)?;
                let mut times = Vec::new();
                for _ in 0..args.runs {
                    let quiet = FrameOptions {
                        read_image: false,
                        ..opts
                    };
                    times.push(renderer.render_one(&view, &quiet)?.gpu_ms());
                }
                frames.push((first, super::median(times)));
            }
            let rgb = |f: &hairmesh::render::FrameReport| -> Result<image::RgbImage> {
                let rgba = f.rgba.clone().context("no image")?;
                let img = image::RgbaImage::from_raw(width, height, rgba).context("image size")?;
                Ok(image::DynamicImage::ImageRgba8(img).to_rgb8())
            };
            let mut pool = super::compare::flip_pool(&rgb(&frames[1].0)?, &rgb(&frames[0].0)?)
                .context("frame sizes")?;
            let flip = format!(
                "{:.4} / {:.4}",
                pool.mean(),
                pool.get_percentile(0.99, true)
            );
            for (i, (f, ms)) in frames.iter().enumerate() {
                let s = &f.stats;
                outln!(
                    "| x{k} | {path:?} | {} | {} | {} | {} | {ms:.2} | {} |",
                    if i == 0 { "on" } else { "off" },
                    s.strands_drawn,
                    s.triangles_drawn,
                    s.segments_written,
                    if i == 0 { flip.as_str() } else { "" }
                )?;
            }
            if path == paths[0] {
                pics.push(frames.swap_remove(0).0);
            }
        }
    }
    if let Some(p) = picture {
        let images = pics.iter().map(|out| out.rgba.clone().context("no image"));
        let strip = super::side_by_side(&[images.collect::<Result<_>>()?], (width, height))?;
        let (w, h) = strip.dimensions();
        super::write_png(&p, strip.into_raw(), w, h)?;
    }
    Ok(())
}
