//! `bench compare --against REV`: the regression harness. Builds REV's `crowd` in its own
//! folder (`target/compare/`), then runs a fixed set of frames with both builds, alternating
//! old and new in one run (old first on even runs, new first on odd ones, so a drifting
//! machine does not favour either), and prints new/old per row with the spread over runs.
//!
//! Every row is a `crowd --headless` run; its figure is the median over frames 1.. (frame 0
//! compiles shaders) of the frame's wall time (submit to completed readback: work cannot hide
//! from it) and, beside it, of the GPU ms the build reports (builds before the frame's outer
//! timestamps report the sum of their scopes there). The last column is FLIP (mean) of the new
//! build's last frame against the old one's, from the first run: "the same picture" as a number.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};
use hairmesh::outln;

/// Arguments of `bench compare`.
#[derive(clap::Args)]
pub struct CompareArgs {
    /// The control: a commit, tag or branch of this repository.
    #[arg(long)]
    against: String,
    /// Alternating runs of every row (old and new each run once per run).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u16).range(1..=50))]
    runs: u16,
    /// Frames per crowd run (the first is not timed).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u16).range(2..=100))]
    frames: u16,
    /// Only rows whose names start with one of these (bare, full, people).
    #[arg(long, value_delimiter = ',')]
    rows: Vec<String>,
    /// Small scale (320x180, a fifth of the strands, 10 and 100 people): a smoke run.
    #[arg(long)]
    quick: bool,
}

/// One row: a name and the `crowd` flags that make its frame.
struct Row {
    name: String,
    flags: Vec<String>,
}

/// The fixed set of frames: bare strands of one head drawn soft and hw on both paths at 20K
/// and 100K strands, the full look at 100K, the people crowd at 100 and 1000.
fn rows(quick: bool) -> Vec<Row> {
    let size = if quick { "320x180" } else { "1280x720" };
    // Strands per bundle of the long straight family for about 20K and 100K strands with
    // LoD off (400 gave 11,701 strands, 2000 gave 57,716).
    let scale = if quick { 5 } else { 1 };
    let heads = [("20K", 690 / scale), ("100K", 3470 / scale)];
    let head = |spb: u32| -> Vec<String> {
        let f = "--count 1 --view front --family longstraight --lod off --animate off";
        let mut v: Vec<String> = f.split(' ').map(String::from).collect();
        v.extend(["--strands-per-bundle".into(), spb.to_string()]);
        v.extend(["--size".into(), size.into()]);
        v
    };
    let plain = "--shading placeholder --shadows off --volumes off --transparency opaque";
    let mut out = Vec::new();
    for (label, spb) in heads {
        for path in ["mesh", "compute"] {
            for draw in ["soft", "hw"] {
                let mut flags = head(spb);
                flags.extend(plain.split(' ').map(String::from));
                flags.extend(["--path".into(), path.into(), "--draw".into(), draw.into()]);
                out.push(Row {
                    name: format!("bare {label} {draw} {path}"),
                    flags,
                });
            }
        }
    }
    let mut full = head(heads[1].1);
    full.extend(["--transparency".into(), "oit".into()]);
    out.push(Row {
        name: format!("full look {} (oit)", heads[1].0),
        flags: full,
    });
    let counts = if quick { [10, 100] } else { [100, 1000] };
    for n in counts {
        let f = format!("--count {n} --size {size} --orbit off");
        out.push(Row {
            name: format!("people {n}"),
            flags: f.split(' ').map(String::from).collect(),
        });
    }
    out
}

