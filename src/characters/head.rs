//! Ellipsoid heads (the furry balls) and their scalp, and simple prop meshes (balls, the
//! ground). All in metres, the character's own frame: feet at the origin, +Y up, facing +Z.

use glam::{Vec2, Vec3};

use super::human::direction;

use crate::model::hair_mesh::Face;
use crate::render::core::shared::PropVertex;

/// The head ellipsoid: centre and radii (x width, y height, z depth).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeadShape {
    /// Centre of the head.
    pub centre: Vec3,
    /// Radii.
    pub radii: Vec3,
}

impl Default for HeadShape {
    fn default() -> Self {
        HeadShape {
            centre: Vec3::new(0.0, 1.62, 0.0),
            radii: Vec3::new(0.078, 0.105, 0.095),
        }
    }
}

impl HeadShape {
    /// Point of the head surface in `direction` (from the centre).
    pub fn surface(&self, dir: Vec3) -> Vec3 {
        let d = dir.normalize_or(Vec3::Y);
        // Ray-ellipsoid: scale so that |d / r| = 1.
        let t = 1.0 / (d / self.radii).length();
        self.centre + d * t
    }

    /// The radius of a sphere around the head (for keeping hair layers outside it).
    pub fn bounding_radius(&self) -> f32 {
        self.radii.max_element()
    }
}

/// A scalp: unique vertices with uv and quad faces, ready for [`crate::extrude`].
pub struct ScalpPatch {
    /// Vertex positions on the head.
    pub positions: Vec<Vec3>,
    /// uv styling coordinates.
    pub uv: Vec<Vec2>,
    /// Quads.
    pub faces: Vec<Face>,
}

/// A grid of `n x n` quads over the ball down to 150 degrees from the top, parametrised by an
/// azimuthal equidistant map from the crown (no seam, no pole).
pub fn scalp(head: &HeadShape, n: usize) -> ScalpPatch {
    let n = n.max(2);
    let theta_max = 150f32.to_radians();
    let grid = |i: usize, j: usize| -> (Vec2, Vec3, f32) {
        let a = Vec2::new(i as f32 / n as f32, j as f32 / n as f32) * 2.0 - 1.0;
        let r = a.length().min(1.0);
        let theta = r * theta_max;
        let phi = a.y.atan2(a.x);
        let p = head.surface(direction(theta, phi));
        (a * 0.5 + 0.5, p, theta)
    };
    let mut index = vec![u32::MAX; (n + 1) * (n + 1)];
    let mut patch = ScalpPatch {
        positions: Vec::new(),
        uv: Vec::new(),
        faces: Vec::new(),
    };
    for j in 0..n {
        for i in 0..n {
            let corners = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
            if !corners
                .iter()
                .all(|&(a, b)| grid(a, b).2 < theta_max * 0.999)
            {
                continue;
            }
            let mut quad = [0u32; 4];
            for (q, &(a, b)) in quad.iter_mut().zip(&corners) {
                let k = b * (n + 1) + a;
                if index[k] == u32::MAX {
                    let (uv, p, _) = grid(a, b);
                    index[k] = patch.positions.len() as u32;
                    patch.positions.push(p);
                    patch.uv.push(uv);
                }
                *q = index[k];
            }
            // Counter-clockwise seen from outside (normals point away from the head).
            patch
                .faces
                .push(Face::Quad([quad[0], quad[3], quad[2], quad[1]]));
        }
    }
    patch
}

fn vertex(p: Vec3, n: Vec3) -> PropVertex {
    PropVertex {
        position: p.extend(1.0).to_array(),
        normal: n.extend(0.0).to_array(),
    }
}

/// An ellipsoid prop mesh (a ball, a bare head).
pub fn sphere_mesh(centre: Vec3, radii: Vec3) -> Vec<PropVertex> {
    let mut tris = Vec::new();
    super::person::ellipsoid(&mut tris, centre, radii, 16, 32);
    super::human::smooth_prop_mesh(&tris)
}

/// A flat square of `half` metres around the origin at y = 0, facing up.
pub fn ground_mesh(half: f32) -> Vec<PropVertex> {
    let n = Vec3::Y;
    let c = [
        Vec3::new(-half, 0.0, -half),
        Vec3::new(-half, 0.0, half),
        Vec3::new(half, 0.0, half),
        Vec3::new(half, 0.0, -half),
    ];
    [c[0], c[1], c[2], c[0], c[2], c[3]]
        .iter()
        .map(|&p| vertex(p, n))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ball_scalp_covers_the_ball() {
        let head = HeadShape::default();
        let s = scalp(&head, 12);
        assert!(s.faces.len() > 80, "{} faces", s.faces.len());
        for p in &s.positions {
            assert!(((*p - head.centre) / head.radii).length() - 1.0 < 1e-4);
        }
        // The ball's prop mesh faces outward.
        for v in sphere_mesh(head.centre, head.radii) {
            let (p, n) = (
                Vec3::from_slice(&v.position[..3]),
                Vec3::from_slice(&v.normal[..3]),
            );
            assert!(n.dot(p - head.centre) > 0.0, "{p} {n}");
        }
    }
}
