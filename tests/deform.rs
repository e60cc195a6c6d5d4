//! Moving hair meshes (`bake::deform`): rebuilding the textures of the rest pose gives the bake
//! itself, and styling stays attached: strands generated from a rigidly moved and rotated hair
//! mesh equal the rigidly moved strands of the original (CPU reference), within 1e-4 of the
//! model size.

use glam::{Mat3, Quat, Vec3};
use hairmesh::bake::deform::DeformBasis;
use hairmesh::bake::{BakeOptions, BakedHairMesh, bake};
use hairmesh::model::hair_mesh::HairMesh;
use hairmesh::model::obj_io::load_hair_mesh_obj;
use hairmesh::model::style::HairStyle;
use hairmesh::reference::generate::CpuGenerator;

fn sample(name: &str) -> (HairMesh, HairStyle) {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("hairmeshes");
    let mesh = load_hair_mesh_obj(&root.join(format!("{name}.obj"))).unwrap();
    let style = HairStyle::load(&root.join(format!("{name}.toml"))).unwrap();
    (mesh, style)
}

/// Layer-major positions of `mesh`.
fn positions(mesh: &HairMesh) -> Vec<Vec3> {
    mesh.layers.iter().flatten().copied().collect()
}

fn with_pose(baked: &BakedHairMesh, basis: &DeformBasis, pose: &[Vec3]) -> BakedHairMesh {
    let t = basis.rebuild(pose);
    BakedHairMesh {
        position: t.position,
        u_dir: t.u_dir,
        v_dir: t.v_dir,
        ..baked.clone()
    }
}

#[test]
fn rebuilding_the_rest_pose_gives_the_bake() {
    for name in ["head_long", "sphere_fur", "small_patch", "triangle_tuft"] {
        let (mesh, style) = sample(name);
        let options = BakeOptions {
            motion_margin: 0.1,
            ..Default::default()
        };
        let baked = bake(&mesh, &style, options, |_, _| {}).unwrap();
        let basis = DeformBasis::new(&mesh, &baked, options).unwrap();
        let t = basis.rebuild(&positions(&mesh));
        assert!(t.position == baked.position, "{name}: position texture");
        assert!(
            t.u_dir == baked.u_dir && t.v_dir == baked.v_dir,
            "{name}: u/v textures"
        );
    }
}

#[test]
fn styling_stays_attached_under_rigid_motion() {
    for name in ["head_long", "sphere_fur"] {
        let (mesh, style) = sample(name);
        let (lo, hi) = hairmesh::model::hair_mesh::bounds(positions(&mesh).into_iter());
        let size = (hi - lo).length();
        // The box must hold the moved mesh: grow it by the move plus the model size.
        let shift = Vec3::new(0.3, -0.1, 0.2) * size;
        let options = BakeOptions {
            motion_margin: size + shift.length(),
            ..Default::default()
        };
        let baked = bake(&mesh, &style, options, |_, _| {}).unwrap();
        let basis = DeformBasis::new(&mesh, &baked, options).unwrap();
        let centre = (lo + hi) * 0.5;
        let rot = Mat3::from_quat(Quat::from_euler(glam::EulerRot::YXZ, 0.7, -0.3, 0.2));
        let moved: Vec<Vec3> = positions(&mesh)
            .iter()
            .map(|p| rot * (*p - centre) + centre + shift)
            .collect();
        let moved_bake = with_pose(&baked, &basis, &moved);
        let original = CpuGenerator::new(&baked, style).generate(16, 4);
        let animated = CpuGenerator::new(&moved_bake, style).generate(16, 4);
        assert_eq!(original.positions.len(), animated.positions.len());
        let worst = original
            .positions
            .iter()
            .zip(&animated.positions)
            .map(|(a, b)| (rot * (*a - centre) + centre + shift).distance(*b))
            .fold(0.0f32, f32::max);
        println!(
            "{name}: worst distance {:.2e} of the model size",
            worst / size
        );
        assert!(
            worst < 1e-4 * size,
            "{name}: {} of the model size",
            worst / size
        );
    }
}
