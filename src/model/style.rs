//! Procedural styling parameters (paper 003, section 3.4): offsets applied in the `u v w`
//! styling frame with object-space amplitudes, so styling follows a deforming hair mesh without
//! being stretched by it.
//!
//! [`HairStyle`] is `#[repr(C)]`; `src/render/core/shared.rs` emits it field for field as
//! `struct HairStyle` into the generated `shared.glsl` (std430), and a test checks the layouts
//! agree. Operations, applied to strand vertex `k` of `ns` (`s = k / ns`, `w` the styling
//! coordinate, `ramp` = `smoothstep(0, root_ramp, w)`):
//! - **length variation**: the strand ends at `(1 - length_variation * rand)` of the bundle length;
//! - **clumping**: `p += clump_strength * s^clump_power * (centre(r) - p)` toward the bundle's
//!   centre curve;
//! - **curl** (helix): `curl_radius * ramp * (cos a, sin a)` in the `u v` plane with
//!   `a = 2 pi (curl_frequency * w + curl_phase_jitter * rand)`;
//! - **wave**: `wave_amplitude * ramp * sin(2 pi (wave_frequency * w + wave_phase_jitter * rand))`
//!   along `cos(wave_angle) u + sin(wave_angle) v`;
//! - **frizz**: `frizz_amplitude * s^frizz_power * noise3(w * frizz_frequency)` in `u v w`, smooth
//!   value noise per strand;
//! - **thickness**: width `strand_width * mix(1, tip_width_ratio, s^taper_power)`.

use std::path::Path;

use bytemuck::{Pod, Zeroable};
use serde::{Deserialize, Serialize};

use crate::error::{HairError, Result};

/// Styling parameters shared by the CPU reference and the shaders (std430 layout).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HairStyle {
    /// Seed of all per-strand random values.
    pub seed: u32,
    /// Strand width at the root, object units.
    pub strand_width: f32,
    /// Tip width as a fraction of the root width.
    pub tip_width_ratio: f32,
    /// Exponent of the taper from root to tip.
    pub taper_power: f32,
    /// Largest fraction by which a strand is shorter than its bundle, in `[0, 1)`.
    pub length_variation: f32,
    /// `w` distance over which curl and wave fade in from the root (0: no fade).
    pub root_ramp: f32,
    /// Pull toward the bundle centre at the tip, in `[0, 1]`.
    pub clump_strength: f32,
    /// Exponent shaping clumping along the strand.
    pub clump_power: f32,
    /// Helix radius, object units.
    pub curl_radius: f32,
    /// Helix turns per unit of `w`.
    pub curl_frequency: f32,
    /// Random phase spread of the helix per strand, in turns.
    pub curl_phase_jitter: f32,
    /// Wave amplitude, object units.
    pub wave_amplitude: f32,
    /// Wave periods per unit of `w`.
    pub wave_frequency: f32,
    /// Wave direction in the `u v` plane, radians.
    pub wave_angle: f32,
    /// Random phase spread of the wave per strand, in periods.
    pub wave_phase_jitter: f32,
    /// Frizz amplitude, object units.
    pub frizz_amplitude: f32,
    /// Frizz noise cells per unit of `w`.
    pub frizz_frequency: f32,
    /// Exponent shaping frizz along the strand.
    pub frizz_power: f32,
    /// 1: strands per bundle proportional to root area (uniform density); 0: equal per bundle.
    pub density_by_area: u32,
    /// Base colour, linear RGB.
    #[serde(deserialize_with = "crate::model::exact_array::exact")]
    pub color: [f32; 3],
    /// Longitudinal roughness of the Marschner lobes: width `beta` of the R lobe in radians
    /// (TT gets `beta / 2`, TRT `2 beta`).
    pub roughness: f32,
    /// Cuticle tilt `alpha` in degrees: the R lobe shifts by `-alpha`, TT by `alpha / 2`, TRT by
    /// `3 alpha / 2` (Marschner et al. 2003).
    pub cuticle_tilt_degrees: f32,
}

impl HairStyle {
    /// The same style for a mesh scaled by `s` (units per old unit): widths, radii and
    /// amplitudes scale with it, frequencies per unit of `w` inversely.
    pub fn scaled(self, s: f32) -> Self {
        HairStyle {
            strand_width: self.strand_width * s,
            root_ramp: self.root_ramp * s,
            curl_radius: self.curl_radius * s,
            curl_frequency: self.curl_frequency / s,
            wave_amplitude: self.wave_amplitude * s,
            wave_frequency: self.wave_frequency / s,
            frizz_amplitude: self.frizz_amplitude * s,
            frizz_frequency: self.frizz_frequency / s,
            ..self
        }
    }
}

