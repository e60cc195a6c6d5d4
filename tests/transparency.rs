//! Transparency (`render::transparency`): the bounded k-buffer against depth peeling, its
//! reference, on dense hair; overflow with a budget of 1-2 fragments per pixel degrades
//! gracefully and cleanly under validation; the result does not depend on the order fragments
//! arrive in (the two generation paths rasterise in different orders); MSAA works with it.

mod common;

use common::*;
use hairmesh::render::{
    FrameOptions, LodSettings, RenderPath, Renderer, RendererDesc, ShadowMode, Transparency, View,
};
use hairmesh::shade::ShadingModel;

const SIZE: u32 = 128;

/// Dense long hair (32 strands per bundle, 33 vertices), Kajiya-Kay, no shadows.
fn frame(
    ctx: &std::sync::Arc<hairmesh::vk::Context>,
    path: RenderPath,
    transparency: Transparency,
    msaa: u32,
) -> Vec<u8> {
    let (baked, style) = sample("head_long.obj");
    let mut r = Renderer::new(ctx, &RendererDesc::default().size(SIZE, SIZE).msaa(msaa)).unwrap();
    upload(&mut r, &baked, &style, 32, 5);
    let settings = RenderSettings {
        path: Some(path),
        lod: LodSettings::off(),
        shading: ShadingModel::KajiyaKay,
        shadows: ShadowMode::Off,
        transparency,
        lod_appearance: true,
    };
    let rgba = render(&mut r, &framing(&baked), &settings).rgba;
    assert_no_validation_errors(ctx);
    rgba
}

/// Enough layers to peel every strand fragment of this scene: 96 and 128 layers give the same
/// image (checked below), so the reference is exact up to float rounding.
const PEEL_LAYERS: u32 = 128;

/// FLIP bounds of the k-buffer against the peeled reference. With 8 nodes per pixel the
/// nearest fragments, which carry most of the colour, are exact up to 8-bit packing and only
/// the tail is approximated (measured on lavapipe: mean 0.012, p99 0.22): bounded by the golden
/// thresholds, 0.02 mean / 0.25 p99. With 1-2 nodes nearly every pixel overflows and the
/// merged tail carries most of the hair (measured mean 0.016-0.017, p99 0.33-0.37); it must
/// stay close (mean 0.03, p99 0.5), where opaque strands are at mean 0.136.
const KBUFFER_MEAN_MAX: f32 = 0.02;
const KBUFFER_P99_MAX: f32 = 0.25;
const OVERFLOW_MEAN_MAX: f32 = 0.03;
const OVERFLOW_P99_MAX: f32 = 0.5;

#[test]
fn kbuffer_matches_depth_peeling_and_overflow_degrades_gracefully() {
    let ctx = context();
    let path = RenderPath::Compute;
    let reference = frame(
        &ctx,
        path,
        Transparency::DepthPeeling {
            layers: PEEL_LAYERS,
        },
        1,
    );
    let fewer = frame(&ctx, path, Transparency::DepthPeeling { layers: 96 }, 1);
    let (_, peel_mean, _) = flip_rgba(SIZE, SIZE, &reference, &fewer);
    println!("peel 96 vs {PEEL_LAYERS} layers: FLIP mean {peel_mean:.5}");
    assert!(
        peel_mean < 1e-3,
        "the reference has not converged: {peel_mean}"
    );
    let opaque = frame(&ctx, path, Transparency::Opaque, 1);
    let (_, opaque_mean, _) = flip_rgba(SIZE, SIZE, &reference, &opaque);
    println!("opaque vs peeled: FLIP mean {opaque_mean:.5}");
    let mut means = Vec::new();
    for budget in [8, 4, 2, 1] {
        let img = frame(&ctx, path, Transparency::KBuffer { budget }, 1);
        let (err, mean, p99) = flip_rgba(SIZE, SIZE, &reference, &img);
        println!("k-buffer {budget} vs peeled: FLIP mean {mean:.5}, p99 {p99:.5}");
        let (mean_max, p99_max) = if budget >= 8 {
            (KBUFFER_MEAN_MAX, KBUFFER_P99_MAX)
        } else {
            (OVERFLOW_MEAN_MAX, OVERFLOW_P99_MAX)
        };
        if mean > mean_max || p99 > p99_max {
            save_failure(&format!("kbuffer_{budget}"), SIZE, SIZE, &img, &err);
            save_png(&output_dir().join("peeled.png"), SIZE, SIZE, &reference);
            panic!(
                "k-buffer {budget}: FLIP mean {mean} (max {mean_max}), p99 {p99} (max {p99_max})"
            );
        }
        means.push(mean);
    }
    // The budget matters (the tail is an approximation) and opaque strands are far off.
    assert!(
        means[3] > means[0],
        "budget 1 {} vs 8 {}",
        means[3],
        means[0]
    );
    assert!(opaque_mean > 5.0 * KBUFFER_MEAN_MAX, "opaque {opaque_mean}");
}

