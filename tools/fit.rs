//! `fit`: turn a strand model (TressFX `.tfx`, Yuksel's `.hair` or Alembic `.abc` curves) into a hair mesh OBJ and a
//! style TOML beside it, ready for `bake` (method: `src/fit/mod.rs`); `--report` measures the
//! fitted hair mesh against the input strands.
//!
//! `fit STRANDS.tfx|.hair|.abc [--head HEAD.obj] -o OUT.obj [--bundles 64] [--layers L] [--report]
//! [--picture side_by_side.png]`

use std::io::Write as _;
use std::path::PathBuf;
use std::sync::Arc;

use anyhow::{Context as _, Result, bail};
use clap::Parser;
use glam::Vec3;
use hairmesh::budget::{self, MemoryBudget, VEC_HEADER};
use hairmesh::cli::DeviceFlags;
use hairmesh::fit::metric::compare;
use hairmesh::fit::picture::{StrandLook, draw_strands};
use hairmesh::fit::{FitOptions, Fitted, fit};
use hairmesh::fsutil::RunFiles;
use hairmesh::model::strands::StrandModel;
use hairmesh::reference::generate::strands_per_bundle_for;
use hairmesh::render::{Camera, Renderer, RendererDesc};
use hairmesh::vk::Context;
use hairmesh::{BakeOptions, BakedHairMesh, CpuGenerator, bake, outln};

/// Fit a hair mesh to a strand model.
#[derive(Parser)]
#[command(version, about)]
struct Args {
    /// Strand model: TressFX 4.0 `.tfx`, `.hair` or Alembic (Ogawa) `.abc` curves.
    strands: PathBuf,
    /// Head mesh OBJ: the scalp is placed on its surface.
    #[arg(long)]
    head: Option<PathBuf>,
    /// Output hair mesh OBJ; the style is written beside it as .toml.
    #[arg(short, long)]
    output: PathBuf,
    /// Target number of bundles.
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..=65536))]
    bundles: u32,
    /// Layers including the scalp (default: from the strands' curvature).
    #[arg(long, value_parser = clap::value_parser!(u32).range(2..=16))]
    layers: Option<u32>,
    /// Measure the fitted hair mesh against the input: distances, coverage, storage, and the
    /// FLIP mean of the two drawn side by side (needs Vulkan).
    #[arg(long)]
    report: bool,
    /// With --report: write the input (left) and the fitted hair mesh (right) here.
    #[arg(long)]
    picture: Option<PathBuf>,
    /// The device of --report.
    #[command(flatten)]
    gpu: DeviceFlags,
    /// Host memory the fit may use, MiB: larger work is refused before it starts.
    #[arg(long, value_name = "MIB", default_value = "4096", value_parser = budget::parse_budget_flag)]
    memory_budget_mib: MemoryBudget,
}