impl Default for HairStyle {
    fn default() -> Self {
        HairStyle {
            seed: 1,
            strand_width: 0.002,
            tip_width_ratio: 0.3,
            taper_power: 2.0,
            length_variation: 0.15,
            root_ramp: 0.05,
            clump_strength: 0.2,
            clump_power: 1.5,
            curl_radius: 0.0,
            curl_frequency: 0.0,
            curl_phase_jitter: 1.0,
            wave_amplitude: 0.0,
            wave_frequency: 0.0,
            wave_angle: 0.0,
            wave_phase_jitter: 0.2,
            frizz_amplitude: 0.002,
            frizz_frequency: 8.0,
            frizz_power: 1.0,
            density_by_area: 1,
            color: [0.35, 0.2, 0.1],
            roughness: 0.25,
            cuticle_tilt_degrees: 3.0,
        }
    }
}

/// A TOML error as one line: `line N: message` (the key's line), without the source excerpt.
pub fn toml_error(text: &str, e: &toml::de::Error) -> String {
    match e.span() {
        Some(span) => {
            let end = span.start.min(text.len());
            let line = text.as_bytes()[..end]
                .iter()
                .filter(|&&b| b == b'\n')
                .count()
                + 1;
            let key = text
                .lines()
                .nth(line - 1)
                .and_then(|l| l.split('=').next())
                .map(str::trim)
                .filter(|k| !k.is_empty() && !k.starts_with('['))
                .map(|k| format!(" ({k})"))
                .unwrap_or_default();
            format!("line {line}{key}: {}", e.message().trim())
        }
        None => e.message().trim().to_string(),
    }
}

/// Largest melanin concentration accepted (black hair is about 8).
pub const MAX_MELANIN: f32 = 50.0;

/// `[eumelanin, pheomelanin]` from a TOML value: two finite numbers in `0..=MAX_MELANIN`.
fn parse_melanin(v: &toml::Value) -> std::result::Result<[f32; 2], String> {
    let items = v
        .as_array()
        .filter(|a| a.len() == 2)
        .ok_or("expected [eumelanin, pheomelanin]")?;
    let mut m = [0.0f32; 2];
    for (slot, item) in m.iter_mut().zip(items) {
        let x = item
            .as_float()
            .or_else(|| item.as_integer().map(|i| i as f64))
            .ok_or("expected numbers")?;
        if !(0.0..=MAX_MELANIN as f64).contains(&x) {
            return Err(format!("{x} is outside 0..={MAX_MELANIN}"));
        }
        *slot = x as f32;
    }
    Ok(m)
}

impl HairStyle {
    /// Parse a style from TOML text; `name` is used in errors. Besides the fields, the text
    /// may give `melanin = [eumelanin, pheomelanin]` (concentrations, 0..=50) instead of
    /// `color`: the colour is then the fibre's transmittance per diameter for that melanin
    /// ([`crate::shade::melanin_color`]).
    pub fn from_toml(name: &str, text: &str) -> Result<Self> {
        let bad = |e: &toml::de::Error| {
            HairError::invalid(name, format!("bad style: {}", toml_error(text, e)))
        };
        let mut table: toml::Table = toml::from_str(text).map_err(|e| bad(&e))?;
        let style: HairStyle = match table.remove("melanin") {
            // Parsed from the text itself, so errors keep their line.
            None => toml::from_str(text).map_err(|e| bad(&e))?,
            Some(melanin) => {
                if table.contains_key("color") {
                    return Err(HairError::invalid(
                        name,
                        "bad style: give color or melanin, not both",
                    ));
                }
                let m = parse_melanin(&melanin)
                    .map_err(|e| HairError::invalid(name, format!("bad style: melanin: {e}")))?;
                let mut s: HairStyle = table.try_into().map_err(|e: toml::de::Error| {
                    HairError::invalid(name, format!("bad style: {}", e.message().trim()))
                })?;
                s.color = crate::shade::melanin_color(m[0], m[1]).to_array();
                s
            }
        };
        style.validate(name)?;
        Ok(style)
    }

    /// Load a style TOML file.
    pub fn load(path: &Path) -> Result<Self> {
        let text = crate::fsutil::read_text_input(path, crate::fsutil::MAX_TEXT_FILE_BYTES)?;
        Self::from_toml(&path.display().to_string(), &text)
    }

    /// Style file that sits next to a mesh: `foo.obj` -> `foo.toml`, if it exists.
    pub fn beside(mesh: &Path) -> Option<std::path::PathBuf> {
        let p = mesh.with_extension("toml");
        p.is_file().then_some(p)
    }

