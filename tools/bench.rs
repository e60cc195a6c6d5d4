//! `bench`: measurements written to the README (never timed tests).
//!
//! `bench cpu-generate [--mesh M] [--strands 100000] [--verts-log2 5] [--runs 7]`: CPU reference
//! generator throughput on one core; prints every run and the median.
//!
//! `bench lod [--mesh M] [--size 1280x720] [--runs 5] [--picture out.png]`: one scene at near,
//! mid and far distances; strand triangles and median GPU time with LoD on vs off, mesh vs
//! compute path (timestamp queries); optionally a near/mid/far picture with LoD on.
//!
//! `bench paper [--scale small|full] [--csv out.csv]`: the paper's comparison in one run:
//! hair mesh (both paths) vs LHS vs static strands per model, crowd and distance LoD speedups,
//! bytes per method.
//!
//! `bench crowd` takes `--draw hw|soft[:K]|auto[:K]` (the rasterizer of every frame);
//! `bench crowd --volume-tier [--counts 100,1000]` measures the crowd's default look with the
//! volume tier off and on instead.
//!
//! `bench raster [--size 1280x720] [--runs 5] [--crowd 100] [--strands 100000]`: the
//! software rasterizer vs hardware strips (opaque and OIT) and the per-bundle split, for one
//! head at near / mid / far, ~100K strands, and a crowd; both paths.
//!
//! `bench temporal [--size 320x180] [--frames 16] [--scenarios orbit,dolly,crowd]`: the
//! flicker measure with temporal accumulation off and on against a supersampled reference.
//!
//! `bench animate [--mesh M] [--wind 30] [--frames 90] [--counts 1,100] [--dynamics gpu,cpu]
//! [--strip out.png] [--volumes]`: copies of one hair mesh in wind, simulated (on the GPU, or the CPU on
//! all cores) and re-textured every frame: CPU and GPU ms of the dynamics, GPU ms of the
//! texture rebuild and of the frame (medians), and with `--volumes` of rebuilding every
//! character's density volume every frame; optionally a strip of frames side by side.

use std::path::{Path, PathBuf};
use std::time::Instant;

#[path = "bench/animate.rs"]
mod animate;
#[path = "bench/compare.rs"]
mod compare;
#[path = "bench/defaults.rs"]
mod defaults;
#[path = "bench/lod.rs"]
mod lod;
#[path = "bench/paper.rs"]
mod paper;
#[path = "bench/raster.rs"]
mod raster;
#[path = "bench/scalp.rs"]
mod scalp;
#[path = "bench/temporal.rs"]
mod temporal;
#[path = "bench/volume_tier.rs"]
mod volume_tier;

use anyhow::{Context as _, Result, bail};
use clap::{Parser, Subcommand};
use std::sync::Arc;

