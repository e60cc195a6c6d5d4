//! `crowd` in a window under Xvfb (installed by tools/setup.sh) on lavapipe, validation on:
//! starts, presents frames, survives a resize to a new size and a zero-size (minimised)
//! window, and exits 0 when closed. Fails loudly when xvfb-run is missing.

use std::process::Command;

#[test]
fn window_presents_survives_resize_and_zero_size_and_closes() {
    let o = Command::new("timeout")
        .args([
            "300",
            "xvfb-run",
            "-a",
            "-s",
            "-screen 0 1280x720x24",
            env!("CARGO_BIN_EXE_crowd"),
            "--count",
            "16",
            "--size",
            "320x180",
            "--exit-after-frames",
            "14",
            "--test-resize",
            "--validation",
        ])
        .output()
        .unwrap_or_else(|e| panic!("xvfb-run is needed for this test (tools/setup.sh): {e}"));
    let stdout = String::from_utf8_lossy(&o.stdout);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        o.status.success(),
        "exit {:?}\n{stdout}\n{stderr}",
        o.status
    );
    assert!(!stderr.contains("validation error"), "{stderr}");
    assert!(stdout.contains("presented 14 frames"), "{stdout}");
    // Initial swapchain, then again after the resize and after the zero-size window came back
    // (the two coincide when the resize lands while the window is held at zero size).
    let created: u32 = stdout
        .split("swapchain created ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or(0);
    assert!((2..=4).contains(&created), "{stdout}");
    assert!(stdout.contains("3 frames skipped at zero size"), "{stdout}");
    assert!(
        stdout.contains("final size 177x99"),
        "the resize took effect: {stdout}"
    );
}
