//! Hair on any head from the command line: `make-hairmeshes --head` grows hairstyles on a
//! glTF character's head joint and on an OBJ bust in its own units, which `bake` reads; bad
//! heads fail in one line naming the file and write nothing.

use std::path::Path;
use std::process::{Command, Output};

fn make(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_make-hairmeshes"))
        .args(args)
        .output()
        .unwrap()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Mean position of an OBJ's first `n` vertices (the root layer) and the largest distance
/// between them.
fn roots(obj: &Path, n: usize) -> (glam::Vec3, f32) {
    let text = std::fs::read_to_string(obj).unwrap();
    let v: Vec<glam::Vec3> = text
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .take(n)
        .map(|l| {
            let c: Vec<f32> = l.split(' ').map(|x| x.parse().unwrap()).collect();
            glam::Vec3::new(c[0], c[1], c[2])
        })
        .collect();
    let mean = v.iter().copied().sum::<glam::Vec3>() / v.len() as f32;
    let spread = v
        .iter()
        .flat_map(|a| v.iter().map(move |b| a.distance(*b)))
        .fold(0.0, f32::max);
    (mean, spread)
}

/// A bob on the example character's head lies where its head is (metres: the top of a
/// 1.6 m figure, a head-wide patch of roots); a ponytail on the Sintel bust OBJ (centimetres)
/// lies on the bust in centimetres; both bake with the style written beside them.
#[test]
fn hairstyles_grow_on_a_gltf_head_and_an_obj_bust_in_their_units() {
    let dir = tempfile::tempdir().unwrap();
    let o = make(&[
        "--head",
        "hairmeshes/people/character.glb",
        "--family",
        "bob,afro",
        "-o",
        s(dir.path()),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (mean, spread) = roots(&dir.path().join("bob.obj"), 36);
    println!("bob roots about {mean}, spread {spread} m");
    assert!(
        (1.45..1.75).contains(&mean.y) && mean.x.abs() < 0.03,
        "{mean}"
    );
    assert!((0.12..0.3).contains(&spread), "{spread}");
    assert!(dir.path().join("afro.toml").is_file());

    let o = make(&[
        "--head",
        "hairmeshes/sintel_head.obj",
        "--family",
        "ponytail",
        "--out",
        s(dir.path()),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (mean, spread) = roots(&dir.path().join("ponytail.obj"), 36);
    println!("ponytail roots about {mean}, spread {spread} cm");
    // The bust's cranium centre is 33 cm up its file; a scalp spans about 15-30 cm.
    assert!((28.0..46.0).contains(&mean.y), "{mean}");
    assert!((12.0..32.0).contains(&spread), "{spread}");
    for name in ["bob", "ponytail"] {
        let hmb = dir.path().join(format!("{name}.hmb"));
        let obj = dir.path().join(format!("{name}.obj"));
        let o = Command::new(env!("CARGO_BIN_EXE_bake"))
            .args([s(&obj), "-o", s(&hmb)])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(String::from_utf8_lossy(&o.stdout).contains(&format!("{name}.toml")));
    }
}

/// A head that is no head, a joint that is not there, fur on a head: one line naming the
/// cause, a failing exit, nothing written.
#[test]
fn bad_heads_fail_in_one_line_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let tri = dir.path().join("tri.obj");
    std::fs::write(&tri, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    let glb = "hairmeshes/people/character.glb";
    for (args, names) in [
        (vec!["--head", s(&tri)], "tri.obj: the head has 3 vertices"),
        (
            vec!["--head", glb, "--joint", "nose"],
            "no joint named 'nose'",
        ),
        (vec!["--head", glb, "--family", "fur"], "--family fur"),
        (
            vec!["--head", "tri.txt"],
            "a head is an .obj, .glb or .gltf",
        ),
        (vec!["--family", "bob"], "--head"),
    ] {
        let mut all = args.clone();
        all.extend(["-o", s(&out)]);
        let o = make(&all);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            !o.status.success() && !err.contains("panicked"),
            "{args:?}: {err}"
        );
        assert!(err.contains(names), "{args:?}: {err}");
        if !names.starts_with("--head") {
            assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        }
        assert_eq!(
            std::fs::read_dir(&out).unwrap().count(),
            0,
            "{args:?} wrote"
        );
    }
}
