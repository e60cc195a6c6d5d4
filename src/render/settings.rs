//! Renderer and frame settings.

pub use super::core::path::RenderPath;
use super::features::soft_raster::StrandRaster;
use super::features::transparency::Transparency;

/// What draws each bundle in a frame composited with `transparency`: `Auto` with k-buffer
/// OIT sends every bundle to software, since the software rasterizer is never slower than
/// hardware strips inserted into a k-buffer (guide, soft_raster chapter, `bench raster`); in
/// opaque frames thick bundles stay opaque hardware strips, which need no k-buffer.
pub fn raster_under(raster: StrandRaster, transparency: Transparency) -> StrandRaster {
    match (raster, transparency) {
        (StrandRaster::Auto { k }, Transparency::KBuffer { .. }) => StrandRaster::Software { k },
        _ => raster,
    }
}

/// How the light's passes draw the hair into the shadow maps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LightRaster {
    /// Hardware strips (task/mesh or vertex + fragment shaders, depth and blending units).
    #[default]
    Hardware,
    /// The software rasterizer in compute: the light's segments are binned into tiles; the
    /// nearest depth per texel by atomic min, deep opacity layers by fixed-point sums.
    Software,
}

impl std::str::FromStr for LightRaster {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "hw" => Ok(LightRaster::Hardware),
            "soft" => Ok(LightRaster::Software),
            _ => Err(format!("shadow draw {s:?}: hw or soft")),
        }
    }
}

impl std::fmt::Display for LightRaster {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str(match self {
            LightRaster::Hardware => "hw",
            LightRaster::Software => "soft",
        })
    }
}

/// A switch flag: `on`/`true` or `off`/`false` (the tools' `--lod`, `--animate`, `--orbit`).
pub fn parse_switch(s: &str) -> Result<bool, String> {
    match s {
        "on" | "true" => Ok(true),
        "off" | "false" => Ok(false),
        _ => Err(format!("{s:?}: on or off")),
    }
}

/// How to create a [`Renderer`](crate::render::Renderer).
#[derive(Clone, Debug)]
pub struct RendererDesc {
    /// Default path; `None` picks mesh where available, else compute.
    pub path: Option<RenderPath>,
    /// Size of the compute path's generated-vertex pool in bytes (<= the device's
    /// `maxStorageBufferRange`). Frames that need more keep whole strands up to it.
    pub vertex_pool_bytes: u64,
    /// Bundles one task workgroup culls (1..=32).
    pub task_bundles: u32,
    /// Most characters at once (five bindless textures each).
    pub max_characters: u32,
    /// Initial target size.
    pub width: u32,
    /// Initial target size.
    pub height: u32,
    /// Samples per pixel (MSAA): 1, or a count the device supports for colour and depth.
    pub msaa: u32,
    /// Side of the square shadow maps in texels (16..=8192).
    pub shadow_resolution: u32,
    /// The software rasterizer's segment and tile-entry budgets (`None`: the most the
    /// device allows, `SoftBudget::for_range`).
    pub soft_budget: Option<super::soft::SoftBudget>,
    /// `StrandRaster::Auto`: bundles whose strands are drawn at most this many pixels wide
    /// go to the software rasterizer (finite, > 0).
    pub auto_split_pixels: f32,
    /// Leave one declared use out of the frame graph: pass and resource names as printed by
    /// `render --print-frame`, and the use (`None`: every use of it by that pass). A
    /// deliberate bug for the test that shows synchronization validation catches a missing
    /// declaration; `None` in every real use.
    pub omit_use: Option<(String, String, Option<crate::vk::Access>)>,
}

impl Default for RendererDesc {
    fn default() -> Self {
        RendererDesc {
            path: None,
            vertex_pool_bytes: 96 << 20,
            task_bundles: super::core::shared::TASK_PAYLOAD_BUNDLES,
            max_characters: 1024,
            width: 1280,
            height: 720,
            msaa: 1,
            shadow_resolution: DEFAULT_SHADOW_RESOLUTION,
            soft_budget: None,
            auto_split_pixels: super::soft::AUTO_SPLIT_PIXELS,
            omit_use: None,
        }
    }
}

impl RendererDesc {
    /// Set the most characters at once.
    pub fn max_characters(mut self, count: u32) -> Self {
        self.max_characters = count;
        self
    }

    /// Set the initial target size.
    pub fn size(mut self, width: u32, height: u32) -> Self {
        self.width = width;
        self.height = height;
        self
    }

    /// Set the default path.
    pub fn path(mut self, path: Option<RenderPath>) -> Self {
        self.path = path;
        self
    }

    /// Set the MSAA sample count.
    pub fn msaa(mut self, samples: u32) -> Self {
        self.msaa = samples;
        self
    }

    /// Set the shadow map resolution.
    pub fn shadow_resolution(mut self, texels: u32) -> Self {
        self.shadow_resolution = texels;
        self
    }

    /// Set the software rasterizer's budgets.
    pub fn soft_budget(mut self, budget: super::soft::SoftBudget) -> Self {
        self.soft_budget = Some(budget);
        self
    }

