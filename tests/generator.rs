//! CPU reference generator: agrees with the curve maths, has seam-free styling frames and
//! produces finite, well-formed strands.

use std::path::Path;

use glam::{Vec2, Vec3};
use hairmesh::bake::curve::{column_control_points, eval_column};
use hairmesh::bake::layout::layout_root_slice;
use hairmesh::model::obj_io::load_hair_mesh_obj;
use hairmesh::reference::generate::{HairTextures, strand_key, styling_offset};
use hairmesh::{BakeOptions, CpuGenerator, Face, HairMesh, HairStyle, bake};

fn mesh(name: &str) -> HairMesh {
    load_hair_mesh_obj(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("hairmeshes")
            .join(name),
    )
    .unwrap()
}

/// Root-slice sample position of vertex `v` in face `f`'s cell, as a cell-local xi.
fn corner_xi(layout: &hairmesh::bake::layout::RootLayout, f: usize, v: u32) -> Vec2 {
    let [x, y] = layout.bundles[f].origin;
    for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
        if layout.texel(x + dx, y + dy) == v {
            return Vec2::new(dx as f32, dy as f32);
        }
    }
    panic!("vertex {v} not in face {f}'s cell");
}

#[test]
fn texture_curves_match_catmull_rom_columns() {
    for charts in [true, false] {
        let m = mesh("head_long.obj");
        let baked = bake(
            &m,
            &HairStyle::default(),
            BakeOptions {
                charts,
                ..Default::default()
            },
            |_, _| {},
        )
        .unwrap();
        let tex = HairTextures::new(&baked);
        let layout = layout_root_slice(&m, charts);
        // Quantisation: 1/65535 of the extent per axis, plus f32 filtering noise.
        let tol = Vec3::from_slice(&baked.info.pos_extent[..3]).length() * 2.0 / 65535.0 + 1e-6;
        for (f, face) in m.faces.iter().enumerate().step_by(7) {
            let b = &baked.bundles[f];
            for &v in face.vertices() {
                let column: Vec<Vec3> = m.layers.iter().map(|l| l[v as usize]).collect();
                let ctrl = column_control_points(&column);
                let fp = tex.footprint(tex.root_coord(b, corner_xi(&layout, f, v)));
                for i in 0..=36 {
                    let r = i as f32 / 4.0;
                    let d = tex.curve_point(&fp, r).distance(eval_column(&ctrl, r));
                    assert!(d <= tol, "face {f} vertex {v} r {r}: {d} > {tol}");
                }
            }
        }
    }
}

#[test]
fn styling_is_continuous_across_bundle_borders() {
    let m = mesh("small_patch.obj");
    let mut style =
        HairStyle::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("hairmeshes/small_patch.toml"))
            .unwrap();
    style.wave_amplitude = 0.01;
    style.wave_frequency = 5.0;
    // Per-face 2x2 blocks: the two sides of an edge read different texels (copies).
    let baked = bake(
        &m,
        &style,
        BakeOptions {
            charts: false,
            ..Default::default()
        },
        |_, _| {},
    )
    .unwrap();
    let tex = HairTextures::new(&baked);
    let layout = layout_root_slice(&m, false);
    let mut checked = 0;
    for (fa, a) in m.faces.iter().enumerate() {
        for (fb, b) in m.faces.iter().enumerate().skip(fa + 1) {
            let shared: Vec<u32> = a
                .vertices()
                .iter()
                .copied()
                .filter(|v| b.vertices().contains(v))
                .collect();
            if shared.len() != 2 {
                continue;
            }
            for lambda in [0.0, 0.3, 0.77, 1.0] {
                let xa = corner_xi(&layout, fa, shared[0])
                    .lerp(corner_xi(&layout, fa, shared[1]), lambda);
                let xb = corner_xi(&layout, fb, shared[0])
                    .lerp(corner_xi(&layout, fb, shared[1]), lambda);
                let pa = tex.footprint(tex.root_coord(&baked.bundles[fa], xa));
                let pb = tex.footprint(tex.root_coord(&baked.bundles[fb], xb));
                for r in [0.3, 1.5, 2.9, 4.0] {
                    let (ma, wa) = tex.frame(&pa, r);
                    let (mb, wb) = tex.frame(&pb, r);
                    let key = strand_key(style.seed, 0, 0);
                    let oa = styling_offset(&style, key, 0.5, wa);
                    let ob = styling_offset(&style, key, 0.5, wb);
                    let sa = tex.curve_point(&pa, r) + ma[0] * oa.x + ma[1] * oa.y + ma[2] * oa.z;
                    let sb = tex.curve_point(&pb, r) + mb[0] * ob.x + mb[1] * ob.y + mb[2] * ob.z;
                    assert!(
                        sa.distance(sb) < 1e-5,
                        "faces {fa}/{fb} lambda {lambda} r {r}: {sa} vs {sb}"
                    );
                    for k in 0..3 {
                        assert!(ma[k].distance(mb[k]) < 1e-5, "frame axis {k} differs");
                    }
                }
            }
            checked += 1;
        }
    }
    assert_eq!(checked, 40, "a 5x5 grid has 40 interior edges");
}

