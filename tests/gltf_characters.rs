//! glTF characters in: the shipped people load with their skeleton, clothes and clips; the
//! walk's planted feet give a stride speed; the CPU skinning of a real clip moves the feet on
//! the ground; broken files are refused in one line naming the file and the part at fault.

use std::path::Path;

use hairmesh::budget::MemoryBudget;
use hairmesh::model::gltf::{load_character, parse_character};
use hairmesh::skin::{ground_speed, skin_vertices};

fn man() -> hairmesh::model::gltf::Character {
    load_character(
        Path::new("hairmeshes/people/man.glb"),
        MemoryBudget::default(),
    )
    .unwrap()
}

/// The man: 53 joints (the game-engine rig), six clothing and skin meshes, a walk and an
/// idle clip; the walk's feet move backward at its stride speed (1.2 m per 1.1 s cycle, as
/// `tools/people/make_people.py` authors it: 1.09 m/s) within 5%.
#[test]
fn the_shipped_man_loads() {
    let c = man();
    assert_eq!(c.skeleton.joints.len(), 53);
    let names: Vec<&str> = c.meshes.iter().map(|m| m.name.as_str()).collect();
    for want in ["skin", "shirt", "sleeves", "trousers", "shoes", "skirt"] {
        assert!(names.contains(&want), "{names:?}");
    }
    let walk = c.clip("walk").expect("walk clip");
    assert!((walk.duration - 1.1).abs() < 1e-3, "{}", walk.duration);
    assert!(c.clip("idle").is_some());
    let s = &c.skeleton;
    let feet = [s.find("ball_l").unwrap(), s.find("ball_r").unwrap()];
    let speed = ground_speed(s, walk, &feet, 0.01).unwrap();
    assert!(
        (speed - 1.2 / 1.1).abs() < 0.05 * 1.2 / 1.1,
        "stride speed {speed}"
    );
}

/// Skinned at every frame of the walk, the shoes' lowest point stays within 2 cm of the
/// ground (the clip plants the feet) and the body never leaves its 2 m box.
#[test]
fn the_walk_keeps_feet_on_the_ground() {
    let c = man();
    let walk = c.clip("walk").unwrap();
    let shoes = c.meshes.iter().find(|m| m.name == "shoes").unwrap();
    let mut lowest = Vec::new();
    for k in 0..22 {
        let pose = walk.sample(&c.skeleton, k as f32 * 0.05);
        let m = c.skeleton.skin_matrices(&pose);
        let posed = skin_vertices(shoes, &m);
        let low = posed
            .iter()
            .map(|v| v.position.y)
            .fold(f32::INFINITY, f32::min);
        assert!(posed.iter().all(|v| v.position.abs().max_element() < 2.0));
        lowest.push(low);
    }
    let (lo, hi) = lowest
        .iter()
        .fold((f32::MAX, f32::MIN), |(a, b), &x| (a.min(x), b.max(x)));
    assert!(
        lo > -0.02 && hi < 0.03,
        "shoe soles between {lo} and {hi} m"
    );
}

/// `glb` with its JSON chunk replaced by `edit` of it (padded, lengths rewritten).
fn with_json(glb: &[u8], edit: impl Fn(&str) -> String) -> Vec<u8> {
    let len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let json = edit(std::str::from_utf8(&glb[20..20 + len]).unwrap());
    let padded = format!("{json:<width$}", width = json.len().div_ceil(4) * 4);
    let mut out = glb[..12].to_vec();
    out.extend((padded.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(padded.as_bytes());
    out.extend(&glb[20 + len..]);
    let total = out.len() as u32;
    out[8..12].copy_from_slice(&total.to_le_bytes());
    out
}

/// Broken files: one line naming the file and the cause.
#[test]
fn broken_files_are_refused_in_one_line() {
    let bytes = std::fs::read("hairmeshes/people/man.glb").unwrap();
    let budget = MemoryBudget::default();
    let truncated =
        parse_character("man.glb", &bytes[..bytes.len() / 2], None, budget).unwrap_err();
    let text = truncated.to_string();
    assert!(
        text.starts_with("man.glb: ") && !text.contains('\n'),
        "{text}"
    );
    // The JSON chunk with an accessor's count made absurd: refused by the bounds check.
    let out = with_json(&bytes, |json| json.replacen("\"count\":", "\"count\":9", 1));
    let e = parse_character("man.glb", &out, None, budget)
        .unwrap_err()
        .to_string();
    assert!(e.contains("accessor") && !e.contains('\n'), "{e}");
    // A node hierarchy with a cycle (the fuzzer's hang: walking up the parents never ended)
    // and a node with two parents: refused, naming the node.
    for (from, to, names) in [
        ("\"children\":[3]", "\"children\":[3,0]", "ancestor"),
        ("\"children\":[3]", "\"children\":[3,5]", "child of nodes"),
        // Animation channels the gltf crate's validation passes and its accessors unwrap
        // (panics the fuzzer found): an unknown target path, a target node that does not exist.
        ("\"path\":\"rotation\"", "\"path\":\"twist\"", "target path"),
        (
            "\"target\":{\"node\":",
            "\"target\":{\"node\":9999,\"x\":",
            "node 9999",
        ),
    ] {
        let out = with_json(&bytes, |json| json.replacen(from, to, 1));
        let e = parse_character("man.glb", &out, None, budget)
            .unwrap_err()
            .to_string();
        assert!(e.contains(names) && !e.contains('\n'), "{e}");
    }
    // A tiny budget is refused before reading.
    let tiny = MemoryBudget::from_mib(1, "--memory-budget-mib").unwrap();
    let e = parse_character("man.glb", &bytes, None, tiny)
        .unwrap_err()
        .to_string();
    assert!(e.contains("budget"), "{e}");
}
