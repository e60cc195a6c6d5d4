//! Golden images: fixed scenes rendered on lavapipe (no MSAA, fixed seeds) compared with the
//! PNGs in `tests/golden/` using FLIP (nv-flip), as wgpu does.
//!
//! Thresholds: mean FLIP <= 0.02 and 99th percentile <= 0.25. Same-driver renders are
//! bit-identical (FLIP 0); the margin absorbs rasterisation differences between Mesa versions
//! (one-pixel shifts of thin strand edges) while any change to generation or shading — a moved
//! root, a different curve, another colour — raises the mean well above 0.02.
//! On failure `tests/output/<name>-actual.png` and `<name>-diff.png` (magma) are written.
//! Re-bless after an intended change: `HAIRMESH_BLESS=1 cargo test --release --test golden`,
//! look at the new PNGs, and commit them.

mod common;

use common::*;

const MEAN_MAX: f32 = 0.02;
const P99_MAX: f32 = 0.25;

fn check(name: &str, mesh: &str, n: u32, e: u32) {
    let ctx = context();
    let out = render_sample(&ctx, mesh, n, e, 256, None);
    assert_no_validation_errors(&ctx);
    let reference = root().join("tests/golden").join(format!("{name}.png"));
    if std::env::var("HAIRMESH_BLESS").is_ok_and(|v| v == "1") {
        save_png(&reference, out.width, out.height, &out.rgba);
        return;
    }
    let expected = image::open(&reference)
        .unwrap_or_else(|e| panic!("{}: {e} (bless with HAIRMESH_BLESS=1)", reference.display()))
        .to_rgb8();
    let actual_rgb: Vec<u8> = out
        .rgba
        .chunks(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    assert_eq!(
        (expected.width(), expected.height()),
        (out.width, out.height)
    );
    let ref_img = nv_flip::FlipImageRgb8::with_data(out.width, out.height, expected.as_raw());
    let test_img = nv_flip::FlipImageRgb8::with_data(out.width, out.height, &actual_rgb);
    let err = nv_flip::flip(ref_img, test_img, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    let mut pool = nv_flip::FlipPool::from_image(&err);
    let mean = pool.mean();
    let p99 = pool.get_percentile(0.99, true);
    println!("{name}: FLIP mean {mean:.5}, p99 {p99:.5}");
    if mean > MEAN_MAX || p99 > P99_MAX {
        let dir = output_dir();
        save_png(
            &dir.join(format!("{name}-actual.png")),
            out.width,
            out.height,
            &out.rgba,
        );
        let diff = err.apply_color_lut(&nv_flip::magma_lut());
        image::RgbImage::from_raw(out.width, out.height, diff.to_vec())
            .unwrap()
            .save(dir.join(format!("{name}-diff.png")))
            .unwrap();
        panic!(
            "{name}: FLIP mean {mean} (max {MEAN_MAX}), p99 {p99} (max {P99_MAX}); see tests/output/"
        );
    }
}

#[test]
fn golden_head_long() {
    check("head_long", "head_long.obj", 32, 5);
}

#[test]
fn golden_sphere_fur() {
    check("sphere_fur", "sphere_fur.obj", 24, 3);
}

#[test]
fn golden_small_patch() {
    check("small_patch", "small_patch.obj", 64, 5);
}

#[test]
fn golden_triangle_tuft() {
    check("triangle_tuft", "triangle_tuft.obj", 64, 4);
}