use glam::{Mat4, Vec3};
use hairmesh::fsutil::OutputPath;
use hairmesh::model::obj_io::load_hair_mesh_obj;
use hairmesh::outln;
use hairmesh::render::scene::load_mesh;
use hairmesh::render::{
    Camera, FrameOptions, FrameReport, LodSettings, RenderPath, Renderer, RendererDesc,
    StrandParams, StrandRaster, View,
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
        #[arg(long, default_value_t = 100_000, value_parser = clap::value_parser!(u32).range(1..=10000000))]
        strands: u32,
        /// Vertices per strand are 2^e + 1.
        #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(0..=10))]
        verts_log2: u32,
        /// Timed runs (after one warm-up).
        #[arg(long, default_value_t = 7, value_parser = clap::value_parser!(u16).range(1..=1000))]
        runs: u16,
    },
    /// GPU LoD against full detail at near / mid / far distances, both paths: strands,
    /// triangles, GPU ms and FLIP of LoD on against off.
    Lod(lod::LodArgs),
    /// Fuzz every reader (OBJ + bake, style TOML, scene TOML, .hmb) with seeded mutations.
    Fuzz {
        /// Inputs per reader.
        #[arg(long, default_value_t = 100_000, value_parser = clap::value_parser!(u64).range(1..=1_000_000_000))]
        iterations: u64,
        /// Campaign seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Only these readers (default: every one).
        #[arg(long, value_delimiter = ',')]
        readers: Vec<hairmesh::fuzz::Reader>,
        /// Instead of a campaign: write input N (from 0) of the one --readers campaign to
        /// --to, to reproduce a finding alone.
        #[arg(long, value_name = "N", requires = "to")]
        save_input: Option<u64>,
        /// Where --save-input writes the input.
        #[arg(long, requires = "save_input")]
        to: Option<PathBuf>,
    },
    /// The paper's comparison in one run: hair mesh (mesh and compute paths) vs linear hair
    /// skinning vs static strands per model, crowd LoD on/off, near/mid/far LoD, GPU bytes.
    Paper {
        /// small (lavapipe: about a minute per scenario) or full (the paper's counts).
        #[arg(long, default_value = "small", value_parser = ["small", "full"])]
        scale: String,
        /// One scenario: models (a, d), crowd (b), distance (c), storage (d for the crowd's
        /// generated styles), or all.
        #[arg(long, default_value = "all", value_parser = ["all", "models", "crowd", "distance", "storage", "teapots"])]
        scenario: String,
        /// Write every measurement here as CSV.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Choose the GPU by name substring.
        #[arg(long)]
        device: Option<String>,
        /// How every method's strands are rasterized: hw, soft, soft:K, auto or auto:K (the static
        /// and LHS paths give their stored strands to the software rasterizer too).
        #[arg(long, default_value = "hw")]
        draw: StrandRaster,
    },
    /// The software rasterizer against hardware strips: one head at near / mid / far,
    /// ~100K strands, a crowd with LoD; median GPU ms and ratios per path.
    Raster {
        /// Image size.
        #[arg(long, default_value = "1280x720")]
        size: String,
        /// Timed frames per measurement (after one warm-up).
        #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u16).range(1..=1000))]
        runs: u16,
        /// Characters in the crowd scene.
        #[arg(long, default_value_t = 100)]
        crowd: usize,
        /// Strands of the dense scene.
        #[arg(long, default_value_t = 100_000, value_parser = clap::value_parser!(u32).range(1..=10000000))]
        strands: u32,
        /// Only the scenes whose names start with these (head, crowd, or the strand count).
        #[arg(long, value_delimiter = ',')]
        scenes: Vec<String>,
        /// auto: strands drawn at most this many pixels wide go to the software rasterizer.
        #[arg(long, default_value_t = hairmesh::render::soft::AUTO_SPLIT_PIXELS)]
        auto_split: f32,
        /// Only these columns: hw-opaque, hw-oit, soft, auto (default all).
        #[arg(long, value_delimiter = ',', value_parser = ["hw-opaque", "hw-oit", "soft", "auto"])]
        draws: Vec<String>,
        /// Choose the GPU by name substring.
        #[arg(long)]
        device: Option<String>,
    },
    /// The flicker measure: a slow orbit, a slow dolly and an animated crowd rendered with
    /// temporal accumulation off and on and as a supersampled reference; the change of the
    /// hair's luminance between frames moved along the true motion, ours over the
    /// reference's, FLIP against the reference, and the accumulation's GPU ms.
    Temporal(temporal::TemporalArgs),
    /// The regression harness: build REV's crowd in target/compare, run a fixed set of
    /// frames (bare strands soft and hw on both paths at 20K and 100K, the full look, the
    /// people crowd at 100 and 1000) alternating old and new, print new/old per row.
    Compare(compare::CompareArgs),
    /// Scalp show-through of every family's portrait at each density: the share of the
    /// scalp's pixels whose light through the hair is above one half (a real head: only at
    /// partings and the hairline).
    Scalp(scalp::ScalpArgs),
    /// FLIP (nv-flip) of a test picture against a reference of the same size: mean and 99th
    /// percentile, as the golden tests and `compare` measure.
    Flip {
        /// Reference PNG.
        reference: PathBuf,
        /// Test PNG.
        test: PathBuf,
    },
    /// Copies of one hair mesh in wind, simulated and re-textured every frame (30 Hz), for
    /// each character count and dynamics path: CPU and GPU ms of the dynamics, GPU ms of the
    /// texture rebuild and of the frame; optionally a strip of frames.
    Animate(AnimateFlags),
    /// A crowd of mixed sample meshes on a ground plane seen from human height: GPU ms per
    /// pass, CPU ms to record a frame, peak RSS and GPU memory, for N characters, LoD on/off,
    /// both paths (and the mesh path with 1 vs 32 bundles per task workgroup).
    Crowd {
        /// Character counts (default 1,16,64,256; with --compare-defaults, 100).
        #[arg(long, value_delimiter = ',')]
        counts: Option<Vec<usize>>,
        /// Image width.
        #[arg(long, default_value_t = 1280, value_parser = clap::value_parser!(u32).range(1..=8192))]
        width: u32,
        /// Image height.
        #[arg(long, default_value_t = 720, value_parser = clap::value_parser!(u32).range(1..=8192))]
        height: u32,
        /// Strands per bundle.
        #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=16384))]
        strands_per_bundle: u32,
        /// Vertex level e (2^e + 1 vertices at full detail).
        #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(0..=6))]
        verts_log2: u32,
        /// Timed frames per configuration (after one warm-up).
        #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u16).range(1..=1000))]
        runs: u16,
        /// Choose the GPU by name substring.
        #[arg(long)]
        device: Option<String>,
        /// Write the largest crowd's frame (mesh path or compute, LoD on) here.
        #[arg(long)]
        picture: Option<PathBuf>,
        /// Strand rasterization: hw, soft, soft:K, auto or auto:K (see `render --help`).
        #[arg(long, default_value = "hw")]
        draw: hairmesh::render::StrandRaster,
        /// Instead: the crowd's default look (Marschner, deep opacity shadows) with the old
        /// default rasterizers (hw for camera and light) against today's (auto and the
        /// software light passes where supported), frame wall time and speed-up.
        #[arg(long)]
        compare_defaults: bool,
        /// Instead: the crowd's default look with the volume tier (far hair from density
        /// volumes, volumetric occlusion) off and on, and each one's cost of the largest
        /// count over the smallest.
        #[arg(long, conflicts_with = "compare_defaults")]
        volume_tier: bool,
        /// With --volume-tier: also write one character (head_long) shrinking across the
        /// tier's switch band, tier on (top) and off (bottom), here.
        #[arg(long, requires = "volume_tier")]
        band_strip: Option<PathBuf>,
    },
}

