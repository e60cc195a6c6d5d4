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
        "| distance | path | LoD | strands | triangles | segments | GPU ms (median of {}) | hair box px | FLIP on vs off over the hair (mean / p99) | hair px on / off | hair luminance on / off |",
        args.runs
    )?;
    outln!("|---|---|---|---|---|---|---|---|---|---|---|")?;
    let mut paths = vec![RenderPath::Compute];
    if renderer.has_mesh_path() {
        paths.insert(0, RenderPath::Mesh);
    }
    let mut pics = Vec::new();
    for &k in &args.distances {
        for &path in &paths {
            let mut frames = frames_on_and_off(&mut renderer, &args, at(k), path)?;
            let rgb = |f: &hairmesh::render::FrameReport| -> Result<image::RgbImage> {
                let rgba = f.rgba.clone().context("no image")?;
                let img = image::RgbaImage::from_raw(width, height, rgba).context("image size")?;
                Ok(image::DynamicImage::ImageRgba8(img).to_rgb8())
            };
            let flip = hair_flip(&rgb(&frames[1].0)?, &rgb(&frames[0].0)?)?;
            for (i, (f, ms)) in frames.iter().enumerate() {
                let s = &f.stats;
                let tail = match i {
                    0 => format!("{} | {flip}", flip.pixels),
                    _ => " | | |".into(),
                };
                outln!(
                    "| x{k} | {path:?} | {} | {} | {} | {} | {ms:.2} | {tail} |",
                    if i == 0 { "on" } else { "off" },
                    s.strands_drawn,
                    s.triangles_drawn,
                    s.segments_written,
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

/// The frame of `camera` on `path` with LoD on, then off: each with its image and the median
/// GPU ms of `args.runs` more.
fn frames_on_and_off(
    renderer: &mut Renderer,
    args: &LodArgs,
    camera: hairmesh::render::Camera,
    path: RenderPath,
) -> Result<Vec<(hairmesh::render::FrameReport, f64)>> {
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
        let view = args.view(camera, lod_on);
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
    Ok(frames)
}

/// LoD against full detail over the hair: FLIP of the frames' crop around every pixel either
/// differs from the background in, the hair's pixels in each and their mean luminance.
struct HairFlip {
    pixels: usize,
    mean: f32,
    p99: f32,
    covered: (usize, usize),
    luminance: (f64, f64),
}

impl std::fmt::Display for HairFlip {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{:.4} / {:.4} | {:.3} | {:.3}",
            self.mean,
            self.p99,
            self.covered.0 as f64 / self.covered.1.max(1) as f64,
            self.luminance.0 / self.luminance.1.max(1e-9)
        )
    }
}

/// [`HairFlip`] of `on` (LoD) against `off` (full detail); the background is the top-left
/// pixel's colour.
fn hair_flip(off: &image::RgbImage, on: &image::RgbImage) -> Result<HairFlip> {
    let bg = *off.get_pixel(0, 0);
    let luminance = |p: &image::Rgb<u8>| {
        let l = |c: u8| hairmesh::shade::srgb_to_linear(c as f32 / 255.0) as f64;
        0.2126 * l(p[0]) + 0.7152 * l(p[1]) + 0.0722 * l(p[2])
    };
    let (w, h) = off.dimensions();
    let (mut lo, mut hi) = ((w, h), (0, 0));
    let (mut covered, mut lum) = ((0usize, 0usize), (0.0f64, 0.0f64));
    for (x, y, p) in on.enumerate_pixels() {
        let q = off.get_pixel(x, y);
        let (a, b) = (*p != bg, *q != bg);
        if a || b {
            lo = (lo.0.min(x), lo.1.min(y));
            hi = (hi.0.max(x), hi.1.max(y));
        }
        if a {
            covered.0 += 1;
            lum.0 += luminance(p);
        }
        if b {
            covered.1 += 1;
            lum.1 += luminance(q);
        }
    }
    anyhow::ensure!(covered.1 > 0, "no hair in view");
    let (cw, ch) = (hi.0 - lo.0 + 1, hi.1 - lo.1 + 1);
    let crop =
        |img: &image::RgbImage| image::imageops::crop_imm(img, lo.0, lo.1, cw, ch).to_image();
    let mut pool = super::compare::flip_pool(&crop(off), &crop(on)).context("frame sizes")?;
    Ok(HairFlip {
        pixels: (cw * ch) as usize,
        mean: pool.mean(),
        p99: pool.get_percentile(0.99, true),
        covered,
        luminance: (lum.0 / covered.0.max(1) as f64, lum.1 / covered.1 as f64),
    })
}
