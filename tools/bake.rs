//! `bake`: hair mesh OBJ -> baked five-texture file (`.hmb`).
//!
//! `bake <hairmesh.obj> [--style style.toml] [--extrude N --step S [--gravity G]] -o out.hmb`

use std::path::PathBuf;
use std::time::Instant;

use std::io::Write as _;

use anyhow::{Result, bail};
use clap::Parser;
use hairmesh::bake::baked_file;
use hairmesh::bake::{BakeOptions, texels_per_face};
use hairmesh::budget::{self, MemoryBudget};
use hairmesh::fsutil::OutputPath;
use hairmesh::model::obj_io::{load_hair_mesh_obj, load_scalp};
use hairmesh::{BakedHairMesh, ExtrudeDesc, HairMesh, HairStyle, extrude, outln};

/// Bake a hair mesh into the five textures of the hair-meshes paper.
#[derive(Parser)]
#[command(version, about)]
struct Args {
    /// Hair mesh OBJ (groups layer0..layerN), or a scalp OBJ with --extrude.
    input: PathBuf,
    /// Style TOML (default: the .toml next to the input, else built-in defaults).
    #[arg(long)]
    style: Option<PathBuf>,
    /// Output file (.hmb).
    #[arg(short, long)]
    output: PathBuf,
    /// Treat the input as a scalp and extrude it into N layers (2..=512) along its normals.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(2..=hairmesh::model::hair_mesh::MAX_LAYERS as i64))]
    extrude: Option<u16>,
    /// Layer step length for --extrude (object units).
    #[arg(long, default_value_t = 0.02)]
    step: f32,
    /// Bend extruded layers toward -Y, 0..1.
    #[arg(long, default_value_t = 0.0)]
    gravity: f32,
    /// One 2x2 block per face instead of shared-vertex charts.
    #[arg(long)]
    no_charts: bool,
    /// Host memory the bake may use, MiB: larger work is refused before it starts.
    #[arg(long, value_name = "MIB", default_value = "4096", value_parser = budget::parse_budget_flag)]
    memory_budget_mib: MemoryBudget,
}

fn run(parsed: hairmesh::cli::Parsed<Args>) -> Result<()> {
    let start = Instant::now();
    for id in ["step", "gravity"] {
        parsed
            .unused_unless(
                id,
                parsed.args.extrude.is_some(),
                "it shapes --extrude, not given",
            )
            .map_err(anyhow::Error::msg)?;
    }
    let args = parsed.args;
    check_args(&args)?;
    let style_path = args
        .style
        .clone()
        .or_else(|| HairStyle::beside(&args.input));
    let mut inputs = vec![args.input.as_path()];
    inputs.extend(style_path.as_deref());
    let output = OutputPath::check(&args.output, &inputs)?;
    let mesh = load_mesh(&args)?;
    let style = match &style_path {
        Some(p) => HairStyle::load(p)?,
        None => HairStyle::default(),
    };
    let baked = bake_with_progress(&mesh, &style, &args)?;
    let bytes = baked_file::to_bytes(&baked);
    outln!("{}", args.input.display())?;
    outln!(
        "  {} vertices ({} per layer x {} layers), {} bundles, style {}",
        mesh.vertex_count(),
        mesh.vertices_per_layer(),
        mesh.layer_count(),
        mesh.faces.len(),
        style_path.map_or("defaults".into(), |p| p.display().to_string())
    )?;
    print_textures(&baked)?;
    // The last line comes before the file: a stdout that fails leaves no output behind.
    outln!(
        "  writing {} ({} bytes with bundle table and header), baked in {:.2} s",
        args.output.display(),
        bytes.len(),
        start.elapsed().as_secs_f32()
    )?;
    output.write(&bytes)?;
    Ok(())
}

/// The numeric flags and the output's name, checked before anything is read.
fn check_args(args: &Args) -> Result<()> {
    if !(args.step.is_finite() && args.step > 0.0 && args.step <= 1e3) {
        bail!("--step {} must be in (0, 1000]", args.step);
    }
    if !(args.gravity.is_finite() && (0.0..=1.0).contains(&args.gravity)) {
        bail!("--gravity {} must be in [0, 1]", args.gravity);
    }
    if args.output.extension().is_none() {
        bail!(
            "{}: output needs an extension (e.g. .hmb)",
            args.output.display()
        );
    }
    Ok(())
}

/// The hair mesh to bake: the input OBJ, or its scalp extruded (`--extrude`), estimated
/// against the memory budget before either allocates.
fn load_mesh(args: &Args) -> Result<HairMesh> {
    let Some(layers) = args.extrude else {
        return Ok(load_hair_mesh_obj(&args.input)?);
    };
    let layers = layers as usize;
    let scalp = load_scalp(&args.input)?;
    // The root slice holds at least one texel per scalp vertex.
    let n = scalp.positions.len() as u64;
    let estimate = hairmesh::bake::memory_estimate(n, layers as u64, n);
    args.memory_budget_mib.check(
        &args.input.display().to_string(),
        &format!("--extrude {layers} of {n} scalp vertices"),
        &estimate,
        "lower --extrude",
    )?;
    Ok(extrude(
        args.input.display().to_string(),
        &scalp.positions,
        &scalp.uv,
        &scalp.faces,
        &ExtrudeDesc::new(layers, args.step).gravity(args.gravity, glam::Vec3::NEG_Y),
    )?)
}

/// Bake `mesh`, printing progress on stderr for big meshes.
fn bake_with_progress(mesh: &HairMesh, style: &HairStyle, args: &Args) -> Result<BakedHairMesh> {
    let big = mesh.vertex_count() > 200_000;
    let baked = hairmesh::bake(
        mesh,
        style,
        BakeOptions {
            motion_margin: 0.0,
            charts: !args.no_charts,
            memory_budget: args.memory_budget_mib,
        },
        |done, total| {
            if big {
                let _ = write!(
                    std::io::stderr(),
                    "\rbaking {:3}%",
                    done * 100 / total.max(1)
                );
            }
        },
    )?;
    if big {
        let _ = writeln!(std::io::stderr());
    }
    Ok(baked)
}

/// The root slice and every texture's extent, format and size.
fn print_textures(baked: &BakedHairMesh) -> Result<()> {
    outln!(
        "  root slice {}x{} texels, {:.2} texels per face",
        baked.info.root_size[0],
        baked.info.root_size[1],
        texels_per_face(baked)
    )?;
    for t in baked.textures() {
        outln!(
            "  {:<18} {:>4}x{:<4}x{:<4} {:<20} {:>10} bytes",
            t.name,
            t.extent[0],
            t.extent[1],
            t.extent[2],
            t.format,
            t.bytes.len()
        )?;
    }
    let total = baked.texture_bytes();
    outln!(
        "  {:<18} {:>45} bytes ({:.1} KB)",
        "total textures",
        total,
        total as f64 / 1024.0
    )?;
    Ok(())
}

fn main() {
    let parsed = hairmesh::cli::parse::<Args>("bake");
    hairmesh::cli::clean_up_on_signals("bake");
    if let Err(e) = run(parsed) {
        hairmesh::fsutil::exit_with_error("bake", &e, 1);
    }
}
