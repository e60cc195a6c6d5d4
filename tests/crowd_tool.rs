//! `crowd --headless`: 16 characters with validation on render non-empty frames, write the
//! PNGs and the stats CSV, and the 16 hairstyles look different from each other.

use std::process::Command;

#[test]
fn headless_crowd_renders_frames_and_stats() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("frames");
    let o = Command::new(env!("CARGO_BIN_EXE_crowd"))
        .args([
            "--headless",
            "--frames",
            "3",
            "--count",
            "16",
            "--size",
            "320x180",
            "--validation",
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(!String::from_utf8_lossy(&o.stderr).contains("validation error"));
    let csv = std::fs::read_to_string(out.join("stats.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), 3, "{csv}");
    for (f, row) in rows.iter().enumerate() {
        let cols: Vec<&str> = row.split(',').collect();
        let strands: u64 = cols[4].parse().unwrap();
        assert!(strands > 1000, "frame {f}: {strands} strands");
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
    }
}
