//! Hair self-shadowing, and hair and bodies shadowing each other, from one directional light:
//! what the modes are and how the light's orthographic view is fitted to the crowd.
//!
//! - **Deep opacity maps** (Yuksel and Keyser 2008; seed 004 sec. on shadows): the hair nearest
//!   the light gives a depth map; a second pass adds each strand fragment's opacity into one of
//!   [`SHADOW_LAYERS`] layers behind that depth; a lookup sums the layers in front of a point.
//! - **Approximate deep shadow maps** (seed 002, vkhr): the depth map alone; the number of
//!   strands between the first hair and a point is estimated from the depth difference and a
//!   strand spacing, and transmittance is `(1 - alpha)^n`. Cheaper: one light pass, not two.
//!
//! Both render the hair from the light with the same generator (task/mesh shaders or the
//! compute path), with LoD from the orthographic form of paper 003 eq. 7, so distant or small
//! characters are cheap in the light's view too. Opaque props (heads, bodies) get a plain depth
//! map. The GLSL side is `glsl/shadow_lookup.glsl` (lookup) and `glsl/shadow.frag` (passes).

use glam::{Mat4, Vec3, Vec4};

use super::camera::{LodSettings, box_corners, frustum_planes};
use super::core::shared::{
    BodyShadowFields, FrameBlock, LodFields, STRAND_SHADOW_OPACITY, ShadowFields, SoftFields,
    TemporalFields,
};

/// Deep opacity layers (the 4 channels of one RGBA16F map).
pub const SHADOW_LAYERS: u32 = 4;

/// The light's passes choose strand and vertex level of detail with eq. 7's alphas times this
/// (paper 003 sec. 3.6): as if the map had this share of its resolution. Shadows are soft and
/// the thick-strand term keeps each bundle's coverage, so the light draws fewer, thicker
/// strands than the camera for the same bundle.
pub const LIGHT_LOD_SCALE: f32 = 0.5;

/// How many texels of the bodies' light map count as one pixel where a body's far version is
/// chosen for the light: the map is read through a box filter three texels wide
/// ([`box_pcf_weights`]), and the camera's far levels switch where a cell spans two pixels
/// (`characters::preset::FAR_CELL_PIXELS`), so the light switches where a cell spans the
/// filter's three texels. Measured on lavapipe (2-core VM, 1000 people, 1280x720, two
/// alternating runs against 1.0): the bodies' shadow draw 262-289 -> 158-170 ms, the frame
/// 3% faster, FLIP 0.0035.
pub const LIGHT_FAR_TEXELS_PER_PIXEL: f32 = 1.5;
pub use super::settings::{DEFAULT_SHADOW_RESOLUTION, ShadowMode};

impl std::str::FromStr for ShadowMode {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        ShadowMode::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| format!("unknown shadow mode '{s}' (off, deep-opacity, approximate)"))
    }
}

/// The light's orthographic view, fitted around the characters that receive shadows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightView {
    /// World to the light's Vulkan clip space (depth 0 nearest the light).
    pub view_proj: Mat4,
    /// Unit direction toward the light.
    pub dir: Vec3,
    /// A point on the near plane, at the centre of the view.
    pub eye: Vec3,
    /// Side of the square view, world units.
    pub size: f32,
    /// far - near, world units.
    pub depth_range: f32,
    /// Thickness of one deep-opacity layer, world units.
    pub layer_spacing: f32,
    /// Map resolution (square).
    pub resolution: u32,
}

impl LightView {
    /// Fit a `resolution`-texel square view along `light_dir` (toward the light) around
    /// `bounds` (world boxes of the hair that casts and receives shadows). The far plane is
    /// pushed back by half the view size so the ground and bodies below receive shadows.
    /// `None` when there is nothing to fit.
    pub fn fit(bounds: &[(Vec3, Vec3)], light_dir: Vec3, resolution: u32) -> Option<Self> {
        if bounds.is_empty() || resolution == 0 {
            return None;
        }
        let basis = LightBasis::new(light_dir)?;
        let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
        let mut diag_sum = 0.0;
        for (blo, bhi) in bounds {
            diag_sum += (*bhi - *blo).length();
            for c in box_corners(*blo, *bhi) {
                let l = basis.local(c);
                lo = lo.min(l);
                hi = hi.max(l);
            }
        }
        if !(lo.is_finite() && hi.is_finite()) {
            return None;
        }
        let size = (hi.x - lo.x).max(hi.y - lo.y).max(1e-4) * 1.02;
        let mut view = basis.view((lo, hi), size, resolution);
        // Four layers span about a fifth of a character's hair box.
        view.layer_spacing = (diag_sum / bounds.len() as f32 * 0.05).max(view.texel());
        Some(view)
    }

