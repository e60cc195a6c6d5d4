//! CPU reference generator: the oracle the GPU paths are tested against.
//!
//! It reads only the baked textures and emulates what a shader does with them: normalised
//! texture coordinates, clamp-to-edge linear filtering of the decoded texel values (the texture
//! unit's two trilinear fetches per quadratic Bezier), one software lerp (paper 003, section 3.1),
//! root placement from the shared blue-noise sets (section 3.3), styling in the `u v w` frame
//! (section 3.4), roots on a curved root surface ([`crate::reference::root_surface`]) and
//! tangents by eq. 5-6 (section 3.5). `glsl/strand_eval.glsl` is the GPU twin.

use super::texel::{snorm, unorm};
use glam::{Vec2, Vec3, Vec4};

use crate::bake::blue_noise::{MAX_STRANDS_PER_BUNDLE, quad_samples_for, triangle_samples_for};
use crate::bake::{BakedHairMesh, BundleDesc, MeshInfo};
use crate::model::style::HairStyle;
use crate::reference::root_surface::{RootCell, bulge_fade, local_coord};
use crate::rng::{hash_f32, hash_u32};

/// A decoded texture sampled like a GPU texture unit: normalised coordinates, linear filter,
/// clamp to edge. Texels are stored decoded as `Vec4` (unused channels 0).
#[derive(Clone, Debug)]
pub struct SampledTexture {
    size: [usize; 3],
    texels: Vec<Vec4>,
}

/// Bilinear footprint in the xy plane: four texel offsets and weights.
#[derive(Clone, Copy, Debug)]
pub struct Footprint {
    offsets: [usize; 4],
    weights: [f32; 4],
}

/// One axis of linear filtering with clamp-to-edge: `(i0, i1, frac)` for normalised `u`.
fn axis(u: f32, size: usize) -> (usize, usize, f32) {
    let x = u * size as f32 - 0.5;
    let f = x.floor();
    let frac = x - f;
    let last = size as i64 - 1;
    let i0 = (f as i64).clamp(0, last) as usize;
    let i1 = (f as i64 + 1).clamp(0, last) as usize;
    (i0, i1, frac)
}

impl SampledTexture {
    /// Decode texels with `decode` into a texture of `size` (x fastest).
    pub fn new<T: Copy>(size: [u32; 3], data: &[T], decode: impl Fn(T) -> Vec4) -> Self {
        SampledTexture {
            size: size.map(|s| s as usize),
            texels: data.iter().map(|&t| decode(t)).collect(),
        }
    }

    /// Bilinear footprint of normalised `(u, v)`; shared by every slice of this texture.
    pub fn footprint(&self, uv: Vec2) -> Footprint {
        let (x0, x1, fx) = axis(uv.x, self.size[0]);
        let (y0, y1, fy) = axis(uv.y, self.size[1]);
        let w = self.size[0];
        Footprint {
            offsets: [y0 * w + x0, y0 * w + x1, y1 * w + x0, y1 * w + x1],
            weights: [
                (1.0 - fx) * (1.0 - fy),
                fx * (1.0 - fy),
                (1.0 - fx) * fy,
                fx * fy,
            ],
        }
    }

    fn bilinear(&self, fp: &Footprint, slice: usize) -> Vec4 {
        let base = slice * self.size[0] * self.size[1];
        let t = &self.texels;
        t[base + fp.offsets[0]] * fp.weights[0]
            + t[base + fp.offsets[1]] * fp.weights[1]
            + t[base + fp.offsets[2]] * fp.weights[2]
            + t[base + fp.offsets[3]] * fp.weights[3]
    }

    /// Trilinear sample at footprint `fp` and normalised depth `w`.
    pub fn sample_3d(&self, fp: &Footprint, w: f32) -> Vec4 {
        self.sample_depth(fp, axis(w, self.size[2]))
    }

    /// Trilinear sample with a precomputed depth axis (shared by same-sized textures).
    fn sample_depth(&self, fp: &Footprint, (z0, z1, fz): (usize, usize, f32)) -> Vec4 {
        self.bilinear(fp, z0).lerp(self.bilinear(fp, z1), fz)
    }

