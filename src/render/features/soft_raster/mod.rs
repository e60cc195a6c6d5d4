//! The software rasterizer for thin strands ([`StrandRaster`]), the third way strands reach
//! the image after hardware strips drawn from the mesh path or the vertex pool (after Tafuri,
//! "Strand-based Hair Rendering in Frostbite", 2019, and Lipp et al., "High-Performance
//! Real-Time Implicit Strand-Based Hair Rendering via Software Rasterization", 2025).
//!
//! 1. **Segments.** The strand builders of either generation path (`generate.comp`,
//!    `strands.mesh`, through `soft_segments.glsl`) shade each vertex of a software bundle and
//!    append its projected segments ([`SoftSegment`], 32 bytes) to a bounded buffer; a
//!    workgroup reserves its segments with one atomic add. Segments past the budget are
//!    counted and dropped.
//! 2. **Binning.** One thread per stored segment counts the 16x16-pixel tiles its footprint
//!    touches (row of tiles by row of tiles, so a long diagonal segment visits only its own
//!    tiles); one workgroup scans the tile counts into offsets (entries past the entry budget
//!    are counted and dropped, whole tiles' tails first); the same walk then scatters segment
//!    indices into each tile's range.
//! 3. **Raster.** One workgroup per tile: each thread takes segments of the tile, walks the
//!    pixels of its footprint inside the tile and computes the exact area of the pixel square
//!    covered by the segment's rectangle (analytic coverage: no MSAA needed), the depth at the
//!    pixel centre (tested against the opaque depth), and the colour interpolated between the
//!    shaded ends. Fragments go into per-pixel lists of the `K` nearest in shared memory
//!    (64-bit `atomicMin` of depth bits << 32 | packed colour, as the k-buffer), evicted ones
//!    into fixed-point tail sums, so the result does not depend on the order. At the end each
//!    pixel merges its list with the frame's k-buffer (hardware-drawn transparent strands of
//!    the same frame), and the k-buffer resolve composites everything front to back.
//!
//! In [`StrandRaster::Auto`] the split is per bundle, in `bundle_lod.glsl`: a bundle whose
//! strands are drawn at most [`AUTO_SPLIT_PIXELS`] wide at its nearest point (strand width,
//! widened by the LoD thickness, over the pixel size at the bundle's nearest distance) goes
//! to software, thicker ones stay on hardware strips.

pub mod payload;
pub mod pixel;

use glam::Vec2;

use crate::render::core::graph::TransientBuffer;
use crate::render::core::shared::{FrameBinding, FrameBlock, SOFT_MAX_K, SOFT_TILE, SoftSegment};

/// Default number of fragments per pixel the software rasterizer keeps sorted.
pub const DEFAULT_SOFT_K: u32 = 8;
/// [`StrandRaster::Auto`]: bundles whose strands are drawn at most this many pixels wide go
/// to the software rasterizer (default of `RendererDesc::auto_split_pixels`). Measured on
/// lavapipe (`bench crowd`, 100 characters, opaque, LoD on): with 1.5 px the crowd's far LoD
/// clusters went to hardware strips and the frame took 506 / 592 ms (mesh / compute path)
/// against 435 / 379 ms all in software; with 4 px `auto` draws that crowd all in software.
pub const AUTO_SPLIT_PIXELS: f32 = 4.0;

/// How strands are rasterized, chosen per frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum StrandRaster {
    /// Camera-facing strips through the hardware rasterizer.
    #[default]
    Hardware,
    /// Every bundle through the compute software rasterizer, keeping `k` fragments per pixel
    /// sorted (1..=[`SOFT_MAX_K`]).
    Software {
        /// Fragments per pixel kept sorted.
        k: u32,
    },
    /// Per bundle: thin strands to software, thick ones to hardware.
    Auto {
        /// Fragments per pixel kept sorted by the software part.
        k: u32,
    },
}

