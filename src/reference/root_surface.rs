//! Curved roots: strands of a bundle start on a smooth surface through its root corners, not
//! on the flat bilinear patch between them.
//!
//! A coarse root layer (a bundle a few centimetres across on a head of 10 cm radius) is a chord
//! of the scalp: bilinear roots in the middle of a bundle lie millimetres inside the head, and
//! from outside the first centimetre of those strands is hidden, so the scalp shows through.
//! Phong tessellation (Boubekeur and Alexa 2008, eq. 4, on the root quads and triangles) moves
//! each root toward the tangent planes of the corners:
//! `p* = q - alpha sum_i w_i ((q - p_i) . n_i) n_i` with `q` the bilinear root, `w_i` its
//! bilinear weights and `n_i` the root-layer normals at the corners (`u x v` of the styling
//! directions, eq. 1-3; the formula ignores their sign). A flat root layer is unchanged. The
//! offset fades out along the first layer segment ([`bulge_fade`]), so the strand joins the
//! hair mesh's curve by layer 1. `glsl/strand_eval.glsl` (`root_cell`, `root_bulge`) is the GPU
//! twin.

use glam::{Vec2, Vec3};

use crate::bake::{BakedHairMesh, BundleDesc};
use crate::reference::texel::{snorm, unorm};

/// Phong tessellation's shape factor `alpha`. On a sphere, a cell of angular half-diagonal
/// `t` bulges `alpha r sin^2(t) cos(t)` at its middle where the sphere is `r (1 - cos t)` above
/// the chord: 0.5 matches to second order (Boubekeur and Alexa's 0.75 overshoots by half).
pub const ROOT_PHONG_SHAPE: f32 = 0.5;

/// A bundle's root cell: corner positions and unit root-layer normals (zero where the
/// styling directions are parallel), in texel order `(0,0) (1,0) (0,1) (1,1)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RootCell {
    /// Object-space root corners.
    pub corners: [Vec3; 4],
    /// Unit normals of the root layer at the corners, or zero.
    pub normals: [Vec3; 4],
}

/// Bilinear weights of `local` in texel order.
fn weights(local: Vec2) -> [f32; 4] {
    let (x, y) = (local.x, local.y);
    [(1.0 - x) * (1.0 - y), x * (1.0 - y), (1.0 - x) * y, x * y]
}

impl RootCell {
    /// The root cell of bundle `b`, decoded from the root slices of the hair mesh, u- and
    /// v-textures as the GPU's `texelFetch` reads them.
    pub fn from_baked(baked: &BakedHairMesh, b: &BundleDesc) -> RootCell {
        let info = &baked.info;
        let o = Vec3::from_slice(&info.pos_origin[..3]);
        let e = Vec3::from_slice(&info.pos_extent[..3]);
        let width = info.root_size[0];
        let mut cell = RootCell {
            corners: [Vec3::ZERO; 4],
            normals: [Vec3::ZERO; 4],
        };
        for c in 0..4u32 {
            let i = ((b.origin[1] + (c >> 1)) * width + b.origin[0] + (c & 1)) as usize;
            let t = baked.position[i];
            cell.corners[c as usize] = o + e * Vec3::new(unorm(t[0]), unorm(t[1]), unorm(t[2]));
            let dir = |d: [i16; 4]| Vec3::new(snorm(d[0]), snorm(d[1]), snorm(d[2]));
            let n = dir(baked.u_dir[i]).cross(dir(baked.v_dir[i]));
            cell.normals[c as usize] = n.normalize_or_zero();
        }
        cell
    }

    /// The bilinear root at local cell coordinate `local` (in `[0, 1]^2`).
    pub fn bilinear(&self, local: Vec2) -> Vec3 {
        let w = weights(local);
        (0..4).map(|i| self.corners[i] * w[i]).sum()
    }

