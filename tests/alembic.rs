//! Alembic curves in (`model::alembic`): the committed sample `hairmeshes/sintel_hair.abc`
//! (written by Blender's exporter, which links the reference Alembic library, from
//! `hairmeshes/sintel_hair.tfx`: `tools/alembic/make_sample.py`) against the same strands
//! through `.hair`; fitting it like the `.tfx`; damaged archives.

mod common;

use glam::Vec3;
use hairmesh::fit::metric::compare;
use hairmesh::fit::{FitOptions, fit};
use hairmesh::model::alembic::read_curves;
use hairmesh::model::hair_file::HairFile;
use hairmesh::model::strands::StrandModel;
use hairmesh::reference::generate::strands_per_bundle_for;
use hairmesh::{BakeOptions, CpuGenerator, bake};

fn sample_bytes() -> Vec<u8> {
    std::fs::read(common::root().join("hairmeshes/sintel_hair.abc")).unwrap()
}

/// The `.tfx` strands with the sample's widths (2 x 0.001 (1 - 0.8 t)) written as `.hair`
/// and read back: the known strand set.
fn known_strands() -> StrandModel {
    let tfx = StrandModel::load(&common::root().join("hairmeshes/sintel_hair.tfx")).unwrap();
    let n = tfx.strands[0].len();
    let positions: Vec<Vec3> = tfx.strands.iter().flatten().copied().collect();
    let widths: Vec<f32> = (0..positions.len())
        .map(|i| 0.002 * (1.0 - 0.8 * (i % n) as f32 / (n - 1) as f32))
        .collect();
    let hair = HairFile::from_strands(&positions, &widths, n, ([0.5; 3], "known")).unwrap();
    let bytes = hair.to_bytes();
    let parsed = HairFile::parse("known.hair", &bytes).unwrap();
    StrandModel::from_hair("known.hair", &parsed, bytes.len() as u64).unwrap()
}

#[test]
fn sample_round_trips_against_hair() {
    let known = known_strands();
    let objects = read_curves("sintel_hair.abc", &sample_bytes()).unwrap();
    let names: Vec<&str> = objects.iter().map(|o| o.name.as_str()).collect();
    // Two curve objects, one below a moved, turned and scaled transform.
    assert_eq!(names.len(), 2, "{names:?}");
    assert!(
        names.iter().any(|n| n.starts_with("/groom_rig/")),
        "{names:?}"
    );
    let model = StrandModel::load(&common::root().join("hairmeshes/sintel_hair.abc")).unwrap();
    assert_eq!(model.strands.len(), known.strands.len());
    // The objects may come in either order: match strands by their roots.
    let diag = known.diagonal();
    let mut worst = 0.0f32;
    for s in &model.strands {
        let k = known
            .strands
            .iter()
            .min_by(|a, b| a[0].distance(s[0]).total_cmp(&b[0].distance(s[0])))
            .unwrap();
        assert_eq!(s.len(), k.len());
        for (p, q) in s.iter().zip(k) {
            worst = worst.max(p.distance(*q) / diag);
        }
    }
    println!("worst point distance {worst:e} of the diagonal");
    // f32 positions stored through the rig's inverse and composed back.
    assert!(worst < 1e-5, "{worst}");
    // Widths: 2 x radius 0.001 (1 - 0.8 t), in world units (the rig's scale undone), as in
    // the .hair.
    let widths = model.widths.as_ref().expect("the sample has widths");
    let known_widths = known.widths.as_ref().expect("the .hair has thickness");
    for (s, w) in model.strands.iter().zip(widths) {
        let k = known
            .strands
            .iter()
            .position(|k| k[0].distance(s[0]) < 1e-3 * diag)
            .unwrap();
        for (a, b) in w.iter().zip(&known_widths[k]) {
            assert!((a - b).abs() < 1e-6, "{a} vs {b}");
        }
    }
}

/// Fit `model` (20 bundles, 6 layers), bake, generate about as many strands and measure them
/// against the model (as `fit --report` does).
fn fidelity(model: &StrandModel) -> (hairmesh::fit::metric::Fidelity, hairmesh::HairStyle) {
    let opts = FitOptions {
        bundles: 20,
        layers: Some(6),
        ..FitOptions::default()
    };
    let fitted = fit(model, None, &opts).unwrap();
    let baked = bake(
        &fitted.mesh,
        &fitted.style,
        BakeOptions::default(),
        |_, _| {},
    )
    .unwrap();
    let (per, _) = strands_per_bundle_for(&baked, &fitted.style, model.strands.len() as u64);
    let out = CpuGenerator::new(&baked, fitted.style)
        .generate(per, 5)
        .polylines();
    let f = compare(&model.strands, &out, model.diagonal(), fitted.bundle_size);
    (f, fitted.style)
}