impl StrandRaster {
    /// Mode number in `SoftFields::mode`.
    pub fn mode(self) -> u32 {
        match self {
            StrandRaster::Hardware => crate::render::core::shared::RASTER_HARDWARE,
            StrandRaster::Software { .. } => crate::render::core::shared::RASTER_SOFTWARE,
            StrandRaster::Auto { .. } => crate::render::core::shared::RASTER_AUTO,
        }
    }

    /// Whether the software rasterizer runs.
    pub fn uses_software(self) -> bool {
        self != StrandRaster::Hardware
    }

    /// Fragments per pixel kept sorted (0 for hardware).
    pub fn k(self) -> u32 {
        match self {
            StrandRaster::Hardware => 0,
            StrandRaster::Software { k } | StrandRaster::Auto { k } => k,
        }
    }

    /// Check `k`.
    pub fn validate(self) -> Result<(), String> {
        match self {
            StrandRaster::Hardware => Ok(()),
            _ if (1..=SOFT_MAX_K).contains(&self.k()) => Ok(()),
            _ => Err(format!(
                "software raster K {} must be 1..={SOFT_MAX_K} fragments per pixel",
                self.k()
            )),
        }
    }
}

impl std::fmt::Display for StrandRaster {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StrandRaster::Hardware => write!(f, "hw"),
            StrandRaster::Software { k } => write!(f, "soft:{k}"),
            StrandRaster::Auto { k } => write!(f, "auto:{k}"),
        }
    }
}

impl std::str::FromStr for StrandRaster {
    type Err = String;
    /// `hw`, `soft` or `soft:K`, `auto` or `auto:K` (K fragments per pixel kept sorted).
    fn from_str(s: &str) -> Result<Self, String> {
        let (name, k) = crate::render::core::mode_name::name_and_count("draw", s)?;
        let k_or_default = k.unwrap_or(DEFAULT_SOFT_K);
        let r = match name {
            "hw" if k.is_none() => StrandRaster::Hardware,
            "soft" => StrandRaster::Software { k: k_or_default },
            "auto" => StrandRaster::Auto { k: k_or_default },
            _ => {
                return Err(format!(
                    "unknown draw '{s}' (hw, soft, soft:K, auto, auto:K)"
                ));
            }
        };
        r.validate()?;
        Ok(r)
    }
}

/// Sizes of the software rasterizer's buffers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SoftBudget {
    /// Segments stored per frame (32 bytes each); more are counted and dropped.
    pub segments: u32,
    /// (tile, segment) entries per frame (4 bytes each); more are counted and dropped.
    pub tile_entries: u32,
}

impl SoftBudget {
    /// No budget (no buffers).
    pub const EMPTY: SoftBudget = SoftBudget {
        segments: 0,
        tile_entries: 0,
    };

    /// The largest budgets the device's `maxStorageBufferRange` allows, at most 4M segments
    /// and 16M entries (128 MiB + 64 MiB).
    pub fn for_range(range: u64) -> Self {
        let seg = size_of::<SoftSegment>() as u64;
        SoftBudget {
            segments: (range / seg).min(4 << 20) as u32,
            tile_entries: (range / 4).min(16 << 20) as u32,
        }
    }

    /// Check against the device limit.
    pub fn validate(&self, range: u64) -> Result<(), String> {
        let seg = size_of::<SoftSegment>() as u64;
        if self.segments == 0 || self.segments as u64 * seg > range {
            return Err(format!(
                "software raster segment budget {} must be 1..={} ({}-byte segments, maxStorageBufferRange {range})",
                self.segments,
                range / seg,
                seg
            ));
        }
        if self.tile_entries == 0 || self.tile_entries as u64 * 4 > range {
            return Err(format!(
                "software raster tile entry budget {} must be 1..={}",
                self.tile_entries,
                range / 4
            ));
        }
        Ok(())
    }
}

/// Tiles per row and tile rows of a `width x height` target.
pub fn tile_grid(width: u32, height: u32) -> (u32, u32) {
    (width.div_ceil(SOFT_TILE), height.div_ceil(SOFT_TILE))
}

