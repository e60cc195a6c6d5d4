//! The `render` tool: scene files work; bad input fails before any GPU work with one line
//! naming the file, exit code 1 and no output image.

use std::process::Command;

fn render(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_render"))
        .args(args)
        .output()
        .unwrap()
}

/// `passes` appear in `--print-frame` output `stdout` in this order.
fn assert_passes_in_order(stdout: &str, passes: &[&str]) {
    let mut at = 0;
    for p in passes {
        let line = format!(". {p}\n");
        let found = stdout[at..]
            .find(&line)
            .unwrap_or_else(|| panic!("no pass {p} after byte {at}:\n{stdout}"));
        at += found + line.len();
    }
}

/// Run `render` with validation on, writing `out`; it must succeed. Its standard output.
fn render_ok(args: &[&str], out: &std::path::Path) -> String {
    let mut all = args.to_vec();
    all.extend(["--validation", "-o", out.to_str().unwrap()]);
    let o = render(&all);
    let stdout = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(
        o.status.success(),
        "{args:?}: {stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    stdout
}

#[test]
fn renders_a_scene_file_with_two_characters() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    let root = env!("CARGO_MANIFEST_DIR");
    std::fs::write(
        &scene,
        format!(
            "size = [96, 64]\n[camera]\neye = [0.0, 0.1, -0.9]\ntarget = [0.0, -0.05, 0.0]\n\
             [[character]]\nmesh = \"{root}/hairmeshes/head_long.obj\"\ntranslation = [-0.15, 0.0, 0.0]\nstrands_per_bundle = 8\n\
             [[character]]\nmesh = \"{root}/hairmeshes/sphere_fur.obj\"\ntranslation = [0.2, 0.0, 0.0]\nscale = 0.2\nstrands_per_bundle = 8\nverts_log2 = 3\n"
        ),
    )
    .unwrap();
    let out = dir.path().join("scene.png");
    let stdout = render_ok(&["--scene", scene.to_str().unwrap()], &out);
    assert!(
        stdout.contains("2 character(s)") && stdout.contains("strand triangles"),
        "{stdout}"
    );
    let img = image::open(&out).unwrap();
    assert_eq!((img.width(), img.height()), (96, 64));
}

#[test]
fn bad_inputs_fail_before_the_gpu() {
    let dir = tempfile::tempdir().unwrap();
    let bad_mesh = dir.path().join("bad.obj");
    std::fs::write(&bad_mesh, "v 0 0 0\ng layer0\nf 1 1 1\n").unwrap();
    let bad_scene = dir.path().join("bad.toml");
    std::fs::write(
        &bad_scene,
        "[[character]]\nmesh = \"x.obj\"\nscale = -1.0\n",
    )
    .unwrap();
    let bad_hmb = dir.path().join("bad.hmb");
    std::fs::write(&bad_hmb, b"HAIRMESH\x01\x00\x00\x00").unwrap();
    let out = dir.path().join("never.png");
    let o = out.to_str().unwrap();
    for (args, names) in [
        (
            vec!["--mesh", bad_mesh.to_str().unwrap(), "-o", o],
            bad_mesh.to_str().unwrap(),
        ),
        (
            vec!["--scene", bad_scene.to_str().unwrap(), "-o", o],
            bad_scene.to_str().unwrap(),
        ),
        (
            vec!["--mesh", bad_hmb.to_str().unwrap(), "-o", o],
            bad_hmb.to_str().unwrap(),
        ),
        (
            vec![
                "--mesh",
                bad_hmb.to_str().unwrap(),
                "--size",
                "0x5",
                "-o",
                o,
            ],
            "--size",
        ),
    ] {
        let r = render(&args);
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(1), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
        assert!(err.contains(names), "{err}");
        assert!(
            !err.contains("device:") && String::from_utf8_lossy(&r.stdout).is_empty(),
            "no GPU work: {err}"
        );
        assert!(!out.exists());
    }
}