/// `bench animate`'s flags.
#[derive(clap::Args)]
struct AnimateFlags {
    /// Hair mesh OBJ (style: the .toml beside it).
    #[arg(long, default_value = "hairmeshes/head_long.obj")]
    mesh: PathBuf,
    /// Frames (1/30 s apart).
    #[arg(long, default_value_t = 90, value_parser = clap::value_parser!(u32).range(1..=100000))]
    frames: u32,
    /// Wind strength on the tips, m/s^2 (0..=100).
    #[arg(long, default_value_t = 30.0)]
    wind: f32,
    /// Image size.
    #[arg(long, default_value = "240x240")]
    size: String,
    /// Strands per bundle.
    #[arg(long, default_value_t = 32, value_parser = clap::value_parser!(u32).range(1..=16384))]
    strands_per_bundle: u32,
    /// Character counts, one run each (copies of the mesh on a grid, all simulated every
    /// frame on all cores).
    #[arg(long, value_delimiter = ',', default_value = "1")]
    counts: Vec<u32>,
    /// Where the dynamics run, one run each: gpu (one dispatch for every character) and/or
    /// cpu (all cores, poses uploaded).
    #[arg(long, value_delimiter = ',', default_value = "gpu,cpu")]
    dynamics: Vec<hairmesh::animate::DynamicsPath>,
    /// Write frames (of the first count and path) side by side here.
    #[arg(long)]
    strip: Option<PathBuf>,
    /// Frames in the strip (evenly spaced).
    #[arg(long, default_value_t = 6, value_parser = clap::value_parser!(u32).range(1..=32))]
    strip_frames: u32,
    /// Choose the GPU by name substring.
    #[arg(long)]
    device: Option<String>,
    /// Also rebuild every character's strand density volume (32^3 cells, 16 strands per
    /// bundle) every frame, and report its GPU ms.
    #[arg(long)]
    volumes: bool,
}