#[test]
fn triangle_roots_are_barycentric() {
    let m = mesh("triangle_tuft.obj");
    let baked = bake(&m, &HairStyle::default(), BakeOptions::default(), |_, _| {}).unwrap();
    let tex = HairTextures::new(&baked);
    let tol = Vec3::from_slice(&baked.info.pos_extent[..3]).length() * 2.0 / 65535.0;
    for (f, face) in m.faces.iter().enumerate() {
        let Face::Tri([a, b, c]) = *face else {
            panic!("all triangles")
        };
        let b_desc = &baked.bundles[f];
        assert!(b_desc.is_triangle());
        for xi in [
            Vec2::new(0.2, 0.3),
            Vec2::new(0.7, 0.1),
            Vec2::new(0.05, 0.9),
        ] {
            let got = tex.root_point(&tex.footprint(tex.root_coord(b_desc, xi)));
            let p = &m.layers[0];
            let want =
                p[a as usize] * (1.0 - xi.x - xi.y) + p[b as usize] * xi.x + p[c as usize] * xi.y;
            assert!(
                got.distance(want) < tol,
                "face {f} xi {xi}: {got} vs {want}"
            );
        }
    }
}

#[test]
fn generated_strands_are_well_formed() {
    for name in [
        "sphere_fur.obj",
        "head_long.obj",
        "small_patch.obj",
        "triangle_tuft.obj",
    ] {
        let m = mesh(name);
        let style = HairStyle::load(
            &Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("hairmeshes")
                .join(name)
                .with_extension("toml"),
        )
        .unwrap();
        let baked = bake(&m, &style, BakeOptions::default(), |_, _| {}).unwrap();
        let set = CpuGenerator::new(&baked, style).generate(8, 4);
        assert_eq!(set.verts_per_strand, 17);
        assert!(set.strand_count() >= m.faces.len());
        assert_eq!(set.positions.len(), set.strand_count() * 17);
        for (i, (p, t)) in set.positions.iter().zip(&set.tangents).enumerate() {
            assert!(p.is_finite(), "{name}: vertex {i} not finite");
            assert!(
                (t.length() - 1.0).abs() < 1e-4,
                "{name}: tangent {i} not unit"
            );
        }
        assert!(set.widths.iter().all(|w| *w > 0.0));
        // Deterministic: the oracle must give the same strands every time.
        let again = CpuGenerator::new(&baked, style).generate(8, 4);
        assert_eq!(again.positions, set.positions);
    }
}

