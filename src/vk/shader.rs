//! GLSL -> SPIR-V with shaderc. Sources are embedded from `glsl/` at build time (so binaries run
//! anywhere); `#include "x.glsl"` resolves against generated includes (ShaderOptions), then
//! the same set. Errors name file and line.

use super::{GpuError, GpuResult};

/// Every file under `glsl/`, embedded.
pub const SOURCES: &[(&str, &str)] = &[
    ("bindings.glsl", include_str!("../../glsl/bindings.glsl")),
    ("common.glsl", include_str!("../../glsl/common.glsl")),
    (
        "strand_eval.glsl",
        include_str!("../../glsl/strand_eval.glsl"),
    ),
    (
        "bundle_lod.glsl",
        include_str!("../../glsl/bundle_lod.glsl"),
    ),
    (
        "bundle_sizes.glsl",
        include_str!("../../glsl/bundle_sizes.glsl"),
    ),
    (
        "strand_build.glsl",
        include_str!("../../glsl/strand_build.glsl"),
    ),
    ("strip.glsl", include_str!("../../glsl/strip.glsl")),
    (
        "shadow_lookup.glsl",
        include_str!("../../glsl/shadow_lookup.glsl"),
    ),
    ("shadow.frag", include_str!("../../glsl/shadow.frag")),
    (
        "hair_shading.glsl",
        include_str!("../../glsl/hair_shading.glsl"),
    ),
    ("strands.task", include_str!("../../glsl/strands.task")),
    ("strands.mesh", include_str!("../../glsl/strands.mesh")),
    ("cull.comp", include_str!("../../glsl/cull.comp")),
    ("scan.comp", include_str!("../../glsl/scan.comp")),
    ("scan_add.comp", include_str!("../../glsl/scan_add.comp")),
    ("finalize.comp", include_str!("../../glsl/finalize.comp")),
    ("generate.comp", include_str!("../../glsl/generate.comp")),
    ("strands.vert", include_str!("../../glsl/strands.vert")),
    ("strands.frag", include_str!("../../glsl/strands.frag")),
    ("scalp.vert", include_str!("../../glsl/scalp.vert")),
    ("scalp.frag", include_str!("../../glsl/scalp.frag")),
    ("props.vert", include_str!("../../glsl/props.vert")),
    ("props.frag", include_str!("../../glsl/props.frag")),
    (
        "shading_probe.comp",
        include_str!("../../glsl/shading_probe.comp"),
    ),
    (
        "strand_fragment.glsl",
        include_str!("../../glsl/strand_fragment.glsl"),
    ),
    (
        "lod_appearance.glsl",
        include_str!("../../glsl/lod_appearance.glsl"),
    ),
    ("oit.glsl", include_str!("../../glsl/oit.glsl")),
    (
        "fragment_pack.glsl",
        include_str!("../../glsl/fragment_pack.glsl"),
    ),
    (
        "strand_radiance.glsl",
        include_str!("../../glsl/strand_radiance.glsl"),
    ),
    (
        "soft_segments.glsl",
        include_str!("../../glsl/soft_segments.glsl"),
    ),
    (
        "soft_raster.glsl",
        include_str!("../../glsl/soft_raster.glsl"),
    ),
    ("soft_bin.comp", include_str!("../../glsl/soft_bin.comp")),
    (
        "soft_bin_args.comp",
        include_str!("../../glsl/soft_bin_args.comp"),
    ),
    (
        "soft_tile_scan.comp",
        include_str!("../../glsl/soft_tile_scan.comp"),
    ),
    (
        "soft_raster.comp",
        include_str!("../../glsl/soft_raster.comp"),
    ),
    ("oit.frag", include_str!("../../glsl/oit.frag")),
    ("peel.glsl", include_str!("../../glsl/peel.glsl")),
    (
        "peel_depth.frag",
        include_str!("../../glsl/peel_depth.frag"),
    ),
    (
        "peel_color.frag",
        include_str!("../../glsl/peel_color.frag"),
    ),
    (
        "fullscreen.vert",
        include_str!("../../glsl/fullscreen.vert"),
    ),
    (
        "oit_resolve.frag",
        include_str!("../../glsl/oit_resolve.frag"),
    ),
    ("curve.glsl", include_str!("../../glsl/curve.glsl")),
    ("lhs_skin.comp", include_str!("../../glsl/lhs_skin.comp")),
    (
        "hair_mesh_update.comp",
        include_str!("../../glsl/hair_mesh_update.comp"),
    ),
];

fn source(name: &str) -> Option<&'static str> {
    SOURCES.iter().find(|(n, _)| *n == name).map(|(_, s)| *s)
}

/// Preprocessor definitions and generated include files for one compilation.
#[derive(Clone, Debug, Default)]
pub struct ShaderOptions {
    /// `#define NAME VALUE` pairs.
    pub defines: Vec<(String, String)>,
    /// Include files made at run time (`#include "name"` finds them before `glsl/`).
    pub generated: Vec<(String, String)>,
}

impl ShaderOptions {
    /// Add a definition.
    pub fn define(mut self, name: &str, value: impl ToString) -> Self {
        self.defines.push((name.into(), value.to_string()));
        self
    }

    /// Add a generated include file.
    pub fn include(mut self, name: &str, text: String) -> Self {
        self.generated.push((name.into(), text));
        self
    }
}

/// Compile embedded shader `name` (stage from its extension) to SPIR-V.
pub fn compile(name: &str, opts: &ShaderOptions) -> GpuResult<Vec<u32>> {
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
    for (k, v) in &opts.defines {
        options.add_macro_definition(k, Some(v));
    }
    let generated = opts.generated.clone();
    options.set_include_callback(move |requested, _ty, _from, _depth| {
        let content = generated
            .iter()
            .find(|(n, _)| n == requested)
            .map(|(_, t)| t.clone())
            .or_else(|| source(requested).map(str::to_string));
        content
            .map(|content| shaderc::ResolvedInclude {
                resolved_name: requested.to_string(),
                content,
            })
            .ok_or_else(|| format!("include '{requested}' not found in glsl/"))
    });
    let artifact = compiler
        .compile_into_spirv(text, kind, name, "main", Some(&options))
        .map_err(|e| GpuError::Shader(format!("glsl/{}", e.to_string().trim())))?;
    Ok(artifact.as_binary().to_vec())
}
