//! Hostile inputs, round 4 (issue 46), through the real binaries: the parser's own errors,
//! flags without effect, lists checked whole, refusals in the user's terms, output folders
//! made and removed, interrupted runs and two runs writing the same outputs.

use std::path::Path;
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use super::{assert_fails, bench, run, s, workspace};

fn crowd(args: &[&str]) -> Output {
    run(env!("CARGO_BIN_EXE_crowd"), args)
}

/// Failed before any work: one line (see `assert_fails`) and nothing on stdout (every tool
/// prints its device or its first result line once work starts).
#[track_caller]
fn refused_before_work(o: &Output, names: &str) {
    assert_fails(o, names);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
    assert!(!err.contains("Usage"), "a usage block: {err}");
    assert!(
        o.stdout.is_empty(),
        "work started: {}",
        String::from_utf8_lossy(&o.stdout)
    );
}

/// clap's own errors are one line naming the flag; `-5` is a value, refused by its range.
#[test]
fn parser_errors_are_one_line_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.png");
    let budget = ["--memory-budget-mib", "-5"];
    let o = run(
        env!("CARGO_BIN_EXE_bake"),
        &[&["x.obj", "-o", s(&out)], &budget[..]].concat(),
    );
    refused_before_work(&o, "--memory-budget-mib");
    assert!(String::from_utf8_lossy(&o.stderr).contains("'-5'"));
    refused_before_work(&crowd(&["--headless", "--count", "-5"]), "--count");
    refused_before_work(&crowd(&["--headless", "--wind", "-1"]), "--wind");
    refused_before_work(
        &crowd(&["--headless", "--lod-alpha-strands", "NaN"]),
        "--lod-alpha-strands",
    );
    // A missing required flag, an unknown one (with clap's suggestion), a bad choice (with the
    // possible values), a missing value, a missing subcommand.
    refused_before_work(&run(env!("CARGO_BIN_EXE_bake"), &["x.obj"]), "--output");
    let o = crowd(&["--headles"]);
    refused_before_work(&o, "--headles");
    assert!(String::from_utf8_lossy(&o.stderr).contains("did you mean '--headless'"));
    let o = crowd(&["--view", "top"]);
    refused_before_work(&o, "--view");
    assert!(String::from_utf8_lossy(&o.stderr).contains("orbit, eye, front, side, back"));
    refused_before_work(&crowd(&["--count"]), "--count");
    refused_before_work(&bench(&[]), "subcommand");
    for o in [
        &crowd(&["--count", "x"]),
        &bench(&["fuzz", "--iterations", "0"]),
    ] {
        assert_eq!(o.status.code(), Some(2), "parser errors exit 2");
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

/// A flag whose feature another flag turns off is refused, naming both, before any work.
#[test]
fn flags_without_effect_are_refused() {
    let (dir, obj, _) = workspace();
    let out = dir.path().join("frames");
    let png = dir.path().join("o.png");
    let crowd_cases: [(&[&str], &str); 9] = [
        (
            &["--volumes", "off", "--volume-band", "64,40"],
            "--volume-band",
        ),
        (&["--animate", "off", "--wind", "5"], "--wind"),
        (&["--wind-dir", "0,0,1"], "--wind-dir"),
        (&["--present-mode", "mailbox"], "--present-mode"),
        (
            &["--shadows", "off", "--shadow-draw", "soft"],
            "--shadow-draw",
        ),
        (
            &["--shading", "kajiya-kay", "--multiple-scattering", "on"],
            "--multiple-scattering",
        ),
        (
            &["--lod", "off", "--lod-appearance", "false"],
            "--lod-appearance",
        ),
        (&["--preset", "teapots", "--family", "bob"], "--family"),
        (
            &["--lod", "off", "--lod-alpha-verts", "0.2"],
            "--lod-alpha-verts",
        ),
    ];
    for (extra, flag) in crowd_cases {
        let args = [&["--headless", "--count", "1", "--out", s(&out)], extra].concat();
        let o = crowd(&args);
        refused_before_work(&o, flag);
        assert!(String::from_utf8_lossy(&o.stderr).contains("has no effect"));
    }
    refused_before_work(&crowd(&["--frames", "5"]), "--headless");
    let render = |extra: &[&str]| {
        let args = [&["--mesh", s(&obj), "-o", s(&png)], extra].concat();
        run(env!("CARGO_BIN_EXE_render"), &args)
    };
    refused_before_work(
        &render(&["--lod", "off", "--lod-lambda", "0.3"]),
        "--lod-lambda",
    );
    refused_before_work(
        &render(&["--shading", "placeholder", "--multiple-scattering", "true"]),
        "--multiple-scattering",
    );
    let hmb = dir.path().join("o.hmb");
    let bake = |extra: &[&str]| {
        let args = [&[s(&obj), "-o", s(&hmb)], extra].concat();
        run(env!("CARGO_BIN_EXE_bake"), &args)
    };
    refused_before_work(&bake(&["--step", "0.1"]), "--step");
    let fit = run(
        env!("CARGO_BIN_EXE_fit"),
        &["x.hair", "-o", s(&dir.path().join("f.obj")), "--validation"],
    );
    refused_before_work(&fit, "--validation");
    refused_before_work(
        &bench(&["crowd", "--compare-defaults", "--draw", "soft"]),
        "--draw",
    );
    assert!(!out.exists() && !png.exists());
}

/// A bad item anywhere in a list is refused before the first item runs.
#[test]
fn lists_are_checked_whole_before_work() {
    let cases: [(&[&str], &str); 5] = [
        (
            &["temporal", "--scenarios", "orbit,dolly,sideways"],
            "sideways",
        ),
        (&["raster", "--draws", "soft,fast"], "fast"),
        (&["raster", "--scenes", "head near,tail"], "--scenes tail"),
        (&["paper", "--scenario", "everything"], "everything"),
        // A prefix chooses whole words: "people 10" is not "people 100".
        (
            &[
                "compare",
                "--against",
                "HEAD",
                "--rows",
                "people 100,people 10",
            ],
            "people 10",
        ),
    ];
    for (args, names) in cases {
        refused_before_work(&bench(args), names);
    }
}

/// A frame no device buffer can hold is refused naming the flags a user changes.
#[test]
fn refusals_name_flags_not_buffers() {
    let (dir, obj, _) = workspace();
    let png = dir.path().join("big.png");
    let args = [
        "--mesh",
        s(&obj),
        "--size",
        "8192x8192",
        "--transparency",
        "oit:8",
        "-o",
        s(&png),
    ];
    let o = run(env!("CARGO_BIN_EXE_render"), &args);
    assert_fails(&o, "--size 8192x8192");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("--transparency oit:K"), "{err}");
    assert!(
        !err.contains("maxStorageBufferRange") && !err.contains("oit nodes"),
        "{err}"
    );
    assert!(!png.exists());
    // The window's crowd too: the device's limits are checked before the crowd is built or a
    // window opened (no display is needed to be refused).
    refused_before_work(&crowd(&["--msaa", "64", "--count", "1"]), "--msaa 64");
}

