//! `bake`: hair mesh OBJ -> baked five-texture file (`.hmb`).
//!
//! `bake <hairmesh.obj> [--style style.toml] [--extrude N --step S [--gravity G]] -o out.hmb`

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Result;
use clap::Parser;
use hairmesh::bake::baked_file;
use hairmesh::bake::{BakeOptions, texels_per_face};
use hairmesh::model::obj_io::{load_hair_mesh_obj, load_scalp};
use hairmesh::{ExtrudeDesc, HairStyle, extrude};

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
    /// Treat the input as a scalp and extrude it into N layers along its normals.
    #[arg(long, value_name = "N")]
    extrude: Option<usize>,
    /// Layer step length for --extrude (object units).
    #[arg(long, default_value_t = 0.02)]
    step: f32,
    /// Bend extruded layers toward -Y, 0..1.
    #[arg(long, default_value_t = 0.0)]
    gravity: f32,
    /// One 2x2 block per face instead of shared-vertex charts.
    #[arg(long)]
    no_charts: bool,
}

fn run(args: Args) -> Result<()> {
    let start = Instant::now();
    let mesh = match args.extrude {
        Some(layers) => {
            let scalp = load_scalp(&args.input)?;
            extrude(
                args.input.display().to_string(),
                &scalp.positions,
                &scalp.uv,
                &scalp.faces,
                &ExtrudeDesc::new(layers, args.step).gravity(args.gravity, glam::Vec3::NEG_Y),
            )?
        }
        None => load_hair_mesh_obj(&args.input)?,
    };
    let style_path = args
        .style
        .clone()
        .or_else(|| HairStyle::beside(&args.input));
    let style = match &style_path {
        Some(p) => HairStyle::load(p)?,
        None => HairStyle::default(),
    };
    let big = mesh.vertex_count() > 200_000;
    let baked = hairmesh::bake(
        &mesh,
        &style,
        BakeOptions {
            charts: !args.no_charts,
        },
        |done, total| {
            if big {
                eprint!("\rbaking {:3}%", done * 100 / total.max(1));
            }
        },
    )?;
    if big {
        eprintln!();
    }
    baked_file::save(&baked, &args.output)?;

    println!("{}", args.input.display());
    println!(
        "  {} vertices ({} per layer x {} layers), {} bundles, style {}",
        mesh.vertex_count(),
        mesh.vertices_per_layer(),
        mesh.layer_count(),
        mesh.faces.len(),
        style_path.map_or("defaults".into(), |p| p.display().to_string())
    );
    println!(
        "  root slice {}x{} texels, {:.2} texels per face",
        baked.info.root_size[0],
        baked.info.root_size[1],
        texels_per_face(&baked)
    );
    for t in baked.textures() {
        println!(
            "  {:<18} {:>4}x{:<4}x{:<4} {:<20} {:>10} bytes",
            t.name,
            t.extent[0],
            t.extent[1],
            t.extent[2],
            t.format,
            t.bytes.len()
        );
    }
    let total = baked.texture_bytes();
    println!(
        "  {:<18} {:>45} bytes ({:.1} KB)",
        "total textures",
        total,
        total as f64 / 1024.0
    );
    println!(
        "  wrote {} ({} bytes with bundle table and header) in {:.2} s",
        args.output.display(),
        std::fs::metadata(&args.output)
            .map(|m| m.len())
            .unwrap_or(0),
        start.elapsed().as_secs_f32()
    );
    Ok(())
}

fn main() {
    let args = Args::parse();
    if args.output.extension().is_none() {
        eprintln!(
            "bake: {}: output needs an extension (e.g. .hmb)",
            args.output.display()
        );
        std::process::exit(2);
    }
    if let Err(e) = run(args) {
        eprintln!("bake: {e:#}");
        std::process::exit(1);
    }
}
