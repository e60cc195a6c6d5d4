//! Strand models made elsewhere, as polylines from root to tip: TressFX `.tfx` files and
//! Yuksel's `.hair` files ([`super::hair_file`]). The input of `fit`.
//!
//! TressFX 4.0 `.tfx` layout (little-endian):
//! ```text
//! offset  size  field
//! 0       4     version (f32, 4.0)
//! 4       4     strand count (u32)
//! 8       4     vertices per strand (u32)
//! 12      20    byte offsets of: positions (float4 per vertex), strand UVs, vertex UVs,
//!               strand thickness, vertex colours (0: absent)
//! 32      128   reserved
//! 160     ...   the arrays; positions are x, y, z, w (w: TressFX's inverse mass, ignored)
//! ```
//! Vertex 0 of each strand is its root.

use std::path::Path;

use glam::Vec3;

use super::hair_file::{HairFile, MAX_POINTS};
use crate::error::{HairError, Result};

/// Bytes of the TressFX header.
pub const TFX_HEADER_BYTES: usize = 160;

/// A strand model: polylines from root to tip.
#[derive(Clone, Debug, PartialEq)]
pub struct StrandModel {
    /// Source name (file path) for messages.
    pub name: String,
    /// Strands, root first; every one has at least two points.
    pub strands: Vec<Vec<Vec3>>,
    /// Per-point widths (object units), when the file has them (Alembic curves); the same
    /// shape as `strands`.
    pub widths: Option<Vec<Vec<f32>>>,
    /// Size of the file it was read from, bytes.
    pub file_bytes: u64,
}

impl StrandModel {
    /// Read a `.tfx`, `.hair` or Alembic `.abc` file (chosen by extension).
    pub fn load(path: &Path) -> Result<Self> {
        let bytes = crate::fsutil::read_input(path, crate::fsutil::MAX_MESH_FILE_BYTES)?;
        let name = path.display().to_string();
        match path.extension().and_then(|e| e.to_str()) {
            Some(e) if e.eq_ignore_ascii_case("tfx") => Self::from_tfx(&name, &bytes),
            Some(e) if e.eq_ignore_ascii_case("hair") => {
                Self::from_hair(&name, &HairFile::parse(&name, &bytes)?, bytes.len() as u64)
            }
            Some(e) if e.eq_ignore_ascii_case("abc") => Self::from_alembic(&name, &bytes),
            _ => Err(HairError::invalid(
                name,
                "unknown strand file type (expected .tfx, .hair or .abc)",
            )),
        }
    }

    /// All curves of all curve objects of `bytes` as one strand model (widths kept when every
    /// object has them).
    pub fn from_alembic(name: &str, bytes: &[u8]) -> Result<Self> {
        let objects = super::alembic::read_curves(name, bytes)?;
        let all_widths = objects.iter().all(|o| o.widths.is_some());
        let mut strands = Vec::new();
        let mut widths = Vec::new();
        for o in objects {
            strands.extend(o.strands);
            if let Some(w) = o.widths {
                widths.extend(w);
            }
        }
        StrandModel::checked(
            name,
            strands,
            all_widths.then_some(widths),
            bytes.len() as u64,
        )
    }

