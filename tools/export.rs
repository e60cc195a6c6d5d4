//! `export`: the full strand model a hair mesh produces at full detail (the strands the GPU
//! generates with LoD off, from the CPU reference generator) as Yuksel's `.hair` file, so it
//! opens in other hair tools; prints the storage of the hair mesh's five textures against it.
//!
//! `export --mesh hairmeshes/head_long.obj [--style S] [--strands-per-bundle 64]
//! [--verts-log2 5] -o head_long.hair`

use std::io::Write as _;
use std::path::PathBuf;

use anyhow::{Result, bail};
use clap::Parser;
use hairmesh::fsutil::RunFiles;
use hairmesh::model::hair_file::{HairFile, MAX_POINTS};
use hairmesh::reference::generate::strands_in_bundle;
use hairmesh::render::scene::load_mesh;
use hairmesh::{CpuGenerator, outln};

/// Write the strands of a hair mesh as a `.hair` file.
#[derive(Parser)]
#[command(version, about)]
struct Args {
    /// Hair mesh (.obj, baked on load, or .hmb).
    #[arg(long)]
    mesh: PathBuf,
    /// Style TOML (default: the .toml beside an OBJ, else the style stored in the bake).
    #[arg(long)]
    style: Option<PathBuf>,
    /// Strands per average bundle.
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..=16384))]
    strands_per_bundle: u32,
    /// Strands get 2^e + 1 points (e in 1..=6, as the GPU generates).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=6))]
    verts_log2: u32,
    /// Output `.hair` file.
    #[arg(short, long)]
    output: PathBuf,
}

fn run(args: Args) -> Result<()> {
    // The style beside an OBJ mesh is read too: never overwritten.
    let inputs = hairmesh::render::scene::mesh_inputs(&args.mesh, args.style.as_deref());
    let out = RunFiles::new()
        .inputs(inputs.iter().map(PathBuf::as_path))
        .output(&args.output, "-o")?;
    let (baked, style) = load_mesh(&args.mesh, args.style.as_deref(), Default::default())?;
    // Refuse absurd counts before generating anything.
    let strands: u64 = baked
        .bundles
        .iter()
        .map(|b| strands_in_bundle(b, &style, args.strands_per_bundle) as u64)
        .sum();
    let points = strands * ((1u64 << args.verts_log2) + 1);
    if points > MAX_POINTS {
        bail!(
            "{strands} strands x {} points = {points} points, more than the {MAX_POINTS} a .hair file may hold here",
            (1u64 << args.verts_log2) + 1
        );
    }
    let set = CpuGenerator::new(&baked, style).generate(args.strands_per_bundle, args.verts_log2);
    let info = format!("hairmesh export of {}", args.mesh.display());
    let hair = HairFile::from_strands(
        &set.positions,
        &set.widths,
        set.verts_per_strand,
        (style.color, &info),
    )?;
    let bytes = hair.to_bytes();
    outln!(
        "{}: {} strands, {} points; .hair {:.2} MiB, hair mesh textures {:.1} KiB ({:.0}x smaller)",
        args.mesh.display(),
        hair.hair_count,
        hair.points.len(),
        bytes.len() as f64 / (1 << 20) as f64,
        baked.texture_bytes() as f64 / 1024.0,
        bytes.len() as f64 / baked.texture_bytes().max(1) as f64
    )?;
    // The last line comes before the file: a stdout that fails leaves no output behind.
    outln!("writing {}", args.output.display())?;
    out.write(&bytes)?;
    Ok(())
}

fn main() {
    let parsed = hairmesh::cli::parse::<Args>("export");
    hairmesh::cli::clean_up_on_signals("export");
    if let Err(e) = run(parsed.args) {
        let _ = std::io::stdout().flush();
        hairmesh::fsutil::exit_with_error("export", &e, 1);
    }
}