impl AnimateFlags {
    /// The run's settings, the image size parsed.
    fn into_args(self) -> Result<animate::AnimateArgs> {
        Ok(animate::AnimateArgs {
            size: hairmesh::render::scene::parse_size(&self.size).map_err(anyhow::Error::msg)?,
            mesh: self.mesh,
            frames: self.frames,
            wind: self.wind,
            strands_per_bundle: self.strands_per_bundle,
            counts: self.counts,
            dynamics: self.dynamics,
            strip: self.strip,
            strip_frames: self.strip_frames,
            device: self.device,
            volumes: self.volumes,
        })
    }
}

/// Cameras on the line from the mesh's framing view (40 degrees, `DEFAULT_VIEW_DIR`) to its
/// target, `k` times the framing distance away: the near / mid / far views of `bench lod` and
/// `bench raster`.
pub(crate) fn dolly(baked: &hairmesh::BakedHairMesh) -> impl Fn(f32) -> Camera {
    let o = Vec3::from_slice(&baked.info.pos_origin[..3]);
    let e = Vec3::from_slice(&baked.info.pos_extent[..3]);
    let frame = Camera::framing(o, o + e, hairmesh::render::DEFAULT_VIEW_DIR, 40.0);
    move |k| {
        Camera::look_at(
            frame.target + (frame.eye - frame.target) * k,
            frame.target,
            40.0,
        )
    }
}

/// Most vertices `bench cpu-generate` generates (about 0.9 GB of positions, tangents, widths).
const MAX_CPU_VERTICES: u64 = 32 << 20;

/// Peak resident set size of this process in MiB (Linux `VmHWM`).
fn peak_rss_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|kb| kb.parse::<f64>().ok())
        })
        .map_or(0.0, |kb| kb / 1024.0)
}

const CROWD_MESHES: [&str; 4] = [
    "hairmeshes/head_long.obj",
    "hairmeshes/sphere_fur.obj",
    "hairmeshes/small_patch.obj",
    "hairmeshes/triangle_tuft.obj",
];

/// Model transform of character `i` of a crowd: a grid on the ground with 1 m spacing, each
/// mesh scaled to 0.3 m at head height (1.6 m), turned a little differently.
fn crowd_model(i: usize, side: usize, baked: &hairmesh::BakedHairMesh) -> Mat4 {
    let o = Vec3::from_slice(&baked.info.pos_origin[..3]);
    let ext = Vec3::from_slice(&baked.info.pos_extent[..3]);
    let scale = 0.3 / ext.max_element();
    let x = (i % side) as f32 - (side as f32 - 1.0) * 0.5;
    let z = 2.0 + (i / side) as f32;
    Mat4::from_scale_rotation_translation(
        Vec3::splat(scale),
        glam::Quat::from_rotation_y(i as f32 * 2.4),
        Vec3::new(x, 1.6, z) - (o + ext * 0.5) * scale,
    )
}

/// One `bench crowd` configuration set: what every measured row shares.
struct CrowdRun<'a> {
    ctx: &'a Arc<Context>,
    meshes: &'a [(hairmesh::BakedHairMesh, hairmesh::HairStyle)],
    params: StrandParams,
    size: (u32, u32),
    runs: usize,
    camera: Camera,
    read_image: bool,
    raster: hairmesh::render::StrandRaster,
}