    /// Bilinear sample of a 2D texture.
    pub fn sample_2d(&self, fp: &Footprint) -> Vec4 {
        self.bilinear(fp, 0)
    }

    /// Depth in texels.
    pub fn depth(&self) -> usize {
        self.size[2]
    }
}

/// Decoded textures of one baked hair mesh, ready for sampling.
pub struct HairTextures {
    /// Decode constants and sizes.
    pub info: MeshInfo,
    /// Bundle table.
    pub bundles: Vec<BundleDesc>,
    position: SampledTexture,
    uv: SampledTexture,
    w: SampledTexture,
    u_dir: SampledTexture,
    v_dir: SampledTexture,
}

impl HairTextures {
    /// Decode the textures of `baked` exactly as the GPU's UNORM/SNORM conversion does.
    pub fn new(baked: &BakedHairMesh) -> Self {
        let info = baked.info;
        let [wd, ht] = info.root_size;
        let l = info.layers;
        let o = Vec3::from_slice(&info.pos_origin[..3]);
        let e = Vec3::from_slice(&info.pos_extent[..3]);
        let [uo0, uo1, ue0, ue1] = info.uv_origin_extent;
        let w_scale = info.pos_origin[3];
        HairTextures {
            info,
            bundles: baked.bundles.clone(),
            position: SampledTexture::new([wd, ht, info.position_depth()], &baked.position, |t| {
                (o + e * Vec3::new(unorm(t[0]), unorm(t[1]), unorm(t[2]))).extend(unorm(t[3]))
            }),
            uv: SampledTexture::new([wd, ht, 1], &baked.uv, |t| {
                Vec4::new(uo0 + ue0 * unorm(t[0]), uo1 + ue1 * unorm(t[1]), 0.0, 0.0)
            }),
            w: SampledTexture::new([wd, ht, l], &baked.w, |t| {
                Vec4::new(w_scale * unorm(t), 0.0, 0.0, 0.0)
            }),
            u_dir: SampledTexture::new([wd, ht, l], &baked.u_dir, |t| {
                Vec4::new(snorm(t[0]), snorm(t[1]), snorm(t[2]), 0.0)
            }),
            v_dir: SampledTexture::new([wd, ht, l], &baked.v_dir, |t| {
                Vec4::new(snorm(t[0]), snorm(t[1]), snorm(t[2]), 0.0)
            }),
        }
    }

    /// Normalised root-slice coordinate of root sample `xi` in bundle `b` (section 3.3).
    /// Triangles map `xi` (with `xi.x + xi.y < 1`) to the quad layout by
    /// `(xi.x / (1 - xi.y), xi.y)`: bilinear weights then equal barycentrics, with `xi.y` the
    /// weight of the duplicated vertex. (The paper prints `xi_s (1 - xi_t)`, the inverse map.)
    pub fn root_coord(&self, b: &BundleDesc, xi: Vec2) -> Vec2 {
        let local = local_coord(b, xi);
        let [w, h] = self.info.root_size;
        Vec2::new(
            (b.origin[0] as f32 + 0.5 + local.x) / w as f32,
            (b.origin[1] as f32 + 0.5 + local.y) / h as f32,
        )
    }

    /// Object-space curve point at curve parameter `r` in `[0, L-1]` for footprint `fp`:
    /// two trilinear fetches and one lerp (section 3.1).
    pub fn curve_point(&self, fp: &Footprint, r: f32) -> Vec3 {
        let (slice, t) = crate::bake::curve::quadratic_slice(r, self.info.layers as usize);
        let depth = self.position.depth() as f32;
        let a = self
            .position
            .sample_3d(fp, (slice as f32 + 0.5 + t) / depth);
        let b = self
            .position
            .sample_3d(fp, (slice as f32 + 1.5 + t) / depth);
        a.lerp(b, t).truncate()
    }

