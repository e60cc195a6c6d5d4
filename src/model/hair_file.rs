//! Yuksel's `.hair` strand file (the format of cyHairFile, read by many hair tools), so the
//! strands a hair mesh produces can be opened elsewhere and compared with other methods.
//!
//! Layout (little-endian):
//! ```text
//! offset  size  field
//! 0       4     signature "HAIR"
//! 4       4     hair count (u32)
//! 8       4     point count (u32)
//! 12      4     arrays: bit 0 segments, 1 points, 2 thickness, 3 transparency, 4 colours
//! 16      4     default segments per hair (u32)
//! 20      4     default thickness (f32)
//! 24      4     default transparency (f32)
//! 28      12    default colour (3 x f32)
//! 40      88    information (text, NUL padded)
//! 128     ...   segments (u16 per hair), points (3 x f32), thickness (f32), transparency
//!               (f32), colours (3 x f32 per point): each present if its bit is set
//! ```
//! A hair of `s` segments has `s + 1` points; the point count must equal the sum.

use crate::error::{HairError, Result};

/// `arrays` bit: per-hair segment counts.
pub const HAS_SEGMENTS: u32 = 1;
/// `arrays` bit: point positions.
pub const HAS_POINTS: u32 = 2;
/// `arrays` bit: per-point thickness.
pub const HAS_THICKNESS: u32 = 4;
/// `arrays` bit: per-point transparency.
pub const HAS_TRANSPARENCY: u32 = 8;
/// `arrays` bit: per-point colour.
pub const HAS_COLORS: u32 = 16;
/// Header bytes.
pub const HEADER_BYTES: usize = 128;
/// Most points a file may hold (about 3.2 GB of positions); larger counts are refused before
/// anything is allocated.
pub const MAX_POINTS: u64 = 1 << 28;

/// A strand model in `.hair` terms.
#[derive(Clone, Debug, PartialEq)]
pub struct HairFile {
    /// Segments of each hair (`None`: every hair has `default_segments`).
    pub segments: Option<Vec<u16>>,
    /// Default segments per hair.
    pub default_segments: u32,
    /// Point positions.
    pub points: Vec<[f32; 3]>,
    /// Per-point thickness (`None`: `default_thickness`).
    pub thickness: Option<Vec<f32>>,
    /// Default thickness.
    pub default_thickness: f32,
    /// Per-point transparency (`None`: `default_transparency`).
    pub transparency: Option<Vec<f32>>,
    /// Default transparency.
    pub default_transparency: f32,
    /// Per-point colour (`None`: `default_color`).
    pub colors: Option<Vec<[f32; 3]>>,
    /// Default colour.
    pub default_color: [f32; 3],
    /// Information text (at most 88 bytes; longer text is cut on a character boundary).
    pub info: String,
    /// Number of hairs.
    pub hair_count: u32,
}

/// The counts of a `.hair` header (hairs, points, array flags) after its signature, flags,
/// point limit and the file's length are checked.
fn checked_header(name: &str, bytes: &[u8]) -> Result<(u32, u32, u32)> {
    let bad = |what: String| HairError::invalid(name, what);
    if bytes.len() < HEADER_BYTES || &bytes[..4] != b"HAIR" {
        return Err(bad(
            "not a .hair file (no 128-byte header with signature HAIR)".into(),
        ));
    }
    let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().expect("4 bytes"));
    let (hair_count, point_count, arrays) = (u32_at(4), u32_at(8), u32_at(12));
    if arrays & !0x1F != 0 {
        return Err(bad(format!("unknown array flags {arrays:#x}")));
    }
    if arrays & HAS_POINTS == 0 {
        return Err(bad("the file has no point array".into()));
    }
    if point_count as u64 > MAX_POINTS {
        return Err(bad(format!(
            "{point_count} points: more than {MAX_POINTS} this reader accepts"
        )));
    }
    let (hairs, points) = (hair_count as u64, point_count as u64);
    let per_point = 12
        + 4 * (arrays & HAS_THICKNESS != 0) as u64
        + 4 * (arrays & HAS_TRANSPARENCY != 0) as u64
        + 12 * (arrays & HAS_COLORS != 0) as u64;
    let expected =
        HEADER_BYTES as u64 + 2 * hairs * (arrays & HAS_SEGMENTS != 0) as u64 + per_point * points;
    if bytes.len() as u64 != expected {
        return Err(bad(format!(
            "{} bytes, but the header ({hair_count} hairs, {point_count} points, arrays {arrays:#x}) needs {expected}",
            bytes.len()
        )));
    }
    Ok((hair_count, point_count, arrays))
}

