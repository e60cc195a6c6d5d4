//! Scene files (TOML): a camera, a light and any number of characters.
//!
//! ```toml
//! size = [1280, 720]
//! [camera]
//! eye = [0.0, 0.1, 0.6]
//! target = [0.0, -0.05, 0.0]
//! fov_y_degrees = 40.0
//! [light]
//! direction = [0.3, 1.0, 0.5]      # toward the light
//! [look]                           # optional; `render` flags override it
//! shading = "marschner"            # placeholder, kajiya-kay, marschner
//! shadows = "deep-opacity"         # off, deep-opacity, approximate
//! msaa = 4                         # samples per pixel
//! transparency = "oit:8"           # opaque, oit[:K] (K-buffer), peel[:N] (depth peeling)
//! temporal = "taa"                 # off, taa (temporal accumulation made for strands)
//! lod_appearance = true            # seed 000's thick-strand term under LoD (default on)
//! multiple_scattering = true       # dual scattering under marschner (default off)
//! [[character]]
//! mesh = "hairmeshes/head_long.obj" # .obj (baked on load) or .hmb; relative to this file
//! style = "hairmeshes/head_long.toml" # optional: default is the style beside the mesh / baked in
//! translation = [0.0, 0.0, 0.0]
//! rotation_y_degrees = 0.0
//! scale = 1.0
//! strands_per_bundle = 64
//! verts_log2 = 5
//! ```

use std::path::{Path, PathBuf};

use glam::{Mat4, Quat, Vec3};
use serde::Deserialize;

use crate::bake::baked_file;
use crate::budget::MemoryBudget;
use crate::error::{HairError, Result};
use crate::model::obj_io::load_hair_mesh_obj;
use crate::model::style::HairStyle;
use crate::render::camera::{validate_camera, validate_light};
use crate::{BakeOptions, BakedHairMesh, bake};

/// Camera block of a scene file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    /// Eye position.
    #[serde(deserialize_with = "crate::model::exact_array::exact")]
    pub eye: [f32; 3],
    /// Target position.
    #[serde(deserialize_with = "crate::model::exact_array::exact")]
    pub target: [f32; 3],
    /// Vertical field of view in degrees.
    #[serde(default = "default_fov")]
    pub fov_y_degrees: f32,
}

fn default_fov() -> f32 {
    40.0
}

/// Light block of a scene file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightDesc {
    /// Direction toward the light.
    #[serde(deserialize_with = "crate::model::exact_array::exact")]
    pub direction: [f32; 3],
}

/// How a scene looks: shading model, shadows, anti-aliasing, transparency (each optional).
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LookDesc {
    /// Strand shading model name (`shade::ShadingModel`).
    pub shading: Option<String>,
    /// Shadow mode name (`render::ShadowMode`).
    pub shadows: Option<String>,
    /// Samples per pixel.
    pub msaa: Option<u32>,
    /// Transparency (`render::Transparency`): `opaque`, `oit[:K]`, `peel[:N]`.
    pub transparency: Option<String>,
    /// Thick-strand appearance term under LoD.
    pub lod_appearance: Option<bool>,
    /// Multiple scattering (dual scattering) under the Marschner model.
    pub multiple_scattering: Option<bool>,
    /// Temporal accumulation (`render::Temporal`): `off` or `taa`.
    pub temporal: Option<String>,
}

impl LookDesc {
    /// The shading model, if given (validated by [`SceneDesc::validate`]).
    pub fn shading_model(&self) -> Option<crate::shade::ShadingModel> {
        self.shading.as_deref().and_then(|s| s.parse().ok())
    }

    /// The shadow mode, if given (validated by [`SceneDesc::validate`]).
    pub fn shadow_mode(&self) -> Option<crate::render::ShadowMode> {
        self.shadows.as_deref().and_then(|s| s.parse().ok())
    }

    /// The transparency mode, if given (validated by [`SceneDesc::validate`]).
    pub fn transparency_mode(&self) -> Option<crate::render::Transparency> {
        self.transparency.as_deref().and_then(|s| s.parse().ok())
    }

    /// The temporal mode, if given (validated by [`SceneDesc::validate`]).
    pub fn temporal_mode(&self) -> Option<crate::render::Temporal> {
        self.temporal.as_deref().and_then(|s| s.parse().ok())
    }
}

/// One character.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CharacterDesc {
    /// Hair mesh `.obj` or baked `.hmb`.
    pub mesh: PathBuf,
    /// Style TOML overriding the baked/beside style.
    pub style: Option<PathBuf>,
    /// World translation.
    #[serde(default, deserialize_with = "crate::model::exact_array::exact")]
    pub translation: [f32; 3],
    /// Rotation about +Y in degrees.
    #[serde(default)]
    pub rotation_y_degrees: f32,
    /// Uniform scale.
    #[serde(default = "one")]
    pub scale: f32,
    /// Strands per average bundle.
    #[serde(default = "default_strands")]
    pub strands_per_bundle: u32,
    /// Vertices per strand are `2^verts_log2 + 1`.
    #[serde(default = "default_verts")]
    pub verts_log2: u32,
}

