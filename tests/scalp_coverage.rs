//! Seen from above, every family's hair covers its scalp: the scalp region (the root faces,
//! subdivided and laid on the head) is drawn as a blue prop; the share of its pixels that stay
//! blue once the hair is shown is what the hair leaves uncovered (lavapipe, validation on).

mod common;

use common::*;
use glam::{Mat4, Vec3};
use hairmesh::characters::hairstyle::{StyleFamily, generate};
use hairmesh::characters::human::smooth_prop_mesh;
use hairmesh::characters::person::{PersonShape, head_mesh};
use hairmesh::characters::scalp::scalp_triangles;
use hairmesh::render::shared::PropInstance;
use hairmesh::render::{Camera, StrandParams};
use hairmesh::{BakeOptions, bake};

/// Least share of the scalp's pixels the hair must cover (issue 20 asks for 0.98), every
/// family. Measured (this test, lavapipe, 400 strands per reference bundle as the crowd asks
/// for them, `Hairstyle::strands_per_bundle`, about 10,000 strands): 98.54% side bangs,
/// 99.1-100% the other grown families, 98.86% the fitted Sintel hair (96.9% when it had
/// 400 per bundle, its bundles being 1.7 times the reference's area). Two things closed the holes the first version left
/// (86-98%): strand roots on the curved root surface (`reference::root_surface`) instead of
/// the chords between root corners, and bundle interiors lifted outside the head where
/// neighbouring columns spread or part (`hairstyle::lift_bundle_interiors`).
const MIN_COVERAGE: f64 = 0.98;

fn blue_pixels(rgba: &[u8]) -> usize {
    rgba.chunks(4)
        .filter(|p| {
            let (r, g, b) = (p[0] as i32, p[1] as i32, p[2] as i32);
            b > 24 && b > 2 * r.max(g)
        })
        .count()
}

#[test]
fn hair_covers_the_scalp_seen_from_above() {
    let ctx = context();
    let size = 256;
    let mut failures = Vec::new();
    for (k, family) in StyleFamily::PEOPLE.into_iter().enumerate() {
        let person = PersonShape::draw(40 + k as u32);
        let hair = generate(family, 5 + k as u32, &person).unwrap();
        let baked = bake(&hair.mesh, &hair.style, BakeOptions::default(), |_, _| {}).unwrap();
        let mut r = renderer(&ctx, size);
        let params = StrandParams {
            strands_per_bundle: hair.strands_per_bundle(400),
            verts_log2: 4,
        };
        let id = r
            .add_character(&baked, &hair.style, params, Mat4::IDENTITY)
            .unwrap();
        let scalp = smooth_prop_mesh(&scalp_triangles(&hair.mesh, &person.head().unwrap(), 8));
        r.set_prop_meshes(&[head_mesh().unwrap(), scalp]).unwrap();
        let prop = |mesh: usize, model: Mat4, color: [f32; 4]| {
            (
                mesh,
                PropInstance {
                    model: model.to_cols_array_2d(),
                    color,
                    clip_to_prev: Mat4::IDENTITY.to_cols_array_2d(),
                    skin: [hairmesh::render::shared::SKIN_NONE, 0, 0, 0],
                },
            )
        };
        r.set_prop_instances(&[
            prop(0, person.head_transform().unwrap(), [0.6, 0.4, 0.3, 1.0]),
            prop(1, Mat4::IDENTITY, [0.0, 0.0, 1.0, 1.0]),
        ])
        .unwrap();
        let head = person.head().unwrap();
        let top = head.surface(0.0, 0.0);
        let camera = Camera::look_at(top + Vec3::new(0.0, 0.7, 0.02), top, 30.0);
        let settings = compute_full();
        r.set_visible(id, false).unwrap();
        let bare = blue_pixels(&render(&mut r, &camera, &settings).rgba);
        r.set_visible(id, true).unwrap();
        let out = render(&mut r, &camera, &settings);
        let left = blue_pixels(&out.rgba);
        assert!(bare > 2000, "{family:?}: only {bare} scalp pixels in view");
        let coverage = 1.0 - left as f64 / bare as f64;
        println!(
            "{family:?}: hair covers {:.2}% of {bare} scalp pixels",
            coverage * 100.0
        );
        let bound = MIN_COVERAGE;
        if coverage < bound {
            let path = output_dir().join(format!("scalp_coverage_{}.png", family.name()));
            save_png(&path, size, size, &out.rgba);
            failures.push(format!(
                "{family:?}: {:.2}% < {:.0}% ({})",
                coverage * 100.0,
                bound * 100.0,
                path.display()
            ));
        }
    }
    assert_no_validation_errors(&ctx);
    assert!(failures.is_empty(), "scalp coverage too low: {failures:#?}");
}

/// Scalp show-through (issue 64), through `bench scalp`: in the crowd's 320x320 portrait of a
/// bob from the front, the share of the scalp's pixels whose light through the hair is above
/// one half is 0.078 at a real head's 175 strands per cm² (the hairline and the parting) and
/// reads high, 0.998, at the 96 strands a bundle the crowd wore before 2026-12-07 (of today's
/// strand width). Bounds: under 0.25 and over 0.8.
#[test]
fn a_real_heads_hair_hides_its_scalp_and_the_old_density_did_not() {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_bench"))
        .args([
            "scalp",
            "--families",
            "bob",
            "--views",
            "front",
            "--size",
            "320",
        ])
        .args(["--densities", "175,96/bundle"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let share = |density: &str| -> f32 {
        let row = stdout
            .lines()
            .find(|l| l.starts_with("| bob |") && l.contains(&format!("| {density} |")))
            .unwrap_or_else(|| panic!("no {density} row in {stdout}"));
        let cols: Vec<&str> = row.split('|').map(str::trim).collect();
        assert!(
            cols[7].parse::<u32>().unwrap() > 1000,
            "scalp pixels: {row}"
        );
        cols[8].parse().unwrap()
    };
    let (real, old) = (share("175/cm²"), share("96/bundle"));
    println!("show-through: {real} at 175 per cm², {old} at 96 a bundle");
    assert!(
        real < 0.25,
        "{real} of the scalp shows through a real head's hair"
    );
    assert!(
        old > 0.8,
        "{old}: the measure should read high at the old density"
    );
}
