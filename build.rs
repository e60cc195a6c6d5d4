//! Two jobs. The shader list: every file directly under `glsl/` is embedded into the library
//! through a generated `shader_sources.rs` (`vk::shader::SOURCES`), so adding a shader is
//! adding its file. Linking: Debian packages shaderc's `libshaderc_combined.a` without glslang and SPIRV-Tools (they ship
//! as separate static libraries in glslang-dev / spirv-tools). When those are present, link them
//! so the `shaderc` crate can use Debian's prebuilt library instead of compiling shaderc from
//! source (minutes of C++ on a 2-core CI machine).

use std::path::Path;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    write_shader_list();
    link_debian_shaderc();
}

/// `$OUT_DIR/shader_sources.rs`: `(name, include_str!(path))` for each file in `glsl/`,
/// sorted by name (generated copies under `glsl/generated/` are for reading and are left out).
fn write_shader_list() {
    let root = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let dir = Path::new(&root).join("glsl");
    println!("cargo:rerun-if-changed={}", dir.display());
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .expect("glsl/ is part of the crate")
        .filter_map(|e| e.ok())
        .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
        .filter_map(|e| e.file_name().into_string().ok())
        .collect();
    names.sort();
    let mut out = String::from("&[\n");
    for n in &names {
        println!("cargo:rerun-if-changed={}", dir.join(n).display());
        let path = dir.join(n);
        out += &format!(
            "    ({n:?}, include_str!({:?})),\n",
            path.display().to_string()
        );
    }
    out += "]\n";
    let out_dir = std::env::var("OUT_DIR").expect("cargo sets OUT_DIR");
    std::fs::write(Path::new(&out_dir).join("shader_sources.rs"), out)
        .expect("write the shader list");
}

/// Link Debian's static glslang and SPIRV-Tools libraries when they are installed.
fn link_debian_shaderc() {
    let arch = std::env::var("CARGO_CFG_TARGET_ARCH").unwrap_or_default();
    let dir = format!("/usr/lib/{arch}-linux-gnu");
    let libs = [
        "MachineIndependent",
        "GenericCodeGen",
        "OSDependent",
        "OGLCompiler",
        "HLSL",
        "SPIRV",
        "SPIRV-Tools-opt",
        "SPIRV-Tools",
        "glslang",
        "glslang-default-resource-limits",
    ];
    if libs
        .iter()
        .all(|l| Path::new(&dir).join(format!("lib{l}.a")).is_file())
    {
        println!("cargo:rustc-link-search=native={dir}");
        for l in libs {
            println!("cargo:rustc-link-lib=static={l}");
        }
    }
}
