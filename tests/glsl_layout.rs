//! The CPU/GPU contract: every struct emitted into `shared.glsl` (src/render/shared.rs) has the
//! same std430 layout as its Rust `#[repr(C)]` twin, field by field, and the copy of the
//! generated header in `glsl/generated/` is current.

use hairmesh::render::shared::{glsl_header, shared_structs, std430_layout, std430_type};

#[test]
fn every_shared_struct_has_the_rust_layout() {
    let mut known: Vec<(String, usize, usize)> = Vec::new();
    let structs = shared_structs();
    assert!(structs.len() >= 10, "every shared struct is registered");
    for s in &structs {
        let (offsets, size, align) = std430_layout(s, &known);
        for (f, off) in s.fields.iter().zip(&offsets) {
            assert_eq!(
                f.offset, *off,
                "{}.{}: Rust offset {} but std430 offset {}",
                s.name, f.name, f.offset, off
            );
        }
        assert_eq!(
            size, s.rust_size,
            "{}: std430 size differs from Rust",
            s.name
        );
        known.push((s.name.to_string(), size, align));
    }
}

#[test]
fn the_frame_block_is_the_same_in_std140() {
    // Uniform blocks use std140; with only 16-byte-aligned vec4/uvec4/mat4 fields (and arrays
    // of vec4) std140 and std430 agree.
    let s = shared_structs()
        .into_iter()
        .find(|s| s.name == "FrameBlock")
        .unwrap();
    for f in &s.fields {
        assert_eq!(std430_type(f.glsl).unwrap().1, 16, "FrameBlock.{}", f.name);
    }
}

#[test]
fn a_wrong_offset_is_caught() {
    // The check above can fail: shifting one field breaks it.
    let mut s = shared_structs().remove(0);
    s.fields[1].offset += 4;
    let (offsets, ..) = std430_layout(&s, &[]);
    assert_ne!(offsets[1], s.fields[1].offset);
}

#[test]
fn generated_header_copy_is_current() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/glsl/generated/shared.glsl");
    let text = glsl_header();
    if std::env::var("HAIRMESH_BLESS").is_ok_and(|v| v == "1") {
        std::fs::write(path, &text).unwrap();
    }
    let copy = std::fs::read_to_string(path).unwrap_or_default();
    assert!(
        copy == text,
        "glsl/generated/shared.glsl is stale: run HAIRMESH_BLESS=1 cargo test --release --test glsl_layout"
    );
}
