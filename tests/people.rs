//! People of the crowd: hair that stays outside the head (rest pose and 300 simulated frames
//! with wind and head turns), hair sized to its head per family, textures of paper-like
//! size, and roots that stay on the drawn scalp through 120 animated crowd frames.

use glam::{Mat4, Vec3};
use hairmesh::animate::{CharacterMotion, DynamicsSettings, HairDynamics, Wind};
use hairmesh::characters::hairstyle::{StyleFamily, generate};
use hairmesh::characters::human::human_head;
use hairmesh::characters::person::PersonShape;
use hairmesh::characters::preset::{Body, Preset, build};
use hairmesh::{BakeOptions, bake};

#[test]
fn hair_stays_outside_its_head_at_rest_and_in_motion() {
    for (k, family) in StyleFamily::PEOPLE.into_iter().enumerate() {
        let person = PersonShape::draw(100 + k as u32);
        let hair = generate(family, 11 + k as u32, &person).unwrap();
        let head = person.head().unwrap();
        // Rest pose: every vertex above the root layer outside the head (the radial map is
        // the farthest crossing of the mesh: a non-negative gap is outside the mesh).
        // The fitted Sintel hair follows its input strands, which dip into the head: not yet.
        let grown = family != StyleFamily::Fitted;
        for (l, layer) in hair
            .mesh
            .layers
            .iter()
            .enumerate()
            .skip(1)
            .filter(|_| grown)
        {
            for p in layer {
                assert!(
                    head.gap(*p) >= -1e-4,
                    "{family:?}: layer {l} vertex {p} inside the head"
                );
            }
        }
        // 300 frames with gusty wind and sudden head turns: the radial gap stays >= 0.
        let motion = CharacterMotion {
            jerk: 0.6,
            ..CharacterMotion::idle(Mat4::IDENTITY, k as u32)
        };
        let settings = DynamicsSettings {
            wind: Wind {
                direction: Vec3::new(1.0, 0.0, 0.4),
                strength: 12.0,
                gustiness: 0.6,
            },
            ..Default::default()
        };
        let colliders = person.colliders().unwrap();
        let mut sim = HairDynamics::new(&hair.mesh, colliders, settings, motion.model(0.0));
        let n = hair.mesh.vertices_per_layer();
        let mut worst = f32::INFINITY;
        for f in 1..=300 {
            let model = motion.model(f as f32 / 30.0);
            sim.step(1.0 / 30.0, model);
            for p in &sim.pose()[n..] {
                worst = worst.min(head.gap(*p));
            }
        }
        assert!(
            worst >= -1e-4,
            "{family:?}: a vertex {worst} m inside the head"
        );
        println!(
            "{family:?}: nearest simulated vertex {:.1} mm outside",
            worst * 1e3
        );
    }
}

#[test]
fn hair_is_sized_to_its_head() {
    let head = human_head().unwrap();
    let (lo, hi) = hairmesh::model::hair_mesh::bounds(
        head.triangles
            .iter()
            .flatten()
            .copied()
            .filter(|p| p.y > head.centre.y - 0.02),
    );
    let head_width = hi.x - lo.x;
    for (k, family) in StyleFamily::PEOPLE.into_iter().enumerate() {
        for seed in 0..4 {
            let person = PersonShape::draw(seed * 31 + k as u32);
            let hair = generate(family, seed + 7, &person).unwrap();
            // Across the head: the hair above the jaw (long hair below it drapes the shoulders).
            let jaw = person.head().unwrap().centre().y - 0.08;
            let (lo, hi) = hairmesh::model::hair_mesh::bounds(
                hair.mesh
                    .layers
                    .iter()
                    .flatten()
                    .copied()
                    .filter(|p| p.y > jaw),
            );
            let width = (hi.x - lo.x) / (head_width * person.head.x * person.height);
            println!("{family:?} #{seed}: {width:.3}");
            assert!(
                width <= family.max_width(),
                "{family:?} #{seed}: {width:.2} head widths (at most {})",
                family.max_width()
            );
            let least = if family == StyleFamily::Mohawk {
                0.2
            } else {
                0.6
            };
            assert!(width > least, "{family:?} #{seed}: {width:.2} head widths");
            // Nothing above the head by more than a short crop's volume, except standing hair.
            let top = person.head().unwrap().surface(0.0, 0.0).y;
            let over = hi.y - top;
            let stands = matches!(
                family,
                StyleFamily::Mohawk | StyleFamily::Afro | StyleFamily::Bun
            );
            assert!(
                stands || over < 0.05,
                "{family:?} #{seed}: {over} m above the head"
            );
        }
    }
}