/// Run `cmd` in `dir` and fail with its output when it fails.
fn run_checked(cmd: &mut Command, what: &str) -> Result<String> {
    let out = cmd
        .output()
        .with_context(|| format!("{what}: could not start"))?;
    if !out.status.success() {
        bail!(
            "{what} failed: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    Ok(String::from_utf8_lossy(&out.stdout).trim().to_string())
}

/// The repository this bench was built from.
fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Build `crowd` of commit `rev` in `target/compare/` (sources from `git archive`, one
/// target folder for every control so dependencies build once); the binary's path.
fn build_control(rev: &str) -> Result<(String, PathBuf)> {
    let repo = repo();
    let git = |args: &[&str]| {
        run_checked(
            Command::new("git").arg("-C").arg(&repo).args(args),
            &format!("git {}", args.join(" ")),
        )
    };
    let sha = git(&["rev-parse", "--verify", &format!("{rev}^{{commit}}")])
        .with_context(|| format!("--against {rev}: not a commit of this repository"))?;
    let short = &sha[..10];
    let root = repo.join("target/compare");
    let bin = root.join(format!("bin-{short}/crowd"));
    if bin.exists() {
        return Ok((sha, bin));
    }
    let src = root.join(format!("src-{short}"));
    if !src.join("Cargo.toml").exists() {
        let staging = root.join(format!("src-{short}.tmp"));
        let _ = std::fs::remove_dir_all(&staging);
        std::fs::create_dir_all(&staging)?;
        let archive = root.join(format!("src-{short}.tar"));
        git(&[
            "archive",
            "--format=tar",
            "-o",
            &archive.to_string_lossy(),
            &sha,
        ])?;
        run_checked(
            Command::new("tar")
                .arg("-xf")
                .arg(&archive)
                .arg("-C")
                .arg(&staging),
            "tar -x",
        )?;
        std::fs::remove_file(&archive)?;
        std::fs::rename(&staging, &src)?;
    }
    own_workspace(&src.join("Cargo.toml"))?;
    eprintln!("building crowd of {short} in {}", root.display());
    run_checked(
        Command::new("cargo")
            .args(["build", "--release", "--bin", "crowd", "--manifest-path"])
            .arg(src.join("Cargo.toml"))
            .env("CARGO_TARGET_DIR", root.join("target")),
        &format!("cargo build of {short}"),
    )?;
    std::fs::create_dir_all(bin.parent().unwrap())?;
    std::fs::copy(root.join("target/release/crowd"), &bin)?;
    Ok((sha, bin))
}

/// Make the control's manifest its own workspace root: the sources lie under this
/// repository's `target/`, so cargo would otherwise take this repository's workspace for
/// theirs and refuse a commit from before the workspace existed (one package, no
/// `[workspace]` table).
fn own_workspace(manifest: &Path) -> Result<()> {
    let text = std::fs::read_to_string(manifest)
        .with_context(|| format!("{}: cannot read the control's manifest", manifest.display()))?;
    if text.lines().any(|l| l.trim() == "[workspace]") {
        return Ok(());
    }
    std::fs::write(manifest, format!("{text}\n[workspace]\n")).with_context(|| {
        format!(
            "{}: cannot write the control's manifest",
            manifest.display()
        )
    })
}

/// Build this tree's `crowd` (up to date in the usual case).
fn build_current() -> Result<PathBuf> {
    let repo = repo();
    run_checked(
        Command::new("cargo")
            .args(["build", "--release", "--bin", "crowd", "--manifest-path"])
            .arg(repo.join("Cargo.toml")),
        "cargo build of this tree",
    )?;
    let target = std::env::var_os("CARGO_TARGET_DIR").map_or(repo.join("target"), PathBuf::from);
    Ok(target.join("release/crowd"))
}

/// One run of a row: median wall ms and GPU ms over frames 1.., and the last frame.
struct Measured {
    wall: f64,
    gpu: f64,
    last: image::RgbImage,
}

/// One `crowd` run of `row`; `None` where the build refused the row (a flag it does not know).
fn measure(crowd: &Path, row: &Row, frames: u16) -> Result<Option<Measured>> {
    let dir = std::env::temp_dir().join(format!("hairmesh-compare-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = Command::new(crowd)
        .arg("--headless")
        .args(&row.flags)
        .args(["--frames", &frames.to_string(), "--out"])
        .arg(&dir)
        .output()?;
    let csv = std::fs::read_to_string(dir.join("stats.csv"));
    let last = image::open(dir.join(format!("frame_{:05}.png", frames - 1)));
    let _ = std::fs::remove_dir_all(&dir);
    if !out.status.success() {
        eprintln!(
            "{} with {}: {}",
            row.name,
            crowd.display(),
            String::from_utf8_lossy(&out.stderr).trim()
        );
        return Ok(None);
    }
    let csv = csv?;
    let header: Vec<&str> = csv.lines().next().unwrap_or("").split(',').collect();
    let col = |name: &str| header.iter().position(|c| *c == name);
    let (Some(wall), Some(gpu)) = (col("wall_ms"), col("gpu_ms")) else {
        bail!(
            "{}: stats.csv has no wall_ms or gpu_ms column",
            crowd.display()
        );
    };
    let mut walls = Vec::new();
    let mut gpus = Vec::new();
    for line in csv.lines().skip(2) {
        let cols: Vec<&str> = line.split(',').collect();
        walls.push(cols[wall].parse::<f64>()?);
        gpus.push(cols[gpu].parse::<f64>()?);
    }
    Ok(Some(Measured {
        wall: super::median(walls),
        gpu: super::median(gpus),
        last: last?.to_rgb8(),
    }))
}

/// FLIP mean of `new` against `old` (the same frame of both builds).
fn flip_mean(old: &image::RgbImage, new: &image::RgbImage) -> Option<f64> {
    flip_pool(old, new).map(|p| p.mean() as f64)
}

/// FLIP of `new` against `old`, pooled (`None` when their sizes differ).
pub(crate) fn flip_pool(old: &image::RgbImage, new: &image::RgbImage) -> Option<nv_flip::FlipPool> {
    if old.dimensions() != new.dimensions() {
        return None;
    }
    let (w, h) = old.dimensions();
    let err = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(w, h, old.as_raw()),
        nv_flip::FlipImageRgb8::with_data(w, h, new.as_raw()),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    Some(nv_flip::FlipPool::from_image(&err))
}

/// `bench flip`: print FLIP's mean and 99th percentile of `test` against `reference`.
pub fn print_flip(reference: &std::path::Path, test: &std::path::Path) -> anyhow::Result<()> {
    let load = |p: &std::path::Path| {
        image::open(p)
            .map(|i| i.to_rgb8())
            .map_err(|e| anyhow::anyhow!("{}: {e}", p.display()))
    };
    let (old, new) = (load(reference)?, load(test)?);
    let mut pool = flip_pool(&old, &new).ok_or_else(|| {
        anyhow::anyhow!(
            "{}: {}x{}, the reference is {}x{}",
            test.display(),
            new.width(),
            new.height(),
            old.width(),
            old.height()
        )
    })?;
    println!(
        "FLIP mean {:.4}, 99th percentile {:.4}",
        pool.mean(),
        pool.get_percentile(0.99, true)
    );
    Ok(())
}

/// Whether row `name` is chosen by `pattern`: its whole name, or its first words
/// (`people` and `people 100` choose `people 100`; `people 10` does not).
fn row_matches(name: &str, pattern: &str) -> bool {
    let pattern = pattern.trim();
    !pattern.is_empty()
        && (name == pattern
            || name
                .strip_prefix(pattern)
                .is_some_and(|r| r.starts_with(' ')))
}

/// Per row and build: what each run measured.
type Samples = Vec<[Vec<Measured>; 2]>;

/// Build both, run every row `runs` times alternating, print the table.
pub fn bench_compare(args: CompareArgs) -> Result<()> {
    let all = rows(args.quick);
    if let Some(p) = args
        .rows
        .iter()
        .find(|p| !all.iter().any(|r| row_matches(&r.name, p)))
    {
        bail!(
            "--rows {p}: matches no row; rows: {}",
            all.iter()
                .map(|r| r.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let rows: Vec<Row> = all
        .into_iter()
        .filter(|r| args.rows.is_empty() || args.rows.iter().any(|p| row_matches(&r.name, p)))
        .collect();
    let (sha, old) = build_control(&args.against)?;
    let new = build_current()?;
    let mut samples: Samples = rows.iter().map(|_| [Vec::new(), Vec::new()]).collect();
    for run in 0..args.runs {
        for (row, s) in rows.iter().zip(samples.iter_mut()) {
            let order = if run % 2 == 0 { [0, 1] } else { [1, 0] };
            for which in order {
                let bin = if which == 0 { &old } else { &new };
                if let Some(m) = measure(bin, row, args.frames)? {
                    s[which].push(m);
                }
                let wall = s[which].last().map(|m| m.wall);
                eprintln!(
                    "run {run} {} {}: {wall:?} ms",
                    row.name,
                    ["old", "new"][which]
                );
            }
        }
    }
    print_table(&sha, &rows, &samples, &args)
}

/// `| row | old | new | new/old (spread) | GPU old | GPU new |`, pasted as measured.
fn print_table(sha: &str, rows: &[Row], samples: &Samples, args: &CompareArgs) -> Result<()> {
    outln!(
        "bench compare --against {} ({}), {} alternating runs of {} frames; median over frames 1.. of each run, then over runs; new/old per run: median (min-max)",
        args.against,
        &sha[..10],
        args.runs,
        args.frames
    )?;
    outln!("")?;
    outln!(
        "| row | old wall ms | new wall ms | new/old wall | old GPU ms | new GPU ms | FLIP new vs old |"
    )?;
    outln!("|---|---|---|---|---|---|---|")?;
    for (row, [old, new]) in rows.iter().zip(samples) {
        let med = |v: &[Measured], gpu: bool| {
            let v: Vec<f64> = v.iter().map(|m| if gpu { m.gpu } else { m.wall }).collect();
            if v.is_empty() {
                f64::NAN
            } else {
                super::median(v)
            }
        };
        let ratios: Vec<f64> = old.iter().zip(new).map(|(o, n)| n.wall / o.wall).collect();
        let flip = match (old.first(), new.first()) {
            (Some(o), Some(n)) => {
                flip_mean(&o.last, &n.last).map_or("n/a".into(), |f| format!("{f:.4}"))
            }
            _ => "n/a".to_string(),
        };
        let ratio = if ratios.is_empty() {
            "n/a".to_string()
        } else {
            let lo = ratios.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = ratios.iter().copied().fold(0.0, f64::max);
            format!("{:.2} ({lo:.2}-{hi:.2})", super::median(ratios.clone()))
        };
        outln!(
            "| {} | {:.1} | {:.1} | {ratio} | {:.1} | {:.1} | {flip} |",
            row.name,
            med(old, false),
            med(new, false),
            med(old, true),
            med(new, true)
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A manifest without a `[workspace]` table gets one, once; one with it is left alone.
    #[test]
    fn a_control_manifest_becomes_its_own_workspace() {
        let dir = std::env::temp_dir().join(format!("hairmesh-own-ws-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let manifest = dir.join("Cargo.toml");
        let package = "[package]\nname = \"old\"\n";
        std::fs::write(&manifest, package).unwrap();
        own_workspace(&manifest).unwrap();
        own_workspace(&manifest).unwrap();
        let text = std::fs::read_to_string(&manifest).unwrap();
        assert_eq!(text, format!("{package}\n[workspace]\n"));
        let workspace = "[workspace]\nmembers = [\"a\"]\n";
        std::fs::write(&manifest, workspace).unwrap();
        own_workspace(&manifest).unwrap();
        assert_eq!(std::fs::read_to_string(&manifest).unwrap(), workspace);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