/// Folders above an output are made as `mkdir -p` would, and removed again when the run fails.
#[test]
fn output_folders_are_made_and_removed_on_failure() {
    let (dir, obj, _) = workspace();
    let deep = dir.path().join("a/b/c.hmb");
    let o = run(env!("CARGO_BIN_EXE_bake"), &[s(&obj), "-o", s(&deep)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(deep.is_file());
    // A failing run (an unreadable input found only while working) leaves no folder.
    let bad = dir.path().join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nv 0 1 0\ng layer0\nf 1 2 3\n").unwrap();
    let o = run(
        env!("CARGO_BIN_EXE_bake"),
        &[s(&bad), "-o", s(&dir.path().join("x/y.hmb"))],
    );
    assert_fails(&o, "bad.obj");
    assert!(!dir.path().join("x").exists());
    let samples = dir.path().join("made/samples");
    let o = run(env!("CARGO_BIN_EXE_make-hairmeshes"), &[s(&samples)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(samples.join("small_patch.obj").is_file());
    let o = run(
        env!("CARGO_BIN_EXE_make-hairmeshes"),
        &[s(&dir.path().join("z/w")), "--head", s(&bad)],
    );
    assert_fails(&o, "bad.obj");
    assert!(!dir.path().join("z").exists());
}

/// Start `bin` with `args` (and `env`), stdout and stderr piped.
fn spawn(bin: &str, args: &[&str], env: &[(&str, &str)]) -> Child {
    Command::new(bin)
        .args(args)
        .envs(env.iter().copied())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Wait (at most `secs`) until `ready` holds.
#[track_caller]
fn wait_for(secs: u64, what: &str, ready: impl Fn() -> bool) {
    let start = Instant::now();
    while !ready() {
        assert!(
            start.elapsed() < Duration::from_secs(secs),
            "waited {secs} s for {what}"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
}

fn signal(child: &Child, name: &str) {
    let pid = child.id().to_string();
    assert!(
        Command::new("kill")
            .args([name, &pid])
            .status()
            .unwrap()
            .success()
    );
}

/// Entries of `dir` whose names contain `part`.
fn entries_with(dir: &Path, part: &str) -> Vec<String> {
    std::fs::read_dir(dir)
        .map(|r| {
            r.filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.contains(part))
                .collect()
        })
        .unwrap_or_default()
}

/// SIGINT or SIGTERM while `crowd --headless` has frames staged: the staging folder and the
/// folders made for `--out` are removed, an existing `--out` is left as it was, exit 128 + N.
#[test]
fn an_interrupted_crowd_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let existing = dir.path().join("existing");
    std::fs::create_dir(&existing).unwrap();
    std::fs::write(existing.join("frame_00000.png"), b"before").unwrap();
    for (out, sig, code) in [
        (dir.path().join("new/deeper"), "-INT", 130),
        (existing.clone(), "-TERM", 143),
    ] {
        let args = [
            "--headless",
            "--frames",
            "1000",
            "--count",
            "1",
            "--size",
            "32x32",
        ];
        let args = [&args[..], &["--out", s(&out)]].concat();
        let child = spawn(env!("CARGO_BIN_EXE_crowd"), &args, &[]);
        let parent = out.parent().unwrap().to_path_buf();
        let staged_frame = || {
            entries_with(&parent, ".partial")
                .iter()
                .any(|p| !entries_with(&parent.join(p), "frame_").is_empty())
        };
        wait_for(300, "a staged frame", staged_frame);
        signal(&child, sig);
        let o = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(code), "{err}");
        assert!(err.contains("interrupted"), "{err}");
        assert!(
            entries_with(&parent, ".partial").is_empty(),
            "staging left behind"
        );
    }
    assert!(
        !dir.path().join("new").exists(),
        "a folder made for --out was left"
    );
    assert_eq!(
        std::fs::read(existing.join("frame_00000.png")).unwrap(),
        b"before"
    );
    assert_eq!(std::fs::read_dir(&existing).unwrap().count(), 1);
}

/// The OBJ and style a `fit` run writes.
type FitOutputs = (Vec<u8>, Vec<u8>);

/// A `.hair` model of the small patch, and the outputs `fit --bundles N` makes of it
/// (reference copies written elsewhere).
fn fit_inputs(dir: &Path) -> (std::path::PathBuf, [FitOutputs; 2]) {
    let obj = dir.join("m.obj");
    let hair = dir.join("few.hair");
    let o = run(
        env!("CARGO_BIN_EXE_export"),
        &[
            "--mesh",
            s(&obj),
            "--strands-per-bundle",
            "4",
            "-o",
            s(&hair),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let reference = |bundles: &str| {
        let out = dir.join(format!("ref{bundles}.obj"));
        let args = [s(&hair), "-o", s(&out), "--bundles", bundles];
        let o = run(env!("CARGO_BIN_EXE_fit"), &args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        (
            std::fs::read(&out).unwrap(),
            std::fs::read(out.with_extension("toml")).unwrap(),
        )
    };
    let refs = [reference("4"), reference("9")];
    assert_ne!(
        refs[0], refs[1],
        "the two fits must differ to tell them apart"
    );
    (hair, refs)
}

/// Two `fit` runs writing the same `-o`: the second's publish waits for the first's (the
/// first pauses between its two renames), so the OBJ and its style are from one run.
/// A signal during a publish lets it finish: the outputs are the run's, whole.
#[test]
fn concurrent_and_interrupted_publishes_never_mix_runs() {
    let (dir, _, _) = workspace();
    let (hair, refs) = fit_inputs(dir.path());
    let out = dir.path().join("out.obj");
    let style = out.with_extension("toml");
    let fit = |bundles: &str, pause: &str| {
        let args = [s(&hair), "-o", s(&out), "--bundles", bundles];
        spawn(
            env!("CARGO_BIN_EXE_fit"),
            &args,
            &[("HAIRMESH_TEST_PUBLISH_PAUSE_MS", pause)],
        )
    };
    // A's OBJ is in place and its style still staged: A is inside its publish.
    let in_publish = || out.exists() && !entries_with(dir.path(), "out.toml.tmp").is_empty();
    let a = fit("4", "6000");
    wait_for(60, "the first fit's publish", in_publish);
    let b = fit("9", "0").wait_with_output().unwrap();
    assert!(b.status.success(), "{}", String::from_utf8_lossy(&b.stderr));
    assert!(a.wait_with_output().unwrap().status.success());
    let now = (std::fs::read(&out).unwrap(), std::fs::read(&style).unwrap());
    assert!(
        now == refs[1],
        "the outputs mix two runs (or are not the last run's)"
    );
    // SIGTERM inside a publish: it completes, then the run exits.
    std::fs::remove_file(&out).unwrap();
    std::fs::remove_file(&style).unwrap();
    let a = fit("4", "3000");
    wait_for(60, "the fit's publish", in_publish);
    signal(&a, "-TERM");
    // 143 when the signal's cleanup ran; 0 when the run ended first, right after its publish.
    let o = a.wait_with_output().unwrap();
    let code = o.status.code();
    assert!(
        matches!(code, Some(0 | 143)),
        "{code:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let now = (std::fs::read(&out).unwrap(), std::fs::read(&style).unwrap());
    assert!(now == refs[0], "an interrupted publish left a mix");
    assert!(
        entries_with(dir.path(), ".tmp").is_empty(),
        "staged files left"
    );
}
