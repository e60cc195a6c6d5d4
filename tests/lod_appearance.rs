//! Thick-strand appearance under LoD (seed 000; `glsl/lod_appearance.glsl`): with strand LoD
//! on, the hair region's mean luminance and mean hue at mid and far distance stay within 5% of
//! full detail when the thick-strand term is on; the figures without it are printed (and kept
//! in the guide's shading chapter).

mod common;

use common::*;
use glam::Vec3;
use hairmesh::render::{
    Camera, FrameOptions, LodSettings, RenderPath, Renderer, RendererDesc, ShadowMode,
    Transparency, View,
};
use hairmesh::shade::ShadingModel;

const SIZE: u32 = 160;

/// Mean linear colour of `img` over the pixels where `a` or `b` is not background.
fn region_mean(img: &[u8], a: &[u8], b: &[u8]) -> [f64; 3] {
    let bg = &a[..4];
    let mut sum = [0.0; 3];
    let mut n = 0usize;
    for ((p, pa), pb) in img.chunks(4).zip(a.chunks(4)).zip(b.chunks(4)) {
        if pa != bg || pb != bg {
            for c in 0..3 {
                sum[c] += srgb_to_linear(p[c]);
            }
            n += 1;
        }
    }
    sum.map(|s| s / n.max(1) as f64)
}

fn luminance(c: [f64; 3]) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// Hue angle in degrees of a linear RGB colour.
fn hue(c: [f64; 3]) -> f64 {
    let (r, g, b) = (c[0], c[1], c[2]);
    let h = (3f64.sqrt() * (g - b)).atan2(2.0 * r - g - b).to_degrees();
    if h < 0.0 { h + 360.0 } else { h }
}

struct Scene {
    r: Renderer,
    near: Camera,
}

fn scene(ctx: &std::sync::Arc<hairmesh::vk::Context>) -> Scene {
    scene_coloured(ctx, None)
}

/// The sample with its own colour or `color`.
fn scene_coloured(ctx: &std::sync::Arc<hairmesh::vk::Context>, color: Option<Vec3>) -> Scene {
    let (baked, mut style) = sample("head_long.obj");
    if let Some(c) = color {
        style.color = c.to_array();
    }
    let mut r = Renderer::new(ctx, &RendererDesc::default().size(SIZE, SIZE)).unwrap();
    upload(&mut r, &baked, &style, 64, 5);
    Scene {
        r,
        near: framing(&baked),
    }
}

/// The camera `k` times further from the target than `near`, with the field of view narrowed
/// so the hair keeps its size in the image (the LoD metric sees the distance; the image
/// compares like with like).
fn at_distance(near: &Camera, k: f32) -> Camera {
    let half = (near.fov_y * 0.5).tan() / k;
    Camera::look_at(
        near.target + (near.eye - near.target) * k,
        near.target,
        (2.0 * half.atan()).to_degrees(),
    )
}

fn frame(s: &mut Scene, cam: Camera, lod: bool, term: bool, t: Transparency) -> Vec<u8> {
    frame_with(s, cam, lod, term, t, false)
}

fn frame_with(
    s: &mut Scene,
    cam: Camera,
    lod: bool,
    term: bool,
    t: Transparency,
    multiple_scattering: bool,
) -> Vec<u8> {
    let view = View {
        light_dir: Vec3::new(0.4, 1.0, 0.6),
        lod: if lod {
            LodSettings::default()
        } else {
            LodSettings::off()
        },
        shading: ShadingModel::Marschner,
        shadows: ShadowMode::DeepOpacity,
        transparency: t,
        lod_appearance: term,
        multiple_scattering,
        ..View::new(cam)
    };
    let opts = FrameOptions {
        path: Some(RenderPath::Compute),
        read_image: true,
        ..Default::default()
    };
    s.r.render_one(&view, &opts).unwrap().rgba.unwrap()
}

/// Mean luminance and hue of the hair region within this fraction of full detail with the term.
/// Measured at most 1.2% (opaque, mid) with the term, 18-22% without (opaque): 5% is about 4x
/// the first, kept below the second so that the control (without the term) fails.
const TOLERANCE: f64 = 0.05;