    /// Phong offset of the root at `local`: `-alpha sum_i w_i ((q - p_i) . n_i) n_i`.
    pub fn bulge(&self, local: Vec2) -> Vec3 {
        let w = weights(local);
        let q = self.bilinear(local);
        let sum: Vec3 = (0..4)
            .map(|i| self.normals[i] * (w[i] * (q - self.corners[i]).dot(self.normals[i])))
            .sum();
        -ROOT_PHONG_SHAPE * sum
    }

    /// Largest length of [`Self::bulge`] anywhere in the cell: `(q - p_i) . n_i` is linear in
    /// `q`, which lies in the corners' convex hull, so it is at most the largest height of a
    /// corner over another's tangent plane.
    pub fn bulge_bound(&self) -> f32 {
        let mut most = 0.0f32;
        for i in 0..4 {
            for j in 0..4 {
                let h = (self.corners[j] - self.corners[i]).dot(self.normals[i]);
                most = most.max(h.abs());
            }
        }
        ROOT_PHONG_SHAPE * most
    }
}

/// Share of the root offset left at curve parameter `r` (layer units): `(1 - r)^2` over the
/// first segment, 0 from layer 1 on (its slope vanishes there, so the strand has no kink).
pub fn bulge_fade(r: f32) -> f32 {
    let x = (1.0 - r).max(0.0);
    x * x
}

/// Local cell coordinate of root sample `xi` in bundle `b`: triangles map `xi` (with
/// `xi.x + xi.y < 1`) to `(xi.x / (1 - xi.y), xi.y)`, so bilinear weights equal barycentrics
/// with `xi.y` the weight of the duplicated vertex (paper 003 sec. 3.3).
pub fn local_coord(b: &BundleDesc, xi: Vec2) -> Vec2 {
    if b.is_triangle() {
        Vec2::new(xi.x / (1.0 - xi.y).max(1e-6), xi.y)
    } else {
        xi
    }
    .clamp(Vec2::ZERO, Vec2::ONE)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere_cell(half_angle: f32) -> RootCell {
        // A square cell on the unit sphere around +Z, corners at +-half_angle on both axes.
        let p = |a: f32, b: f32| Vec3::new(a.tan(), b.tan(), 1.0).normalize();
        let corners = [
            p(-half_angle, -half_angle),
            p(half_angle, -half_angle),
            p(-half_angle, half_angle),
            p(half_angle, half_angle),
        ];
        RootCell {
            corners,
            normals: corners,
        }
    }

    #[test]
    fn roots_of_a_curved_cell_lie_near_the_sphere() {
        for half in [0.1f32, 0.2, 0.3] {
            let cell = sphere_cell(half);
            for local in [Vec2::splat(0.5), Vec2::new(0.25, 0.5), Vec2::new(0.1, 0.8)] {
                let flat = cell.bilinear(local).length();
                let curved = (cell.bilinear(local) + cell.bulge(local)).length();
                assert!(
                    (1.0 - curved).abs() < 0.25 * (1.0 - flat),
                    "half angle {half} at {local}: flat {flat}, curved {curved}"
                );
                assert!(cell.bulge(local).length() <= cell.bulge_bound() + 1e-6);
            }
        }
    }

    #[test]
    fn a_flat_cell_and_its_corners_do_not_move() {
        let cell = RootCell {
            corners: [Vec3::ZERO, Vec3::X, Vec3::Z, Vec3::X + Vec3::Z],
            normals: [Vec3::Y; 4],
        };
        assert_eq!(cell.bulge(Vec2::splat(0.5)), Vec3::ZERO);
        assert_eq!(cell.bulge_bound(), 0.0);
        let curved = sphere_cell(0.3);
        for (c, local) in [Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE]
            .into_iter()
            .enumerate()
        {
            assert!(curved.bulge(local).length() < 1e-6, "corner {c}");
        }
        assert_eq!(bulge_fade(0.0), 1.0);
        assert_eq!(bulge_fade(1.0), 0.0);
        assert_eq!(bulge_fade(3.0), 0.0);
    }
}
