//! Mesh path vs compute path, level of detail (paper sec. 3.6) against the CPU LoD functions,
//! LoD continuity over a camera dolly, and culling on the mesh path. All on lavapipe with
//! validation on.

mod common;

use common::*;
use glam::Vec3;
use hairmesh::reference::lod::bundle_lod;
use hairmesh::render::{Camera, LodSettings, RenderPath};
use hairmesh::{CpuGenerator, reference::generate::strands_in_bundle};

const SIZE: u32 = 160;

fn settings(path: RenderPath, lod: bool) -> RenderSettings {
    RenderSettings {
        path: Some(path),
        lod: if lod {
            LodSettings::default()
        } else {
            LodSettings::off()
        },
        shading: hairmesh::shade::ShadingModel::Placeholder,
        shadows: hairmesh::render::ShadowMode::Off,
        transparency: hairmesh::render::Transparency::Opaque,
        lod_appearance: true,
    }
}

/// Camera on the default framing axis at `dist` times the framing distance.
fn dolly(name: &str, dist: f32) -> Camera {
    let (baked, _) = sample(name);
    let c = framing(&baked);
    Camera::look_at(c.target + (c.eye - c.target) * dist, c.target, 40.0)
}

fn flip_mean(a: &RenderOutput, b: &RenderOutput) -> f32 {
    let rgb = |o: &RenderOutput| -> Vec<u8> {
        o.rgba.chunks(4).flat_map(|p| [p[0], p[1], p[2]]).collect()
    };
    let ra = nv_flip::FlipImageRgb8::with_data(a.width, a.height, &rgb(a));
    let rb = nv_flip::FlipImageRgb8::with_data(b.width, b.height, &rgb(b));
    nv_flip::FlipPool::from_image(&nv_flip::flip(ra, rb, nv_flip::DEFAULT_PIXELS_PER_DEGREE)).mean()
}

#[test]
fn mesh_path_matches_compute_path() {
    let ctx = context();
    assert!(
        ctx.info.mesh_shader,
        "lavapipe from Mesa 25 must expose VK_EXT_mesh_shader (run tools/setup.sh)"
    );
    for (name, n, e, lod, dist) in [
        ("head_long.obj", 16, 5, false, 1.0),
        ("triangle_tuft.obj", 32, 4, false, 1.0),
        ("head_long.obj", 32, 5, true, 3.0),
    ] {
        let cam = dolly(name, dist);
        let mesh = render_sample_with(
            &ctx,
            name,
            n,
            e,
            SIZE,
            Some(cam),
            &settings(RenderPath::Mesh, lod),
        );
        let compute = render_sample_with(
            &ctx,
            name,
            n,
            e,
            SIZE,
            Some(cam),
            &settings(RenderPath::Compute, lod),
        );
        assert_eq!(mesh.path, RenderPath::Mesh);
        // The task shader's counters agree with the device's mesh primitive query.
        assert_eq!(mesh.mesh_primitives_query.is_some(), ctx.info.mesh_queries);
        if let Some(q) = mesh.mesh_primitives_query {
            assert_eq!(
                q, mesh.triangles,
                "{name}: MESH_PRIMITIVES_GENERATED_EXT vs task counters"
            );
        }
        assert_eq!(
            mesh.triangles, compute.triangles,
            "{name}: triangle counts differ"
        );
        assert_eq!(mesh.strands, compute.strands);
        let d = mean_abs_diff(&mesh.rgba, &compute.rgba);
        println!(
            "{name} lod {lod}: {} triangles, mean abs diff {d:.6}",
            mesh.triangles
        );
        assert!(
            // Measured 0.000000 for every mesh and LoD setting (the two paths emit the same
            // triangles); 1e-4 fails a few wrong strands where 1/255 passed a shifted image.
            d <= 1e-4,
            "{name}: mean absolute pixel difference {d} > 1e-4"
        );
    }
    assert_no_validation_errors(&ctx);
}