    /// Set the vertex pool size in bytes.
    pub fn vertex_pool_bytes(mut self, bytes: u64) -> Self {
        self.vertex_pool_bytes = bytes;
        self
    }
}

/// Per-frame choices.
#[derive(Clone, Copy, Debug)]
pub struct FrameOptions {
    /// Path for this frame (`None`: the renderer's default).
    pub path: Option<RenderPath>,
    /// Clear colour and depth first (else draw over the previous frame's contents).
    pub clear: bool,
    /// Read the colour target back into the report.
    pub read_image: bool,
    /// Compute the motion vectors (as temporal accumulation does) and read them back into
    /// the report (`FrameReport::motion`).
    pub read_motion: bool,
    /// Keep a printable account of the frame graph (passes, uses, derived dependencies) in the
    /// frame's report (`render --print-frame`).
    pub describe_frame: bool,
    /// Hardware strips, the software rasterizer, or a split per bundle (mesh and compute
    /// paths).
    pub raster: super::soft::StrandRaster,
    /// How the light's passes draw the hair (with shadows on).
    pub light_raster: LightRaster,
    /// Place every bundle's first strand root on the GPU from this frame's textures and
    /// records and read them back (`FrameReport::roots`): the root-gap measure's input.
    pub probe_roots: bool,
}

impl Default for FrameOptions {
    fn default() -> Self {
        FrameOptions {
            path: None,
            clear: true,
            read_image: false,
            read_motion: false,
            describe_frame: false,
            raster: super::soft::StrandRaster::Hardware,
            light_raster: LightRaster::Hardware,
            probe_roots: false,
        }
    }
}

/// A submitted frame, to [`Renderer::wait`](crate::render::Renderer::wait) for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameTicket(pub u64);

/// What a device (and renderer) offers, for [`FrameSettings::validate`].
#[derive(Clone, Debug)]
pub struct DeviceCaps {
    /// Device name (for messages).
    pub name: String,
    /// VK_EXT_mesh_shader usable for the mesh path.
    pub mesh_path: bool,
    /// 64-bit shared and buffer atomics (the software rasterizer and k-buffer OIT).
    pub int64_atomics: bool,
}

/// The settings of one frame that constrain each other: generation path, strand raster,
/// transparency and MSAA. Every compatibility rule is in [`FrameSettings::validate`]; the
/// tools call it rather than restating the rules.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameSettings {
    /// Generation path.
    pub path: RenderPath,
    /// How strands are rasterized.
    pub raster: super::soft::StrandRaster,
    /// How strands are composited.
    pub transparency: super::Transparency,
    /// Samples per pixel of the renderer's targets.
    pub msaa: u32,
    /// How the light's passes draw the hair.
    pub light_raster: LightRaster,
}

impl FrameSettings {
    /// The rules between the settings themselves (any device): tools call this before
    /// touching the GPU; [`Self::validate`] adds the device's.
    pub fn check_combination(&self) -> Result<(), String> {
        self.raster.validate()?;
        self.transparency.validate()?;
        if matches!(self.transparency, super::Transparency::DepthPeeling { .. }) && self.msaa > 1 {
            return Err("depth peeling is the single-sample reference: use it without MSAA".into());
        }
        if self.raster.uses_software()
            && let Some(why) = software_raster_conflict(self.msaa, self.transparency)
        {
            return Err(why);
        }
        if self.light_raster == LightRaster::Software
            && matches!(self.path, RenderPath::Static | RenderPath::Lhs)
        {
            return Err(format!(
                "software shadows draw the light's generated segments: use them with the mesh or compute path, not {}",
                self.path
            ));
        }
        Ok(())
    }

    /// Why these settings cannot be drawn on a device with `caps`, or the frame's k-buffer
    /// budget (the OIT budget, or the software rasterizer's K in opaque frames).
    pub fn validate(&self, caps: &DeviceCaps) -> Result<u32, String> {
        use super::Transparency;
        self.check_combination()?;
        if self.path == RenderPath::Mesh && !caps.mesh_path {
            return Err(format!(
                "{}: no usable VK_EXT_mesh_shader for the mesh path",
                caps.name
            ));
        }
        match self.transparency {
            Transparency::KBuffer { .. } if !caps.int64_atomics => {
                return Err(format!(
                    "{}: k-buffer OIT needs shaderInt64 and shaderBufferInt64Atomics",
                    caps.name
                ));
            }
            _ => {}
        }
        let budget = match self.transparency {
            Transparency::KBuffer { budget } => budget,
            _ => self.raster.k(),
        };
        let soft_light = self.light_raster == LightRaster::Software;
        if !self.raster.uses_software() && !soft_light {
            return Ok(budget);
        }
        if !caps.int64_atomics {
            return Err(format!(
                "{}: the software rasterizer needs shaderInt64 and 64-bit buffer and shared atomics",
                caps.name
            ));
        }
        Ok(budget)
    }
}