    /// The bodies' map (props that move with characters: heads, eyes, clothes), fitted to what
    /// the camera sees of them: the light-space rectangle of `bodies` (world spheres, centre
    /// and radius) in the camera's frustum (`view_proj`, eye at `eye`), cut down to the part of
    /// the frustum in front of the farthest of them, so a portrait's map spans the head and
    /// shoulders and a crowd's the crowd. Every body in that rectangle casts (the near plane
    /// reaches the highest of them). The side snaps to steps of 2^(1/8) and the centre to whole
    /// texels, so the map holds still while the camera moves a little. `None` when no body is
    /// in view.
    pub fn fit_bodies(
        bodies: &[(Vec3, f32)],
        (view_proj, eye): (Mat4, Vec3),
        light_dir: Vec3,
        resolution: u32,
    ) -> Option<Self> {
        let planes = frustum_planes(view_proj);
        let seen = |&&(c, r): &&(Vec3, f32)| {
            planes
                .iter()
                .all(|p| Vec3::from_slice(&p[..3]).dot(c) + p[3] >= -r)
        };
        let visible: Vec<(Vec3, f32)> = bodies.iter().filter(seen).copied().collect();
        if visible.is_empty() || resolution == 0 {
            return None;
        }
        let basis = LightBasis::new(light_dir)?;
        let spread = |lo: &mut Vec3, hi: &mut Vec3, p: Vec3, r: f32| {
            *lo = lo.min(p - Vec3::splat(r));
            *hi = hi.max(p + Vec3::splat(r));
        };
        let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
        for &(c, r) in &visible {
            spread(&mut lo, &mut hi, basis.local(c), r);
        }
        if let Some(slice) = frustum_slice(view_proj, eye, &visible) {
            let (mut flo, mut fhi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
            for p in slice {
                spread(&mut flo, &mut fhi, basis.local(p), 0.0);
            }
            let (clo, chi) = (lo.max(flo), hi.min(fhi));
            if clo.x < chi.x && clo.y < chi.y {
                (lo.x, lo.y, hi.x, hi.y) = (clo.x, clo.y, chi.x, chi.y);
            }
        }
        // Casters outside the view that overhang the rectangle move the near plane up.
        for &(c, r) in bodies {
            let l = basis.local(c);
            if l.x + r > lo.x && l.x - r < hi.x && l.y + r > lo.y && l.y - r < hi.y {
                lo.z = lo.z.min(l.z - r);
            }
        }
        if !(lo.is_finite() && hi.is_finite()) {
            return None;
        }
        let side = (hi.x - lo.x).max(hi.y - lo.y).max(1e-3) * 1.02;
        let size = 2f32.powf((side.log2() * 8.0).ceil() / 8.0);
        Some(basis.view((lo, hi), size, resolution))
    }

    /// The bodies' map fields of a camera frame block: `(body_view_proj, body_shadow)`.
    pub fn body_fields(&self) -> ([[f32; 4]; 4], BodyShadowFields) {
        (
            self.view_proj.to_cols_array_2d(),
            BodyShadowFields {
                resolution: self.resolution as f32,
                depth_range: self.depth_range,
                bias: self.bias(),
                texel: self.texel(),
            },
        )
    }

    /// World size of one texel.
    pub fn texel(&self) -> f32 {
        self.size / self.resolution as f32
    }

    /// Depth bias of lookups, world units: a few texels' worth of slope.
    pub fn bias(&self) -> f32 {
        2.0 * self.texel()
    }

    /// The light's own frame block: orthographic (`lod.tan_fov = 0`, `cot_half_fov = 0`), LoD from the
    /// view size, culling against the light's box; otherwise as `camera` (counts, shading,
    /// shadow settings). With `soft` (the software shadow passes' budgets) every bundle goes to
    /// the software rasterizer as depth and coverage (`RASTER_LIGHT`), binned into the map's
    /// tiles; otherwise the light's passes draw hardware strips.
    pub fn frame_block(
        &self,
        camera: &FrameBlock,
        lod: &LodSettings,
        soft: Option<super::soft::SoftBudget>,
    ) -> FrameBlock {
        let res = self.resolution as f32;
        let (tiles_x, tiles_y) = super::soft::tile_grid(self.resolution, self.resolution);
        let soft = match soft {
            Some(b) => SoftFields {
                mode: super::core::shared::RASTER_LIGHT,
                segment_budget: b.segments,
                tile_entry_budget: b.tile_entries,
                tiles_x,
                tiles_y,
                ..Default::default()
            },
            None => SoftFields::default(),
        };
        FrameBlock {
            view_proj: self.view_proj.to_cols_array_2d(),
            eye: self.eye.to_array(),
            pixels_high: res,
            to_light: self.dir.to_array(),
            cot_half_fov: 0.0,
            viewport: [res, res, 1.0 / res, 1.0 / res],
            planes: frustum_planes(self.view_proj),
            lod: LodFields {
                alpha_strands: lod.alpha_strands * LIGHT_LOD_SCALE,
                alpha_verts: lod.alpha_verts * LIGHT_LOD_SCALE,
                lambda: lod.lambda,
                tan_fov: 0.0,
                ortho_height: self.size,
                area_below: lod.area_below,
                // The pixel cap counts texels of the map at LIGHT_LOD_SCALE of its
                // resolution, as eq. 7's alphas do: a quarter of the camera's strands per
                // texel².
                strands_per_pixel: lod.strands_per_pixel * LIGHT_LOD_SCALE * LIGHT_LOD_SCALE,
                _pad: 0.0,
            },
            soft,
            // The light's views note no visibility and accumulate nothing.
            temporal: TemporalFields::default(),
            ..*camera
        }
    }

    /// The shadow fields of a frame block in `mode`: the light's view and its maps.
    pub fn shadow_fields(&self, mode: ShadowMode) -> ([[f32; 4]; 4], ShadowFields) {
        (
            self.view_proj.to_cols_array_2d(),
            ShadowFields {
                mode: mode as u32,
                resolution: self.resolution,
                _pad: [0; 2],
                layer_thickness: self.layer_spacing,
                depth_range: self.depth_range,
                strand_opacity: STRAND_SHADOW_OPACITY,
                bias: self.bias(),
            },
        )
    }
}

/// Weights of the bodies' map filter (`body_visibility` in `glsl/shadow_lookup.glsl`) along one
/// axis: the 4 depth comparisons at texel offsets -1..=2 from the texel below a point at
/// fraction `f` (0..1) of the way to the next texel centre. A 3x3-texel box sliding with the
/// point, `(1 - f, 1, 1, f)`, summing to 3: the filtered visibility is continuous as the point
/// crosses texels, so a shadow edge is a ramp three texels wide instead of a staircase.
pub fn box_pcf_weights(f: f32) -> [f32; 4] {
    let f = f.clamp(0.0, 1.0);
    [1.0 - f, 1.0, 1.0, f]
}

/// The light's orthonormal frame: `side` and `up` span the map, `forward` points away from
/// the light.
struct LightBasis {
    dir: Vec3,
    side: Vec3,
    up: Vec3,
    forward: Vec3,
}

impl LightBasis {
    /// The frame of unit direction `light_dir` (toward the light); `None` for a zero vector.
    fn new(light_dir: Vec3) -> Option<Self> {
        let dir = light_dir.try_normalize()?;
        let forward = -dir;
        let up_ref = if forward.y.abs() < 0.99 {
            Vec3::Y
        } else {
            Vec3::Z
        };
        let side = forward.cross(up_ref).normalize();
        let up = side.cross(forward);
        Some(LightBasis {
            dir,
            side,
            up,
            forward,
        })
    }