impl CrowdRun<'_> {
    /// An empty renderer at the run's size, `task_bundles` bundles per task workgroup.
    fn renderer(&self, task_bundles: u32) -> Result<Renderer> {
        let desc = RendererDesc {
            task_bundles,
            ..RendererDesc::default().size(self.size.0, self.size.1)
        };
        Ok(Renderer::new(self.ctx, &desc)?)
    }

    /// Add `count` characters of the run's meshes to `renderer`, in a square grid.
    fn add_crowd(&self, renderer: &mut Renderer, count: usize) -> Result<()> {
        let side = (count as f32).sqrt().ceil() as usize;
        for i in 0..count {
            let (baked, style) = &self.meshes[i % self.meshes.len()];
            renderer.add_character(baked, style, self.params, crowd_model(i, side, baked))?;
        }
        Ok(())
    }

    /// Print the LoD-on and LoD-off rows of `count` characters on `path`; returns the LoD-on
    /// image when asked for.
    fn measure(
        &self,
        count: usize,
        label: &str,
        task_bundles: u32,
        path: RenderPath,
    ) -> Result<Option<Vec<u8>>> {
        let ctx = self.ctx;
        let before = ctx.memory_report().allocated_bytes;
        let mut renderer = self.renderer(task_bundles)?;
        let empty = ctx.memory_report().allocated_bytes;
        self.add_crowd(&mut renderer, count)?;
        let full = ctx.memory_report().allocated_bytes;
        let per_char = (full - empty) as f64 / count as f64 / 1024.0;
        let tex_per_char = renderer.crowd().texture_bytes() as f64 / count as f64 / 1024.0;
        let mut picture = None;
        for lod_on in [true, false] {
            let view = bench_view(self.camera, lod_on);
            let opts = FrameOptions {
                path: Some(path),
                raster: self.raster,
                ..Default::default()
            };
            let read_image = self.read_image && lod_on;
            let first = renderer.render_one(&view, &FrameOptions { read_image, ..opts })?;
            let (reports, wall) = timed_frames(&mut renderer, &view, &opts, self.runs)?;
            let passes: Vec<String> = median_passes(&first, &reports)
                .iter()
                .map(|(n, ms)| format!("{n} {ms:.1}"))
                .collect();
            let gpu = median(reports.iter().map(|r| r.gpu_ms()).collect());
            let record = median(reports.iter().map(|r| r.record_ms).collect());
            let used = ctx.memory_report().allocated_bytes - before;
            outln!(
                "| {count} | {label} | {} | {} ({}) | {} | {} | {gpu:.1} | {record:.3} | {:.1} | {per_char:.1} ({tex_per_char:.1}) | {:.0} | {wall:.1} |",
                if lod_on { "on" } else { "off" },
                first.stats.strands_drawn,
                first.stats.strands_demanded,
                first.stats.triangles_drawn,
                passes.join(", "),
                used as f64 / (1 << 20) as f64,
                peak_rss_mib()
            )?;
            if read_image {
                picture = first.rgba;
            }
        }
        Ok(picture)
    }
}

#[allow(clippy::too_many_arguments)]
fn bench_crowd(
    counts: Vec<usize>,
    width: u32,
    height: u32,
    n: u32,
    e: u32,
    runs: usize,
    device: Option<String>,
    picture: Option<PathBuf>,
    (raster, compare_defaults, volume_tier): (hairmesh::render::StrandRaster, bool, bool),
    band_strip: Option<PathBuf>,
) -> Result<()> {
    if counts.is_empty() || counts.iter().any(|&c| c == 0 || c > 1024) {
        bail!("--counts: every count must be in 1..=1024");
    }
    let inputs: Vec<&std::path::Path> = CROWD_MESHES.iter().map(std::path::Path::new).collect();
    let picture = picture
        .map(|p| OutputPath::check(&p, &inputs))
        .transpose()?;
    let band_strip = band_strip
        .map(|p| OutputPath::check(&p, &inputs))
        .transpose()?;
    let meshes = CROWD_MESHES
        .iter()
        .map(|m| load_mesh(std::path::Path::new(m), None, Default::default()))
        .collect::<Result<Vec<_>, _>>()?;
    let params = StrandParams {
        strands_per_bundle: n,
        verts_log2: e,
    };
    params.validate()?;
    let ctx = Arc::new(Context::new(&ContextDesc::default().device(device))?);
    outln!(
        "device: {} ({}), {width}x{height}, {n} strands/bundle, {} vertices at full detail, median of {runs}",
        ctx.info.name,
        ctx.info.driver,
        (1u32 << e) + 1
    )?;
    let camera = Camera::look_at(Vec3::new(0.0, 1.7, 0.6), Vec3::new(0.0, 1.5, 6.0), 50.0);
    let run = CrowdRun {
        ctx: &ctx,
        meshes: &meshes,
        params,
        size: (width, height),
        runs,
        camera,
        read_image: picture.is_some(),
        raster,
    };
    if volume_tier {
        let image = volume_tier::compare(&run, &counts, picture.is_some())?;
        if let (Some(out), Some(rgba)) = (picture, image) {
            write_png(&out, rgba, width, height)?;
        }
        if let Some(out) = band_strip {
            let (rgba, (w, h)) = volume_tier::band_strip(&ctx, &meshes[0])?;
            write_png(&out, rgba, w, h)?;
        }
        return Ok(());
    }
    if compare_defaults {
        outln!("| N | path | rasterizers | GPU ms | frame wall ms |\n|---|---|---|---|---|")?;
        for &count in &counts {
            defaults::compare(&run, count)?;
        }
        return Ok(());
    }
    let last_picture = crowd_table(&run, &counts)?;
    if let (Some(out), Some(rgba)) = (picture, last_picture) {
        write_png(&out, rgba, width, height)?;
    }
    Ok(())
}