fn one() -> f32 {
    1.0
}
fn default_strands() -> u32 {
    64
}
fn default_verts() -> u32 {
    5
}

/// A scene file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDesc {
    /// Image size.
    #[serde(default, deserialize_with = "crate::model::exact_array::exact_option")]
    pub size: Option<[u32; 2]>,
    /// Camera (default: frame all characters).
    pub camera: Option<CameraDesc>,
    /// Light (default: from above-front).
    pub light: Option<LightDesc>,
    /// Shading, shadows, MSAA.
    #[serde(default)]
    pub look: LookDesc,
    /// Characters.
    #[serde(rename = "character")]
    pub characters: Vec<CharacterDesc>,
}

/// Most characters in one scene file.
pub const MAX_SCENE_CHARACTERS: usize = 4096;
/// Largest image side of a scene file (as `render --size`).
pub const MAX_IMAGE_SIDE: u32 = 8192;
/// Largest uniform scale of a character.
pub const MAX_SCALE: f32 = 1e4;
/// Largest translation component of a character, metres: strands are placed in 32-bit world
/// coordinates, whose spacing at 1e4 is 1 mm (at 1e6 it is 6 cm, coarser than a strand).
pub const MAX_TRANSLATION: f32 = 1e4;

/// Parse `x,y,z` (three finite numbers).
pub fn parse_vec3(s: &str) -> std::result::Result<Vec3, String> {
    let v: Option<Vec<f32>> = s.split(',').map(|x| x.trim().parse::<f32>().ok()).collect();
    match v.as_deref() {
        Some(&[x, y, z]) if [x, y, z].iter().all(|c| c.is_finite()) => Ok(Vec3::new(x, y, z)),
        _ => Err(format!(
            "bad vector '{s}': expected three finite numbers x,y,z"
        )),
    }
}

/// Parse an image size `WIDTHxHEIGHT` with 1..=[`MAX_IMAGE_SIDE`] per side (tools' `--size`).
pub fn parse_size(s: &str) -> std::result::Result<(u32, u32), String> {
    let bad = || format!("--size '{s}': expected WIDTHxHEIGHT with 1..={MAX_IMAGE_SIDE} per side");
    let (w, h) = s.split_once('x').ok_or_else(bad)?;
    let (w, h): (u32, u32) = (w.parse().map_err(|_| bad())?, h.parse().map_err(|_| bad())?);
    if w == 0 || h == 0 || w > MAX_IMAGE_SIDE || h > MAX_IMAGE_SIDE {
        return Err(bad());
    }
    Ok((w, h))
}

impl SceneDesc {
    /// Load and validate a scene file; relative paths are resolved against its folder.
    pub fn load(path: &Path) -> Result<Self> {
        let text = crate::fsutil::read_text_input(path, crate::fsutil::MAX_TEXT_FILE_BYTES)?;
        Self::parse(
            &path.display().to_string(),
            &text,
            path.parent().unwrap_or(Path::new(".")),
        )
    }

    /// Parse and validate scene TOML text; `name` names it in errors, relative paths are
    /// resolved against `base`.
    pub fn parse(name: &str, text: &str, base: &Path) -> Result<Self> {
        let mut scene: SceneDesc = toml::from_str(text).map_err(|e| {
            HairError::invalid(
                name,
                format!("bad scene: {}", crate::model::style::toml_error(text, &e)),
            )
        })?;
        scene
            .validate()
            .map_err(|what| HairError::invalid(name, what))?;
        for c in &mut scene.characters {
            if c.mesh.is_relative() {
                c.mesh = base.join(&c.mesh);
            }
            if let Some(s) = &mut c.style
                && s.is_relative()
            {
                *s = base.join(&*s);
            }
        }
        Ok(scene)
    }