#[test]
fn textures_are_paper_sized() {
    let people = build(Preset::People, 100, 1).unwrap();
    let mut total = 0usize;
    let mut per_family: std::collections::BTreeMap<String, (usize, usize)> = Default::default();
    for c in &people {
        assert!(matches!(c.body, Body::Person(_)));
        let b = bake(
            &c.hair.mesh,
            &c.hair.style,
            BakeOptions::default(),
            |_, _| {},
        )
        .unwrap();
        let bytes = b.texture_bytes();
        total += bytes;
        let e = per_family.entry(c.hair.family.name()).or_default();
        e.0 += bytes;
        e.1 += 1;
        assert!(
            c.hair.mesh.vertex_count() <= 600,
            "{:?}: {} hair mesh vertices",
            c.hair.family,
            c.hair.mesh.vertex_count()
        );
    }
    for (name, (bytes, n)) in &per_family {
        let mean = *bytes as f64 / *n as f64;
        println!("{name}: {:.1} KB mean over {n}", mean / 1000.0);
        assert!(
            mean <= 21_000.0,
            "{name}: {mean} bytes of textures on average"
        );
    }
    println!("100 people: {:.3} MiB", total as f64 / (1 << 20) as f64);
    // 1.0 MiB until the short cuts got finer grids so their hair lies down (issue 44):
    // measured 0.99 MiB before, 1.22 MiB after (buzz 5.9 -> 18.7 KB, short crop -> 18.6 KB,
    // the parted fitted hair 13.7 -> 20.8 KB): 12.5 KB a person.
    assert!(
        total <= 1_300_000,
        "100 people take {total} bytes of textures"
    );
}

#[test]
fn roots_stay_on_the_drawn_scalp_in_an_animated_crowd() {
    let out = std::env::temp_dir().join(format!("hairmesh-roots-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_crowd"))
        .args([
            "--headless",
            "--frames",
            "120",
            "--count",
            "4",
            "--size",
            "96x64",
            "--orbit",
            "off",
            "--wind",
            "10",
            "--shadows",
            "off",
            "--strands-per-bundle",
            "4",
            "--validation",
            "--out",
        ])
        .arg(&out)
        .status()
        .unwrap();
    assert!(status.success());
    let csv = std::fs::read_to_string(out.join("stats.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = header
        .iter()
        .position(|h| *h == "root_gap")
        .expect("root_gap column");
    let gaps: Vec<f32> = lines
        .map(|l| l.split(',').nth(col).unwrap().parse().unwrap())
        .collect();
    assert_eq!(gaps.len(), 120);
    let worst = gaps.iter().copied().fold(0.0, f32::max);
    println!("largest root gap over 120 frames: {worst:.6} head radii");
    assert!(worst < 0.01, "roots {worst} head radii from the scalp");
    let _ = std::fs::remove_dir_all(&out);
}

/// A real head's strand count (issue 64): at the crowd's 175 strands per cm² every family grows
/// 175 strands on each cm² of the scalp it covers (within the rounding of its strands per
/// bundle), and every family that covers the whole head grows 90-160K strands, as a real head
/// does (90-150K); the mohawk by its strip's own area. The people's heads differ: over 39
/// people a family covers 521-888 cm² (91-156K strands; at 150 per cm² the smallest were
/// under 80K). The table (family, scalp cm², strands) is printed for the crowd chapter.
#[test]
fn every_family_grows_a_real_heads_count() {
    use hairmesh::characters::hairstyle::SCALP_STRANDS_PER_CM2;
    use hairmesh::characters::preset::{Preset, StrandDensity, build_families};
    use hairmesh::reference::generate::strands_at_full_detail;
    println!("| family | scalp cm² | strands per bundle | strands |");
    for family in StyleFamily::PEOPLE {
        for seed in [1, 2, 3] {
            let c = build_families(Preset::People, 1, seed, &[family])
                .unwrap()
                .remove(0);
            let density = StrandDensity::PerCm2(SCALP_STRANDS_PER_CM2);
            let n = c.strand_params_at(density, 4).unwrap().strands_per_bundle;
            let b = bake(
                &c.hair.mesh,
                &c.hair.style,
                BakeOptions::default(),
                |_, _| {},
            )
            .unwrap();
            let strands = strands_at_full_detail(&b, &c.hair.style, n);
            let cm2 = c.hair.scalp_cm2(1.0);
            if seed == 1 {
                println!("| {} | {cm2:.0} | {n} | {strands} |", family.name());
            }
            let per_cm2 = strands as f32 / cm2;
            assert!(
                (per_cm2 - SCALP_STRANDS_PER_CM2).abs() < 0.03 * SCALP_STRANDS_PER_CM2,
                "{family:?} #{seed}: {per_cm2:.1} strands per cm² over {cm2:.0} cm²"
            );
            if family != StyleFamily::Mohawk {
                assert!(
                    (90_000..=160_000).contains(&strands),
                    "{family:?} #{seed}: {strands} strands on {cm2:.0} cm²"
                );
            }
        }
    }
}
