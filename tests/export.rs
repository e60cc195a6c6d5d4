//! `export`: the `.hair` file holds exactly the strands of the CPU reference generator (the
//! strands the GPU generates with LoD off) and reads back through the loader; bad requests are
//! one-line errors with no file written.

use std::process::Command;

use hairmesh::CpuGenerator;
use hairmesh::model::hair_file::HairFile;
use hairmesh::render::scene::load_mesh;

#[test]
fn export_round_trips_the_reference_strands() {
    let dir = tempfile::tempdir().unwrap();
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("hairmeshes");
    for name in ["head_long", "sphere_fur"] {
        let mesh = root.join(format!("{name}.obj"));
        let out = dir.path().join(format!("{name}.hair"));
        let o = Command::new(env!("CARGO_BIN_EXE_export"))
            .args(["--strands-per-bundle", "16", "--verts-log2", "4", "--mesh"])
            .arg(&mesh)
            .arg("-o")
            .arg(&out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let hair = HairFile::load(&out).unwrap();
        let (baked, style) = load_mesh(&mesh, None, Default::default()).unwrap();
        let set = CpuGenerator::new(&baked, style).generate(16, 4);
        assert_eq!(hair.hair_count as usize, set.strand_count());
        assert_eq!(hair.default_segments, 16);
        assert!(hair.segments.is_none());
        let points: Vec<[f32; 3]> = set.positions.iter().map(|p| p.to_array()).collect();
        assert!(hair.points == points, "{name}: points differ");
        assert_eq!(hair.thickness.as_deref(), Some(&set.widths[..]));
        assert_eq!(hair.default_color, style.color);
        assert_eq!(hair.to_bytes(), std::fs::read(&out).unwrap());
    }
    // The output may not be the input, and absurd counts are refused before any work.
    let mesh = root.join("head_long.obj");
    for (args, what) in [
        (vec!["-o", mesh.to_str().unwrap()], "input"),
        (vec!["--verts-log2", "9", "-o", "x.hair"], "verts-log2"),
    ] {
        let o = Command::new(env!("CARGO_BIN_EXE_export"))
            .current_dir(dir.path())
            .arg("--mesh")
            .arg(&mesh)
            .args(&args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(what), "{err}");
        assert!(err.lines().count() <= 3, "{err}");
        assert!(!dir.path().join("x.hair").exists());
    }
}