    /// Root position (single root-slice lookup, no styling).
    pub fn root_point(&self, fp: &Footprint) -> Vec3 {
        self.position
            .sample_3d(fp, 0.5 / self.position.depth() as f32)
            .truncate()
    }

    /// Root thinning at `fp`: the cube of the root slice's alpha, bilinear like every root
    /// lookup (the bake stores cube roots: `bake::deform::encode_columns`).
    pub fn root_thinning(&self, fp: &Footprint) -> f32 {
        let a = self
            .position
            .sample_3d(fp, 0.5 / self.position.depth() as f32)
            .w;
        a * a * a
    }

    /// Styling frame `(u, v, w)` at curve parameter `r` (eq. 4 for `w`), and the `w` coordinate.
    pub fn frame(&self, fp: &Footprint, r: f32) -> ([Vec3; 3], f32) {
        // u-, v- and w-textures share their size: one depth axis for all three fetches.
        let z = axis(
            (r + 0.5) / self.info.layers as f32,
            self.info.layers as usize,
        );
        let u = self
            .u_dir
            .sample_depth(fp, z)
            .truncate()
            .normalize_or(Vec3::X);
        let v = self
            .v_dir
            .sample_depth(fp, z)
            .truncate()
            .normalize_or(Vec3::Y);
        let w = u.cross(v).normalize_or(Vec3::Z);
        ([u, v, w], self.w.sample_depth(fp, z).x)
    }

    /// Root `uv` styling coordinate.
    pub fn root_uv(&self, fp: &Footprint) -> Vec2 {
        self.uv.sample_2d(fp).truncate().truncate()
    }

    /// Bilinear footprint of a normalised root coordinate (valid for every texture).
    pub fn footprint(&self, coord: Vec2) -> Footprint {
        self.position.footprint(coord)
    }
}

/// Per-strand random key from the style seed, bundle and strand index (GLSL: `strand_key`).
pub fn strand_key(seed: u32, bundle: u32, strand: u32) -> u32 {
    hash_u32(hash_u32(bundle ^ hash_u32(seed)).wrapping_add(strand))
}

/// [`strand_rand`] slot deciding whether a strand is thinned out: it is where the value is
/// below the root thinning at its root (`HairMesh::root_thinning`).
pub const STRAND_RAND_THINNING: u32 = 3;

/// Random value `slot` of a strand in `[0, 1)` (GLSL: `strand_rand`).
pub fn strand_rand(key: u32, slot: u32) -> f32 {
    hash_f32(key.wrapping_add(slot.wrapping_mul(0x9E37_79B9)))
}

/// Smooth 1D value noise in `[-1, 1]`, `x >= 0` (GLSL: `value_noise`).
pub fn value_noise(key: u32, x: f32) -> f32 {
    let i = x.floor();
    let f = x - i;
    let i = i as u32;
    let a = hash_f32(key.wrapping_add(hash_u32(i)));
    let b = hash_f32(key.wrapping_add(hash_u32(i.wrapping_add(1))));
    let s = f * f * (3.0 - 2.0 * f);
    (a + (b - a) * s) * 2.0 - 1.0
}

fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    if e1 <= e0 {
        return if x >= e1 { 1.0 } else { 0.0 };
    }
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Root sample of strand `strand` in bundle `index`: the shared progressive blue-noise set,
/// shifted toroidally per quad bundle (a shift keeps a periodic blue-noise set blue).
pub fn root_sample(b: &BundleDesc, index: u32, strand: u32) -> Vec2 {
    let s = strand as usize % MAX_STRANDS_PER_BUNDLE;
    if b.is_triangle() {
        triangle_samples_for(s + 1)[s]
    } else {
        let h = hash_u32(index ^ 0x51ed_270b);
        let shift = Vec2::new(hash_f32(h), hash_f32(h.wrapping_add(1)));
        (quad_samples_for(s + 1)[s] + shift).fract()
    }
}