/// The renderer's fixed choices for the software rasterizer (from `RendererDesc`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoftTuning {
    /// Segment and tile-entry budgets.
    pub budget: SoftBudget,
    /// [`StrandRaster::Auto`]'s split width, pixels.
    pub auto_split_pixels: f32,
}

/// Fill the software rasterizer's fields of a camera frame block: `raster` with strands of
/// `opacity`, as `tuning` says.
pub fn frame_fields(
    block: &mut FrameBlock,
    raster: StrandRaster,
    opacity: f32,
    tuning: SoftTuning,
) {
    let (w, h) = (block.viewport[0] as u32, block.viewport[1] as u32);
    let (tiles_x, tiles_y) = tile_grid(w, h);
    block.soft = crate::render::core::shared::SoftFields {
        mode: raster.mode(),
        k: raster.k(),
        segment_budget: tuning.budget.segments,
        tile_entry_budget: tuning.budget.tile_entries,
        auto_split_pixels: tuning.auto_split_pixels,
        strand_opacity: opacity,
        tiles_x,
        tiles_y,
        ..Default::default()
    };
}

impl SoftBudget {
    /// The software rasterizer's buffers, as the frame graph creates them, for this budget,
    /// the camera's `width x height` target when it draws the camera's strands, and the
    /// light's map side when it draws the shadows (sized 0 where neither): segments and
    /// entries (the views take turns), the tile table (`uvec4` per tile, the larger grid),
    /// and the camera's opaque depth (one float per pixel).
    pub fn buffers(self, camera: Option<(u32, u32)>, light: Option<u32>) -> [TransientBuffer; 4] {
        let tiles = |(w, h)| {
            let (tx, ty) = tile_grid(w, h);
            tx as u64 * ty as u64 * 16
        };
        let any = camera.is_some() || light.is_some();
        const BUDGET: (&str, &str) = (
            "the software rasterizer's budget",
            "use fewer strands, or --draw hw",
        );
        const DEPTH: (&str, &str) = (
            "the software rasterizer's per-pixel depth",
            "lower --size, or use --draw hw",
        );
        let need = [
            any as u64 * self.segments as u64 * size_of::<SoftSegment>() as u64,
            camera
                .map_or(0, tiles)
                .max(light.map_or(0, |r| tiles((r, r)))),
            any as u64 * self.tile_entries as u64 * 4,
            camera.map_or(0, |(w, h)| w as u64 * h as u64 * 4),
        ];
        [
            TransientBuffer::storage("soft segments", need[0], FrameBinding::SoftSegments as u32)
                .for_user(BUDGET.0, BUDGET.1),
            TransientBuffer::storage("soft tiles", need[1], FrameBinding::SoftTiles as u32)
                .for_user(DEPTH.0, DEPTH.1),
            TransientBuffer::storage("soft entries", need[2], FrameBinding::SoftEntries as u32)
                .for_user(BUDGET.0, BUDGET.1),
            TransientBuffer::storage("soft depth", need[3], FrameBinding::SoftDepth as u32)
                .for_user(DEPTH.0, DEPTH.1),
        ]
    }
}

