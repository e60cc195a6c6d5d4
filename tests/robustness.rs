//! Hostile use of the tools, through the real binaries: every bad output path, absurd argument,
//! degenerate value and misleading input fails with a short message (at most three lines) that
//! names the argument or file, a non-zero exit, no panic, and no output created or replaced.
//! None of these cases reaches the GPU.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn run(bin: &str, args: &[&str]) -> Output {
    // `timeout` turns a hang (e.g. a blocking FIFO) into a failure instead of a stuck test.
    Command::new("timeout")
        .arg("60")
        .arg(bin)
        .args(args)
        .stdin(Stdio::null())
        .output()
        .unwrap()
}

fn bake(args: &[&str]) -> Output {
    run(env!("CARGO_BIN_EXE_bake"), args)
}

fn render(args: &[&str]) -> Output {
    run(env!("CARGO_BIN_EXE_render"), args)
}

fn bench(args: &[&str]) -> Output {
    run(env!("CARGO_BIN_EXE_bench"), args)
}

/// Failed with a non-zero exit (not a timeout), a short message naming `names`, no panic.
#[track_caller]
fn assert_fails(o: &Output, names: &str) {
    let err = String::from_utf8_lossy(&o.stderr);
    let code = o.status.code();
    assert!(
        code.is_some_and(|c| c != 0 && c != 124),
        "exit {code:?} (124 = hang): {err}"
    );
    assert!(!err.contains("panicked"), "panic: {err}");
    let lines = err.trim_end().lines().count();
    assert!((1..=3).contains(&lines), "{lines} lines: {err}");
    assert!(err.contains(names), "message should name '{names}': {err}");
}