#[test]
fn fits_like_the_hair() {
    let abc = StrandModel::load(&common::root().join("hairmeshes/sintel_hair.abc")).unwrap();
    let (fa, style) = fidelity(&abc);
    let (fk, known_style) = fidelity(&known_strands());
    println!("abc: {fa}\nhair: {fk}");
    let close = |x: f32, y: f32| (x - y).abs() <= 0.05 * y.abs() + 1e-4;
    assert!(close(fa.two_sided.0, fk.two_sided.0), "{fa} vs {fk}");
    assert!(close(fa.coverage, fk.coverage), "{fa} vs {fk}");
    // The widths set the style's: root 2 mm, tip a fifth of it, as from the .hair.
    assert!(
        (style.strand_width - 0.002).abs() < 1e-6,
        "{}",
        style.strand_width
    );
    assert!(
        (style.tip_width_ratio - 0.2).abs() < 1e-3,
        "{}",
        style.tip_width_ratio
    );
    assert!((style.strand_width - known_style.strand_width).abs() < 1e-7);
    assert!((style.tip_width_ratio - known_style.tip_width_ratio).abs() < 1e-6);
}

#[test]
fn damaged_archives_fail_in_one_line() {
    let bytes = sample_bytes();
    let mut rng = hairmesh::rng::Pcg32::new(7);
    let mut below = |n: usize| rng.next_u32() as usize % n.max(1);
    let mut failures = 0;
    for k in 0..300 {
        let mut b = bytes.clone();
        match k % 3 {
            0 => b.truncate(below(b.len())),
            1 => {
                for _ in 0..4 {
                    let i = below(b.len());
                    b[i] = below(256) as u8;
                }
            }
            _ => {
                // A word somewhere set to a huge size or address.
                let i = below(b.len() / 8) * 8;
                b[i..i + 8].copy_from_slice(&(u64::MAX >> below(40)).to_le_bytes());
            }
        }
        if let Err(e) = read_curves("bad.abc", &b) {
            let e = e.to_string();
            assert!(e.starts_with("bad.abc: ") && !e.contains('\n'), "{e}");
            failures += 1;
        }
    }
    println!("{failures} of 300 damaged archives refused");
    assert!(failures > 100);
}

#[test]
fn points_stay_in_place() {
    // The rig's transform is not the identity: without it the front strands would be elsewhere.
    let objects = read_curves("sintel_hair.abc", &sample_bytes()).unwrap();
    let known = known_strands();
    let roots: Vec<Vec3> = known.strands.iter().map(|s| s[0]).collect();
    for o in &objects {
        let near = o
            .strands
            .iter()
            .filter(|s| roots.iter().any(|r| r.distance(s[0]) < 1e-3))
            .count();
        assert_eq!(near, o.strands.len(), "{}", o.name);
    }
}

/// `fit --report` on the sample reports fidelity and FLIP as for `.tfx` (validation on); an
/// HDF5 archive and a truncated one are refused in one line naming the file, writing nothing.
#[test]
fn fit_tool_reads_the_sample() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("fitted.obj");
    let abc = common::root().join("hairmeshes/sintel_hair.abc");
    let run = |input: &std::path::Path, extra: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_fit"))
            .arg(input)
            .args([
                "-o",
                out.to_str().unwrap(),
                "--bundles",
                "20",
                "--layers",
                "6",
            ])
            .args(extra)
            .output()
            .unwrap()
    };
    let o = run(&abc, &["--report", "--validation"]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(stdout.contains("228 strands, 7296 points"), "{stdout}");
    assert!(
        stdout.contains("two-sided mean") && stdout.contains("FLIP mean"),
        "{stdout}"
    );
    assert!(stdout.contains("strand_width 0.0020"), "{stdout}");
    let bytes = sample_bytes();
    let hdf5 = dir.path().join("old.abc");
    std::fs::write(&hdf5, [&b"\x89HDF\r\n\x1a\n"[..], &bytes[8..]].concat()).unwrap();
    let cut = dir.path().join("cut.abc");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    for (file, cause) in [(&hdf5, "HDF5"), (&cut, "malformed")] {
        std::fs::remove_file(&out).ok();
        let o = run(file, &[]);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success());
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
        assert!(
            stderr.contains(file.to_str().unwrap()) && stderr.contains(cause),
            "{stderr}"
        );
        assert!(!out.exists());
    }
}