#[test]
fn triangle_counts_follow_cpu_lod_functions() {
    let ctx = context();
    let name = "head_long.obj";
    let (baked, style) = sample(name);
    let (n, e) = (32, 5);
    let mut previous = u64::MAX;
    for dist in [0.5, 1.0, 2.0, 4.0, 8.0, 16.0] {
        let cam = dolly(name, dist);
        let out = render_sample_with(
            &ctx,
            name,
            n,
            e,
            SIZE,
            Some(cam),
            &settings(RenderPath::Mesh, true),
        );
        let view = lod_view(&cam, SIZE);
        let expected: u64 = baked
            .bundles
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let l = bundle_lod(&baked, &style, i, strands_in_bundle(b, &style, n), e, &view);
                l.strands as u64 * 2 * (1u64 << l.e)
            })
            .sum();
        println!(
            "distance x{dist}: {} triangles (CPU LoD predicts {expected})",
            out.triangles
        );
        // Rounding of ceil() at exact level boundaries may differ by an ulp between CPU and GPU.
        let rel = (out.triangles as f64 - expected as f64).abs() / expected as f64;
        assert!(
            rel <= 0.005,
            "distance x{dist}: GPU {} vs CPU {expected} triangles",
            out.triangles
        );
        assert!(
            out.triangles <= previous,
            "triangles must not grow with distance"
        );
        previous = out.triangles;
    }
    let full = render_sample_with(
        &ctx,
        name,
        n,
        e,
        SIZE,
        Some(dolly(name, 16.0)),
        &settings(RenderPath::Mesh, false),
    );
    assert!(
        previous * 4 < full.triangles,
        "far LoD should cut triangles at least 4x ({previous} vs {})",
        full.triangles
    );
    assert_no_validation_errors(&ctx);
}

#[test]
fn gpu_lod_strands_match_cpu_oracle() {
    let ctx = context();
    let eq7 = lod_strands_match_cpu_oracle(&ctx, LodSettings::default(), 8);
    // The crowd's area term (eq. 7's extent under 8 px: strands fall with the bundle's area,
    // widths grow), through the same oracle: 168 strands against 245 measured.
    let crowd = LodSettings {
        area_below: hairmesh::render::CROWD_AREA_BELOW,
        ..LodSettings::default()
    };
    let area = lod_strands_match_cpu_oracle(&ctx, crowd, 8);
    assert!(
        area * 5 < eq7 * 4,
        "area term {area} strands, eq. 7 alone {eq7}"
    );
    // The crowd's pixel cap (0.5 strands per square pixel of a bundle's extent, the
    // cross-section cap on the thick strands left) at 64 strands a bundle, against the area
    // term alone, strand for strand and width for width.
    let dense = lod_strands_match_cpu_oracle(&ctx, crowd, 64);
    let capped = lod_strands_match_cpu_oracle(
        &ctx,
        LodSettings {
            strands_per_pixel: hairmesh::render::CROWD_STRANDS_PER_PIXEL,
            ..crowd
        },
        64,
    );
    println!("eq. 7 {eq7}, area term {area}; at 64: {dense}, pixel cap {capped} strands");
    // Measured 168 against 246 (one strand a visible bundle).
    assert!(
        capped * 5 < dense * 4,
        "pixel cap {capped} strands, area term {dense}"
    );
}