    /// Reject values that would produce NaN or nonsense strands.
    pub fn validate(&self, name: &str) -> Result<()> {
        let floats = [
            ("strand_width", self.strand_width),
            ("tip_width_ratio", self.tip_width_ratio),
            ("taper_power", self.taper_power),
            ("length_variation", self.length_variation),
            ("root_ramp", self.root_ramp),
            ("clump_strength", self.clump_strength),
            ("clump_power", self.clump_power),
            ("curl_radius", self.curl_radius),
            ("curl_frequency", self.curl_frequency),
            ("curl_phase_jitter", self.curl_phase_jitter),
            ("wave_amplitude", self.wave_amplitude),
            ("wave_frequency", self.wave_frequency),
            ("wave_angle", self.wave_angle),
            ("wave_phase_jitter", self.wave_phase_jitter),
            ("frizz_amplitude", self.frizz_amplitude),
            ("frizz_frequency", self.frizz_frequency),
            ("frizz_power", self.frizz_power),
            ("color[0]", self.color[0]),
            ("color[1]", self.color[1]),
            ("color[2]", self.color[2]),
            ("roughness", self.roughness),
            ("cuticle_tilt_degrees", self.cuticle_tilt_degrees),
        ];
        for (field, v) in floats {
            if !v.is_finite() {
                return Err(HairError::invalid(
                    name,
                    format!("style field {field} is not finite"),
                ));
            }
            if v < 0.0 && field != "wave_angle" && field != "cuticle_tilt_degrees" {
                return Err(HairError::invalid(
                    name,
                    format!("style field {field} must be >= 0, got {v}"),
                ));
            }
        }
        let check = |ok: bool, what: &str| {
            if ok {
                Ok(())
            } else {
                Err(HairError::invalid(name, format!("style: {what}")))
            }
        };
        check(self.strand_width > 0.0, "strand_width must be > 0")?;
        check(self.length_variation < 1.0, "length_variation must be < 1")?;
        check(self.clump_strength <= 1.0, "clump_strength must be <= 1")?;
        check(self.density_by_area <= 1, "density_by_area must be 0 or 1")?;
        check(
            (0.1..=1.0).contains(&self.roughness),
            "roughness must be in [0.1, 1] radians",
        )?;
        check(
            self.cuticle_tilt_degrees.abs() <= 20.0,
            "cuticle_tilt_degrees must be in [-20, 20]",
        )?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn toml_round_trip_and_defaults() {
        let s = HairStyle::from_toml("t", "curl_radius = 0.01\ncurl_frequency = 20.0\n").unwrap();
        assert_eq!(s.curl_radius, 0.01);
        assert_eq!(s.strand_width, HairStyle::default().strand_width);
        let text = toml::to_string(&s).unwrap();
        assert_eq!(HairStyle::from_toml("t", &text).unwrap(), s);
    }

    #[test]
    fn rejects_bad_styles() {
        let e = HairStyle::from_toml("s.toml", "curl_radus = 1.0")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("s.toml: bad style") && e.contains("curl_radus"),
            "{e}"
        );
        let e = HairStyle::from_toml("s.toml", "strand_width = nan")
            .unwrap_err()
            .to_string();
        assert!(e.contains("strand_width is not finite"), "{e}");
        let e = HairStyle::from_toml("s.toml", "length_variation = 1.5")
            .unwrap_err()
            .to_string();
        assert!(e.contains("length_variation"), "{e}");
    }

    #[test]
    fn melanin_gives_the_colour() {
        let dark = HairStyle::from_toml("t", "melanin = [8.0, 0.0]").unwrap();
        let blond = HairStyle::from_toml("t", "melanin = [0.3, 0.1]\nroughness = 0.3").unwrap();
        let red = HairStyle::from_toml("t", "melanin = [0.3, 1.5]").unwrap();
        assert_eq!(blond.roughness, 0.3);
        assert!(dark.color.iter().all(|&c| c < 0.05), "{:?}", dark.color);
        assert!(blond.color.iter().all(|&c| c > 0.55), "{:?}", blond.color);
        // Red hair: red well above green, green above blue.
        assert!(red.color[0] > 1.4 * red.color[1] && red.color[1] > red.color[2]);
        assert_eq!(
            blond.color,
            crate::shade::melanin_color(0.3, 0.1).to_array()
        );
        for (bad, what) in [
            ("melanin = [1.0]", "expected [eumelanin"),
            ("melanin = [1.0, -1.0]", "outside"),
            ("melanin = [\"a\", 1.0]", "expected numbers"),
            ("melanin = [1.0, 0.0]\ncolor = [0.1, 0.1, 0.1]", "not both"),
            ("melanin = [1.0, 0.0]\nstrand_widht = 0.1", "strand_widht"),
        ] {
            let e = HairStyle::from_toml("s.toml", bad).unwrap_err().to_string();
            assert!(
                e.starts_with("s.toml: bad style") && e.contains(what),
                "{bad}: {e}"
            );
        }
    }
}
