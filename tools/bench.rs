//! `bench`: measurements written to the README (never timed tests).
//!
//! `bench cpu-generate [--mesh M] [--strands 100000] [--verts-log2 5] [--runs 7]`: CPU reference
//! generator throughput on one core; prints every run and the median.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Result, bail};
use clap::{Parser, Subcommand};
use hairmesh::obj_io::load_hair_mesh_obj;
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
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() -> Result<()> {
    match Args::parse().cmd {
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