/// Render head_long at 3x its framing distance with `lod` and `n` strands a bundle on the
/// compute path and compare the strands, widths and positions with the CPU oracle; the strands
/// drawn.
fn lod_strands_match_cpu_oracle(
    ctx: &std::sync::Arc<hairmesh::vk::Context>,
    lod: LodSettings,
    n: u32,
) -> usize {
    let name = "head_long.obj";
    let (baked, style) = sample(name);
    let e = 5;
    let cam = dolly(name, 3.0);
    let mut r = renderer(ctx, SIZE);
    upload(&mut r, &baked, &style, n, e);
    let opts = RenderSettings {
        lod,
        ..settings(RenderPath::Compute, true)
    };
    let out = render(&mut r, &cam, &opts);
    let strands = out.stats.strands_drawn;
    let gpu = r.read_vertices(out.stats.vertex_slots_written).unwrap();
    let view = lod_view_with(&cam, SIZE, &lod);
    let (cpu, counts) = CpuGenerator::new(&baked, style).generate_lod(n, e, &baked, &view);
    assert_eq!(strands as usize, counts.len(), "strand count");
    assert_eq!(gpu.len(), cpu.positions.len(), "vertex count");
    let morphing = counts.iter().any(|&c| c < 33);
    assert!(morphing, "the test view must reduce vertices somewhere");
    let ext = Vec3::from_slice(&baked.info.pos_extent[..3]).length();
    let mut worst = 0.0f32;
    for (i, v) in gpu.iter().enumerate() {
        let (p, t) = (v.pos_width, v.tangent_s);
        worst = worst.max(Vec3::new(p[0], p[1], p[2]).distance(cpu.positions[i]));
        assert!(
            (p[3] - cpu.widths[i]).abs() <= 1e-6 + 1e-3 * cpu.widths[i],
            "width {i}: {} vs {}",
            p[3],
            cpu.widths[i]
        );
        assert!(
            Vec3::new(t[0], t[1], t[2]).dot(cpu.tangents[i]) > 0.99,
            "tangent {i}"
        );
    }
    println!(
        "LoD oracle: {} strands, worst position error {worst:e}",
        counts.len()
    );
    // Same bound as tests/gpu_oracle.rs (measured ~1e-7 here).
    assert!(worst <= ext * 1e-5, "worst {worst}");
    assert_no_validation_errors(ctx);
    counts.len()
}

#[test]
fn lod_has_no_popping_over_a_dolly() {
    let ctx = context();
    let name = "head_long.obj";
    let distances: Vec<f32> = (0..16).map(|i| 0.8 * 1.22f32.powi(i)).collect();
    let frames = |lod: bool| -> Vec<RenderOutput> {
        distances
            .iter()
            .map(|&d| {
                render_sample_with(
                    &ctx,
                    name,
                    32,
                    5,
                    SIZE,
                    Some(dolly(name, d)),
                    &settings(RenderPath::Mesh, lod),
                )
            })
            .collect()
    };
    let on = frames(true);
    let off = frames(false);
    let mut worst_ratio = 0.0f64;
    for i in 1..distances.len() {
        let d_on = mean_abs_diff(&on[i - 1].rgba, &on[i].rgba);
        let d_off = mean_abs_diff(&off[i - 1].rgba, &off[i].rgba);
        worst_ratio = worst_ratio.max(d_on / d_off.max(1e-9));
        println!(
            "step {i}: consecutive diff LoD on {d_on:.5}, off {d_off:.5}; on vs off FLIP {:.4}, triangles {} / {}",
            flip_mean(&on[i], &off[i]),
            on[i].triangles,
            off[i].triangles
        );
        assert!(
            d_on <= 1.5 * d_off,
            "step {i}: LoD pops ({d_on} vs {d_off} without LoD)"
        );
    }
    for (i, (a, b)) in on.iter().zip(&off).enumerate() {
        // Documented threshold: LoD on vs off at the same distance, FLIP mean <= 0.06.
        let f = flip_mean(a, b);
        assert!(
            f <= 0.06,
            "distance {i}: LoD image differs from full detail by FLIP {f}"
        );
    }
    println!("worst consecutive-difference ratio on/off: {worst_ratio:.3}");
    assert_no_validation_errors(&ctx);
}

#[test]
fn mesh_path_culls_bundles_outside_the_frustum() {
    let ctx = context();
    let (baked, _) = sample("small_patch.obj");
    let o = Vec3::from_slice(&baked.info.pos_origin[..3]);
    let away = Camera::look_at(
        o + Vec3::new(0.0, 0.0, 5.0),
        o + Vec3::new(0.0, 0.0, 10.0),
        40.0,
    );
    let out = render_sample_with(
        &ctx,
        "small_patch.obj",
        16,
        4,
        32,
        Some(away),
        &settings(RenderPath::Mesh, false),
    );
    assert_eq!((out.strands, out.triangles), (0, 0));
    assert_no_validation_errors(&ctx);
}