/// `bench crowd`'s table: every count on every path (the mesh path with 32 and 1 bundles a
/// task where the device has it); the last picture taken, if any.
fn crowd_table(run: &CrowdRun, counts: &[usize]) -> Result<Option<Vec<u8>>> {
    outln!(
        "| N | path | LoD | strands drawn (demanded) | triangles | GPU ms per pass | GPU ms | CPU record ms | GPU MiB | per-character KiB (textures) | peak RSS MiB | frame wall ms |"
    )?;
    outln!("|---|---|---|---|---|---|---|---|---|---|---|---|")?;
    let mut configs = Vec::new();
    if hairmesh::render::passes::strands::mesh_path_supported(run.ctx) {
        configs.push(("mesh (32/task)", 32, RenderPath::Mesh));
        configs.push(("mesh (1/task)", 1, RenderPath::Mesh));
    }
    configs.push(("compute", 32, RenderPath::Compute));
    let mut last_picture = None;
    for &count in counts {
        for &(label, task_bundles, path) in &configs {
            if let Some(p) = run.measure(count, label, task_bundles, path)? {
                last_picture = Some(p);
            }
        }
    }
    Ok(last_picture)
}

/// The benchmarks' view: `camera`, a fixed light, default LoD on or LoD off.
fn bench_view(camera: Camera, lod_on: bool) -> View {
    View {
        light_dir: Vec3::new(0.4, 1.0, 0.6),
        lod: if lod_on {
            LodSettings::default()
        } else {
            LodSettings::off()
        },
        ..View::new(camera)
    }
}

