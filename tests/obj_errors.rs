//! Every validation error of the OBJ loader: one line naming the file, the location and cause.

use hairmesh::model::obj_io::load_hair_mesh_obj;

const LAYER0: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";
const LAYER1: &str = "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n";

fn load(text: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.obj");
    std::fs::write(&path, text).unwrap();
    let e = load_hair_mesh_obj(&path).unwrap_err().to_string();
    assert!(e.contains("bad.obj: "), "error must name the file: {e}");
    assert!(!e.contains('\n'), "one line: {e}");
    e
}

fn ok_text() -> String {
    format!("{LAYER0}{LAYER1}g layer0\nf 1/1 2/2 3/3 4/4\ng layer1\nf 5/1 6/2 7/3 8/4\n")
}

#[test]
fn well_formed_loads() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ok.obj");
    std::fs::write(&path, ok_text()).unwrap();
    let m = load_hair_mesh_obj(&path).unwrap();
    assert_eq!(
        (m.layer_count(), m.faces.len(), m.vertices_per_layer()),
        (2, 1, 4)
    );
    assert_eq!(m.w[1][0], 1.0, "w generated from path length");
}

#[test]
fn explicit_w_from_vt() {
    let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
        vt 0 0 0\nvt 1 0 0\nvt 1 1 0\nvt 0 1 0\nvt 0 0 7\nvt 1 0 7\nvt 1 1 7\nvt 0 1 7\n\
        g layer0\nf 1/1 2/2 3/3 4/4\ng layer1\nf 5/5 6/6 7/7 8/8\n";
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("w.obj");
    std::fs::write(&path, text).unwrap();
    assert_eq!(load_hair_mesh_obj(&path).unwrap().w[1][2], 7.0);
}

#[test]
fn layer_face_count_mismatch() {
    let e = load(&format!(
        "{LAYER0}{LAYER1}g layer0\nf 1/1 2/2 3/3 4/4\nf 1/1 3/3 4/4\ng layer1\nf 5/1 6/2 7/3 8/4\n"
    ));
    assert!(e.contains("layer1 has 1 faces but layer0 has 2"), "{e}");
}

#[test]
fn single_layer_and_gaps_and_no_groups() {
    assert!(load(&format!("{LAYER0}g layer0\nf 1/1 2/2 3/3 4/4\n")).contains("at least 2 layers"));
    let gap = load(&format!(
        "{LAYER0}{LAYER1}g layer0\nf 1/1 2/2 3/3 4/4\ng layer2\nf 5/1 6/2 7/3 8/4\n"
    ));
    assert!(gap.contains("layer1 is missing"), "{gap}");
    assert!(load(&format!("{LAYER0}f 1/1 2/2 3/3 4/4\n")).contains("no layer groups"));
}

#[test]
fn non_finite_coordinates() {
    let e = load(&ok_text().replace("v 1 1 1", "v 1 nan 1"));
    assert!(
        e.contains("line 11") && e.contains("not a finite number"),
        "{e}"
    );
    let e = load(&ok_text().replace("v 1 0 0", "v 1 inf 0"));
    assert!(e.contains("line 2"), "{e}");
}

#[test]
fn degenerate_face() {
    let e = load(
        &ok_text()
            .replace("v 1 1 0\n", "v 1 0 0\n")
            .replace("v 0 1 0\n", "v 0 0 0\n"),
    );
    assert!(e.contains("face 0: degenerate"), "{e}");
    let e = load(
        &ok_text()
            .replace("f 1/1 2/2 3/3 4/4", "f 1/1 2/2 2/2 4/4")
            .replace("f 5/1 6/2 7/3 8/4", "f 5/1 6/2 6/2 8/4"),
    );
    assert!(e.contains("degenerate"), "{e}");
}

#[test]
fn zero_area_uv() {
    let e = load(&ok_text().replace("vt 1 1\nvt 0 1", "vt 2 0\nvt 3 0"));
    assert!(e.contains("zero-area uv triangle"), "{e}");
}

#[test]
fn inconsistent_layer_topology() {
    let text = format!(
        "{LAYER0}v 2 0 0\nv 2 1 0\nvt 2 0\nvt 2 1\n{LAYER1}v 2 0 1\nv 2 1 1\nv 9 9 9\n\
         g layer0\nf 1/1 2/2 3/3 4/4\nf 2/2 5/5 6/6 3/3\n\
         g layer1\nf 7/1 8/2 9/3 10/4\nf 13/2 11/5 12/6 9/3\n"
    );
    let e = load(&text);
    assert!(e.contains("inconsistent layer topology"), "{e}");
    let e = load(&ok_text().replace("f 5/1 6/2 7/3 8/4", "f 5/1 6/2 7/3"));
    assert!(e.contains("has 3 corners"), "{e}");
}

#[test]
fn empty_truncated_and_garbage() {
    assert!(load("").contains("empty"));
    assert!(load("# nothing\n").contains("empty"));
    // Truncated mid-file: face refers to vertices that were cut off.
    let text = ok_text();
    let e = load(&text[..text.len() - 30]);
    assert!(!e.is_empty());
    assert!(load("v 1 2\n").contains("malformed OBJ"));
    let e = load(&format!("{}curv 0 1 1 2\n", ok_text()));
    assert!(e.contains("free-form curve") && e.contains("line "), "{e}");
    assert!(load(&ok_text().replace("f 1/1 2/2 3/3 4/4", "f 1 2 3 4")).contains("no vt"));
    assert!(
        load(&ok_text().replace("f 1/1 2/2 3/3 4/4", "f 1/1 2/2 3/3 99/4")).contains("malformed")
    );
}