/// The software shadow passes' outputs for a `side x side` map, with deep opacity layers or
/// not (`None`: hardware light passes, sized 0): the hair depth (a float per texel) and, for
/// deep opacity maps, the layers (an RGBA16F texel each), which transfers copy into the maps.
pub fn shadow_buffers(light: Option<(u32, bool)>) -> [TransientBuffer; 2] {
    let texels = light.map_or(0, |(side, _)| side as u64 * side as u64);
    let layers = matches!(light, Some((_, true)));
    [
        TransientBuffer::storage(
            "soft shadow depth",
            texels * 4,
            FrameBinding::SoftShadowDepth as u32,
        )
        .for_user("the software shadow maps", "use --shadow-draw hw"),
        TransientBuffer::storage(
            "soft shadow layers",
            layers as u64 * texels * 8,
            FrameBinding::SoftShadowLayers as u32,
        )
        .for_user("the software shadow maps", "use --shadow-draw hw"),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each raster reaches the shaders as its own mode number (`SoftFields::mode`).
    #[test]
    fn each_raster_has_its_shader_mode() {
        use crate::render::core::shared::{RASTER_AUTO, RASTER_HARDWARE, RASTER_SOFTWARE};
        assert_eq!(StrandRaster::Hardware.mode(), RASTER_HARDWARE);
        assert_eq!(StrandRaster::Software { k: 4 }.mode(), RASTER_SOFTWARE);
        assert_eq!(StrandRaster::Auto { k: 4 }.mode(), RASTER_AUTO);
    }

    #[test]
    fn parses_and_rejects() {
        assert_eq!("hw".parse(), Ok(StrandRaster::Hardware));
        assert_eq!(
            "soft".parse(),
            Ok(StrandRaster::Software { k: DEFAULT_SOFT_K })
        );
        assert_eq!("auto:4".parse(), Ok(StrandRaster::Auto { k: 4 }));
        for bad in ["soft:0", "soft:9", "hw:2", "auto:x", "sw", ""] {
            assert!(bad.parse::<StrandRaster>().is_err(), "{bad}");
        }
        for t in ["hw", "soft:3", "auto:8"] {
            assert_eq!(t.parse::<StrandRaster>().unwrap().to_string(), t);
        }
        assert_eq!(tile_grid(1280, 720), (80, 45));
        assert_eq!(tile_grid(17, 1), (2, 1));
        let b = SoftBudget::for_range(128 << 20);
        assert_eq!(b.segments, 4 << 20);
        assert!(b.validate(128 << 20).is_ok());
        assert!(b.validate(64 << 20).is_err());
    }
}

/// The box-filtered edge constants of a unit direction `d` (and of its normal, which shares
/// them): the larger and smaller absolute components `e` and `f`, `1 / e` and `1 / (2 e f)`.
/// CPU twin of the `edge` of `segment_frame` in `soft_raster.glsl`.
pub fn edge_constants(d: Vec2) -> [f32; 4] {
    let (e, f) = (d.x.abs().max(d.y.abs()), d.x.abs().min(d.y.abs()));
    [e, f, 1.0 / e, 1.0 / (2.0 * e * f)]
}

/// Area of the unit square centred on the origin where `n . y <= t`, for a unit normal `n`
/// with [`edge_constants`] `edge` (the box-filtered edge: a triangle, a trapezoid, then the
/// complement of a triangle; with `f = 0` only the trapezoid). CPU twin of `square_below` in
/// `soft_raster.glsl`.
pub fn square_below(t: f32, edge: [f32; 4]) -> f32 {
    let [e, f, inv_e, inv_2ef] = edge;
    let s = t + 0.5 * (e + f);
    if s <= 0.0 {
        0.0
    } else if s >= e + f {
        1.0
    } else if s < f {
        s * s * inv_2ef
    } else if s <= e {
        (s - 0.5 * f) * inv_e
    } else {
        let r = e + f - s;
        1.0 - r * r * inv_2ef
    }
}

/// Share of the unit pixel square with corner `pmin` covered by the rectangle of half-width
/// `h` around the segment `a -> b`: CPU twin of `pixel_coverage` in `soft_raster.glsl`. The
/// exact area of the square inside the strip `|v| <= h` ([`square_below`] twice) times the
/// share of the square between the end lines (the same along the segment): exact for pixels
/// between the end lines, within 0.06 of the exactly clipped area where a pixel
/// crosses an end line, and the shares of a joint between collinear segments add up to 1.
pub fn pixel_coverage(a: Vec2, b: Vec2, h: f32, pmin: Vec2) -> f32 {
    let len = (b - a).length();
    if len < 1e-9 {
        return 0.0;
    }
    let d = (b - a) / len;
    let n = Vec2::new(-d.y, d.x);
    let q = pmin + Vec2::splat(0.5) - a;
    let (uc, vc) = (q.dot(d), q.dot(n));
    let edge = edge_constants(d);
    let across = square_below(h - vc, edge) - square_below(-h - vc, edge);
    let along = square_below(len - uc, edge) - square_below(-uc, edge);
    across * along
}

/// The exact share of the unit pixel square with corner `pmin` inside the rectangle of
/// half-width `h` around the segment `a -> b`: the square in the segment's frame clipped to
/// `[0, len] x [-h, h]` (Sutherland-Hodgman), its area. The reference [`pixel_coverage`] is
/// tested against (tests only).
#[cfg(test)]
fn exact_coverage(a: Vec2, b: Vec2, h: f32, pmin: Vec2) -> f32 {
    let len = (b - a).length();
    if len < 1e-9 {
        return 0.0;
    }
    let d = (b - a) / len;
    let n = Vec2::new(-d.y, d.x);
    let mut poly: Vec<Vec2> = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
        .iter()
        .map(|&(x, y)| {
            let q = pmin + Vec2::new(x, y) - a;
            Vec2::new(q.dot(d), q.dot(n))
        })
        .collect();
    // Wholly outside one side, or wholly inside: no clipping.
    let lo = poly.iter().fold(Vec2::splat(f32::MAX), |m, p| m.min(*p));
    let hi = poly.iter().fold(Vec2::splat(f32::MIN), |m, p| m.max(*p));
    if hi.x <= 0.0 || lo.x >= len || hi.y <= -h || lo.y >= h {
        return 0.0;
    }
    if lo.x >= 0.0 && hi.x <= len && lo.y >= -h && hi.y <= h {
        return 1.0;
    }
    for (axis, bound, sign) in [(0, len, 1.0), (0, 0.0, -1.0), (1, h, 1.0), (1, -h, -1.0)] {
        let f = |p: Vec2| sign * (p[axis] - bound);
        let mut out = Vec::with_capacity(8);
        for i in 0..poly.len() {
            let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
            let (fp, fq) = (f(p), f(q));
            if fp <= 0.0 {
                out.push(p);
            }
            if (fp < 0.0 && fq > 0.0) || (fp > 0.0 && fq < 0.0) {
                out.push(p + (q - p) * (fp / (fp - fq)));
            }
        }
        poly = out;
        if poly.len() < 3 {
            return 0.0;
        }
    }
    let area: f32 = (0..poly.len())
        .map(|i| poly[i].perp_dot(poly[(i + 1) % poly.len()]))
        .sum();
    (0.5 * area.abs()).min(1.0)
}

#[cfg(test)]
mod coverage_tests {
    use super::*;

    /// Total coverage of a straight strand of `segments` equal segments from `a` to `b`.
    fn total(a: Vec2, b: Vec2, h: f32, segments: usize) -> f64 {
        let mut sum = 0.0f64;
        for s in 0..segments {
            let p = a + (b - a) * (s as f32 / segments as f32);
            let q = a + (b - a) * ((s + 1) as f32 / segments as f32);
            let lo = p.min(q) - Vec2::splat(h + 1.0);
            let hi = p.max(q) + Vec2::splat(h + 1.0);
            for y in lo.y.floor() as i32..=hi.y.floor() as i32 {
                for x in lo.x.floor() as i32..=hi.x.floor() as i32 {
                    sum += pixel_coverage(p, q, h, Vec2::new(x as f32, y as f32)) as f64;
                }
            }
        }
        sum
    }

    /// The check on the CPU twin: widths below and above a pixel, several angles
    /// and sub-pixel offsets.
    #[test]
    fn a_straight_strand_deposits_its_area() {
        let mut worst = 0.0f64;
        for width in [0.2f32, 0.5, 0.9, 1.5, 3.0] {
            for degrees in [0.0f32, 7.0, 30.0, 45.0, 61.0, 90.0] {
                for offset in [0.0f32, 0.3, 0.71] {
                    let dir = Vec2::from_angle(degrees.to_radians());
                    let a = Vec2::new(20.0 + offset, 15.0 + offset * 0.5);
                    let b = a + dir * 100.0;
                    let area = width as f64 * 100.0;
                    let got = total(a, b, 0.5 * width, 23);
                    // The 22 joints add nothing; each end (where the coverage along the
                    // strand is the pixel's share, not the clipped area) within 0.05 px^2.
                    let tolerance = 1e-4 * area + 2.0 * 0.05;
                    worst = worst.max((got - area).abs() / 2.0);
                    assert!(
                        (got - area).abs() < tolerance,
                        "width {width}, {degrees} deg, offset {offset}: {got} vs {area}"
                    );
                }
            }
        }
        println!("worst error per end: {worst} px^2");
    }

    /// Against the exact clipped area: exact for pixels between the end lines, within 0.06
    /// (worst seen 0.042) where a pixel crosses one (short and long, thin and wide segments
    /// at every angle).
    #[test]
    fn coverage_is_the_exact_area_within_bounds() {
        let mut rng = crate::rng::Pcg32::new(7);
        let (mut worst, mut worst_inside) = (0.0f32, 0.0f32);
        for _ in 0..400 {
            let a = Vec2::new(10.0 + rng.next_f32(), 10.0 + rng.next_f32());
            let dir = Vec2::from_angle(rng.next_f32() * std::f32::consts::TAU);
            let len = 0.3 + 8.0 * rng.next_f32();
            let h = 0.05 + 3.0 * rng.next_f32();
            let b = a + dir * len;
            let r = 0.5 * (dir.x.abs() + dir.y.abs());
            for y in 0..24 {
                for x in 0..24 {
                    let pmin = Vec2::new(x as f32, y as f32);
                    let e = (pixel_coverage(a, b, h, pmin) - exact_coverage(a, b, h, pmin)).abs();
                    let u = (pmin + Vec2::splat(0.5) - a).dot(dir);
                    if u - r >= 1e-4 && u + r <= len - 1e-4 {
                        worst_inside = worst_inside.max(e);
                    }
                    worst = worst.max(e);
                }
            }
        }
        println!("worst {worst}, between the end lines {worst_inside}");
        assert!(worst_inside < 1e-5, "between the end lines: {worst_inside}");
        assert!(worst < 0.06, "{worst}");
    }

    #[test]
    fn coverage_is_a_share_of_the_pixel() {
        let a = Vec2::new(0.5, -3.0);
        let b = Vec2::new(0.5, 5.0);
        // A vertical strand through the pixel centre, 0.4 wide: 0.4 of the pixel.
        let c = pixel_coverage(a, b, 0.2, Vec2::ZERO);
        assert!((c - 0.4).abs() < 1e-5, "{c}");
        // Wide strands cover whole pixels, exactly.
        assert!((pixel_coverage(a, b, 4.0, Vec2::ZERO) - 1.0).abs() < 1e-6);
        assert_eq!(pixel_coverage(a, b, 0.2, Vec2::new(3.0, 0.0)), 0.0);
        assert_eq!(pixel_coverage(a, a, 0.2, Vec2::ZERO), 0.0);
    }
}

/// IEEE half-precision bits of `x` (round to nearest; the range `packHalf2x16` covers).
fn f16_bits(x: f32) -> u32 {
    let b = x.to_bits();
    let sign = (b >> 16) & 0x8000;
    let exp = ((b >> 23) & 0xff) as i32 - 127 + 15;
    let mant = b & 0x7f_ffff;
    if x == 0.0 || exp <= 0 {
        return sign; // zero (and the tiny values segments never carry)
    }
    if exp >= 31 {
        return sign | 0x7c00;
    }
    let h = ((exp as u32) << 10) | (mant >> 13);
    // Round to nearest, ties away: carries into the exponent correctly.
    sign | (h + ((mant >> 12) & 1))
}

/// `pack_fragment` of `fragment_pack.glsl`: sqrt-encoded RGB and linear alpha, 8 bits each.
pub(crate) fn pack_fragment(rgb: [f32; 3], alpha: f32) -> u32 {
    let q = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u32;
    q(rgb[0].max(0.0).sqrt())
        | q(rgb[1].max(0.0).sqrt()) << 8
        | q(rgb[2].max(0.0).sqrt()) << 16
        | q(alpha) << 24
}

/// `unpack_fragment` of `fragment_pack.glsl`: linear colour and alpha.
pub(crate) fn unpack_fragment(p: u32) -> ([f32; 3], f32) {
    let byte = |i: u32| ((p >> (8 * i)) & 0xff) as f32 / 255.0;
    let sq = |x: f32| x * x;
    ([sq(byte(0)), sq(byte(1)), sq(byte(2))], byte(3))
}

impl SoftSegment {
    /// A segment from `a` to `b` (pixels) at depth `depth` (0..1), `width` pixels wide, of one
    /// colour, standing for one strand that covers all of its width (for tests and tools that
    /// feed `Renderer::rasterize_segments`).
    pub fn flat(a: Vec2, b: Vec2, depth: f32, width: f32, rgb: [f32; 3]) -> Self {
        Self::shaded(a.extend(depth), b.extend(depth), width, [rgb, rgb])
    }

    /// A segment between `a` and `b` (x, y in pixels, z depth 0..1), `width` pixels wide,
    /// coloured `rgb[0]` at `a` and `rgb[1]` at `b`, standing for one strand that covers all of
    /// its width.
    pub fn shaded(a: glam::Vec3, b: glam::Vec3, width: f32, rgb: [[f32; 3]; 2]) -> Self {
        let d = b - a;
        SoftSegment {
            a: [a.x, a.y],
            za: a.z,
            dz_id: f16_bits(b.z - a.z),
            b: [
                f16_bits(d.x) | f16_bits(d.y) << 16,
                pack_fragment(rgb[0], 1.0),
                pack_fragment(rgb[1], 1.0),
                f16_bits(width) | f16_bits(1.0) << 16,
            ],
        }
    }
}

#[cfg(test)]
mod pack_tests {
    use super::*;

    #[test]
    fn half_bits_match_ieee() {
        assert_eq!(f16_bits(1.0), 0x3c00);
        assert_eq!(f16_bits(-2.0), 0xc000);
        assert_eq!(f16_bits(0.5), 0x3800);
        assert_eq!(f16_bits(65504.0), 0x7bff);
        assert_eq!(f16_bits(0.0), 0);
        assert_eq!(pack_fragment([1.0, 0.0, 0.25], 1.0), 0xff80_00ff);
        // Green in its own byte (its shift reversed survived the 2026-12-06 sample).
        assert_eq!(pack_fragment([0.0, 1.0, 0.0], 0.0), 0x0000_ff00);
    }

    /// A shaded segment carries its ends, depth step, colours and width in `SoftSegment`'s
    /// packing (what `rasterize_segments` hands the GPU; the whole constructor replaced by a
    /// default survived the third sample).
    #[test]
    fn shaded_segment_packs_its_ends_colours_and_width() {
        let s = SoftSegment::shaded(
            glam::Vec3::new(3.0, 4.0, 0.25),
            glam::Vec3::new(5.0, 3.0, 0.75),
            1.5,
            [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
        );
        assert_eq!((s.a, s.za), ([3.0, 4.0], 0.25));
        assert_eq!(s.dz_id, f16_bits(0.5));
        assert_eq!(s.b[0], f16_bits(2.0) | f16_bits(-1.0) << 16);
        assert_eq!((s.b[1], s.b[2]), (0xff00_00ff, 0xffff_0000));
        assert_eq!(s.b[3], f16_bits(1.5) | f16_bits(1.0) << 16);
    }
}
