//! The CPU/GPU contract: every struct emitted into `shared.glsl` (src/render/core/shared.rs) has the
//! same std430 layout as its Rust `#[repr(C)]` twin, field by field, and the copy of the
//! generated header in `glsl/generated/` is current.

use hairmesh::render::shared::{glsl_header, shared_structs, std140_layout, std430_layout};

/// Every way the structs' Rust layouts disagree with std430 (field offsets, struct sizes),
/// one line each, the structs laid out in order (a struct's layout depends on those before).
fn mismatches(structs: &[hairmesh::render::shared::StructInfo]) -> Vec<String> {
    let mut known: Vec<(String, usize, usize)> = Vec::new();
    let mut out = Vec::new();
    for s in structs {
        let (offsets, size, align) = std430_layout(s, &known);
        for (f, off) in s.fields.iter().zip(&offsets) {
            if f.offset != *off {
                out.push(format!(
                    "{}.{}: Rust offset {} but std430 offset {}",
                    s.name, f.name, f.offset, off
                ));
            }
        }
        if size != s.rust_size {
            out.push(format!(
                "{}: std430 size {size}, Rust {}",
                s.name, s.rust_size
            ));
        }
        known.push((s.name.to_string(), size, align));
    }
    out
}

#[test]
fn every_shared_struct_has_the_rust_layout() {
    let structs = shared_structs();
    assert!(structs.len() >= 10, "every shared struct is registered");
    let wrong = mismatches(&structs);
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// Every way `block` (a uniform block) laid out in std140 disagrees with its Rust twin, the
/// structs before it in `structs` laid out in std140 too.
fn std140_mismatches(
    structs: &[hairmesh::render::shared::StructInfo],
    block: &hairmesh::render::shared::StructInfo,
) -> Vec<String> {
    let mut known: Vec<(String, usize, usize)> = Vec::new();
    for s in structs.iter().take_while(|s| s.name != block.name) {
        let (_, size, align) = std140_layout(s, &known);
        known.push((s.name.to_string(), size, align));
    }
    let (offsets, size, _) = std140_layout(block, &known);
    let mut out: Vec<String> = block
        .fields
        .iter()
        .zip(&offsets)
        .filter(|(f, off)| f.offset != **off)
        .map(|(f, off)| {
            format!(
                "{}.{}: Rust offset {} but std140 offset {off}",
                block.name, f.name, f.offset
            )
        })
        .collect();
    if size != block.rust_size {
        out.push(format!(
            "{}: std140 size {size}, Rust {}",
            block.name, block.rust_size
        ));
    }
    out
}

#[test]
fn the_frame_block_is_the_same_in_std140() {
    // The frame block is a uniform block (std140): its named scalars, vec3s and field groups
    // must land where the Rust struct has them.
    let structs = shared_structs();
    let block = structs.iter().find(|s| s.name == "FrameBlock").unwrap();
    let wrong = std140_mismatches(&structs, block);
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    // Negative control: an array of scalars (stride 16 in std140, 4 in Rust) moves the field
    // after it.
    let mut planted = hairmesh::render::shared::StructInfo {
        name: "FrameBlock",
        fields: block.fields.clone(),
        rust_size: block.rust_size,
    };
    let k = planted
        .fields
        .iter()
        .position(|f| f.name == "pixels_high")
        .unwrap();
    planted.fields[k].glsl = "float";
    planted.fields[k].array = 2;
    assert!(!std140_mismatches(&structs, &planted).is_empty());
}

/// The check above fails on each kind of drift it guards against, run through the same
/// function: a Rust field moved, a GLSL field type that grows (a `vec4` declared `mat4`: the
/// fields after it, or the struct's size, move in std430), a Rust struct that grew.
#[test]
fn the_layout_check_catches_drift() {
    let find = |name: &str| {
        shared_structs()
            .into_iter()
            .position(|s| s.name == name)
            .unwrap()
    };
    // A Rust offset moved by 4 bytes.
    let mut moved = shared_structs();
    moved[0].fields[1].offset += 4;
    assert_eq!(mismatches(&moved).len(), 1, "{:?}", mismatches(&moved));
    // A GLSL field type that grows: every later field of that struct moves in std430.
    let mut retyped = shared_structs();
    let k = find("FrameBlock");
    let f = retyped[k]
        .fields
        .iter()
        .position(|f| f.glsl == "vec4")
        .unwrap();
    retyped[k].fields[f].glsl = "mat4";
    let wrong = mismatches(&retyped);
    assert!(
        wrong.iter().any(|w| w.starts_with("FrameBlock")),
        "{wrong:?}"
    );
    // A Rust struct that grew without its GLSL twin.
    let mut grown = shared_structs();
    let last = grown.len() - 1;
    grown[last].rust_size += 16;
    assert_eq!(mismatches(&grown).len(), 1, "{:?}", mismatches(&grown));
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