    /// World point `p` in the light's frame (x side, y up, z depth away from the light).
    fn local(&self, p: Vec3) -> Vec3 {
        Vec3::new(p.dot(self.side), p.dot(self.up), p.dot(self.forward))
    }

    /// A square view of side `size` centred on the light-space box `(lo, hi)`: the centre
    /// snapped to whole texels so the map does not shimmer as the crowd moves, the near plane
    /// just in front of the box and the far plane half a view behind it, so the ground and
    /// bodies below receive shadows.
    fn view(&self, (lo, hi): (Vec3, Vec3), size: f32, resolution: u32) -> LightView {
        let texel = size / resolution as f32;
        let cx = (((lo.x + hi.x) * 0.5) / texel).round() * texel;
        let cy = (((lo.y + hi.y) * 0.5) / texel).round() * texel;
        let near = lo.z - 0.02 * size;
        let far = hi.z + 0.5 * size;
        let range = far - near;
        let rows = [
            (self.side * (2.0 / size)).extend(-cx * 2.0 / size),
            (self.up * (-2.0 / size)).extend(cy * 2.0 / size),
            (self.forward / range).extend(-near / range),
            Vec4::new(0.0, 0.0, 0.0, 1.0),
        ];
        let view_proj = Mat4::from_cols(rows[0], rows[1], rows[2], rows[3]).transpose();
        LightView {
            view_proj,
            dir: self.dir,
            eye: self.side * cx + self.up * cy + self.forward * near,
            size,
            depth_range: range,
            layer_spacing: texel,
            resolution,
        }
    }
}

/// The 8 corners of the part of the camera's frustum (`view_proj`, eye at `eye`) between its
/// near plane and the far side of the farthest of `spheres`; `None` for views that are not
/// perspective.
fn frustum_slice(view_proj: Mat4, eye: Vec3, spheres: &[(Vec3, f32)]) -> Option<[Vec3; 8]> {
    let inv = view_proj.inverse();
    let unproject = |x: f32, y: f32, z: f32| inv.project_point3(Vec3::new(x, y, z));
    let forward = (unproject(0.0, 0.0, 1.0) - unproject(0.0, 0.0, 0.0)).try_normalize()?;
    let reach = spheres
        .iter()
        .map(|&(c, r)| (c - eye).dot(forward) + r)
        .fold(0.0, f32::max);
    let mut out = [Vec3::ZERO; 8];
    for (k, (x, y)) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)]
        .into_iter()
        .enumerate()
    {
        let near = unproject(x, y, 0.0);
        let far = unproject(x, y, 1.0);
        let depth = (far - eye).dot(forward);
        if !(depth > 0.0 && near.is_finite() && far.is_finite()) {
            return None;
        }
        out[2 * k] = near;
        out[2 * k + 1] = eye + (far - eye) * (reach.max((near - eye).dot(forward)) / depth);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sliding box turns a shadow edge into a continuous ramp three texels wide: the
    /// filtered visibility of a point moving across a straight edge (texels at or beyond 0 in
    /// shadow) never jumps by more than the step's share of the ramp, and runs from lit to
    /// shadowed over 3 texels. (A fixed 3x3 box, `[1, 1, 1, 0]` whatever `f`, jumps by a
    /// third at every texel.)
    #[test]
    fn the_body_map_filter_ramps_across_an_edge() {
        let visibility = |x: f32| {
            // Texel centres at k + 0.5; the point's texel below and its fraction.
            let st = x - 0.5;
            let (base, f) = (st.floor(), st - st.floor());
            let w = box_pcf_weights(f);
            let lit: f32 = (0..4)
                .map(|i| {
                    let texel = base as i32 + i - 1;
                    if texel < 0 { w[i as usize] } else { 0.0 }
                })
                .sum();
            lit / 3.0
        };
        let steps = 1000;
        let (from, to) = (-3.0f32, 3.0f32);
        let mut prev = visibility(from);
        assert_eq!(prev, 1.0);
        for k in 1..=steps {
            let x = from + (to - from) * k as f32 / steps as f32;
            let v = visibility(x);
            assert!(v <= prev + 1e-6, "{x}: {prev} -> {v}");
            assert!(prev - v < 0.01, "{x}: jumps {prev} -> {v}");
            prev = v;
        }
        assert_eq!(prev, 0.0);
        // The ramp is centred on the edge (x = 0) and three texels wide.
        assert_eq!(visibility(-1.5), 1.0);
        assert!(visibility(-1.4) < 1.0);
        assert_eq!(visibility(1.5), 0.0);
        assert!((visibility(0.0) - 0.5).abs() < 1e-6);
        assert_eq!(box_pcf_weights(0.3).iter().sum::<f32>(), 3.0);
    }

    #[test]
    fn light_view_contains_the_bounds_and_orders_depth_from_the_light() {
        let bounds = [
            (Vec3::new(-1.0, 1.4, -0.2), Vec3::new(-0.6, 1.9, 0.2)),
            (Vec3::new(2.0, 1.4, 3.0), Vec3::new(2.4, 1.9, 3.4)),
        ];
        let dir = Vec3::new(0.4, 1.0, 0.3);
        let v = LightView::fit(&bounds, dir, 512).unwrap();
        for (lo, hi) in bounds {
            for p in [lo, hi, (lo + hi) * 0.5] {
                let c = v.view_proj * p.extend(1.0);
                assert!((c.w - 1.0).abs() < 1e-6);
                assert!(c.x.abs() <= 1.0 && c.y.abs() <= 1.0, "{p} -> {c}");
                assert!((0.0..=1.0).contains(&c.z), "{p} -> {c}");
            }
        }
        // Closer to the light means smaller depth.
        let mid = (bounds[0].0 + bounds[0].1) * 0.5;
        let a = v.view_proj * mid.extend(1.0);
        let b = v.view_proj * (mid - dir.normalize() * 0.1).extend(1.0);
        assert!(b.z > a.z);
        // Depth is linear in world distance: 0.1 further is 0.1 / range in depth.
        assert!(((b.z - a.z) * v.depth_range - 0.1).abs() < 1e-4);
        assert!(v.layer_spacing > 0.0 && v.bias() > 0.0);
        assert!(LightView::fit(&[], dir, 512).is_none());
        assert!(LightView::fit(&bounds, Vec3::ZERO, 512).is_none());
        assert_eq!(
            "approximate".parse::<ShadowMode>(),
            Ok(ShadowMode::Approximate)
        );
        assert!("soft".parse::<ShadowMode>().is_err());
    }
}