/// Strands generated for bundle `b` given `n` strands per (average) bundle.
pub fn strands_in_bundle(b: &BundleDesc, style: &HairStyle, n: u32) -> u32 {
    let count = if style.density_by_area != 0 {
        (n as f32 * b.density).round() as u32
    } else {
        n
    };
    count.clamp(1, MAX_STRANDS_PER_BUNDLE as u32)
}

/// Strands `baked`'s bundles grow at full detail with `n` per (average) bundle.
pub fn strands_at_full_detail(
    baked: &crate::bake::BakedHairMesh,
    style: &HairStyle,
    n: u32,
) -> u64 {
    baked
        .bundles
        .iter()
        .map(|b| strands_in_bundle(b, style, n) as u64)
        .sum()
}

/// Strands per (average) bundle that give about `target` strands over `baked`'s bundles
/// (1..=[`MAX_STRANDS_PER_BUNDLE`]), and the strands that makes.
pub fn strands_per_bundle_for(
    baked: &crate::bake::BakedHairMesh,
    style: &HairStyle,
    target: u64,
) -> (u32, u64) {
    let per = (target as f32 / baked.bundles.len().max(1) as f32).ceil() as u32;
    let per = per.clamp(1, MAX_STRANDS_PER_BUNDLE as u32);
    (per, strands_at_full_detail(baked, style, per))
}

/// Styled offset of a vertex in the `u v w` frame (object units), section 3.4.
/// `s` is the normalised position along the strand, `w` the styling coordinate.
pub fn styling_offset(style: &HairStyle, key: u32, s: f32, w: f32) -> Vec3 {
    use std::f32::consts::TAU;
    let ramp = smoothstep(0.0, style.root_ramp, w);
    let mut off = Vec3::ZERO;
    let curl_phase =
        TAU * (style.curl_frequency * w + style.curl_phase_jitter * strand_rand(key, 1));
    off += Vec3::new(curl_phase.cos(), curl_phase.sin(), 0.0) * (style.curl_radius * ramp);
    let wave_phase =
        TAU * (style.wave_frequency * w + style.wave_phase_jitter * strand_rand(key, 2));
    let wave_dir = Vec3::new(style.wave_angle.cos(), style.wave_angle.sin(), 0.0);
    off += wave_dir * (style.wave_amplitude * ramp * wave_phase.sin());
    let frizz = style.frizz_amplitude * s.powf(style.frizz_power);
    let x = w * style.frizz_frequency;
    let fk = hash_u32(key ^ 0x7f4a_7c15);
    off += Vec3::new(
        value_noise(fk, x),
        value_noise(fk.wrapping_add(0x68bc_21eb), x),
        value_noise(fk.wrapping_add(0x02e5_be93), x),
    ) * frizz;
    off
}

/// Strand width at normalised position `s` (before LoD thickness compensation).
pub fn strand_width(style: &HairStyle, s: f32) -> f32 {
    let taper = s.powf(style.taper_power);
    style.strand_width * (1.0 + (style.tip_width_ratio - 1.0) * taper)
}

/// Generated strands, strand-major: strand `i` owns vertices `i * verts .. (i + 1) * verts`.
#[derive(Clone, Debug, Default)]
pub struct StrandSet {
    /// Vertices per strand (`2^e + 1`).
    pub verts_per_strand: usize,
    /// Object-space positions.
    pub positions: Vec<Vec3>,
    /// Unit tangents (eq. 5-6).
    pub tangents: Vec<Vec3>,
    /// Widths, object units.
    pub widths: Vec<f32>,
    /// Bundle of each strand.
    pub strand_bundle: Vec<u32>,
}

impl StrandSet {
    /// Number of strands.
    pub fn strand_count(&self) -> usize {
        self.strand_bundle.len()
    }

    /// The strands as polylines, root first.
    pub fn polylines(&self) -> Vec<Vec<Vec3>> {
        self.positions
            .chunks(self.verts_per_strand)
            .map(|c| c.to_vec())
            .collect()
    }
}

/// The CPU reference generator over one baked mesh and style.
pub struct CpuGenerator {
    /// Decoded textures.
    pub tex: HairTextures,
    /// Style in use.
    pub style: HairStyle,
    /// Root cell of every bundle (curved roots, [`crate::reference::root_surface`]).
    cells: Vec<RootCell>,
}