/// A temporary folder with the small_patch sample (`m.obj`, `m.toml`) and its bake (`m.hmb`).
fn workspace() -> (tempfile::TempDir, PathBuf, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("m.obj");
    std::fs::copy(root().join("hairmeshes/small_patch.obj"), &obj).unwrap();
    std::fs::copy(
        root().join("hairmeshes/small_patch.toml"),
        dir.path().join("m.toml"),
    )
    .unwrap();
    let hmb = dir.path().join("m.hmb");
    let o = bake(&[s(&obj), "-o", s(&hmb)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    (dir, obj, hmb)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn mkfifo(p: &Path) {
    assert!(Command::new("mkfifo").arg(p).status().unwrap().success());
}

#[test]
fn outputs_never_replace_inputs_links_or_special_files() {
    let (dir, obj, hmb) = workspace();
    let obj_bytes = std::fs::read(&obj).unwrap();
    let hmb_bytes = std::fs::read(&hmb).unwrap();
    // The output is the input.
    assert_fails(&bake(&[s(&obj), "-o", s(&obj)]), "is the input");
    assert_fails(&render(&["--mesh", s(&hmb), "-o", s(&hmb)]), "is the input");
    // ... through a hard link, and the style beside the mesh is an input too.
    let hard = dir.path().join("hard.obj");
    std::fs::hard_link(&obj, &hard).unwrap();
    assert_fails(&bake(&[s(&obj), "-o", s(&hard)]), "is the input");
    let style = dir.path().join("m.toml");
    let style_bytes = std::fs::read(&style).unwrap();
    assert_fails(&bake(&[s(&obj), "-o", s(&style)]), "is the input");
    // A symbolic link given as the output is not followed or replaced.
    let link = dir.path().join("link.hmb");
    std::os::unix::fs::symlink(&hmb, &link).unwrap();
    assert_fails(&bake(&[s(&obj), "-o", s(&link)]), "symbolic link");
    assert!(
        std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    // Folders and FIFOs are refused (a FIFO without a reader would block).
    let sub = dir.path().join("sub.hmb");
    std::fs::create_dir(&sub).unwrap();
    assert_fails(&bake(&[s(&obj), "-o", s(&sub)]), "folder");
    let fifo = dir.path().join("pipe.hmb");
    mkfifo(&fifo);
    assert_fails(&bake(&[s(&obj), "-o", s(&fifo)]), "FIFO");
    // An output below a file is refused naming it; a missing folder is made only when the
    // run succeeds (`cli::output_folders_are_made_and_removed_on_failure`).
    let below_file = dir.path().join("m.obj/out.hmb");
    assert_fails(&bake(&[s(&obj), "-o", s(&below_file)]), "is not a folder");
    assert_eq!(std::fs::read(&obj).unwrap(), obj_bytes);
    assert_eq!(std::fs::read(&hmb).unwrap(), hmb_bytes);
    assert_eq!(std::fs::read(&style).unwrap(), style_bytes);
    // A character device such as /dev/null is written in place, not replaced.
    let o = Command::new(env!("CARGO_BIN_EXE_bake"))
        .args([s(&obj), "-o", "/dev/null"])
        .output()
        .unwrap();
    // bake wants an extension; render does not.
    assert_fails(&o, "extension");
    let o = render(&["--mesh", s(&hmb), "--size", "16x16", "-o", "/dev/null"]);
    assert!(
        o.status.success(),
        "render -o /dev/null: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let meta = std::fs::metadata("/dev/null").unwrap();
    assert!(std::os::unix::fs::FileTypeExt::is_char_device(
        &meta.file_type()
    ));
}

#[test]
fn a_stdout_that_cannot_be_written_is_an_error_not_a_panic() {
    let (dir, obj, _) = workspace();
    let out = dir.path().join("new.hmb");
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_bake"))
        .args([s(&obj), "-o", s(&out)])
        .stdout(full)
        .output()
        .unwrap();
    assert_fails(&o, "stdout");
    assert!(!out.exists(), "the report comes before the output file");
}

#[test]
fn absurd_arguments_are_refused_before_allocating() {
    let (dir, obj, _) = workspace();
    let out = dir.path().join("x.hmb");
    for (args, names) in [
        (vec!["--extrude", "18446744073709551615"], "--extrude"),
        (vec!["--extrude", "100000"], "--extrude"),
        (vec!["--extrude", "4", "--gravity", "nan"], "--gravity"),
        (vec!["--extrude", "4", "--step", "inf"], "--step"),
        (vec!["--extrude", "4", "--step=-1"], "--step"),
    ] {
        let mut a = vec![s(&obj), "-o", s(&out)];
        a.extend(args);
        assert_fails(&bake(&a), names);
        assert!(!out.exists());
    }
    let mesh = s(&obj);
    for (args, names) in [
        (
            vec!["cpu-generate", "--mesh", mesh, "--strands", "4000000000"],
            "--strands",
        ),
        (
            vec![
                "cpu-generate",
                "--mesh",
                mesh,
                "--strands",
                "10000000",
                "--verts-log2",
                "10",
            ],
            "--strands",
        ),
        (
            vec!["cpu-generate", "--mesh", mesh, "--runs", "1000000"],
            "--runs",
        ),
        (
            vec!["cpu-generate", "--mesh", mesh, "--verts-log2", "40"],
            "--verts-log2",
        ),
        (vec!["lod", "--mesh", mesh, "--width", "100000"], "--width"),
        (vec!["crowd", "--counts", "0"], "--counts"),
        (vec!["animate", "--counts", "0"], "--counts"),
        (vec!["animate", "--counts", "1,5000"], "--counts"),
        (vec!["animate", "--dynamics", "gpu,fpga"], "--dynamics"),
        (
            vec!["crowd", "--strands-per-bundle", "50000"],
            "--strands-per-bundle",
        ),
    ] {
        assert_fails(&bench(&args), names);
    }
    for (args, names) in [
        (
            vec!["--strands-per-bundle", "100000"],
            "--strands-per-bundle",
        ),
        (vec!["--verts-log2", "7"], "--verts-log2"),
        (vec!["--vertex-pool-mib", "0"], "--vertex-pool-mib"),
    ] {
        let mut a = vec!["--mesh", mesh, "-o", s(&out)];
        a.extend(args);
        assert_fails(&render(&a), names);
    }
    assert!(!out.exists());
}

#[test]
fn special_and_oversized_input_files_are_refused() {
    let (dir, _, _) = workspace();
    let out = dir.path().join("x.hmb");
    // A FIFO with no writer would block a reader forever.
    let fifo = dir.path().join("pipe.obj");
    mkfifo(&fifo);
    assert_fails(&bake(&[s(&fifo), "-o", s(&out)]), "not a regular file");
    assert_fails(
        &bake(&[dir.path().to_str().unwrap(), "-o", s(&out)]),
        "not a regular file",
    );
    // Style files are capped at 1 MiB.
    let obj = dir.path().join("m.obj");
    let big = dir.path().join("big.toml");
    std::fs::write(&big, vec![b'#'; 2 << 20]).unwrap();
    assert_fails(
        &bake(&[s(&obj), "--style", s(&big), "-o", s(&out)]),
        "limit",
    );
    assert!(!out.exists());
}

#[test]
fn degenerate_cameras_lights_and_scene_values_are_refused() {
    let (dir, obj, hmb) = workspace();
    let out = dir.path().join("x.png");
    let mesh = s(&hmb);
    for fov in ["0", "180", "nan", "inf", "-5"] {
        let flag = format!("--fov={fov}");
        assert_fails(&render(&["--mesh", mesh, &flag, "-o", s(&out)]), "--fov");
    }
    for cam in ["0,0,1:0,0,1", "nan,0,0:0,0,0", "0,0:0,0,1", "1,2,3,4:0,0,0"] {
        let flag = format!("--camera={cam}");
        assert_fails(&render(&["--mesh", mesh, &flag, "-o", s(&out)]), "--camera");
    }
    let scene = |body: &str| {
        let p = dir.path().join("scene.toml");
        std::fs::write(
            &p,
            format!("{body}\n[[character]]\nmesh = \"{}\"\n", obj.display()),
        )
        .unwrap();
        p
    };
    for (body, names) in [
        ("[light]\ndirection = [0.0, 0.0, 0.0]", "[light]"),
        ("[light]\ndirection = [nan, 0.0, 1.0]", "[light]"),
        ("size = [64, 64, 64]", "exactly 2"),
        ("size = [0, 64]", "size"),
        (
            "[camera]\neye = [0.0, 0.0, 1.0]\ntarget = [0.0, 0.0, 1.0]",
            "[camera]",
        ),
        (
            "[camera]\neye = [0.0, 0.0, 1.0]\ntarget = [0.0, 0.0, 0.0]\nfov_y_degrees = 180.0",
            "[camera]",
        ),
    ] {
        let p = scene(body);
        assert_fails(&render(&["--scene", s(&p), "-o", s(&out)]), names);
    }
    // A colour with four components is an error, not a dropped value.
    let style = dir.path().join("four.toml");
    std::fs::write(&style, "color = [0.1, 0.2, 0.3, 0.4]\n").unwrap();
    let hmb_out = dir.path().join("y.hmb");
    assert_fails(
        &bake(&[s(&obj), "--style", s(&style), "-o", s(&hmb_out)]),
        "exactly 3",
    );
    assert!(!out.exists() && !hmb_out.exists());
}

#[test]
fn obj_layer_groups_and_coordinates_are_strict() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.hmb");
    let quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
                vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";
    let faces = "f 1/1 2/2 3/3 4/4\n";
    let upper = "f 5/1 6/2 7/3 8/4\n";
    for (name, text, names) in [
        (
            "leading_zero.obj",
            format!("{quad}g layer0\n{faces}g layer01\n{upper}"),
            "layer01",
        ),
        (
            "outside.obj",
            format!("{quad}{faces}g layer0\n{faces}g layer1\n{upper}"),
            "outside any layer group",
        ),
        (
            "huge.obj",
            format!("v 1e25 0 0\n{quad}g layer0\n{faces}g layer1\n{upper}"),
            "out of range",
        ),
    ] {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        assert_fails(&bake(&[s(&p), "-o", s(&out)]), names);
        assert!(!out.exists());
    }
}

#[test]
fn messages_name_the_argument_and_say_things_once() {
    let (dir, _, hmb) = workspace();
    let out = dir.path().join("x.png");
    assert_fails(
        &render(&["--mesh", s(&hmb), "--size", "10x10x10", "-o", s(&out)]),
        "--size",
    );
    let missing = dir.path().join("missing.obj");
    let o = bake(&[s(&missing), "-o", s(&dir.path().join("y.hmb"))]);
    assert_fails(&o, "missing.obj");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(
        err.matches("No such file").count(),
        1,
        "the OS message once: {err}"
    );
}

/// The small patch as real exporters write it: a byte-order mark, CRLF line ends, tabs,
/// comments, `o` / `s` / `usemtl` / `mtllib`, a group line naming two groups, free-form
/// attribute statements (on which obj-rs 0.7 panics) and negative (relative) indices.
fn exported_like_a_tool(original: &str) -> String {
    let mut out = String::from("\u{feff}# exported by a tool\r\nmtllib patch.mtl\r\no Patch\r\n");
    out.push_str("g hair scalp\r\ncstype bezier\r\ndeg 3\r\nbmat u 1 0 0 0\r\nstep 1\r\n");
    out.push_str("ctech cparm 1.0\r\nstech cparm 1.0 1.0\r\nlod 1\r\nbevel off\r\n");
    out.push_str("c_interp off\r\nd_interp off\r\nshadow_obj a.obj\r\ntrace_obj a.obj\r\n");
    let (mut v, mut vt) = (0i64, 0i64);
    for line in original.lines() {
        let mut tok = line.split_whitespace();
        match tok.next() {
            Some("v") => v += 1,
            Some("vt") => vt += 1,
            Some("f") => {
                // Relative indices: -1 is the latest vertex defined so far.
                let corners: Vec<String> = tok
                    .map(|c| {
                        let mut parts = c.split('/');
                        let p: i64 = parts.next().unwrap().parse().unwrap();
                        match parts.next() {
                            Some(t) if !t.is_empty() => {
                                let t: i64 = t.parse().unwrap();
                                format!("{}/{}", p - v - 1, t - vt - 1)
                            }
                            _ => format!("{}", p - v - 1),
                        }
                    })
                    .collect();
                out.push_str(&format!("f\t{}\t# a face\r\n", corners.join("\t")));
                continue;
            }
            Some(g) if g == "g" && line.contains("layer0") => {
                out.push_str(&format!("{line}\r\ns 1\r\nusemtl skin\r\n"));
                continue;
            }
            _ => {}
        }
        out.push_str(&line.replace(' ', "\t"));
        out.push_str("\r\n");
    }
    out
}

#[test]
fn obj_files_real_exporters_write_are_accepted() {
    use hairmesh::model::obj_io::load_hair_mesh_obj;
    let dir = tempfile::tempdir().unwrap();
    let original = root().join("hairmeshes/small_patch.obj");
    let text = std::fs::read_to_string(&original).unwrap();
    let exported = dir.path().join("exported.obj");
    std::fs::write(&exported, exported_like_a_tool(&text)).unwrap();
    let a = load_hair_mesh_obj(&original).unwrap();
    let b = load_hair_mesh_obj(&exported).unwrap();
    assert_eq!(a.layers, b.layers);
    assert_eq!(a.uv, b.uv);
    assert_eq!(a.faces, b.faces);
    let out = dir.path().join("exported.hmb");
    let o = bake(&[s(&exported), "-o", s(&out)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // Free-form geometry carries shape a hair mesh cannot hold: refused, its line named.
    for (stmt, what) in [
        ("curv 0 1 1 2", "free-form curve"),
        ("surf 0 1 0 1 1 2 3 4", "free-form surface"),
    ] {
        let p = dir.path().join("curve.obj");
        std::fs::write(&p, format!("{text}{stmt}\n")).unwrap();
        let lines = text.lines().count() + 1;
        let out = dir.path().join("curve.hmb");
        let o = bake(&[s(&p), "-o", s(&out)]);
        assert_fails(&o, what);
        assert_fails(&o, &format!("line {lines}"));
        assert!(!out.exists());
    }
    // Unknown statements are named with their line, not reported by the parser's wording.
    let p = dir.path().join("unknown.obj");
    std::fs::write(&p, format!("{text}frobnicate 1 2\n")).unwrap();
    assert_fails(
        &bake(&[s(&p), "-o", s(&dir.path().join("u.hmb"))]),
        "'frobnicate'",
    );
}

/// Every file a run reads is an input, also those it finds on its own, and no two outputs of
/// a run may be the same file: refused before any work, nothing changed.
#[test]
fn inputs_found_beside_meshes_and_colliding_outputs_are_not_overwritten() {
    let (dir, obj, _) = workspace();
    let style = dir.path().join("m.toml");
    let before = std::fs::read(&style).unwrap();
    // export reads the style beside the mesh.
    let o = run(
        env!("CARGO_BIN_EXE_export"),
        &["--mesh", s(&obj), "-o", s(&style)],
    );
    assert_fails(&o, "m.toml");
    // render reads the files a scene names (and the style beside its mesh).
    let scene = dir.path().join("s.toml");
    std::fs::write(&scene, "[[character]]\nmesh = \"m.obj\"\n").unwrap();
    assert_fails(&render(&["--scene", s(&scene), "-o", s(&style)]), "m.toml");
    assert_fails(&render(&["--scene", s(&scene), "-o", s(&obj)]), "m.obj");
    assert_eq!(std::fs::read(&style).unwrap(), before);
    // fit: the picture may not be the mesh or its style (the check comes before any work).
    let tfx = root().join("hairmeshes/sintel_hair.tfx");
    let out = dir.path().join("out.obj");
    for picture in ["out.obj", "out.toml"] {
        let p = dir.path().join(picture);
        let o = run(
            env!("CARGO_BIN_EXE_fit"),
            &[s(&tfx), "-o", s(&out), "--report", "--picture", s(&p)],
        );
        assert_fails(&o, "--picture");
        assert!(!out.exists() && !p.exists());
    }
}

/// Every tool parses its arguments: `--help` and `--version` answer and create nothing; a
/// folder that does not exist is refused.
#[test]
fn every_tool_answers_help_and_version() {
    let dir = tempfile::tempdir().unwrap();
    for bin in [
        env!("CARGO_BIN_EXE_bake"),
        env!("CARGO_BIN_EXE_render"),
        env!("CARGO_BIN_EXE_crowd"),
        env!("CARGO_BIN_EXE_bench"),
        env!("CARGO_BIN_EXE_export"),
        env!("CARGO_BIN_EXE_fit"),
        env!("CARGO_BIN_EXE_make-hairmeshes"),
    ] {
        for flag in ["--help", "--version"] {
            let o = Command::new(bin)
                .arg(flag)
                .current_dir(dir.path())
                .output()
                .unwrap();
            assert!(o.status.success(), "{bin} {flag}");
            assert!(!o.stdout.is_empty(), "{bin} {flag}: nothing printed");
        }
    }
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "files created"
    );
}

/// crowd checks every frame's path before the first frame, and its flags before any work.
#[test]
fn crowd_outputs_are_checked_before_the_first_frame() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("frames");
    std::fs::create_dir(&out).unwrap();
    std::fs::create_dir(out.join("frame_00001.png")).unwrap();
    let crowd = |extra: &[&str]| {
        let mut args = vec!["--headless", "--frames", "2", "--size", "16x16"];
        args.extend_from_slice(extra);
        run(env!("CARGO_BIN_EXE_crowd"), &args)
    };
    assert_fails(
        &crowd(&["--count", "1", "--out", s(&out)]),
        "frame_00001.png",
    );
    assert_eq!(
        std::fs::read_dir(&out).unwrap().count(),
        1,
        "a frame was written"
    );
    let new = dir.path().join("new");
    assert_fails(&crowd(&["--out", s(&new), "--count", "5000"]), "--count");
    let soft_msaa = [
        "--count",
        "1",
        "--out",
        s(&new),
        "--draw",
        "soft",
        "--msaa",
        "4",
    ];
    assert_fails(&crowd(&soft_msaa), "--msaa 4");
    for band in ["50,10", "nan,5", "5", "-1,4"] {
        let flag = format!("--volume-band={band}");
        let args = ["--count", "1", "--out", s(&new), flag.as_str()];
        assert_fails(&crowd(&args), "--volume-band");
    }
    assert!(!new.exists());
    std::fs::write(dir.path().join("file"), b"x").unwrap();
    assert_fails(
        &crowd(&["--count", "1", "--out", s(&dir.path().join("file/sub"))]),
        "is not a folder",
    );
}

#[path = "robustness/cli.rs"]
mod cli;

/// What one tool writes, the next reads: `fit` refuses a model whose hair mesh `bake` could
/// not read back (coordinates past the OBJ limit), naming the input, and writes nothing.
#[test]
fn fit_refuses_what_bake_would_refuse() {
    let (dir, obj, _) = workspace();
    let hair = dir.path().join("few.hair");
    let o = run(
        env!("CARGO_BIN_EXE_export"),
        &[
            "--mesh",
            s(&obj),
            "--strands-per-bundle",
            "1",
            "-o",
            s(&hair),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // Scale every point by 1e8 (header: hairs, points, arrays at bytes 4..16; segments first).
    let mut b = std::fs::read(&hair).unwrap();
    let word = |i: usize| u32::from_le_bytes(b[i..i + 4].try_into().unwrap()) as usize;
    let (hairs, points, arrays) = (word(4), word(8), word(12));
    let start = 128 + if arrays & 1 != 0 { 2 * hairs } else { 0 };
    for k in 0..3 * points {
        let at = start + 4 * k;
        let v = f32::from_le_bytes(b[at..at + 4].try_into().unwrap()) * 1e8;
        b[at..at + 4].copy_from_slice(&v.to_le_bytes());
    }
    let huge = dir.path().join("huge.hair");
    std::fs::write(&huge, &b).unwrap();
    let out = dir.path().join("huge.obj");
    assert_fails(
        &run(env!("CARGO_BIN_EXE_fit"), &[s(&huge), "-o", s(&out)]),
        "huge.hair",
    );
    assert!(!out.exists());
}

/// A flat `n x n` grid OBJ with uv: a scalp (`layers` 1) or a hair mesh of `layers` groups
/// `layer0..`, each 1 cm above the last.
fn grid_obj(path: &Path, n: usize, layers: usize) {
    use std::fmt::Write as _;
    let mut t = String::new();
    for l in 0..layers {
        for j in 0..n {
            for i in 0..n {
                writeln!(
                    t,
                    "v {} {} {}",
                    i as f32 * 0.01,
                    l as f32 * 0.01,
                    j as f32 * 0.01
                )
                .unwrap();
            }
        }
    }
    for j in 0..n {
        for i in 0..n {
            writeln!(
                t,
                "vt {} {}",
                i as f32 / (n - 1) as f32,
                j as f32 / (n - 1) as f32
            )
            .unwrap();
        }
    }
    for l in 0..layers {
        if layers > 1 {
            writeln!(t, "g layer{l}").unwrap();
        }
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let a = j * n + i + 1;
                let c = [a, a + n, a + n + 1, a + 1];
                let v = c.map(|k| k + l * n * n);
                let [(v0, t0), (v1, t1), (v2, t2), (v3, t3)] = [0, 1, 2, 3].map(|k| (v[k], c[k]));
                writeln!(t, "f {v0}/{t0} {v1}/{t1} {v2}/{t2} {v3}/{t3}").unwrap();
            }
        }
    }
    std::fs::write(path, t).unwrap();
}

#[test]
fn work_past_the_memory_budget_is_refused_before_it_starts() {
    let (dir, _, _) = workspace();
    let scalp = dir.path().join("scalp.obj");
    grid_obj(&scalp, 100, 1);
    let out = dir.path().join("big.hmb");
    // 10,000 scalp vertices x 128 layers: about 0.3 GiB, over a 256 MiB budget.
    let o = bake(&[
        s(&scalp),
        "--extrude",
        "128",
        "--memory-budget-mib",
        "256",
        "-o",
        s(&out),
    ]);
    assert_fails(&o, "--extrude 128");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("--memory-budget-mib") && err.contains("256.0 MiB"),
        "{err}"
    );
    assert!(!out.exists());
    // The same scalp with few layers fits the same budget.
    let o = bake(&[
        s(&scalp),
        "--extrude",
        "4",
        "--memory-budget-mib",
        "256",
        "-o",
        s(&out),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // A hair mesh OBJ (no --extrude) is estimated by the bake itself, after the layout.
    let tight = dir.path().join("tight.hmb");
    let mesh = dir.path().join("mesh.obj");
    grid_obj(&mesh, 60, 64);
    assert_fails(
        &bake(&[s(&mesh), "--memory-budget-mib", "100", "-o", s(&tight)]),
        "--memory-budget-mib",
    );
    assert!(!tight.exists());
    // fit, render and crowd: each refuses naming the flag that sizes the work. 100K strands
    // (51 MiB .hair) into 65,536 bundles: about 0.75 GiB estimated (252 MB measured).
    let hair = dir.path().join("many.hair");
    let o = run(
        env!("CARGO_BIN_EXE_export"),
        &[
            "--mesh",
            s(&root().join("hairmeshes/small_patch.obj")),
            "--strands-per-bundle",
            "4096",
            "-o",
            s(&hair),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let fit_out = dir.path().join("fit.obj");
    assert_fails(
        &run(
            env!("CARGO_BIN_EXE_fit"),
            &[
                s(&hair),
                "--bundles",
                "65536",
                "--memory-budget-mib",
                "256",
                "-o",
                s(&fit_out),
            ],
        ),
        "lower --bundles",
    );
    assert!(!fit_out.exists() && !fit_out.with_extension("toml").exists());
    let png = dir.path().join("x.png");
    assert_fails(
        &render(&[
            "--mesh",
            s(&out),
            "--size",
            "8192x8192",
            "--memory-budget-mib",
            "500",
            "-o",
            s(&png),
        ]),
        "smaller --size",
    );
    assert!(!png.exists());
    let frames = dir.path().join("frames");
    assert_fails(
        &run(
            env!("CARGO_BIN_EXE_crowd"),
            &[
                "--headless",
                "--count",
                "4096",
                "--size",
                "8192x8192",
                "--memory-budget-mib",
                "1000",
                "--out",
                s(&frames),
            ],
        ),
        "lower --count or --size",
    );
    assert!(!frames.exists());
    for bin in [env!("CARGO_BIN_EXE_bake"), env!("CARGO_BIN_EXE_crowd")] {
        assert_fails(
            &run(bin, &["--memory-budget-mib", "0"]),
            "--memory-budget-mib",
        );
    }
}