/// `runs` timed frames of `view` with `opts` (after the caller's warm-up), and their median
/// wall time (submit to completion), ms.
fn timed_frames(
    renderer: &mut Renderer,
    view: &View,
    opts: &FrameOptions,
    runs: usize,
) -> Result<(Vec<FrameReport>, f64)> {
    let mut walls = Vec::new();
    let reports = (0..runs)
        .map(|_| {
            let start = Instant::now();
            let report = renderer.render_one(view, opts);
            walls.push(start.elapsed().as_secs_f64() * 1e3);
            report
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((reports, median(walls)))
}

/// Median GPU ms of each pass of `first` over `reports`, then of the part no scope covers.
fn median_passes<'a>(first: &'a FrameReport, reports: &[FrameReport]) -> Vec<(&'a str, f64)> {
    let mut out: Vec<(&str, f64)> = first
        .pass_ms
        .iter()
        .map(|(name, _)| {
            let ms = reports
                .iter()
                .map(|r| r.pass_ms.iter().find(|p| p.0 == *name).map_or(0.0, |p| p.1))
                .collect();
            (*name, median(ms))
        })
        .collect();
    let unscoped: Vec<f64> = reports
        .iter()
        .filter_map(FrameReport::unscoped_ms)
        .collect();
    if !unscoped.is_empty() {
        out.push(("unscoped", median(unscoped)));
    }
    out
}

/// RGBA images of `size` laid out side by side, one row of the picture per row given.
pub(crate) fn side_by_side(rows: &[Vec<Vec<u8>>], (w, h): (u32, u32)) -> Result<image::RgbaImage> {
    let cols = rows.iter().map(Vec::len).max().unwrap_or(0) as u32;
    let mut out = image::RgbaImage::new(w * cols, h * rows.len() as u32);
    for (r, row) in rows.iter().enumerate() {
        for (c, rgba) in row.iter().enumerate() {
            let img = image::RgbaImage::from_raw(w, h, rgba.clone()).context("image size")?;
            let (x, y) = (c as u32 * w, r as u32 * h);
            image::imageops::replace(&mut out, &img, x as i64, y as i64);
        }
    }
    Ok(out)
}

/// Write RGBA pixels as a PNG by the output policy.
pub(crate) fn write_png(out: &OutputPath, rgba: Vec<u8>, width: u32, height: u32) -> Result<()> {
    let png = hairmesh::fsutil::encode_png(&out.path().display().to_string(), width, height, rgba)?;
    out.write(&png)?;
    outln!("wrote {}", out.path().display())?;
    Ok(())
}

/// `bench fuzz`: a campaign per chosen reader (every one when none is named), one table row
/// each; or, with `save`, input N of the one named reader written to a file.
fn bench_fuzz(
    iterations: u64,
    seed: u64,
    readers: &[hairmesh::fuzz::Reader],
    save: Option<(u64, PathBuf)>,
) -> Result<()> {
    if let Some((index, to)) = save {
        let [reader] = readers[..] else {
            bail!("--save-input: name one reader with --readers");
        };
        let out = OutputPath::check(&to, &[])?;
        out.write(&hairmesh::fuzz::nth_input(reader, seed, index))?;
        outln!(
            "wrote input {index} of the {reader:?} campaign (seed {seed}) to {}",
            to.display()
        )?;
        return Ok(());
    }
    outln!("| reader | inputs | accepted | rejected | panics | slowest ms | seconds |")?;
    outln!("|---|---|---|---|---|---|---|")?;
    let all = hairmesh::fuzz::Reader::ALL;
    for reader in all
        .into_iter()
        .filter(|r| readers.is_empty() || readers.contains(r))
    {
        let start = Instant::now();
        let r = hairmesh::fuzz::campaign(reader, iterations, seed);
        outln!(
            "| {reader:?} | {} | {} | {} | {} | {:.1} | {:.1} |",
            r.inputs,
            r.accepted,
            r.rejected,
            r.panics.len(),
            r.slowest_ms,
            start.elapsed().as_secs_f64()
        )?;
        for (i, msg) in r.panics.iter().take(5) {
            outln!("  panic at input {i}: {msg}")?;
        }
    }
    Ok(())
}

/// The median of `v` (the mean of the middle two for an even count: two runs read their
/// mean, not the slower one); NaN for none.
pub(crate) fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 0 => 0.5 * (v[n / 2 - 1] + v[n / 2]),
        n => v[n / 2],
    }
}

fn main() {
    let parsed = hairmesh::cli::parse::<Args>("bench");
    hairmesh::cli::clean_up_on_signals("bench");
    if let Err(e) = check_unused(&parsed)
        .map_err(anyhow::Error::msg)
        .and_then(|()| run(parsed.args))
    {
        hairmesh::fsutil::exit_with_error("bench", &e, 1);
    }
}

/// Refuse every flag given that another flag of its subcommand makes unused.
fn check_unused(p: &hairmesh::cli::Parsed<Args>) -> Result<(), String> {
    match &p.args.cmd {
        Cmd::Crowd {
            compare_defaults,
            volume_tier,
            ..
        } => {
            let why = "--compare-defaults and --volume-tier choose their own rasterizers";
            p.unused_unless("draw", !compare_defaults && !volume_tier, why)?;
            p.unused_unless(
                "picture",
                !compare_defaults,
                "--compare-defaults writes no picture",
            )
        }
        Cmd::Animate(a) => {
            p.unused_unless("strip_frames", a.strip.is_some(), "--strip is not given")
        }
        _ => Ok(()),
    }
}

