//! The GLSL structs in `glsl/hair_types.glsl` have the same std430 layout as their Rust twins.

use hairmesh::{BundleDesc, HairStyle, MeshInfo};

/// std430 (size, alignment) of the scalar/vector types used in shared structs.
fn std430(ty: &str) -> (usize, usize) {
    match ty {
        "float" | "uint" | "int" => (4, 4),
        "vec2" | "uvec2" | "ivec2" => (8, 8),
        "vec3" | "uvec3" => (12, 16),
        "vec4" | "uvec4" => (16, 16),
        _ => panic!("type {ty} not supported in shared structs"),
    }
}

/// `(name, offset)` of each field of `struct name` in the GLSL source, and the struct size.
fn glsl_layout(src: &str, name: &str) -> (Vec<(String, usize)>, usize) {
    let start = src
        .find(&format!("struct {name} {{"))
        .unwrap_or_else(|| panic!("struct {name} missing"));
    let body = &src[start..];
    let body = &body[body.find('{').unwrap() + 1..body.find("};").unwrap()];
    let (mut offset, mut align_max, mut fields) = (0usize, 4usize, Vec::new());
    for line in body.lines() {
        let line = line.split("//").next().unwrap().trim();
        if line.is_empty() {
            continue;
        }
        let decl = line.trim_end_matches(';');
        let (ty, var) = decl.split_once(' ').unwrap();
        let (var, count) = match var.split_once('[') {
            Some((v, n)) => (v.trim(), n.trim_end_matches(']').parse::<usize>().unwrap()),
            None => (var.trim(), 1),
        };
        let (size, align) = std430(ty);
        // std430 arrays of scalars/vectors: stride = element alignment-rounded size.
        let stride = size.next_multiple_of(align);
        offset = offset.next_multiple_of(align);
        fields.push((var.to_string(), offset));
        offset += if count > 1 { stride * count } else { size };
        align_max = align_max.max(align);
    }
    (fields, offset.next_multiple_of(align_max))
}

fn check(name: &str, rust: Vec<(&'static str, usize)>, rust_size: usize) {
    let src = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/glsl/hair_types.glsl"))
        .unwrap();
    let (glsl, size) = glsl_layout(&src, name);
    let rust: Vec<(String, usize)> = rust.into_iter().map(|(n, o)| (n.to_string(), o)).collect();
    assert_eq!(
        glsl, rust,
        "{name}: GLSL and Rust field names/offsets differ"
    );
    assert_eq!(size, rust_size, "{name}: std430 size differs");
}

#[test]
fn hair_style_layout() {
    check(
        "HairStyle",
        HairStyle::field_offsets(),
        size_of::<HairStyle>(),
    );
    assert_eq!(size_of::<HairStyle>() % 16, 0);
}

#[test]
fn mesh_info_layout() {
    check("MeshInfo", MeshInfo::field_offsets(), size_of::<MeshInfo>());
    assert_eq!(size_of::<MeshInfo>(), 64);
}

#[test]
fn bundle_desc_layout() {
    check(
        "BundleDesc",
        BundleDesc::field_offsets(),
        size_of::<BundleDesc>(),
    );
    assert_eq!(size_of::<BundleDesc>(), 32);
}
