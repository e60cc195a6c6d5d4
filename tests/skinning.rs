//! GPU skinning equals its CPU twin: a person of the crowd (the man's six skinned parts)
//! posed by the walk clip, skinned by `skin.comp` in a rendered frame and read back, against
//! `skin::skin_vertices` of the same matrices. Validation on; no message allowed.

mod common;

use glam::{Mat4, Vec3};
use hairmesh::characters::people::{Figure, PARTS, figures, skinned_meshes};
use hairmesh::render::{Camera, FrameOptions, View};
use hairmesh::skin::skin_vertices;

/// Largest difference between GPU and CPU posed positions, metres: about 10x the 1.2e-7
/// measured on lavapipe (the same f32 sums in another order).
const POSITION_TOLERANCE: f32 = 1e-6;
/// Largest difference of the unit normals: about 10x the 1.8e-7 measured.
const NORMAL_TOLERANCE: f32 = 2e-6;

#[test]
fn gpu_skinning_equals_the_cpu_twin_on_the_walk() {
    let ctx = common::context();
    let (baked, style) = common::sample("small_patch.obj");
    let mut r = common::renderer(&ctx, 96);
    let id = r
        .add_character(
            &baked,
            &style,
            hairmesh::render::StrandParams {
                strands_per_bundle: 8,
                verts_log2: 3,
            },
            Mat4::IDENTITY,
        )
        .unwrap();
    let meshes = skinned_meshes().unwrap();
    r.set_skinned_meshes(&meshes).unwrap();
    let man = &figures().unwrap()[Figure::Man as usize];
    let parts: Vec<(usize, [f32; 4])> = (0..PARTS.len()).map(|k| (k, [1.0; 4])).collect();
    r.set_character_skin(id, &parts, man.skeleton.joints.len())
        .unwrap();
    let walk = man.clip("walk").unwrap();
    let matrices = man
        .skeleton
        .skin_matrices(&walk.sample(&man.skeleton, 0.37));
    r.set_character_pose(id, Mat4::IDENTITY, &matrices).unwrap();
    let cam = Camera::look_at(Vec3::new(0.0, 1.0, 3.0), Vec3::new(0.0, 1.0, 0.0), 45.0);
    r.render_one(&View::new(cam), &FrameOptions::default())
        .unwrap();
    let total: usize = meshes[..PARTS.len()].iter().map(|m| m.vertices.len()).sum();
    let gpu = r.read_posed_vertices(total).unwrap();
    let mut worst = (0.0f32, 0.0f32);
    let mut at = 0;
    for mesh in &meshes[..PARTS.len()] {
        for cpu in skin_vertices(mesh, &matrices) {
            let g = &gpu[at];
            at += 1;
            worst.0 = worst
                .0
                .max((Vec3::from(g.position) - cpu.position).abs().max_element());
            worst.1 = worst
                .1
                .max((Vec3::from(g.normal) - cpu.normal).abs().max_element());
        }
    }
    // The pose moved the body: a GPU that wrote nothing, or the rest pose, fails here.
    let rest_moved = meshes[0]
        .vertices
        .iter()
        .zip(&gpu)
        .map(|(v, g)| (v.position - Vec3::from(g.position)).length())
        .fold(0.0, f32::max);
    assert!(
        rest_moved > 0.05,
        "the walk pose moved no vertex ({rest_moved} m)"
    );
    assert!(
        worst.0 < POSITION_TOLERANCE && worst.1 < NORMAL_TOLERANCE,
        "GPU vs CPU skinning: position {:e} m, normal {:e}",
        worst.0,
        worst.1
    );
    eprintln!(
        "GPU vs CPU skinning: position {:e} m, normal {:e}",
        worst.0, worst.1
    );
    common::assert_no_validation_errors(&ctx);
}