impl CpuGenerator {
    /// Prepare `baked` for generation with `style`.
    pub fn new(baked: &BakedHairMesh, style: HairStyle) -> Self {
        CpuGenerator {
            tex: HairTextures::new(baked),
            style,
            cells: baked
                .bundles
                .iter()
                .map(|b| RootCell::from_baked(baked, b))
                .collect(),
        }
    }

    /// Generate strand `strand` of bundle `bundle` with `segments` segments into the outputs
    /// (each of length `segments + 1`).
    pub fn strand(
        &self,
        bundle: u32,
        strand: u32,
        segments: u32,
        pos: &mut [Vec3],
        tan: &mut [Vec3],
        width: &mut [f32],
    ) {
        let b = &self.tex.bundles[bundle as usize];
        let style = &self.style;
        let key = strand_key(style.seed, bundle, strand);
        let xi = root_sample(b, bundle, strand);
        let fp = self.tex.footprint(self.tex.root_coord(b, xi));
        let bulge = self.cells[bundle as usize].bulge(local_coord(b, xi));
        let centre_xi = if b.is_triangle() {
            Vec2::new(1.0 / 3.0, 1.0 / 3.0)
        } else {
            Vec2::splat(0.5)
        };
        let centre_fp = self.tex.footprint(self.tex.root_coord(b, centre_xi));
        let length = 1.0 - style.length_variation * strand_rand(key, 0);
        let span = (self.tex.info.layers - 1) as f32 * length;
        pos[0] = self.tex.root_point(&fp) + bulge;
        width[0] = strand_width(style, 0.0);
        if strand_rand(key, STRAND_RAND_THINNING) < self.tex.root_thinning(&fp) {
            // Thinned out: every vertex at the root, a strip of no area (GLSL: StrandInfo.kept).
            for k in 1..=segments as usize {
                pos[k] = pos[0];
                width[k] = strand_width(style, k as f32 / segments as f32);
            }
            crate::bake::curve::strand_tangents(pos, tan);
            return;
        }
        for k in 1..=segments as usize {
            let s = k as f32 / segments as f32;
            let r = s * span;
            let mut p = self.tex.curve_point(&fp, r);
            if style.clump_strength > 0.0 {
                let c = self.tex.curve_point(&centre_fp, r);
                p += (c - p) * (style.clump_strength * s.powf(style.clump_power));
            }
            let ([fu, fv, fw], w) = self.tex.frame(&fp, r);
            let off = styling_offset(style, key, s, w);
            pos[k] = p + fu * off.x + fv * off.y + fw * off.z + bulge * bulge_fade(r);
            width[k] = strand_width(style, s);
        }
        crate::bake::curve::strand_tangents(pos, tan);
    }

    /// Generate with level of detail (paper sec. 3.6): per bundle the strand count, vertex level,
    /// geomorph (eq. 11 + tangent morph) and thickness of [`crate::reference::lod::bundle_lod`]. Strands are
    /// bundle-major; `counts[i]` is the vertex count of strand `i`.
    pub fn generate_lod(
        &self,
        n: u32,
        e_max: u32,
        baked: &BakedHairMesh,
        view: &crate::reference::lod::LodView,
    ) -> (StrandSet, Vec<usize>) {
        let mut set = StrandSet {
            verts_per_strand: 0,
            ..Default::default()
        };
        let mut counts = Vec::new();
        for (bundle, b) in self.tex.bundles.iter().enumerate() {
            let lod = crate::reference::lod::bundle_lod(
                baked,
                &self.style,
                bundle,
                strands_in_bundle(b, &self.style, n),
                e_max,
                view,
            );
            let segments = 1u32 << lod.e;
            let verts = segments as usize + 1;
            for strand in 0..lod.strands {
                let mut p = vec![Vec3::ZERO; verts];
                let mut t = vec![Vec3::ZERO; verts];
                let mut w = vec![0.0; verts];
                self.strand(bundle as u32, strand, segments, &mut p, &mut t, &mut w);
                crate::reference::lod::apply_geomorph(&mut p, &mut t, lod.gamma);
                set.positions.extend(p);
                set.tangents.extend(t);
                let fade = match strand + 1 == lod.strands {
                    true => lod.fade,
                    false => 1.0,
                };
                set.widths
                    .extend(w.iter().map(|x| x * lod.thickness * fade));
                set.strand_bundle.push(bundle as u32);
                counts.push(verts);
            }
        }
        (set, counts)
    }