#[test]
fn print_frame_lists_every_pass_of_the_full_look() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("full.png");
    let mesh = concat!(env!("CARGO_MANIFEST_DIR"), "/hairmeshes/head_long.obj");
    let stdout = render_ok(
        &[
            "--mesh",
            mesh,
            "--size",
            "64x48",
            "--strands-per-bundle",
            "8",
            "--path",
            "compute",
            "--shadows",
            "deep-opacity",
            "--transparency",
            "oit",
            "--print-frame",
        ],
        &out,
    );
    // The defaults on lavapipe: auto for the camera, the software light passes.
    assert!(stdout.contains("draw auto:8, shadow draw soft"), "{stdout}");
    // Every pass of the frame, in order, each with what it reads and writes.
    let passes = [
        "clear args",
        "cull",
        "scan",
        "finalize",
        "generate",
        "shadow props",
        "soft bin count",
        "soft bin scatter",
        "soft shadow depth",
        "soft shadow depth copy",
        "soft shadow opacity",
        "soft shadow layers copy",
        "opaque",
        "k-buffer clear",
        "soft bin count",
        "soft bin scatter",
        "soft raster",
        "transparency resolve",
        "image readback",
        "host reads",
    ];
    assert_passes_in_order(&stdout, &passes);
    // `auto` with k-buffer OIT draws every bundle in software: no hardware insert pass.
    assert!(!stdout.contains(". oit insert\n"), "{stdout}");
    for needle in [
        "writes: shadow layers (TransferWrite, discard)",
        "soft shadow depth (ComputeRead)",
        "barrier: args [ComputeReadWrite] -> IndirectRead",
        "(layout TRANSFER_DST_OPTIMAL -> SHADER_READ_ONLY_OPTIMAL)",
        "transient resources (pool",
        "soft shadow layers: ",
    ] {
        assert!(stdout.contains(needle), "{needle}:\n{stdout}");
    }
}

/// `--temporal taa`: the visibility words are emptied before the camera's passes, every pass
/// that draws a surface writes them, and the temporal passes end the frame's drawing before
/// the image is read back; `--repeat` accumulates.
#[test]
fn temporal_accumulation_adds_its_passes() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("taa.png");
    let mesh = concat!(env!("CARGO_MANIFEST_DIR"), "/hairmeshes/head_long.obj");
    let stdout = render_ok(
        &[
            "--mesh",
            mesh,
            "--size",
            "64x48",
            "--strands-per-bundle",
            "8",
            "--path",
            "compute",
            "--draw",
            "auto",
            "--temporal",
            "taa",
            "--repeat",
            "3",
            "--print-frame",
        ],
        &out,
    );
    let passes = [
        "visibility clear",
        "opaque",
        "soft raster",
        "transparency resolve",
        "temporal input",
        "temporal",
        "temporal output",
        "image readback",
    ];
    assert_passes_in_order(&stdout, &passes);
    for needle in [
        "visibility (FragmentReadWrite)",
        "visibility (ComputeReadWrite)",
    ] {
        assert!(stdout.contains(needle), "{needle}:\n{stdout}");
    }
    assert!(out.exists());
}

/// Static and LHS runs: the generating frame draws hardware strips (software-drawn bundles
/// would leave nothing in the pool), the second frame draws the stored strands with `--draw`.
#[test]
fn static_and_lhs_runs_draw_their_stored_strands_through_the_software_rasterizer() {
    let dir = tempfile::tempdir().unwrap();
    let root = env!("CARGO_MANIFEST_DIR");
    let mesh = format!("{root}/hairmeshes/head_long.obj");
    for path in ["static", "lhs"] {
        let out = dir.path().join(format!("{path}.png"));
        let stdout = render_ok(
            &[
                "--mesh",
                &mesh,
                "--size",
                "80x60",
                "--strands-per-bundle",
                "8",
                "--lod",
                "off",
                "--path",
                path,
                "--draw",
                "soft",
            ],
            &out,
        );
        // The second frame's report: its own segment pass and the software raster.
        let second = stdout.split("then ").nth(1).unwrap_or_default();
        assert!(
            second.contains("soft segments") && second.contains("soft raster"),
            "{path}: {stdout}"
        );
        let img = image::open(&out).unwrap().to_rgb8();
        let background = *img.get_pixel(0, 0);
        assert!(
            img.pixels().filter(|p| **p != background).count() > 200,
            "{path}: hair drawn"
        );
    }
}
