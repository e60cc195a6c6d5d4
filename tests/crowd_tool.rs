//! `crowd --headless`: 16 characters with validation on render non-empty frames and write the
//! PNGs and the stats CSV; the furry-teapot preset renders on the compute path too; with the
//! camera still, animated frames differ from one to the next (and do not without animation).
//! Every run checks that the timing scopes account for each frame.

use std::process::Command;

/// Run `crowd --headless --size 320x180 --validation` with `extra` flags; check `frames`
/// frames of at least `min_strands` strands each and a mostly non-background image.
/// One crowd run at a time: the frames' timing scopes are checked against the GPU time, which
/// on lavapipe (the CPU) another run beside it stretches (13 of 257 ms fell between scopes with
/// the four tests of this file in parallel, against 0.3-0.5% alone).
static ONE_RUN_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn headless(extra: &[&str], frames: usize, min_strands: u64) -> (tempfile::TempDir, Vec<Vec<u8>>) {
    let _alone = ONE_RUN_AT_A_TIME
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("frames");
    let o = Command::new(env!("CARGO_BIN_EXE_crowd"))
        .args(["--headless", "--size", "320x180", "--validation", "--out"])
        .arg(&out)
        .args(extra)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(!String::from_utf8_lossy(&o.stderr).contains("validation error"));
    assert!(!String::from_utf8_lossy(&o.stderr).contains("dropped"));
    let csv = std::fs::read_to_string(out.join("stats.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let column = |name: &str| header.iter().position(|c| *c == name).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), frames, "{csv}");
    let mut images = Vec::new();
    for (f, row) in rows.iter().enumerate() {
        let cols: Vec<&str> = row.split(',').collect();
        scopes_cover_the_frame(f, |name| cols[column(name)]);
        let strands: u64 = cols[column("strands_drawn")].parse().unwrap();
        assert!(strands > min_strands, "frame {f}: {strands} strands");
        // Every frame says what its buffers could not hold, and these hold everything.
        for name in [
            "dropped_strands",
            "dropped_segments",
            "dropped_tile_entries",
        ] {
            assert_eq!(cols[column(name)], "0", "frame {f}: {name}");
        }
        let pressure: f32 = cols[column("lod_pressure")].parse().unwrap();
        assert!(
            pressure > 0.0 && pressure <= 1.0,
            "frame {f}: LoD pressure {pressure}"
        );
        let img = image::open(out.join(format!("frame_{f:05}.png")))
            .unwrap()
            .to_rgb8();
        assert_eq!((img.width(), img.height()), (320, 180));
        // Non-empty: many pixels differ from the background colour of the top-left corner.
        let bg = *img.get_pixel(0, 0);
        let differ = img.pixels().filter(|p| **p != bg).count();
        assert!(
            differ > 320 * 180 / 4,
            "frame {f}: only {differ} non-background pixels"
        );
        images.push(img.into_raw());
    }
    (dir, images)
}

/// The timing scopes account for frame `f` (columns by name): no command recorded outside a
/// scope, and at least 95% of the outer pair inside one (measured 0.1-0.4% outside, 0.6-3 ms of
/// 640-2500 ms frames at 320x180: the gaps between scopes). Checked by breaking it: with the
/// frame graph's own scope per unscoped pass taken out, the command check fails; with the
/// software raster's scope ending where it begins, 89 of 1020 ms fall outside.
fn scopes_cover_the_frame<'c>(f: usize, column: impl Fn(&str) -> &'c str) {
    let commands: u32 = column("unscoped_commands").parse().unwrap();
    assert_eq!(
        commands, 0,
        "frame {f}: commands recorded outside every scope"
    );
    let frame: f64 = column("gpu_ms").parse().unwrap();
    let unscoped: f64 = column("unscoped_ms").parse().unwrap();
    assert!(
        unscoped.is_finite() && unscoped <= 0.05 * frame,
        "frame {f}: {unscoped} of {frame} GPU ms in no scope"
    );
}

/// Hair and characters move: with the camera still, consecutive frames differ; with
/// `--animate off` they are identical (so the difference is the animation).
#[test]
fn animated_frames_differ() {
    let flags = [
        "--frames", "8", "--count", "16", "--orbit", "off", "--wind", "20",
    ];
    // Pixels that differ by more than one level of 255 (measured 9,558-10,412 between animated
    // frames at 320x180).
    let changed = |a: &[u8], b: &[u8]| {
        a.chunks(4)
            .zip(b.chunks(4))
            .filter(|(p, q)| p.iter().zip(q.iter()).any(|(x, y)| x.abs_diff(*y) > 1))
            .count()
    };
    let (_dir, moving) = headless(&flags, 8, 1000);
    for f in 1..8 {
        let n = changed(&moving[f], &moving[f - 1]);
        println!("animated frames {} and {f}: {n} pixels differ", f - 1);
        assert!(
            n > 300,
            "frames {} and {f} differ in only {n} pixels",
            f - 1
        );
    }
    let (_dir2, off) = headless(
        &[
            "--frames",
            "3",
            "--count",
            "16",
            "--orbit",
            "off",
            "--animate",
            "off",
        ],
        3,
        1000,
    );
    // Without animation the frames agree, but for the order in which dense pixels' fragments
    // reach the software rasterizer's hiding (`soft_raster.comp`): at a real head's density,
    // measured 1 pixel of 57,600 by one level of 255 (at the 96 strands a bundle of before
    // 2026-12-07, none).
    for f in 1..3 {
        let n = changed(&off[f], &off[f - 1]);
        assert!(
            n <= 30,
            "frames {} and {f} without animation differ in {n} pixels",
            f - 1
        );
    }
}

/// `--character`: copies of the example glTF character (its own head), walking in wind, their
/// hair grown on that head and bound to its head joint: the GPU's roots stay on the skinned
/// scalp (root gap below 0.01 head radii; 0.00016 measured on lavapipe).
#[test]
fn the_users_character_fills_the_crowd_with_its_hair_on() {
    let (dir, _) = headless(
        &[
            "--character",
            "hairmeshes/people/character.glb",
            "--count",
            "4",
            "--frames",
            "2",
            "--wind",
            "10",
        ],
        2,
        500,
    );
    let csv = std::fs::read_to_string(dir.path().join("frames/stats.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let column = header.iter().position(|c| *c == "root_gap").unwrap();
    for row in csv.lines().skip(1) {
        let gap: f32 = row.split(',').nth(column).unwrap().parse().unwrap();
        assert!(gap < 0.01, "root gap {gap} head radii");
    }
}

#[test]
fn headless_crowd_renders_frames_and_stats() {
    headless(&["--frames", "3", "--count", "16"], 3, 1000);
    // The other passes: hardware strips into a k-buffer, temporal accumulation, the volume band.
    let others = [
        "--frames",
        "2",
        "--count",
        "6",
        "--transparency",
        "oit",
        "--draw",
        "hw",
        "--temporal",
        "taa",
        "--volume-band",
        "2,6",
    ];
    headless(&others, 2, 100);
}

#[test]
fn furry_teapots_render_on_the_compute_path() {
    headless(
        &[
            "--preset", "teapots", "--count", "4", "--frames", "1", "--path", "compute",
        ],
        1,
        4 * 500,
    );
}