fn run(parsed: hairmesh::cli::Parsed<Args>) -> Result<()> {
    for id in ["validation", "device", "picture"] {
        parsed
            .unused_unless(id, parsed.args.report, "it applies to --report, not given")
            .map_err(anyhow::Error::msg)?;
    }
    let args = parsed.args;
    let mut files = RunFiles::new();
    files.inputs(std::iter::once(args.strands.as_path()).chain(args.head.as_deref()));
    let obj_out = files.output(&args.output, "-o")?;
    let toml_path = args.output.with_extension("toml");
    if toml_path == args.output {
        bail!(
            "{}: the output needs an extension other than .toml",
            args.output.display()
        );
    }
    let toml_out = files.output(&toml_path, "the style beside -o")?;
    let picture = args
        .picture
        .as_ref()
        .map(|p| files.output(p, "--picture"))
        .transpose()?;
    if picture.is_some() && !args.report {
        bail!("--picture needs --report");
    }
    let model = StrandModel::load(&args.strands)?;
    let head = args
        .head
        .as_deref()
        .map(hairmesh::model::obj_io::load_triangles)
        .transpose()?;
    let opts = FitOptions {
        bundles: args.bundles as usize,
        layers: args.layers.map(|l| l as usize),
        memory_budget: args.memory_budget_mib,
    };
    if args.report {
        check_report_memory(&args, &model, &opts)?;
    }
    let fitted = fit(&model, head.as_deref(), &opts)?;
    check_reach(&args, &fitted)?;
    let baked = bake(
        &fitted.mesh,
        &fitted.style,
        BakeOptions {
            memory_budget: args.memory_budget_mib,
            ..Default::default()
        },
        |_, _| {},
    )
    .context("the fitted hair mesh does not bake")?;
    let comment = format!(
        "fitted by hairmesh fit from {} ({} strands)",
        args.strands.display(),
        model.strands.len()
    );
    let obj = hairmesh::model::obj_io::hair_mesh_obj_bytes(&fitted.mesh, &comment)?;
    let toml = format!("# {comment}\n{}", toml::to_string(&fitted.style)?);
    print_summary(&args, &model, &fitted, &baked)?;
    let mut png = None;
    if args.report {
        png = report(&args, &model, &fitted, &baked)?;
    }
    // The last lines come before the files: a stdout that fails leaves no output behind.
    if let Some(out) = &picture {
        outln!("writing {}", out.path().display())?;
    }
    outln!(
        "writing {} and {}",
        args.output.display(),
        toml_path.display()
    )?;
    let mut outputs = vec![(&obj_out, obj.as_slice()), (&toml_out, toml.as_bytes())];
    if let (Some(out), Some(bytes)) = (&picture, &png) {
        outputs.push((out, bytes.as_slice()));
    }
    hairmesh::fsutil::write_together(&outputs)?;
    Ok(())
}

/// The strands the fitted hair mesh generates (CPU reference, 33 points each), about as
/// many as the input has.
fn generated(
    model: &StrandModel,
    fitted: &hairmesh::fit::Fitted,
    baked: &hairmesh::BakedHairMesh,
) -> Vec<Vec<Vec3>> {
    let (per, _) = strands_per_bundle_for(baked, &fitted.style, model.strands.len() as u64);
    CpuGenerator::new(baked, fitted.style)
        .generate(per, 5)
        .polylines()
}

fn report(
    args: &Args,
    model: &StrandModel,
    fitted: &hairmesh::fit::Fitted,
    baked: &hairmesh::BakedHairMesh,
) -> Result<Option<Vec<u8>>> {
    let strands = generated(model, fitted, baked);
    let f = compare(
        &model.strands,
        &strands,
        model.diagonal(),
        fitted.bundle_size,
    );
    outln!(
        "fidelity ({} generated strands; distances in % of the {:.3} bounding-box diagonal, coverage of roots within {:.3}, the bundle size): {f}",
        strands.len(),
        model.diagonal(),
        fitted.bundle_size
    )?;
    let ctx = Arc::new(Context::new(&args.gpu.context_desc())?);
    let size = 384;
    let mut r = Renderer::new(&ctx, &RendererDesc::default().size(size, size))?;
    let (lo, hi) = model.bounds();
    let look = StrandLook {
        camera: Camera::framing(lo, hi, Vec3::new(0.0, 0.2, 1.0), 40.0),
        color: Vec3::from_array(fitted.style.color),
        light: Vec3::new(0.4, 1.0, 0.6),
        width_px: 0.8,
    };
    let input_img = draw_strands(&mut r, &model.strands, &look)?;
    let fit_img = draw_strands(&mut r, &strands, &look)?;
    if ctx.validation_errors() > 0 {
        bail!("{} Vulkan validation error(s)", ctx.validation_errors());
    }
    let rgb = |img: &[u8]| -> Vec<u8> { img.chunks(4).flat_map(|p| [p[0], p[1], p[2]]).collect() };
    let err = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(size, size, &rgb(&input_img)),
        nv_flip::FlipImageRgb8::with_data(size, size, &rgb(&fit_img)),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    let mean = nv_flip::FlipPool::from_image(&err).mean();
    outln!(
        "FLIP mean {mean:.4} (input strands vs fitted hair mesh, {size}x{size}, software rasterizer, {})",
        ctx.info.name
    )?;
    if args.picture.is_none() {
        return Ok(None);
    }
    let mut side = image::RgbaImage::new(2 * size, size);
    let left = image::RgbaImage::from_raw(size, size, input_img).context("image size")?;
    let right = image::RgbaImage::from_raw(size, size, fit_img).context("image size")?;
    image::imageops::replace(&mut side, &left, 0, 0);
    image::imageops::replace(&mut side, &right, size as i64, 0);
    let png = hairmesh::fsutil::encode_png("picture", 2 * size, size, side.into_raw())?;
    Ok(Some(png))
}

