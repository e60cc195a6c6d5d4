//! Golden images: fixed scenes rendered on lavapipe (no MSAA, fixed seeds) compared with the
//! PNGs in `tests/golden/` using FLIP (nv-flip), as wgpu does.
//!
//! Thresholds: mean FLIP <= 0.01 and 99th percentile <= 0.25, about 10x the worst measured
//! against the committed images on lavapipe (2026-12-05: mean 0.00027-0.00092, p99
//! 0.0097-0.0234, sphere_fur the widest; small drift from float changes since they were
//! blessed). The negative controls below show what a real change reads: a style value moved
//! 0.3 gives mean 0.018-0.048 and p99 0.24-0.84, a wrong shadow mode p99 0.55-0.61, opaque
//! instead of OIT mean 0.12 — each fails at least one of the two bounds.
//! On failure `tests/output/<name>-actual.png` and `<name>-diff.png` (magma) are written.
//! Re-bless after an intended change: `HAIRMESH_BLESS=1 cargo test --release --test golden`,
//! look at the new PNGs, and commit them.

mod common;

use common::*;
use hairmesh::render::{ShadowMode, Transparency};
use hairmesh::shade::ShadingModel;

const MEAN_MAX: f32 = 0.01;
const P99_MAX: f32 = 0.25;

/// Render sample `mesh` (style changed by `edit`) as the golden scene.
fn render_golden(
    mesh: &str,
    n: u32,
    e: u32,
    edit: impl Fn(&mut hairmesh::HairStyle),
) -> RenderOutput {
    render_golden_shaded(mesh, n, e, ShadingModel::Placeholder, edit)
}

/// [`render_golden`] with a shading model.
fn render_golden_shaded(
    mesh: &str,
    n: u32,
    e: u32,
    shading: ShadingModel,
    edit: impl Fn(&mut hairmesh::HairStyle),
) -> RenderOutput {
    render_golden_look(mesh, n, e, Look::shaded(shading), edit)
}

/// Shading, shadows and transparency of a golden scene.
#[derive(Clone, Copy, Debug)]
struct Look {
    shading: ShadingModel,
    shadows: ShadowMode,
    transparency: Transparency,
}

impl Look {
    fn shaded(shading: ShadingModel) -> Self {
        Look {
            shading,
            shadows: ShadowMode::Off,
            transparency: Transparency::Opaque,
        }
    }

    fn shadows(self, shadows: ShadowMode) -> Self {
        Look { shadows, ..self }
    }

    fn transparency(self, transparency: Transparency) -> Self {
        Look {
            transparency,
            ..self
        }
    }
}

/// [`render_golden`] with a look.
fn render_golden_look(
    mesh: &str,
    n: u32,
    e: u32,
    look: Look,
    edit: impl Fn(&mut hairmesh::HairStyle),
) -> RenderOutput {
    let ctx = context();
    let (baked, mut style) = sample(mesh);
    edit(&mut style);
    let mut r = renderer(&ctx, 256);
    upload(&mut r, &baked, &style, n, e);
    let settings = RenderSettings {
        shading: look.shading,
        shadows: look.shadows,
        transparency: look.transparency,
        lod_appearance: true,
        ..compute_full()
    };
    let out = render(&mut r, &framing(&baked), &settings);
    assert_no_validation_errors(&ctx);
    out
}

/// FLIP error image, mean and 99th percentile of `out` against the golden `name`.
fn flip_against(name: &str, out: &RenderOutput) -> (nv_flip::FlipImageFloat, f32, f32) {
    let reference = root().join("tests/golden").join(format!("{name}.png"));
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
    let (mean, p99) = (pool.mean(), pool.get_percentile(0.99, true));
    (err, mean, p99)
}

fn check(name: &str, mesh: &str, n: u32, e: u32) {
    check_shaded(name, mesh, n, e, ShadingModel::Placeholder);
}

fn check_shaded(name: &str, mesh: &str, n: u32, e: u32, shading: ShadingModel) {
    check_look(name, mesh, n, e, Look::shaded(shading));
}

