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
use super::shared::FrameBlock;

/// Deep opacity layers (the 4 channels of one RGBA16F map).
pub const SHADOW_LAYERS: u32 = 4;
/// Opacity of one strand to the light: fibres pass part of the light (the TT lobe), so one
/// strand does not block it all.
pub const STRAND_SHADOW_OPACITY: f32 = 0.5;
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
        let dir = light_dir.try_normalize()?;
        let forward = -dir;
        let up_ref = if forward.y.abs() < 0.99 {
            Vec3::Y
        } else {
            Vec3::Z
        };
        let side = forward.cross(up_ref).normalize();
        let up = side.cross(forward);
        let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
        let mut diag_sum = 0.0;
        for (blo, bhi) in bounds {
            diag_sum += (*bhi - *blo).length();
            for c in box_corners(*blo, *bhi) {
                let l = Vec3::new(c.dot(side), c.dot(up), c.dot(forward));
                lo = lo.min(l);
                hi = hi.max(l);
            }
        }
        if !(lo.is_finite() && hi.is_finite()) {
            return None;
        }
        let size = (hi.x - lo.x).max(hi.y - lo.y).max(1e-4) * 1.02;
        // Snap the centre to whole texels so the map does not shimmer as the crowd moves.
        let texel = size / resolution as f32;
        let cx = (((lo.x + hi.x) * 0.5) / texel).round() * texel;
        let cy = (((lo.y + hi.y) * 0.5) / texel).round() * texel;
        let near = lo.z - 0.02 * size;
        let far = hi.z + 0.5 * size;
        let range = far - near;
        let rows = [
            (side * (2.0 / size)).extend(-cx * 2.0 / size),
            (up * (-2.0 / size)).extend(cy * 2.0 / size),
            (forward / range).extend(-near / range),
            Vec4::new(0.0, 0.0, 0.0, 1.0),
        ];
        let view_proj = Mat4::from_cols(rows[0], rows[1], rows[2], rows[3]).transpose();
        let mean_diag = diag_sum / bounds.len() as f32;
        Some(LightView {
            view_proj,
            dir,
            eye: side * cx + up * cy + forward * near,
            size,
            depth_range: range,
            // Four layers span about a fifth of a character's hair box.
            layer_spacing: (mean_diag * 0.05).max(texel),
            resolution,
        })
    }

    /// World size of one texel.
    pub fn texel(&self) -> f32 {
        self.size / self.resolution as f32
    }

    /// Depth bias of lookups, world units: a few texels' worth of slope.
    pub fn bias(&self) -> f32 {
        2.0 * self.texel()
    }

    /// The light's own frame block: orthographic (`lod.w = 0`, `light_dir.w = 0`), LoD from the
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
        let (tx, ty) = super::soft::tile_grid(self.resolution, self.resolution);
        let (soft, soft_grid) = match soft {
            Some(b) => (
                [super::shared::RASTER_LIGHT, 0, b.segments, b.tile_entries],
                [tx, ty, 0, 0],
            ),
            None => ([0; 4], [0; 4]),
        };
        FrameBlock {
            view_proj: self.view_proj.to_cols_array_2d(),
            camera_pos: self.eye.extend(res).to_array(),
            light_dir: self.dir.extend(0.0).to_array(),
            viewport: [res, res, 1.0 / res, 1.0 / res],
            planes: frustum_planes(self.view_proj),
            lod: [lod.alpha_strands, lod.alpha_verts, lod.lambda, 0.0],
            lod_ortho: [self.size, 0.0, 0.0, 0.0],
            soft,
            soft_params: [0.0; 4],
            soft_grid,
            // The light's views note no visibility and accumulate nothing.
            temporal: [0; 4],
            temporal_params: [0.0; 4],
            ..*camera
        }
    }

    /// The shadow fields of a frame block in `mode`.
    pub fn shadow_fields(&self, mode: ShadowMode) -> ([[f32; 4]; 4], [u32; 4], [f32; 4]) {
        (
            self.view_proj.to_cols_array_2d(),
            [mode as u32, self.resolution, 0, 0],
            [
                self.layer_spacing,
                self.depth_range,
                STRAND_SHADOW_OPACITY,
                self.bias(),
            ],
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