fn main() {
    let parsed = hairmesh::cli::parse::<Args>("fit");
    hairmesh::cli::clean_up_on_signals("fit");
    if let Err(e) = run(parsed) {
        let _ = std::io::stdout().flush();
        hairmesh::fsutil::exit_with_error("fit", &e, 1);
    }
}

/// The report's memory (about as many generated strands again, and the metric's copies of
/// both sets), checked against the budget before anything is fitted.
fn check_report_memory(args: &Args, model: &StrandModel, opts: &FitOptions) -> Result<()> {
    let s = model.strands.len() as u64;
    let estimate = hairmesh::fit::memory_estimate(
        s,
        model.point_count() as u64,
        model.file_bytes,
        opts.bundles as u64,
        opts.layers.unwrap_or(16) as u64,
    )
    .with("generated strands", s, VEC_HEADER + 33 * 32)
    .with(
        "metric samples",
        s.saturating_add(model.point_count() as u64),
        32,
    );
    args.memory_budget_mib.check(
        &args.strands.display().to_string(),
        &format!("--report on {s} strands"),
        &estimate,
        "drop --report",
    )?;
    Ok(())
}

/// What fit writes, bake must read: OBJ coordinates are limited (obj_io::MAX_COORDINATE).
fn check_reach(args: &Args, fitted: &Fitted) -> Result<()> {
    let (lo, hi) = hairmesh::model::hair_mesh::bounds(fitted.mesh.layers.iter().flatten().copied());
    let reach = lo.abs().max(hi.abs()).max_element();
    let limit = hairmesh::model::obj_io::MAX_COORDINATE;
    if reach > limit {
        bail!(
            "{}: the fitted hair mesh reaches {reach:e}, beyond the {limit:e} an OBJ hair mesh may hold (bake refuses it); scale the model down",
            args.strands.display()
        );
    }
    Ok(())
}

/// One line on the fit's sizes and one on the style it found.
fn print_summary(
    args: &Args,
    model: &StrandModel,
    fitted: &Fitted,
    baked: &BakedHairMesh,
) -> Result<()> {
    outln!(
        "{}: {} strands, {} points -> {} bundles, {} layers; textures {:.1} KiB vs {:.1} KiB input (input / textures = {:.1})",
        args.strands.display(),
        model.strands.len(),
        model.point_count(),
        fitted.mesh.faces.len(),
        fitted.mesh.layer_count(),
        baked.texture_bytes() as f64 / 1024.0,
        model.file_bytes as f64 / 1024.0,
        model.file_bytes as f64 / baked.texture_bytes().max(1) as f64
    )?;
    let s = &fitted.style;
    outln!(
        "style: length_variation {:.3}, clump_strength {:.3}, frizz_amplitude {:.4}, frizz_frequency {:.3}, strand_width {:.4}",
        s.length_variation,
        s.clump_strength,
        s.frizz_amplitude,
        s.frizz_frequency,
        s.strand_width
    )?;
    Ok(())
}
