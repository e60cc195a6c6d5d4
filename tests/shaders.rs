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
            "glsl/{name} is not embedded (build.rs writes the shader list)"
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

/// No GLSL file restates what the generated `shared.glsl` defines (a constant with a Rust
/// twin), and no local size or mesh output limit is a bare number.
#[test]
fn glsl_restates_no_shared_constant() {
    let header = hairmesh::render::shared::glsl_header();
    let shared: Vec<&str> = header
        .lines()
        .filter_map(|l| l.strip_prefix("#define "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|n| !n.contains('('))
        .collect();
    assert!(shared.contains(&"HAIR_ETA") && shared.contains(&"SHADING_MARSCHNER"));
    for (name, text) in SOURCES {
        for line in text.lines() {
            let t = line.trim();
            if let Some(rest) = t.strip_prefix("#define ") {
                let defined = rest.split_whitespace().next().unwrap_or("");
                assert!(
                    !shared.contains(&defined),
                    "glsl/{name} restates {defined}, which shared.glsl defines from Rust: {t}"
                );
            }
            // The shading probe is a test shader with its own fixed size.
            let bare = |key: &str| {
                t.split(key)
                    .nth(1)
                    .map(|r| r.trim_start())
                    // One-invocation workgroups need no twin.
                    .is_some_and(|r| {
                        r.starts_with(|c: char| c.is_ascii_digit()) && !r.starts_with("1)")
                    })
            };
            if *name != "shading_probe.comp" && !t.starts_with("//") {
                for key in ["local_size_x =", "max_vertices =", "max_primitives ="] {
                    let allowed = *name == "strands.mesh" && t.contains("max_vertices = 3,");
                    assert!(allowed || !bare(key), "glsl/{name}: literal {key} in {t}");
                }
            }
        }
    }
}