impl FrameSettings {
    /// These settings with the rasterizers left open (`None`) chosen for speed: the camera's
    /// strands through `auto` (thin strands to the software rasterizer, thick ones as
    /// hardware strips) and the light's through the software passes, each where the
    /// settings and the device (`caps`) allow it, else hardware. Compute generation feeding
    /// the software rasterizer keeps the hair out of the graphics pipeline, the narrow part
    /// of data-centre GPUs and the slowest part of lavapipe (guide, soft_raster chapter).
    pub fn with_fastest(
        self,
        (raster, light): (Option<super::soft::StrandRaster>, Option<LightRaster>),
        caps: &DeviceCaps,
    ) -> Self {
        use super::soft::{DEFAULT_SOFT_K, StrandRaster};
        let ok = |s: &FrameSettings| s.validate(caps).is_ok();
        let mut s = FrameSettings {
            raster: raster.unwrap_or(StrandRaster::Auto { k: DEFAULT_SOFT_K }),
            ..self
        };
        if raster.is_none() && !ok(&s) {
            s.raster = StrandRaster::Hardware;
        }
        s.light_raster = light.unwrap_or(LightRaster::Software);
        if light.is_none() && !ok(&s) {
            s.light_raster = LightRaster::Hardware;
        }
        s
    }
}

/// Why the software rasterizer cannot draw with `msaa` samples and `transparency` (`None`:
/// it can; every generation path can, the static and LHS paths from their stored strands);
/// tools check this before any work to name their flags.
pub fn software_raster_conflict(msaa: u32, transparency: super::Transparency) -> Option<String> {
    if msaa > 1 {
        return Some(
            "the software rasterizer antialiases strands analytically and reads single-sample depth: use it without MSAA".into(),
        );
    }
    if matches!(transparency, super::Transparency::DepthPeeling { .. }) {
        return Some(
            "the software rasterizer composites through the k-buffer: use it with opaque or oit transparency, not depth peeling".into(),
        );
    }
    None
}

/// Sample counts `ctx`'s device supports for the renderer's colour and depth targets.
pub fn supported_msaa(ctx: &crate::vk::Context) -> Vec<u32> {
    (0..7)
        .map(|b| 1u32 << b)
        .filter(|c| ctx.info.attachment_sample_counts & c != 0)
        .collect()
}

/// `samples` per pixel on `ctx`'s device, or why not (naming the device and what it offers);
/// tools prefix the flag that set it.
pub fn check_msaa(ctx: &crate::vk::Context, samples: u32) -> Result<(), String> {
    let supported = supported_msaa(ctx);
    if supported.contains(&samples) {
        return Ok(());
    }
    let list: Vec<String> = supported.iter().map(|c| c.to_string()).collect();
    Err(format!(
        "{} supports {} samples per pixel for colour and depth",
        ctx.info.name,
        list.join(", ")
    ))
}

pub(super) fn check_size(width: u32, height: u32) -> crate::vk::GpuResult<()> {
    if width == 0 || height == 0 || width > 8192 || height > 8192 {
        return Err(crate::vk::GpuError::Unsupported(format!(
            "bad target size {width}x{height}: 1..=8192 per side"
        )));
    }
    Ok(())
}

/// Default shadow map resolution (square).
pub const DEFAULT_SHADOW_RESOLUTION: u32 = 1024;

/// How hair is shadowed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum ShadowMode {
    /// No shadows.
    #[default]
    Off = super::core::shared::SHADOW_OFF,
    /// Deep opacity maps (two light passes).
    DeepOpacity = super::core::shared::SHADOW_DEEP_OPACITY,
    /// Approximate deep shadow maps (one light pass).
    Approximate = super::core::shared::SHADOW_APPROXIMATE,
}

impl ShadowMode {
    /// Every mode, in menu order.
    pub const ALL: [ShadowMode; 3] = [
        ShadowMode::Off,
        ShadowMode::DeepOpacity,
        ShadowMode::Approximate,
    ];

    /// Name used by flags and scene files.
    pub fn name(self) -> &'static str {
        match self {
            ShadowMode::Off => "off",
            ShadowMode::DeepOpacity => "deep-opacity",
            ShadowMode::Approximate => "approximate",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Under k-buffer transparency `Auto` sends every bundle to software, keeping its `k`;
    /// everything else is left as asked (returning the default, hardware, survived the
    /// 2026-12-06 sample).
    #[test]
    fn auto_raster_goes_software_under_a_k_buffer() {
        let oit = Transparency::KBuffer { budget: 8 };
        let auto = StrandRaster::Auto { k: 3 };
        assert_eq!(raster_under(auto, oit), StrandRaster::Software { k: 3 });
        assert_eq!(raster_under(auto, Transparency::Opaque), auto);
        let soft = StrandRaster::Software { k: 5 };
        assert_eq!(raster_under(soft, oit), soft);
        assert_eq!(
            raster_under(StrandRaster::Hardware, oit),
            StrandRaster::Hardware
        );
    }
}
