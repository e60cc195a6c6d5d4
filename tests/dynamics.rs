//! Hair mesh dynamics (`animate::dynamics`), CPU: stable under head jerks and strong wind at
//! 30, 60 and 144 Hz for 600 frames (every layer edge within 10% of its rest length, nothing
//! NaN, nothing inside the head), the hair really moves, and it returns to its authored shape
//! when the motion stops.

use glam::{Mat4, Vec3};
use hairmesh::animate::{CharacterMotion, Collider, DynamicsSettings, HairDynamics, Wind};
use hairmesh::model::hair_mesh::HairMesh;
use hairmesh::model::obj_io::load_hair_mesh_obj;

fn head_long() -> HairMesh {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("hairmeshes");
    load_hair_mesh_obj(&root.join("head_long.obj")).unwrap()
}

fn sim(mesh: &HairMesh, wind: f32) -> (HairDynamics, f32, Vec3) {
    // A sphere fitted to the scalp, slightly inside it.
    let head = Collider::fit_scalp(mesh);
    let Collider::Ellipsoid { centre, radii } = head else {
        unreachable!()
    };
    let radius = radii.x / 0.97;
    assert!(
        (radius - 0.1).abs() < 1e-3 && centre.length() < 1e-3,
        "head_long's head sphere"
    );
    let settings = DynamicsSettings {
        wind: Wind {
            direction: Vec3::new(1.0, 0.2, 0.4),
            strength: wind,
            gustiness: 0.8,
        },
        ..Default::default()
    };
    (
        HairDynamics::new(mesh, vec![head], settings, Mat4::IDENTITY),
        radius,
        centre,
    )
}

#[test]
fn stable_under_jerks_and_strong_wind() {
    let mesh = head_long();
    for hz in [30.0f32, 60.0, 144.0] {
        let (mut d, radius, centre) = sim(&mesh, 40.0);
        let mut motion = CharacterMotion::idle(Mat4::IDENTITY, 3);
        motion.jerk = 0.8;
        let (mut worst_strain, mut most_moved, mut deepest) = (0.0f32, 0.0f32, f32::MAX);
        for f in 0..600 {
            let t = (f + 1) as f32 / hz;
            let model = motion.model(t);
            d.step(1.0 / hz, model);
            let strain = d.max_edge_strain();
            assert!(strain.is_finite(), "{hz} Hz frame {f}: NaN");
            assert!(
                d.positions().iter().all(|p| p.is_finite()),
                "{hz} Hz frame {f}: NaN"
            );
            worst_strain = worst_strain.max(strain);
            most_moved = most_moved.max(d.max_rest_offset());
            // Nothing deep inside the head (the collider is 97% of the scalp sphere; an
            // instantaneous 1.6 rad turn in strong wind pushes a vertex in by at most ~9%).
            let inside = d
                .positions()
                .iter()
                .map(|p| model.inverse().transform_point3(*p).distance(centre))
                .fold(f32::MAX, f32::min);
            deepest = deepest.min(inside / radius);
            assert!(
                inside > radius * 0.85,
                "{hz} Hz frame {f}: a vertex at {inside}"
            );
        }
        println!(
            "{hz} Hz: worst edge strain {worst_strain:.2e}, largest offset {most_moved:.3}, deepest vertex at {deepest:.3} head radii"
        );
        assert!(worst_strain < 0.1, "{hz} Hz: strain {worst_strain}");
        assert!(
            most_moved > 0.05 * radius,
            "{hz} Hz: the wind did not move the hair"
        );
    }
}

#[test]
fn returns_to_rest_when_motion_stops() {
    let mesh = head_long();
    let (mut d, radius, _) = sim(&mesh, 30.0);
    let motion = CharacterMotion::idle(Mat4::IDENTITY, 5);
    for f in 0..240 {
        d.step(1.0 / 60.0, motion.model(f as f32 / 60.0));
    }
    let moved = d.max_rest_offset();
    d.settings.wind.strength = 0.0;
    let still = motion.model(4.0);
    for _ in 0..600 {
        d.step(1.0 / 60.0, still);
    }
    let settled = d.max_rest_offset();
    println!("moving: {moved:.4}, 10 s after stopping: {settled:.5} (head radius {radius:.3})");
    assert!(moved > 0.05 * radius);
    assert!(settled < 0.01 * radius, "settled {settled}");
}

/// Distant characters step several frames at once (up to 8 frames at 60 Hz): still stable.
#[test]
fn stable_with_long_steps() {
    let mesh = head_long();
    let (mut d, _, _) = sim(&mesh, 40.0);
    let mut motion = CharacterMotion::idle(Mat4::IDENTITY, 9);
    motion.jerk = 0.5;
    for f in 0..150 {
        d.step(8.0 / 60.0, motion.model(f as f32 * 8.0 / 60.0));
        assert!(d.positions().iter().all(|p| p.is_finite()), "frame {f}");
        assert!(
            d.max_edge_strain() < 0.1,
            "frame {f}: {}",
            d.max_edge_strain()
        );
    }
}

/// `Collider::bounding_sphere` (which lets the GPU solver skip the exact push-out): every point
/// outside it is left bit-for-bit unchanged by the push-out, and it is tight enough to matter
/// (points just inside it, toward the collider, do get pushed).
#[test]
fn collider_bounding_spheres_hold_every_push_out() {
    let person = hairmesh::characters::person::PersonShape {
        head: Vec3::new(1.05, 0.95, 1.02),
        ..Default::default()
    };
    let mut colliders = person.colliders().unwrap();
    colliders.push(Collider::Ellipsoid {
        centre: Vec3::new(0.1, 1.6, -0.05),
        radii: Vec3::new(0.09, 0.12, 0.1),
    });
    let mut state = 0x9e37_79b9u32;
    let mut unit = || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state as f32 / u32::MAX as f32
    };
    for c in &colliders {
        let (centre, radius) = c.bounding_sphere();
        assert!(
            radius.is_finite() && radius > 0.0 && radius < 1.0,
            "{c:?}: {radius}"
        );
        let mut pushed_inside = 0;
        for _ in 0..4000 {
            let d = Vec3::new(unit() - 0.5, unit() - 0.5, unit() - 0.5).normalize_or(Vec3::Y);
            // Just outside the sphere, and anywhere up to twice its radius out.
            let outside = centre + d * radius * (1.0 + 1e-5 + unit());
            assert_eq!(
                c.push_out(outside),
                outside,
                "{c:?} moved a point outside its bound"
            );
            let inside = centre + d * radius * unit() * 0.5;
            pushed_inside += (c.push_out(inside) != inside) as usize;
        }
        assert!(
            pushed_inside > 100,
            "{c:?}: bound too loose ({pushed_inside} pushed)"
        );
    }
}