fn check_look(name: &str, mesh: &str, n: u32, e: u32, look: Look) {
    let out = render_golden_look(mesh, n, e, look, |_| {});
    let reference = root().join("tests/golden").join(format!("{name}.png"));
    if std::env::var("HAIRMESH_BLESS").is_ok_and(|v| v == "1") {
        save_png(&reference, out.width, out.height, &out.rgba);
        return;
    }
    let (err, mean, p99) = flip_against(name, &out);
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

/// The thresholds can fail: one changed style value (stronger clumping) on each golden scene
/// exceeds them.
#[test]
fn thresholds_catch_a_changed_style_value() {
    for (name, mesh, n, e) in [
        ("head_long", "head_long.obj", 32, 5),
        ("sphere_fur", "sphere_fur.obj", 24, 3),
        ("small_patch", "small_patch.obj", 64, 5),
        ("triangle_tuft", "triangle_tuft.obj", 64, 4),
    ] {
        let out = render_golden(mesh, n, e, |s| {
            s.clump_strength = (s.clump_strength + 0.3).min(1.0)
        });
        let (_, mean, p99) = flip_against(name, &out);
        println!("{name} with clump_strength + 0.3: FLIP mean {mean:.5}, p99 {p99:.5}");
        assert!(
            mean > MEAN_MAX || p99 > P99_MAX,
            "{name}: a changed style passes the golden thresholds (mean {mean}, p99 {p99})"
        );
    }
}

#[test]
fn golden_head_long_kajiya_kay() {
    check_shaded(
        "head_long_kajiya_kay",
        "head_long.obj",
        32,
        5,
        ShadingModel::KajiyaKay,
    );
}

#[test]
fn golden_head_long_marschner() {
    check_shaded(
        "head_long_marschner",
        "head_long.obj",
        32,
        5,
        ShadingModel::Marschner,
    );
}

#[test]
fn golden_head_long_deep_opacity_shadows() {
    check_look(
        "head_long_deep_opacity",
        "head_long.obj",
        32,
        5,
        Look::shaded(ShadingModel::KajiyaKay).shadows(ShadowMode::DeepOpacity),
    );
}

#[test]
fn golden_head_long_approximate_shadows() {
    check_look(
        "head_long_approximate",
        "head_long.obj",
        32,
        5,
        Look::shaded(ShadingModel::KajiyaKay).shadows(ShadowMode::Approximate),
    );
}

/// The shadow goldens fail on a wrong render: the same scene without shadows (measured FLIP
/// mean 0.054 / 0.058, p99 0.55 / 0.61).
#[test]
fn shadow_thresholds_catch_a_wrong_shadow_mode() {
    for (name, wrong) in [
        ("head_long_deep_opacity", ShadowMode::Off),
        ("head_long_approximate", ShadowMode::Off),
    ] {
        let out = render_golden_look(
            "head_long.obj",
            32,
            5,
            Look::shaded(ShadingModel::KajiyaKay).shadows(wrong),
            |_| {},
        );
        let (_, mean, p99) = flip_against(name, &out);
        println!("{name} rendered with {wrong:?}: FLIP mean {mean:.5}, p99 {p99:.5}");
        assert!(
            mean > MEAN_MAX || p99 > P99_MAX,
            "{name}: shadows {wrong:?} pass the golden thresholds (mean {mean}, p99 {p99})"
        );
    }
}

/// The shading goldens fail on a wrong shading input too: another roughness and tilt for
/// Marschner, another colour for Kajiya-Kay.
#[test]
fn shading_thresholds_catch_a_changed_style_value() {
    for (name, shading, edit) in [
        (
            "head_long_marschner",
            ShadingModel::Marschner,
            (|s: &mut hairmesh::HairStyle| {
                s.roughness = 0.6;
                s.cuticle_tilt_degrees = -8.0;
            }) as fn(&mut hairmesh::HairStyle),
        ),
        (
            "head_long_kajiya_kay",
            ShadingModel::KajiyaKay,
            |s: &mut hairmesh::HairStyle| s.color = [0.25, 0.2, 0.1],
        ),
    ] {
        let out = render_golden_shaded("head_long.obj", 32, 5, shading, edit);
        let (_, mean, p99) = flip_against(name, &out);
        println!("{name} with a changed style: FLIP mean {mean:.5}, p99 {p99:.5}");
        assert!(
            mean > MEAN_MAX || p99 > P99_MAX,
            "{name}: a changed style passes the golden thresholds (mean {mean}, p99 {p99})"
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

/// The hair mesh `fit` made from the Sintel Lite guides (hairmeshes/SINTEL_LICENSE.md).
#[test]
fn golden_sintel() {
    check("sintel", "sintel.obj", 32, 4);
}

#[test]
fn golden_triangle_tuft() {
    check("triangle_tuft", "triangle_tuft.obj", 64, 4);
}

/// The full look: Marschner, deep opacity shadows and k-buffer OIT (8 fragments per pixel).
fn full_look() -> Look {
    Look::shaded(ShadingModel::Marschner)
        .shadows(ShadowMode::DeepOpacity)
        .transparency(Transparency::KBuffer { budget: 8 })
}

#[test]
fn golden_head_long_oit() {
    check_look(
        "head_long_oit",
        "head_long.obj",
        32,
        5,
        Look::shaded(ShadingModel::KajiyaKay).transparency(Transparency::KBuffer { budget: 8 }),
    );
}

#[test]
fn golden_head_long_full_look() {
    check_look("head_long_full_look", "head_long.obj", 32, 5, full_look());
}

/// The transparency goldens fail on a wrong render: the same scenes drawn opaque.
#[test]
fn transparency_thresholds_catch_opaque_strands() {
    for (name, look) in [
        (
            "head_long_oit",
            Look::shaded(ShadingModel::KajiyaKay).transparency(Transparency::KBuffer { budget: 8 }),
        ),
        ("head_long_full_look", full_look()),
    ] {
        let wrong = look.transparency(Transparency::Opaque);
        let out = render_golden_look("head_long.obj", 32, 5, wrong, |_| {});
        let (_, mean, p99) = flip_against(name, &out);
        println!("{name} rendered opaque: FLIP mean {mean:.5}, p99 {p99:.5}");
        assert!(
            mean > MEAN_MAX || p99 > P99_MAX,
            "{name}: opaque strands pass the golden thresholds (mean {mean}, p99 {p99})"
        );
    }
}
