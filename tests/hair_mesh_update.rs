//! The GPU rebuild of a moving hair mesh's textures (`glsl/hair_mesh_update.comp`) equals the
//! CPU twin (`bake::deform`) texel for texel within one 16-bit step, for the rest pose (where
//! the CPU twin is the bake itself) and for a bent pose; frames with pose updates run clean
//! under validation.

mod common;

use common::*;
use glam::{Mat4, Vec3};
use hairmesh::HairStyle;
use hairmesh::bake::deform::DeformBasis;
use hairmesh::bake::{BakeOptions, bake};
use hairmesh::model::obj_io::load_hair_mesh_obj;
use hairmesh::render::shared::TextureBinding;
use hairmesh::render::{FrameOptions, RenderPath, StrandParams};

/// Largest difference between two texel arrays of 16-bit components (`signed`: SNORM).
fn worst_step(a: &[u8], b: &[u8], signed: bool) -> i32 {
    assert_eq!(a.len(), b.len());
    a.chunks(2)
        .zip(b.chunks(2))
        .map(|(x, y)| {
            let (x, y) = ([x[0], x[1]], [y[0], y[1]]);
            if signed {
                (i16::from_le_bytes(x) as i32 - i16::from_le_bytes(y) as i32).abs()
            } else {
                (u16::from_le_bytes(x) as i32 - u16::from_le_bytes(y) as i32).abs()
            }
        })
        .max()
        .unwrap_or(0)
}

#[test]
fn gpu_rebuild_equals_the_cpu_twin() {
    let ctx = context();
    for name in ["head_long", "triangle_tuft"] {
        let dir = root().join("hairmeshes");
        let mesh = load_hair_mesh_obj(&dir.join(format!("{name}.obj"))).unwrap();
        // Some root thinning, which the rebuild must keep in the root slice's alpha.
        let thinning = (0..mesh.vertices_per_layer())
            .map(|i| (i % 3) as f32 * 0.4)
            .collect();
        let mesh = mesh.with_root_thinning(thinning).unwrap();
        let style = HairStyle::load(&dir.join(format!("{name}.toml"))).unwrap();
        let options = BakeOptions {
            motion_margin: 0.2,
            ..Default::default()
        };
        let baked = bake(&mesh, &style, options, |_, _| {}).unwrap();
        let basis = DeformBasis::new(&mesh, &baked, options).unwrap();
        let mut r = renderer(&ctx, 64);
        let params = StrandParams {
            strands_per_bundle: 8,
            verts_log2: 3,
        };
        let id = r
            .add_character(&baked, &style, params, Mat4::IDENTITY)
            .unwrap();
        r.make_deformable(id, basis.clone()).unwrap();
        let rest: Vec<Vec3> = mesh.layers.iter().flatten().copied().collect();
        // A bent pose: every layer pushed sideways by its height above the root, growing
        // along the column, and twisted a little.
        let n = mesh.vertices_per_layer();
        let bent: Vec<Vec3> = rest
            .iter()
            .enumerate()
            .map(|(j, p)| {
                let (k, i) = (j / n, j % n);
                let d = p.distance(mesh.layers[0][i]);
                *p + Vec3::new(0.3 * d * d, -0.1 * d, 0.05 * (k as f32).sin() * d)
            })
            .collect();
        for (pose_name, pose) in [("rest", &rest), ("bent", &bent)] {
            r.set_hair_mesh_pose(id, pose).unwrap();
            let opts = FrameOptions {
                path: Some(RenderPath::Compute),
                ..Default::default()
            };
            r.render_one(&light_view(&baked), &opts).unwrap();
            let cpu = basis.rebuild(pose);
            if pose_name == "rest" {
                assert!(cpu.position == baked.position && cpu.u_dir == baked.u_dir);
                assert!(cpu.position.iter().any(|t| t[3] > 0), "root thinning baked");
            }
            let cases = [
                (
                    TextureBinding::Position,
                    bytemuck::cast_slice::<_, u8>(&cpu.position).to_vec(),
                    false,
                ),
                (
                    TextureBinding::U,
                    bytemuck::cast_slice::<_, u8>(&cpu.u_dir).to_vec(),
                    true,
                ),
                (
                    TextureBinding::V,
                    bytemuck::cast_slice::<_, u8>(&cpu.v_dir).to_vec(),
                    true,
                ),
            ];
            for (binding, expected, signed) in cases {
                let gpu = r.read_texture(id, binding).unwrap();
                let worst = worst_step(&gpu, &expected, signed);
                println!("{name} {pose_name} {binding:?}: worst {worst} steps");
                assert!(worst <= 1, "{name} {pose_name} {binding:?}: {worst} steps");
            }
        }
        assert_no_validation_errors(&ctx);
    }
}

fn light_view(baked: &hairmesh::BakedHairMesh) -> hairmesh::render::View {
    hairmesh::render::View {
        light_dir: light(),
        lod: hairmesh::render::LodSettings::default(),
        shading: hairmesh::shade::ShadingModel::Marschner,
        shadows: hairmesh::render::ShadowMode::DeepOpacity,
        ..hairmesh::render::View::new(framing(baked))
    }
}