/// Both transparency modes at 4x and 10x the framing distance (the field of view narrowed to
/// keep the image size): with the term the hair region's mean luminance and hue stay within
/// 5% of full detail (measured on lavapipe: OIT -1.1% / -0.7% luminance, opaque -1.2% / -0.2%,
/// hue within 0.3%); without it opaque hair brightens by 18-22% (sub-pixel thick strips drawn
/// one pixel wide uncover the background), which the test also checks, so that the term is
/// shown to matter.
#[test]
fn thick_strands_keep_luminance_and_hue() {
    let ctx = context();
    let mut s = scene(&ctx);
    for t in [Transparency::KBuffer { budget: 8 }, Transparency::Opaque] {
        for (name, k) in [("mid", 4.0), ("far", 10.0)] {
            let cam = at_distance(&s.near, k);
            let full = frame(&mut s, cam, false, true, t);
            let off = frame(&mut s, cam, true, false, t);
            let on = frame(&mut s, cam, true, true, t);
            let full_c = region_mean(&full, &full, &on);
            let diff = |img: &[u8]| {
                let c = region_mean(img, &full, &on);
                (
                    luminance(c) / luminance(full_c) - 1.0,
                    (hue(c) - hue(full_c)) / 360.0,
                )
            };
            let (l_off, h_off) = diff(&off);
            let (l_on, h_on) = diff(&on);
            println!(
                "{t} {name}: without term luminance {:+.1}% hue {:+.1}%; with term luminance {:+.1}% hue {:+.1}%",
                l_off * 100.0,
                h_off * 100.0,
                l_on * 100.0,
                h_on * 100.0
            );
            if l_on.abs() > TOLERANCE || h_on.abs() > TOLERANCE {
                let dir = output_dir();
                save_png(
                    &dir.join(format!("lod_{name}_{}_full.png", t.mode())),
                    SIZE,
                    SIZE,
                    &full,
                );
                save_png(
                    &dir.join(format!("lod_{name}_{}_on.png", t.mode())),
                    SIZE,
                    SIZE,
                    &on,
                );
                panic!("{t} {name}: luminance {l_on:+.3}, hue {h_on:+.3} off full detail");
            }
            if t == Transparency::Opaque {
                assert!(
                    l_off > 2.0 * TOLERANCE,
                    "{name}: the term should matter ({l_off})"
                );
            }
        }
    }
    assert_no_validation_errors(&ctx);
}

/// With multiple scattering on, blond hair (where it matters most) under LoD with the
/// thick-strand term (seed 000's aggregated model: clusters dim light leaving through their far
/// side and add back-scattering from their gaps) stays within 5% of full detail in mean
/// luminance and hue at mid and far distance. The figures with multiple scattering's cluster
/// terms and without the thick-strand term are printed.
#[test]
fn aggregated_scattering_keeps_thick_strands_close_to_full_detail() {
    let ctx = context();
    let blond = hairmesh::shade::melanin_color(0.3, 0.1);
    let mut s = scene_coloured(&ctx, Some(blond));
    let t = Transparency::Opaque;
    for (name, k) in [("mid", 4.0), ("far", 10.0)] {
        let cam = at_distance(&s.near, k);
        let full = frame_with(&mut s, cam, false, true, t, true);
        let on = frame_with(&mut s, cam, true, true, t, true);
        let off = frame_with(&mut s, cam, true, false, t, true);
        let full_c = region_mean(&full, &full, &on);
        let diff = |img: &[u8]| {
            let c = region_mean(img, &full, &on);
            (
                luminance(c) / luminance(full_c) - 1.0,
                (hue(c) - hue(full_c)) / 360.0,
            )
        };
        let (l_on, h_on) = diff(&on);
        let (l_off, h_off) = diff(&off);
        println!(
            "blond, multiple scattering, {name}: with term luminance {:+.1}% hue {:+.1}%; without {:+.1}% / {:+.1}%",
            l_on * 100.0,
            h_on * 100.0,
            l_off * 100.0,
            h_off * 100.0
        );
        if l_on.abs() > TOLERANCE || h_on.abs() > TOLERANCE {
            let dir = output_dir();
            save_png(
                &dir.join(format!("lod_ms_{name}_full.png")),
                SIZE,
                SIZE,
                &full,
            );
            save_png(&dir.join(format!("lod_ms_{name}_on.png")), SIZE, SIZE, &on);
            panic!("{name}: luminance {l_on:+.3}, hue {h_on:+.3} off full detail");
        }
    }
    assert_no_validation_errors(&ctx);
}
