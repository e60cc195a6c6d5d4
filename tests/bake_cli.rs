//! The `bake` tool: summary on success; one-line error, non-zero exit and no output on failure.

use std::process::Command;

fn bake(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_bake"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn prints_sizes_of_all_five_textures() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("patch.hmb");
    let mesh = concat!(env!("CARGO_MANIFEST_DIR"), "/hairmeshes/small_patch.obj");
    let o = bake(&[mesh, "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    for name in [
        "hair mesh texture",
        "uv-texture",
        "w-texture",
        "u-texture",
        "v-texture",
        "total textures",
    ] {
        assert!(text.contains(name), "missing {name} in\n{text}");
    }
    assert!(text.contains("8280 bytes"), "{text}");
    assert!(out.is_file());
}

#[test]
fn extrudes_a_scalp() {
    let dir = tempfile::tempdir().unwrap();
    let scalp = dir.path().join("scalp.obj");
    std::fs::write(
        &scalp,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n",
    )
    .unwrap();
    let out = dir.path().join("s.hmb");
    let o = bake(&[
        scalp.to_str().unwrap(),
        "--extrude",
        "4",
        "--step",
        "0.1",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("4 layers"));
}

#[test]
fn bad_input_fails_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nv nan 0 0\n").unwrap();
    let out = dir.path().join("never.hmb");
    for input in [bad.to_str().unwrap(), "/nonexistent/x.obj"] {
        let o = bake(&[input, "-o", out.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(1));
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
        assert!(err.contains(input), "names the file: {err}");
        assert!(!out.exists(), "nothing written");
    }
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "no temp files left"
    );
}
