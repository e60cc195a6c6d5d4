//! Every shader in glsl/ is embedded and compiles.

use hairmesh::vk::shader::{SOURCES, compile};

#[test]
fn every_glsl_file_is_embedded_and_compiles() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/glsl");
    for entry in std::fs::read_dir(dir).unwrap() {
        let entry = entry.unwrap();
        if entry.file_type().unwrap().is_dir() {
            continue; // glsl/generated/: copies of run-time generated includes
        }
        let name = entry.file_name().into_string().unwrap();
        assert!(
            SOURCES.iter().any(|(n, _)| *n == name),
            "glsl/{name} is not listed in src/vk/shader.rs SOURCES"
        );
        if !name.ends_with(".glsl") {
            compile(&name, &hairmesh::render::passes::shader_options(32))
                .unwrap_or_else(|e| panic!("{e}"));
        }
    }
}

#[test]
fn unknown_shader_is_an_error_naming_it() {
    let e = compile("nope.comp", &Default::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("glsl/nope.comp"), "{e}");
}