fn run(args: Args) -> Result<()> {
    match args.cmd {
        Cmd::Paper {
            scale,
            scenario,
            csv,
            device,
            draw,
        } => paper::bench_paper(&scale, &scenario, device, csv, draw)?,
        Cmd::Raster {
            size,
            runs,
            crowd,
            strands,
            scenes,
            auto_split,
            draws,
            device,
        } => raster::bench_raster(raster::RasterArgs {
            auto_split,
            draws,
            size: hairmesh::render::scene::parse_size(&size).map_err(anyhow::Error::msg)?,
            runs: runs as usize,
            crowd,
            strands,
            device,
            scenes,
        })?,
        Cmd::Animate(flags) => animate::bench_animate(flags.into_args()?)?,
        Cmd::Temporal(args) => temporal::bench_temporal(args)?,
        Cmd::Compare(args) => compare::bench_compare(args)?,
        Cmd::Scalp(args) => scalp::bench_scalp(args)?,
        Cmd::Flip { reference, test } => compare::print_flip(&reference, &test)?,
        Cmd::Fuzz {
            iterations,
            seed,
            readers,
            save_input,
            to,
        } => bench_fuzz(iterations, seed, &readers, save_input.zip(to))?,
        Cmd::Crowd {
            counts,
            width,
            height,
            strands_per_bundle,
            verts_log2,
            runs,
            device,
            picture,
            draw,
            compare_defaults,
            volume_tier,
            band_strip,
        } => bench_crowd(
            counts.unwrap_or_else(|| default_crowd_counts(compare_defaults, volume_tier)),
            width,
            height,
            strands_per_bundle,
            verts_log2,
            runs as usize,
            device,
            picture,
            (draw, compare_defaults, volume_tier),
            band_strip,
        )?,
        Cmd::Lod(args) => lod::bench_lod(args)?,
        Cmd::CpuGenerate {
            mesh,
            strands,
            verts_log2,
            runs,
        } => bench_cpu_generate(&mesh, strands, verts_log2, runs)?,
    }
    Ok(())
}

/// `bench cpu-generate`: the CPU oracle's strands per second on one thread.
fn bench_cpu_generate(mesh: &Path, strands: u32, verts_log2: u32, runs: u16) -> Result<()> {
    let vertices = strands as u64 * ((1u64 << verts_log2) + 1);
    if vertices > MAX_CPU_VERTICES {
        bail!(
            "--strands {strands} x {} vertices = {vertices} vertices, more than the {MAX_CPU_VERTICES} this benchmark allocates",
            (1u64 << verts_log2) + 1
        );
    }
    let m = load_hair_mesh_obj(mesh)?;
    let style = match HairStyle::beside(mesh) {
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
        outln!("run {i}: {:.3} s ({} strands)", s, set.strand_count())?;
        times.push(s);
    }
    let med = median(times);
    let verts = warm.positions.len();
    outln!(
        "cpu-generate {}: {} strands x {} vertices = {} vertices, median {:.3} s, {:.1} M vertices/s (1 thread)",
        mesh.display(),
        warm.strand_count(),
        warm.verts_per_strand,
        verts,
        med,
        verts as f64 / med / 1e6
    )?;
    Ok(())
}

/// `bench crowd`'s counts when none are given: 100 to compare defaults, 100 and 1000 for the
/// volume tier, else 1 to 256.
fn default_crowd_counts(compare_defaults: bool, volume_tier: bool) -> Vec<usize> {
    match (compare_defaults, volume_tier) {
        (true, _) => vec![100],
        (_, true) => vec![100, 1000],
        _ => vec![1, 16, 64, 256],
    }
}

#[cfg(test)]
mod tests {
    /// Odd counts take the middle value; even counts the mean of the middle two (the upper one
    /// alone read two runs as the slower one).
    #[test]
    fn the_median_of_an_even_count_is_the_mean_of_its_middle_pair() {
        assert_eq!(super::median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(super::median(vec![1915.2, 1712.2]), 1813.7);
        assert_eq!(super::median(vec![4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(super::median(Vec::new()).is_nan());
    }
}
