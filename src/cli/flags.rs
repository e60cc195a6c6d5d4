//! The flag groups every tool that draws shares, flattened into its command line with
//! `#[command(flatten)]`: one spelling, one help text and one default each. A value not given
//! is `None`; each tool resolves it against its own preset (the crowd's look and LoD, or a
//! scene file's `[look]`), as the help says.

use crate::render::{
    LightRaster, LodSettings, ShadowMode, StrandRaster, Temporal, Transparency, parse_switch,
};
use crate::shade::ShadingModel;

/// Level of detail (paper 003 section 3.6, eq. 7, and the strand caps of issue 64).
#[derive(clap::Args, Clone, Debug)]
pub struct LodFlags {
    /// Level of detail: on or off.
    #[arg(long, default_value = "on", value_parser = parse_switch, action = clap::ArgAction::Set)]
    pub lod: bool,
    /// Alpha of eq. 7 for strand LoD. Default: render 0.1; crowd half that (measured FLIP
    /// 0.008 against 0.1 on the people crowd, 1.4x faster).
    #[arg(long)]
    pub lod_alpha_strands: Option<f32>,
    /// Strands of bundles spanning fewer than this many pixels fall with their area,
    /// thickened to keep the coverage (0: off, the paper's eq. 7). Default: render 0; crowd 8
    /// (1000 people draw half the strands, FLIP 0.011 against off).
    #[arg(long)]
    pub lod_area_below: Option<f32>,
    /// At most this many strands per square pixel of a bundle's extent (0: off): at crowd
    /// distance a bundle draws the strands the pixels it covers need, whatever the density,
    /// thickened to keep its coverage. Default: render 0; crowd 0.5.
    #[arg(long)]
    pub lod_strands_per_pixel: Option<f32>,
    /// Alpha of eq. 7 for vertex LoD. Default 0.1.
    #[arg(long)]
    pub lod_alpha_verts: Option<f32>,
    /// Lambda of eq. 7 (how fast the vertex level falls with distance). Default 0.5.
    #[arg(long)]
    pub lod_lambda: Option<f32>,
}

impl LodFlags {
    /// The ids of the flags that tune LoD (unused when `--lod` is off).
    pub const TUNING_IDS: [&str; 5] = [
        "lod_alpha_strands",
        "lod_area_below",
        "lod_strands_per_pixel",
        "lod_alpha_verts",
        "lod_lambda",
    ];

    /// The LoD settings: each flag given, else `preset`'s (LoD off: the flags given over
    /// [`LodSettings::off`]); refused in the flags' terms.
    pub fn settings(&self, preset: LodSettings) -> Result<LodSettings, String> {
        let base = match self.lod {
            true => preset,
            false => LodSettings::off(),
        };
        let lod = LodSettings {
            enabled: self.lod,
            alpha_strands: self.lod_alpha_strands.unwrap_or(base.alpha_strands),
            area_below: self.lod_area_below.unwrap_or(base.area_below),
            strands_per_pixel: self.lod_strands_per_pixel.unwrap_or(base.strands_per_pixel),
            alpha_verts: self.lod_alpha_verts.unwrap_or(base.alpha_verts),
            lambda: self.lod_lambda.unwrap_or(base.lambda),
        };
        lod.validate().map_err(|e| {
            format!(
                "--lod-alpha-strands / --lod-area-below / --lod-strands-per-pixel / --lod-alpha-verts / --lod-lambda: {e}"
            )
        })?;
        Ok(lod)
    }
}

/// How the hair looks: shading, shadows, compositing, anti-aliasing and the strand draws.
#[derive(clap::Args, Clone, Debug)]
pub struct LookFlags {
    /// Samples per pixel (MSAA): 1, 2, 4, 8 where the device supports it (lavapipe: 1 or
    /// 4). Default: the scene's `[look] msaa`, else 1.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub msaa: Option<u32>,
    /// Strand shading: placeholder, kajiya-kay or marschner. Default: the scene's `[look]
    /// shading`, else marschner.
    #[arg(long)]
    pub shading: Option<ShadingModel>,
    /// Shadows: off, deep-opacity (deep opacity maps) or approximate (approximate deep
    /// shadow maps). Default: the scene's `[look] shadows`, else render off, crowd
    /// deep-opacity.
    #[arg(long)]
    pub shadows: Option<ShadowMode>,
    /// Strand compositing: opaque, oit or oit:K (K-buffer OIT with K fragments per pixel,
    /// default 8), peel or peel:N (depth peeling of N layers, default 32: the slow
    /// reference). Default: the scene's `[look] transparency`, else opaque.
    #[arg(long)]
    pub transparency: Option<Transparency>,
    /// Temporal accumulation: off, or taa (jittered frames blended along exact motion
    /// vectors: steadier sub-pixel strands). Default: the scene's `[look] temporal`, else off.
    #[arg(long)]
    pub temporal: Option<Temporal>,
    /// Seed 000's thick-strand appearance term under LoD: on or off. Default: the scene's
    /// `[look] lod_appearance`, else on.
    #[arg(long, value_parser = parse_switch)]
    pub lod_appearance: Option<bool>,
    /// Multiple scattering between strands under marschner (dual scattering, seed 000: light
    /// hair glows through itself instead of going flat and grey): on or off. Default: the
    /// scene's `[look] multiple_scattering`, else render off, crowd on.
    #[arg(long, value_parser = parse_switch)]
    pub multiple_scattering: Option<bool>,
    /// Strand rasterization: hw (camera-facing strips through the hardware rasterizer), soft
    /// or soft:K (the compute software rasterizer keeping K fragments per pixel sorted,
    /// default 8), auto or auto:K (per bundle: strands drawn at most 4 pixels wide to
    /// software, thicker ones to hardware; the static and LHS paths' stored strands all go to
    /// software). Software needs --msaa 1 and opaque or oit transparency. Default: auto where
    /// the device and the other settings allow it, else hw.
    #[arg(long)]
    pub draw: Option<StrandRaster>,
    /// How the light's passes draw the hair with shadows on: hw (hardware strips) or soft
    /// (the compute software rasterizer: nearest depth by atomic min, deep opacity layers by
    /// fixed-point sums). soft needs the mesh or compute path. Default: soft where the device
    /// and the other settings allow it, else hw.
    #[arg(long)]
    pub shadow_draw: Option<LightRaster>,
}

/// The device a tool draws on.
#[derive(clap::Args, Clone, Debug)]
pub struct DeviceFlags {
    /// Choose the GPU by name substring.
    #[arg(long)]
    pub device: Option<String>,
    /// Enable Vulkan validation layers (any error fails the run).
    #[arg(long)]
    pub validation: bool,
}

impl DeviceFlags {
    /// The context these flags ask for.
    pub fn context_desc(&self) -> crate::vk::ContextDesc {
        crate::vk::ContextDesc::default()
            .validation(self.validation)
            .device(self.device.clone())
    }
}
