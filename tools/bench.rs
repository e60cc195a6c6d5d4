//! `bench`: measurements written to the README (never timed tests).
//!
//! `bench cpu-generate [--mesh M] [--strands 100000] [--verts-log2 5] [--runs 7]`: CPU reference
//! generator throughput on one core; prints every run and the median.
//!
//! `bench lod [--mesh M] [--size 1280x720] [--runs 5] [--picture out.png]`: one scene at near,
//! mid and far distances; strand triangles and median GPU time with LoD on vs off, mesh vs
//! compute path (timestamp queries); optionally a near/mid/far picture with LoD on.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context as _, Result, bail};
use clap::{Parser, Subcommand};
use std::sync::Arc;

use glam::{Mat4, Vec3};
use hairmesh::model::obj_io::load_hair_mesh_obj;
use hairmesh::render::scene::load_mesh;
use hairmesh::render::{
    Camera, FrameOptions, LodSettings, RenderPath, Renderer, RendererDesc, StrandParams, View,
};
use hairmesh::vk::{Context, ContextDesc};
use hairmesh::{BakeOptions, CpuGenerator, HairStyle, bake};

#[derive(Parser)]
#[command(version, about = "Benchmarks of the hair pipeline")]
struct Args {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Time the CPU reference generator (single thread).
    CpuGenerate {
        /// Hair mesh OBJ (style: the .toml beside it).
        #[arg(long, default_value = "hairmeshes/head_long.obj")]
        mesh: PathBuf,
        /// Target total strand count.
        #[arg(long, default_value_t = 100_000)]
        strands: u32,
        /// Vertices per strand are 2^e + 1.
        #[arg(long, default_value_t = 5)]
        verts_log2: u32,
        /// Timed runs (after one warm-up).
        #[arg(long, default_value_t = 7)]
        runs: usize,
    },
    /// GPU LoD comparison at near / mid / far distances, both paths.
    Lod {
        /// Hair mesh (.obj or .hmb).
        #[arg(long, default_value = "hairmeshes/head_long.obj")]
        mesh: PathBuf,
        /// Image width.
        #[arg(long, default_value_t = 1280)]
        width: u32,
        /// Image height.
        #[arg(long, default_value_t = 720)]
        height: u32,
        /// Strands per bundle.
        #[arg(long, default_value_t = 64)]
        strands_per_bundle: u32,
        /// Timed runs per configuration (after one warm-up).
        #[arg(long, default_value_t = 5)]
        runs: usize,
        /// Choose the GPU by name substring.
        #[arg(long)]
        device: Option<String>,
        /// Write a near / mid / far picture (LoD on) here.
        #[arg(long)]
        picture: Option<PathBuf>,
    },
}