impl HairFile {
    /// Segments of hair `i`.
    pub fn hair_segments(&self, i: usize) -> u32 {
        self.segments
            .as_ref()
            .map_or(self.default_segments, |s| s[i] as u32)
    }

    /// Serialise.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut arrays = HAS_POINTS;
        for (present, bit) in [
            (self.segments.is_some(), HAS_SEGMENTS),
            (self.thickness.is_some(), HAS_THICKNESS),
            (self.transparency.is_some(), HAS_TRANSPARENCY),
            (self.colors.is_some(), HAS_COLORS),
        ] {
            if present {
                arrays |= bit;
            }
        }
        let mut out = Vec::with_capacity(HEADER_BYTES + self.points.len() * 16);
        out.extend_from_slice(b"HAIR");
        out.extend_from_slice(&self.hair_count.to_le_bytes());
        out.extend_from_slice(&(self.points.len() as u32).to_le_bytes());
        out.extend_from_slice(&arrays.to_le_bytes());
        out.extend_from_slice(&self.default_segments.to_le_bytes());
        out.extend_from_slice(&self.default_thickness.to_le_bytes());
        out.extend_from_slice(&self.default_transparency.to_le_bytes());
        for c in self.default_color {
            out.extend_from_slice(&c.to_le_bytes());
        }
        let mut info = [0u8; 88];
        let mut end = self.info.len().min(88);
        while !self.info.is_char_boundary(end) {
            end -= 1;
        }
        info[..end].copy_from_slice(&self.info.as_bytes()[..end]);
        out.extend_from_slice(&info);
        if let Some(s) = &self.segments {
            s.iter()
                .for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
        }
        self.points
            .iter()
            .flatten()
            .for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
        for arr in [&self.thickness, &self.transparency].into_iter().flatten() {
            arr.iter()
                .for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
        }
        if let Some(c) = &self.colors {
            c.iter()
                .flatten()
                .for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
        }
        out
    }

    /// Parse `bytes`; `name` names the file in errors. Checks the signature, that every array
    /// the header announces is there and nothing follows, that the segment counts add up to
    /// the points, and that every value is finite, before allocating.
    pub fn parse(name: &str, bytes: &[u8]) -> Result<Self> {
        let bad = |what: String| HairError::invalid(name, what);
        let (hair_count, point_count, arrays) = checked_header(name, bytes)?;
        let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().expect("4 bytes"));
        let f32_at = |o: usize| f32::from_le_bytes(bytes[o..o + 4].try_into().expect("4 bytes"));
        let (hairs, points) = (hair_count as u64, point_count as u64);
        let default_segments = u32_at(16);
        let mut o = HEADER_BYTES;
        let segments = if arrays & HAS_SEGMENTS != 0 {
            let s: Vec<u16> = bytes[o..o + 2 * hair_count as usize]
                .chunks_exact(2)
                .map(|c| u16::from_le_bytes([c[0], c[1]]))
                .collect();
            o += 2 * hair_count as usize;
            Some(s)
        } else {
            None
        };
        let total: u64 = match &segments {
            Some(s) => s.iter().map(|&x| x as u64 + 1).sum(),
            None => hairs * (default_segments as u64 + 1),
        };
        if total != points {
            return Err(bad(format!(
                "the hairs' segments need {total} points, the header says {point_count}"
            )));
        }
        let mut floats = |n: usize| -> Result<Vec<f32>> {
            let v: Vec<f32> = bytes[o..o + 4 * n]
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect();
            o += 4 * n;
            if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                return Err(bad(format!("value {i} of an array is not finite")));
            }
            Ok(v)
        };
        let n = point_count as usize;
        let triples = |v: Vec<f32>| v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let points = triples(floats(3 * n)?);
        let thickness = (arrays & HAS_THICKNESS != 0)
            .then(|| floats(n))
            .transpose()?;
        let transparency = (arrays & HAS_TRANSPARENCY != 0)
            .then(|| floats(n))
            .transpose()?;
        let colors = (arrays & HAS_COLORS != 0)
            .then(|| floats(3 * n).map(triples))
            .transpose()?;
        let defaults = [f32_at(20), f32_at(24), f32_at(28), f32_at(32), f32_at(36)];
        if defaults.iter().any(|d| !d.is_finite()) {
            return Err(bad("a default value is not finite".into()));
        }
        let info_bytes = &bytes[40..128];
        let end = info_bytes.iter().position(|&b| b == 0).unwrap_or(88);
        Ok(HairFile {
            segments,
            default_segments,
            points,
            thickness,
            default_thickness: defaults[0],
            transparency,
            default_transparency: defaults[1],
            colors,
            default_color: [defaults[2], defaults[3], defaults[4]],
            info: String::from_utf8_lossy(&info_bytes[..end]).into_owned(),
            hair_count,
        })
    }

    /// Read a `.hair` file (regular files only, at most the mesh-file size cap).
    pub fn load(path: &std::path::Path) -> Result<Self> {
        let bytes = crate::fsutil::read_input(path, crate::fsutil::MAX_MESH_FILE_BYTES)?;
        Self::parse(&path.display().to_string(), &bytes)
    }

    /// Strands of `verts_per_strand` points each (the CPU reference generator's `StrandSet`)
    /// as a `.hair` model: positions and per-point thickness (object units), `color` as the
    /// default colour.
    pub fn from_strands(
        positions: &[glam::Vec3],
        widths: &[f32],
        verts_per_strand: usize,
        (color, info): ([f32; 3], &str),
    ) -> Result<Self> {
        let segments = verts_per_strand.saturating_sub(1);
        if segments == 0 || segments > u16::MAX as usize {
            return Err(HairError::invalid(
                "strands",
                format!("{segments} segments per strand cannot be written"),
            ));
        }
        if positions.len() as u64 > MAX_POINTS {
            return Err(HairError::invalid(
                "strands",
                format!("{} points: more than {MAX_POINTS}", positions.len()),
            ));
        }
        Ok(HairFile {
            segments: None,
            default_segments: segments as u32,
            points: positions.iter().map(|p| p.to_array()).collect(),
            thickness: Some(widths.to_vec()),
            default_thickness: widths.first().copied().unwrap_or(0.0),
            transparency: None,
            default_transparency: 0.0,
            colors: None,
            default_color: color,
            info: info.to_string(),
            hair_count: (positions.len() / verts_per_strand) as u32,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> HairFile {
        HairFile {
            segments: Some(vec![2, 1]),
            default_segments: 0,
            points: vec![
                [0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 2.0, 0.5],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
            ],
            thickness: Some(vec![0.1, 0.09, 0.08, 0.1, 0.05]),
            default_thickness: 0.1,
            transparency: Some(vec![0.0; 5]),
            default_transparency: 0.0,
            colors: Some(vec![[0.3, 0.2, 0.1]; 5]),
            default_color: [0.3, 0.2, 0.1],
            info: "hairmesh test".into(),
            hair_count: 2,
        }
    }

    #[test]
    fn round_trips_and_rejects_bad_files() {
        let h = sample();
        let bytes = h.to_bytes();
        assert_eq!(bytes.len(), 128 + 4 + 5 * (12 + 4 + 4 + 12));
        let back = HairFile::parse("t.hair", &bytes).unwrap();
        assert_eq!(back, h);
        assert_eq!(back.to_bytes(), bytes);
        let cases: Vec<(Vec<u8>, &str)> = vec![
            (bytes[..100].to_vec(), "no 128-byte header"),
            (bytes[..bytes.len() - 4].to_vec(), "needs"),
            ([bytes.clone(), vec![0]].concat(), "needs"),
            (
                {
                    let mut b = bytes.clone();
                    b[128] = 7; // first hair: 7 segments
                    b
                },
                "segments need",
            ),
            (
                {
                    let mut b = bytes.clone();
                    let o = 128 + 4 + 4;
                    b[o..o + 4].copy_from_slice(&f32::NAN.to_le_bytes());
                    b
                },
                "not finite",
            ),
            (
                {
                    let mut b = bytes.clone();
                    b[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
                    b
                },
                "more than",
            ),
        ];
        for (b, what) in cases {
            let e = HairFile::parse("t.hair", &b).unwrap_err().to_string();
            assert!(e.starts_with("t.hair") && e.contains(what), "{e}");
        }
    }
}