    /// Every value in range: size, camera and light by the checks `render` uses, characters'
    /// transforms and strand settings.
    pub fn validate(&self) -> std::result::Result<(), String> {
        if let Some([w, h]) = self.size
            && (w == 0 || h == 0 || w > MAX_IMAGE_SIDE || h > MAX_IMAGE_SIDE)
        {
            return Err(format!("size {w}x{h}: 1..={MAX_IMAGE_SIDE} per side"));
        }
        if let Some(c) = &self.camera {
            validate_camera(Vec3::from(c.eye), Vec3::from(c.target), c.fov_y_degrees)
                .map_err(|e| format!("[camera]: {e}"))?;
        }
        if let Some(l) = &self.light {
            validate_light(Vec3::from(l.direction)).map_err(|e| format!("[light]: {e}"))?;
        }
        if let Some(s) = &self.look.shading {
            s.parse::<crate::shade::ShadingModel>()
                .map_err(|e| format!("[look]: {e}"))?;
        }
        if let Some(s) = &self.look.shadows {
            s.parse::<crate::render::ShadowMode>()
                .map_err(|e| format!("[look]: {e}"))?;
        }
        if let Some(s) = &self.look.transparency {
            s.parse::<crate::render::Transparency>()
                .map_err(|e| format!("[look]: {e}"))?;
        }
        if let Some(s) = &self.look.temporal {
            s.parse::<crate::render::Temporal>()
                .map_err(|e| format!("[look]: {e}"))?;
        }
        if let Some(m) = self.look.msaa
            && !(m.is_power_of_two() && m <= 64)
        {
            return Err(format!("[look]: msaa {m} is not 1, 2, 4, 8, 16, 32 or 64"));
        }
        if self.characters.is_empty() {
            return Err("scene has no [[character]]".into());
        }
        if self.characters.len() > MAX_SCENE_CHARACTERS {
            return Err(format!(
                "{} characters, more than {MAX_SCENE_CHARACTERS}",
                self.characters.len()
            ));
        }
        for (i, c) in self.characters.iter().enumerate() {
            let finite = c
                .translation
                .iter()
                .all(|x| x.is_finite() && x.abs() <= MAX_TRANSLATION)
                && c.rotation_y_degrees.is_finite();
            let scale_ok = c.scale > 0.0 && c.scale <= MAX_SCALE;
            if !finite || !scale_ok {
                return Err(format!(
                    "character {i}: transform must be finite (|translation| <= {MAX_TRANSLATION:e}) and scale in (0, {MAX_SCALE:e}]"
                ));
            }
            let params = crate::render::StrandParams {
                strands_per_bundle: c.strands_per_bundle,
                verts_log2: c.verts_log2,
            };
            params
                .validate()
                .map_err(|e| format!("character {i}: {e}"))?;
        }
        Ok(())
    }
}

impl CharacterDesc {
    /// Object-to-world transform.
    pub fn model(&self) -> Mat4 {
        Mat4::from_scale_rotation_translation(
            Vec3::splat(self.scale),
            Quat::from_rotation_y(self.rotation_y_degrees.to_radians()),
            Vec3::from(self.translation),
        )
    }
}

/// Every file [`load_mesh`] reads for `mesh` and `style`: the mesh, the style given, and the
/// style beside an OBJ mesh.
pub fn mesh_inputs(mesh: &Path, style: Option<&Path>) -> Vec<PathBuf> {
    let mut files = vec![mesh.to_path_buf()];
    let is_obj = mesh
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
    if is_obj && let Some(beside) = HairStyle::beside(mesh) {
        files.push(beside);
    }
    files.extend(style.map(Path::to_path_buf));
    files
}

/// Load a mesh (`.obj` is baked on load, within `budget`; anything else is read as a baked
/// file) and its style: `style` if given, else the `.toml` beside an OBJ, else the style stored
/// in the bake.
pub fn load_mesh(
    mesh: &Path,
    style: Option<&Path>,
    budget: MemoryBudget,
) -> Result<(BakedHairMesh, HairStyle)> {
    let is_obj = mesh
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
    let baked = if is_obj {
        let m = load_hair_mesh_obj(mesh)?;
        let s = match HairStyle::beside(mesh) {
            Some(p) => HairStyle::load(&p)?,
            None => HairStyle::default(),
        };
        let options = BakeOptions {
            memory_budget: budget,
            ..Default::default()
        };
        bake(&m, &s, options, |_, _| {})?
    } else {
        baked_file::load(mesh)?
    };
    let style = match style {
        Some(p) => HairStyle::load(p)?,
        None => baked.style,
    };
    Ok((baked, style))
}

#[cfg(test)]
mod look_tests {
    use super::*;

    const CHARACTER: &str = "[[character]]\nmesh = \"a.obj\"\n";

    #[test]
    fn look_block_is_optional_and_checked() {
        let base = Path::new(".");
        let plain = SceneDesc::parse("s.toml", CHARACTER, base).unwrap();
        assert!(plain.look.shading_model().is_none() && plain.look.shadow_mode().is_none());
        let text = format!(
            "[look]\nshading = \"kajiya-kay\"\nshadows = \"approximate\"\nmsaa = 4\ntransparency = \"oit:3\"\nlod_appearance = false\n{CHARACTER}"
        );
        let s = SceneDesc::parse("s.toml", &text, base).unwrap();
        assert_eq!(
            s.look.shading_model(),
            Some(crate::shade::ShadingModel::KajiyaKay)
        );
        assert_eq!(
            s.look.shadow_mode(),
            Some(crate::render::ShadowMode::Approximate)
        );
        assert_eq!(s.look.msaa, Some(4));
        assert_eq!(
            s.look.transparency_mode(),
            Some(crate::render::Transparency::KBuffer { budget: 3 })
        );
        assert_eq!(s.look.lod_appearance, Some(false));
        for (bad, what) in [
            ("shadows = \"soft\"", "unknown shadow mode"),
            ("shading = \"phong\"", "unknown shading model"),
            ("msaa = 3", "msaa 3"),
            ("transparency = \"oit:99\"", "OIT budget 99"),
            ("transparency = \"glass\"", "unknown transparency"),
            ("temporal = \"blur\"", "temporal \"blur\""),
        ] {
            let text = format!("[look]\n{bad}\n{CHARACTER}");
            let e = SceneDesc::parse("s.toml", &text, base)
                .unwrap_err()
                .to_string();
            assert!(e.contains("s.toml") && e.contains(what), "{e}");
        }
    }
}