fn bench_lod(
    mesh: PathBuf,
    width: u32,
    height: u32,
    n: u32,
    runs: usize,
    device: Option<String>,
    picture: Option<PathBuf>,
) -> Result<()> {
    if runs == 0 || width == 0 || height == 0 || width > 8192 || height > 8192 {
        bail!("runs must be >= 1 and sizes 1..=8192");
    }
    let (baked, style) = load_mesh(&mesh, None)?;
    let ctx = Arc::new(Context::new(&ContextDesc::default().device(device))?);
    let mut renderer = Renderer::new(&ctx, &RendererDesc::default().size(width, height))?;
    renderer.add_character(
        &baked,
        &style,
        StrandParams {
            strands_per_bundle: n,
            verts_log2: 5,
        },
        Mat4::IDENTITY,
    )?;
    let o = Vec3::from_slice(&baked.info.pos_origin[..3]);
    let e = Vec3::from_slice(&baked.info.pos_extent[..3]);
    let frame = Camera::framing(o, o + e, hairmesh::render::DEFAULT_VIEW_DIR, 40.0);
    let at = |k: f32| {
        Camera::look_at(
            frame.target + (frame.eye - frame.target) * k,
            frame.target,
            40.0,
        )
    };
    let views = [("near", at(0.6)), ("mid", at(2.5)), ("far", at(8.0))];
    println!(
        "device: {} ({}), {}x{}, {} strands/bundle, 33 vertices at full detail",
        ctx.info.name, ctx.info.driver, width, height, n
    );
    println!("| view | path | LoD | strands | triangles | GPU ms (median of {runs}) |");
    println!("|---|---|---|---|---|---|");
    let mut paths = vec![RenderPath::Compute];
    if renderer.has_mesh_path() {
        paths.insert(0, RenderPath::Mesh);
    }
    let mut pics = Vec::new();
    for (label, cam) in &views {
        for &path in &paths {
            for lod_on in [true, false] {
                let view = View {
                    camera: *cam,
                    light_dir: Vec3::new(0.4, 1.0, 0.6),
                    lod: if lod_on {
                        LodSettings::default()
                    } else {
                        LodSettings::off()
                    },
                };
                let opts = FrameOptions {
                    path: Some(path),
                    read_image: true,
                    ..Default::default()
                };
                let first = renderer.render_one(&view, &opts)?;
                let mut times = Vec::new();
                for _ in 0..runs {
                    times.push(
                        renderer
                            .render_one(
                                &view,
                                &FrameOptions {
                                    read_image: false,
                                    ..opts
                                },
                            )?
                            .gpu_ms(),
                    );
                }
                println!(
                    "| {label} | {path:?} | {} | {} | {} | {:.2} |",
                    if lod_on { "on" } else { "off" },
                    first.stats.strands_drawn,
                    first.stats.triangles_drawn,
                    median(times)
                );
                if lod_on && path == paths[0] {
                    pics.push(first);
                }
            }
        }
    }
    if let Some(p) = picture {
        let mut strip = image::RgbaImage::new(width * 3, height);
        for (i, out) in pics.iter().enumerate() {
            let rgba = out.rgba.clone().context("no image")?;
            let img = image::RgbaImage::from_raw(width, height, rgba).context("size")?;
            image::imageops::replace(&mut strip, &img, (i as u32 * width) as i64, 0);
        }
        let mut png = Vec::new();
        strip.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)?;
        hairmesh::fsutil::write_atomic(&p, &png)?;
        println!("wrote {}", p.display());
    }
    Ok(())
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() -> Result<()> {
    match Args::parse().cmd {
        Cmd::Lod {
            mesh,
            width,
            height,
            strands_per_bundle,
            runs,
            device,
            picture,
        } => {
            bench_lod(
                mesh,
                width,
                height,
                strands_per_bundle,
                runs,
                device,
                picture,
            )?;
        }
        Cmd::CpuGenerate {
            mesh,
            strands,
            verts_log2,
            runs,
        } => {
            if runs == 0 || verts_log2 > 10 {
                bail!("runs must be >= 1 and verts-log2 <= 10");
            }
            let m = load_hair_mesh_obj(&mesh)?;
            let style = match HairStyle::beside(&mesh) {
                Some(p) => HairStyle::load(&p)?,
                None => HairStyle::default(),
            };
            let baked = bake(&m, &style, BakeOptions::default(), |_, _| {})?;
            let generator = CpuGenerator::new(&baked, style);
            let n = (strands / baked.bundles.len() as u32).max(1);
            let warm = generator.generate(n, verts_log2);
            let mut times = Vec::new();
            for i in 0..runs {
                let t = Instant::now();
                let set = generator.generate(n, verts_log2);
                let s = t.elapsed().as_secs_f64();
                println!("run {i}: {:.3} s ({} strands)", s, set.strand_count());
                times.push(s);
            }
            let med = median(times);
            let verts = warm.positions.len();
            println!(
                "cpu-generate {}: {} strands x {} vertices = {} vertices, median {:.3} s, {:.1} M vertices/s (1 thread)",
                mesh.display(),
                warm.strand_count(),
                warm.verts_per_strand,
                verts,
                med,
                verts as f64 / med / 1e6
            );
        }
    }
    Ok(())
}