/// The k-buffer keeps the K nearest fragments whatever order they arrive in, and the tail sums
/// are integers: the mesh path (fragments from task/mesh workgroups) and the compute path
/// (one indirect draw) give the same image, with overflow too.
#[test]
fn kbuffer_is_independent_of_fragment_order() {
    let ctx = context();
    for budget in [2, 8] {
        let t = Transparency::KBuffer { budget };
        let compute = frame(&ctx, RenderPath::Compute, t, 1);
        let mesh = frame(&ctx, RenderPath::Mesh, t, 1);
        let d = mean_abs_diff(&compute, &mesh);
        println!("budget {budget}: mesh vs compute mean abs diff {d}");
        assert_eq!(d, 0.0, "budget {budget}");
    }
    // Depth peeling on the mesh path: generation runs once per peel pass.
    let t = Transparency::DepthPeeling { layers: 8 };
    let d = mean_abs_diff(
        &frame(&ctx, RenderPath::Compute, t, 1),
        &frame(&ctx, RenderPath::Mesh, t, 1),
    );
    println!("depth peeling, mesh vs compute: mean abs diff {d}");
    // Measured 0 (the same strands peeled the same way); 1e-5 fails a few wrong pixels.
    assert!(d < 1e-5, "peeling mesh vs compute {d}");
}

/// OIT with 4x MSAA (lavapipe's count): the opaque edges are antialiased, the strands
/// resolved per pixel; close to the single-sample image, and clean under validation.
#[test]
fn kbuffer_with_msaa() {
    let ctx = context();
    let t = Transparency::KBuffer { budget: 4 };
    let single = frame(&ctx, RenderPath::Compute, t, 1);
    let msaa = frame(&ctx, RenderPath::Compute, t, 4);
    let (_, mean, _) = flip_rgba(SIZE, SIZE, &single, &msaa);
    println!("4x MSAA vs 1x with OIT: FLIP mean {mean:.5}");
    // Measured 0.016: the strands' opacity is weighed by the samples they cover.
    assert!(mean < 0.03, "{mean}");
    // Peeling is single-sample only: refused with a message, not a device error.
    let (baked, style) = sample("head_long.obj");
    let mut r = Renderer::new(&ctx, &RendererDesc::default().size(32, 32).msaa(4)).unwrap();
    upload(&mut r, &baked, &style, 4, 3);
    let view = View {
        light_dir: light(),
        shading: ShadingModel::KajiyaKay,
        transparency: Transparency::DepthPeeling { layers: 4 },
        ..View::new(framing(&baked))
    };
    let e = r.render_one(&view, &FrameOptions::default()).err().unwrap();
    assert!(e.to_string().contains("without MSAA"), "{e}");
    assert_no_validation_errors(&ctx);
}

/// Switching modes and sizes frame to frame reuses and regrows the per-pixel buffers cleanly.
#[test]
fn modes_switch_per_frame_and_survive_resize() {
    let ctx = context();
    let (baked, style) = sample("sphere_fur.obj");
    let mut r = Renderer::new(&ctx, &RendererDesc::default().size(64, 48)).unwrap();
    upload(&mut r, &baked, &style, 8, 3);
    let mut view = View {
        light_dir: light(),
        shading: ShadingModel::Marschner,
        shadows: ShadowMode::DeepOpacity,
        ..View::new(framing(&baked))
    };
    let modes = [
        Transparency::KBuffer { budget: 2 },
        Transparency::Opaque,
        Transparency::DepthPeeling { layers: 3 },
        Transparency::KBuffer { budget: 16 },
    ];
    let mut tickets = Vec::new();
    for (i, m) in modes.iter().cycle().take(10).enumerate() {
        if i == 5 {
            r.finish().unwrap();
            r.resize(80, 96).unwrap();
        }
        view.transparency = *m;
        let path = if i % 2 == 0 {
            RenderPath::Compute
        } else {
            r.default_path()
        };
        let opts = FrameOptions {
            path: Some(path),
            ..Default::default()
        };
        tickets.push(r.render_frame(&view, &opts).unwrap());
        if tickets.len() == hairmesh::render::FRAMES_IN_FLIGHT {
            r.wait(tickets.remove(0)).unwrap();
        }
    }
    for t in tickets {
        r.wait(t).unwrap();
    }
    assert_no_validation_errors(&ctx);
}