    /// Parse a TressFX 4.0 file; checks every count against the file size and every position
    /// before allocating or returning.
    pub fn from_tfx(name: &str, bytes: &[u8]) -> Result<Self> {
        let bad = |what: String| HairError::invalid(name, what);
        if bytes.len() < TFX_HEADER_BYTES {
            return Err(bad(format!(
                "{} bytes: shorter than the {TFX_HEADER_BYTES}-byte TressFX header",
                bytes.len()
            )));
        }
        let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().expect("4 bytes"));
        let version = f32::from_le_bytes(bytes[0..4].try_into().expect("4 bytes"));
        if !(version.is_finite() && (1.0..=16.0).contains(&version)) {
            return Err(bad(format!(
                "version {version} is not a TressFX version (expected 4.0)"
            )));
        }
        let (strands, verts, offset) = (u32_at(4) as u64, u32_at(8) as u64, u32_at(12) as u64);
        if strands == 0 {
            return Err(bad("no strands".into()));
        }
        if verts < 2 {
            return Err(bad(format!(
                "{verts} vertices per strand: a strand needs at least 2"
            )));
        }
        let points = strands * verts;
        if points > MAX_POINTS {
            return Err(bad(format!(
                "{strands} strands x {verts} vertices: more than {MAX_POINTS} points"
            )));
        }
        if offset < TFX_HEADER_BYTES as u64 {
            return Err(bad(format!(
                "positions at byte {offset}, inside the {TFX_HEADER_BYTES}-byte header"
            )));
        }
        let need = offset + points * 16;
        if need > bytes.len() as u64 {
            return Err(bad(format!(
                "{strands} strands x {verts} vertices need {need} bytes, the file has {} (truncated?)",
                bytes.len()
            )));
        }
        let mut out = Vec::with_capacity(strands as usize);
        let mut o = offset as usize;
        for s in 0..strands {
            let mut strand = Vec::with_capacity(verts as usize);
            for v in 0..verts {
                let f = |k: usize| {
                    f32::from_le_bytes(bytes[o + 4 * k..o + 4 * k + 4].try_into().expect("4 bytes"))
                };
                let p = Vec3::new(f(0), f(1), f(2));
                if !p.is_finite() {
                    return Err(bad(format!(
                        "strand {s} vertex {v}: position {p} is not finite"
                    )));
                }
                strand.push(p);
                o += 16;
            }
            out.push(strand);
        }
        Self::checked(name, out, None, bytes.len() as u64)
    }

    /// The hairs of a `.hair` model.
    pub fn from_hair(name: &str, hair: &HairFile, file_bytes: u64) -> Result<Self> {
        let mut out = Vec::with_capacity(hair.hair_count as usize);
        let thickness = hair
            .thickness
            .as_ref()
            .filter(|t| t.len() == hair.points.len());
        let mut widths = thickness.map(|_| Vec::with_capacity(hair.hair_count as usize));
        let mut o = 0usize;
        for i in 0..hair.hair_count as usize {
            let n = hair.hair_segments(i) as usize + 1;
            out.push(
                hair.points[o..o + n]
                    .iter()
                    .map(|p| Vec3::from_array(*p))
                    .collect(),
            );
            if let (Some(w), Some(t)) = (widths.as_mut(), thickness) {
                w.push(t[o..o + n].to_vec());
            }
            o += n;
        }
        Self::checked(name, out, widths, file_bytes)
    }

    /// Strands with at least two points and non-zero length (with their `widths`, one per
    /// point, when given); errors when none is left.
    pub(crate) fn checked(
        name: &str,
        strands: Vec<Vec<Vec3>>,
        widths: Option<Vec<Vec<f32>>>,
        file_bytes: u64,
    ) -> Result<Self> {
        let keep = |s: &Vec<Vec3>| s.len() >= 2 && polyline_length(s) > 0.0;
        let widths = widths.map(|w| {
            w.into_iter()
                .zip(&strands)
                .filter(|(_, s)| keep(s))
                .map(|(w, _)| w)
                .collect()
        });
        let strands: Vec<Vec<Vec3>> = strands.into_iter().filter(keep).collect();
        if strands.is_empty() {
            return Err(HairError::invalid(
                name,
                "no strand with two distinct points",
            ));
        }
        Ok(StrandModel {
            name: name.into(),
            strands,
            widths,
            file_bytes,
        })
    }

    /// Bounding box of every point.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        super::hair_mesh::bounds(self.strands.iter().flatten().copied())
    }

    /// Length of the bounding box diagonal.
    pub fn diagonal(&self) -> f32 {
        let (lo, hi) = self.bounds();
        (hi - lo).length()
    }

    /// Number of points.
    pub fn point_count(&self) -> usize {
        self.strands.iter().map(|s| s.len()).sum()
    }
}

