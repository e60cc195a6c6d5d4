//! Debian packages shaderc's `libshaderc_combined.a` without glslang and SPIRV-Tools (they ship
//! as separate static libraries in glslang-dev / spirv-tools). When those are present, link them
//! so the `shaderc` crate can use Debian's prebuilt library instead of compiling shaderc from
//! source (minutes of C++ on a 2-core CI machine).

use std::path::Path;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
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