/// Least-squares sphere through `points` (`|p|^2 = 2 c . p + k`): centre and radius.
fn fit_sphere(points: &[Vec3]) -> (Vec3, f32) {
    use glam::{Mat4, Vec4};
    let mean = points.iter().copied().sum::<Vec3>() / points.len() as f32;
    let (mut ata, mut atb) = (Mat4::ZERO, Vec4::ZERO);
    for p in points {
        let q = *p - mean;
        let row = Vec4::new(2.0 * q.x, 2.0 * q.y, 2.0 * q.z, 1.0);
        ata += Mat4::from_cols(row * row.x, row * row.y, row * row.z, row * row.w);
        atb += row * q.length_squared();
    }
    let x = ata.inverse() * atb;
    let c = x.truncate();
    (mean + c, (x.w + c.length_squared()).sqrt())
}

/// Roots follow a curved root layer (reference::root_surface): on the sphere-fur sample the
/// generated roots lie far closer to the sphere through the root vertices than the bilinear
/// roots in the bundles' middles. Measured: 0.29 of the bilinear depth, worst at the pole,
/// where the uv map is singular and the normals from the styling directions (`u x v`) tilt by
/// about 10 degrees.
#[test]
fn roots_follow_a_curved_root_layer() {
    use hairmesh::reference::root_surface::RootCell;
    let m = mesh("sphere_fur.obj");
    let roots = &m.layers[0];
    let (centre, radius) = fit_sphere(roots);
    assert!(
        roots
            .iter()
            .all(|p| (p.distance(centre) - radius).abs() < 1e-3 * radius),
        "sphere_fur's roots are not on one sphere"
    );
    let baked = bake(&m, &HairStyle::default(), BakeOptions::default(), |_, _| {}).unwrap();
    let flat_sag = baked
        .bundles
        .iter()
        .map(|b| {
            radius
                - RootCell::from_baked(&baked, b)
                    .bilinear(Vec2::splat(0.5))
                    .distance(centre)
        })
        .fold(0.0f32, f32::max);
    let set = CpuGenerator::new(&baked, HairStyle::default()).generate(32, 2);
    let curved_sag = set
        .positions
        .chunks(set.verts_per_strand)
        .map(|s| (radius - s[0].distance(centre)).abs())
        .fold(0.0f32, f32::max);
    println!(
        "sphere_fur (radius {radius}): bilinear roots up to {flat_sag} inside, curved {curved_sag}"
    );
    assert!(
        flat_sag > 0.01 * radius,
        "the sample's bundles are too small to test this"
    );
    assert!(
        curved_sag < 0.35 * flat_sag,
        "roots {curved_sag} off the sphere, bilinear {flat_sag}"
    );
}

/// Every strand's root lies inside its bundle's bounds (`reference::lod::bundle_bounds`, the
/// CPU twin of the task shader's culling box): a bundle culled by a wrong box would lose hair
/// that is on screen. (The box with the texel offset subtracted instead of added survived the
/// 2026-12-06 mutation sample.)
#[test]
fn strand_roots_lie_inside_their_bundle_bounds() {
    let m = mesh("head_long.obj");
    let style = HairStyle::default();
    let baked = bake(&m, &style, BakeOptions::default(), |_, _| {}).unwrap();
    let set = CpuGenerator::new(&baked, style).generate(8, 3);
    let extent = Vec3::from_slice(&baked.info.pos_extent[..3]).length();
    // Roots interpolate the decoded corners; 1e-4 of the mesh's size covers float rounding.
    let slack = 1e-4 * extent;
    for (s, b) in set.strand_bundle.iter().enumerate() {
        let root = set.positions[s * set.verts_per_strand];
        let (lo, hi) = hairmesh::reference::lod::bundle_bounds(&baked, *b as usize, slack);
        assert!(
            root.cmpge(lo).all() && root.cmple(hi).all(),
            "strand {s}: root {root} outside bundle {b}'s bounds {lo}..{hi}"
        );
    }
}