/// Length of a polyline.
pub fn polyline_length(p: &[Vec3]) -> f32 {
    p.windows(2).map(|w| w[0].distance(w[1])).sum()
}

/// The point at arc length `s` along polyline `p` (past the tip: extended along the last
/// segment).
pub fn point_at_length(p: &[Vec3], s: f32) -> Vec3 {
    let mut left = s.max(0.0);
    for w in p.windows(2) {
        let l = w[0].distance(w[1]);
        if left <= l && l > 0.0 {
            return w[0].lerp(w[1], left / l);
        }
        left -= l;
    }
    let n = p.len();
    let dir = (p[n - 1] - p[n - 2]).normalize_or_zero();
    p[n - 1] + dir * left
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tfx(strands: u32, verts: u32, points: &[[f32; 4]]) -> Vec<u8> {
        let mut b = Vec::new();
        b.extend_from_slice(&4.0f32.to_le_bytes());
        b.extend_from_slice(&strands.to_le_bytes());
        b.extend_from_slice(&verts.to_le_bytes());
        b.extend_from_slice(&160u32.to_le_bytes());
        b.resize(160, 0);
        for p in points {
            for x in p {
                b.extend_from_slice(&x.to_le_bytes());
            }
        }
        b
    }

    #[test]
    fn reads_tfx_and_rejects_bad_files() {
        let pts = [
            [0.0, 0.0, 0.0, 1.0],
            [0.0, 1.0, 0.0, 1.0],
            [1.0, 0.0, 0.0, 1.0],
            [1.0, 2.0, 0.0, 1.0],
        ];
        let m = StrandModel::from_tfx("a.tfx", &tfx(2, 2, &pts)).unwrap();
        assert_eq!(m.strands.len(), 2);
        assert_eq!(m.strands[1][1], Vec3::new(1.0, 2.0, 0.0));
        let one_line = |e: HairError| {
            let s = e.to_string();
            assert!(s.starts_with("b.tfx: ") && !s.contains('\n'), "{s}");
            s
        };
        let e = StrandModel::from_tfx("b.tfx", &tfx(2, 2, &pts)[..170]).unwrap_err();
        assert!(one_line(e).contains("truncated"));
        let e = StrandModel::from_tfx("b.tfx", &tfx(3, 2, &pts)).unwrap_err();
        assert!(one_line(e).contains("need"));
        let e = StrandModel::from_tfx("b.tfx", &tfx(0, 2, &[])).unwrap_err();
        assert!(one_line(e).contains("no strands"));
        let mut nan = pts;
        nan[3][1] = f32::NAN;
        let e = StrandModel::from_tfx("b.tfx", &tfx(2, 2, &nan)).unwrap_err();
        assert!(one_line(e).contains("strand 1 vertex 1"));
        let e = StrandModel::from_tfx("b.tfx", &tfx(u32::MAX, u32::MAX, &pts)).unwrap_err();
        assert!(one_line(e).contains("more than"));
        let e = StrandModel::from_tfx("b.tfx", &[0u8; 40]).unwrap_err();
        assert!(one_line(e).contains("header"));
        let e = StrandModel::from_tfx("b.tfx", &tfx(1, 2, &[[0.0; 4], [0.0; 4]])).unwrap_err();
        assert!(one_line(e).contains("two distinct"));
    }

    #[test]
    fn arc_length_resampling() {
        let p = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0)];
        assert_eq!(polyline_length(&p), 2.0);
        assert_eq!(point_at_length(&p, 0.5), Vec3::new(0.5, 0.0, 0.0));
        assert_eq!(point_at_length(&p, 1.5), Vec3::new(1.0, 0.5, 0.0));
        assert_eq!(point_at_length(&p, 3.0), Vec3::new(1.0, 2.0, 0.0));
    }
}