    /// Generate every strand with `n` strands per average bundle and `2^e + 1` vertices each.
    pub fn generate(&self, n: u32, e: u32) -> StrandSet {
        let segments = 1u32 << e;
        let verts = segments as usize + 1;
        let counts: Vec<u32> = self
            .tex
            .bundles
            .iter()
            .map(|b| strands_in_bundle(b, &self.style, n))
            .collect();
        let total: usize = counts.iter().map(|&c| c as usize).sum();
        let mut set = StrandSet {
            verts_per_strand: verts,
            positions: vec![Vec3::ZERO; total * verts],
            tangents: vec![Vec3::ZERO; total * verts],
            widths: vec![0.0; total * verts],
            strand_bundle: Vec::with_capacity(total),
        };
        let mut i = 0;
        for (bundle, &count) in counts.iter().enumerate() {
            for strand in 0..count {
                let range = i * verts..(i + 1) * verts;
                self.strand(
                    bundle as u32,
                    strand,
                    segments,
                    &mut set.positions[range.clone()],
                    &mut set.tangents[range.clone()],
                    &mut set.widths[range],
                );
                set.strand_bundle.push(bundle as u32);
                i += 1;
            }
        }
        set
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::lod::{LodView, bundle_lod};

    /// `generate_lod` draws each bundle as `bundle_lod` decides: its strand count, `2^e + 1`
    /// vertices a strand, widths times eq. 8's thickness, and the newest strand's times its
    /// fade as well (a survivor of the fourth mutation sample faded no strand).
    #[test]
    fn lod_strands_follow_the_bundle_decisions() {
        let (baked, style) = crate::reference::lod::tests::small_patch();
        let generator = CpuGenerator::new(&baked, style);
        let view = LodView {
            eye: Vec3::new(0.0, 0.0, 6.0),
            resolution: 720.0,
            fov_y: 0.8,
            alpha_strands: 0.05,
            area_below: 0.0,
            strands_per_pixel: 0.0,
            alpha_verts: 0.1,
            lambda: 0.5,
            strand_share: 1.0,
            pressure: 1.0,
        };
        let (n, e_max) = (16, 4);
        let (set, counts) = generator.generate_lod(n, e_max, &baked, &view);
        let (mut at, mut s, mut faded) = (0, 0, 0);
        for (bundle, b) in baked.bundles.iter().enumerate() {
            let count = strands_in_bundle(b, &style, n);
            let l = bundle_lod(&baked, &style, bundle, count, e_max, &view);
            for k in 0..l.strands {
                let verts = (1usize << l.e) + 1;
                assert_eq!((set.strand_bundle[s], counts[s]), (bundle as u32, verts));
                let (mut p, mut t, mut w) = (
                    vec![Vec3::ZERO; verts],
                    vec![Vec3::ZERO; verts],
                    vec![0.0; verts],
                );
                generator.strand(bundle as u32, k, 1 << l.e, &mut p, &mut t, &mut w);
                let fade = if k + 1 == l.strands { l.fade } else { 1.0 };
                faded += (fade < 1.0) as usize;
                for (i, w) in w.iter().enumerate() {
                    let want = w * l.thickness * fade;
                    assert!((set.widths[at + i] - want).abs() <= 1e-6 * want.max(1e-6));
                }
                (at, s) = (at + verts, s + 1);
            }
        }
        assert_eq!(s, set.strand_count());
        assert!(faded > 0, "the view must fade some bundle's newest strand");
    }
}
