//! GLSL -> SPIR-V with shaderc. Sources are embedded from `glsl/` at build time (so binaries run
//! anywhere); `#include "x.glsl"` resolves against the same set. Errors name file and line.

use super::{GpuError, GpuResult};

/// Every file under `glsl/`, embedded.
pub const SOURCES: &[(&str, &str)] = &[
    ("bindings.glsl", include_str!("../../glsl/bindings.glsl")),
    ("common.glsl", include_str!("../../glsl/common.glsl")),
    (
        "hair_types.glsl",
        include_str!("../../glsl/hair_types.glsl"),
    ),
    (
        "strand_eval.glsl",
        include_str!("../../glsl/strand_eval.glsl"),
    ),
    (
        "bundle_lod.glsl",
        include_str!("../../glsl/bundle_lod.glsl"),
    ),
    (
        "strand_build.glsl",
        include_str!("../../glsl/strand_build.glsl"),
    ),
    ("strip.glsl", include_str!("../../glsl/strip.glsl")),
    ("strands.task", include_str!("../../glsl/strands.task")),
    ("strands.mesh", include_str!("../../glsl/strands.mesh")),
    ("cull.comp", include_str!("../../glsl/cull.comp")),
    ("scan.comp", include_str!("../../glsl/scan.comp")),
    ("generate.comp", include_str!("../../glsl/generate.comp")),
    ("strands.vert", include_str!("../../glsl/strands.vert")),
    ("strands.frag", include_str!("../../glsl/strands.frag")),
    ("scalp.vert", include_str!("../../glsl/scalp.vert")),
    ("scalp.frag", include_str!("../../glsl/scalp.frag")),
];

fn source(name: &str) -> Option<&'static str> {
    SOURCES.iter().find(|(n, _)| *n == name).map(|(_, s)| *s)
}

/// Compile embedded shader `name` (stage from its extension) to SPIR-V.
pub fn compile(name: &str) -> GpuResult<Vec<u32>> {
    let kind = match name.rsplit('.').next() {
        Some("comp") => shaderc::ShaderKind::Compute,
        Some("vert") => shaderc::ShaderKind::Vertex,
        Some("frag") => shaderc::ShaderKind::Fragment,
        Some("task") => shaderc::ShaderKind::Task,
        Some("mesh") => shaderc::ShaderKind::Mesh,
        _ => {
            return Err(GpuError::Shader(format!(
                "glsl/{name}: unknown shader stage"
            )));
        }
    };
    let text =
        source(name).ok_or_else(|| GpuError::Shader(format!("glsl/{name}: not embedded")))?;
    let compiler = shaderc::Compiler::new().map_err(|e| GpuError::Shader(e.to_string()))?;
    let mut options =
        shaderc::CompileOptions::new().map_err(|e| GpuError::Shader(e.to_string()))?;
    options.set_target_env(
        shaderc::TargetEnv::Vulkan,
        shaderc::EnvVersion::Vulkan1_3 as u32,
    );
    options.set_target_spirv(shaderc::SpirvVersion::V1_6);
    options.set_optimization_level(shaderc::OptimizationLevel::Performance);
    options.set_include_callback(|requested, _ty, _from, _depth| {
        source(requested)
            .map(|content| shaderc::ResolvedInclude {
                resolved_name: requested.to_string(),
                content: content.to_string(),
            })
            .ok_or_else(|| format!("include '{requested}' not found in glsl/"))
    });
    let artifact = compiler
        .compile_into_spirv(text, kind, name, "main", Some(&options))
        .map_err(|e| GpuError::Shader(format!("glsl/{}", e.to_string().trim())))?;
    Ok(artifact.as_binary().to_vec())
}
