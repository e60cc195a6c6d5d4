//! A procedural character: an ellipsoid head on a neck, shoulders and a tapered body standing
//! on the ground, and the scalp region of the head that hair grows from. All in metres, the
//! character's own frame: feet at the origin, +Y up, facing +Z.

use glam::{Vec2, Vec3};

use crate::model::hair_mesh::Face;
use crate::render::shared::PropVertex;

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

/// Direction from polar angle `theta` (from +Y) and azimuth `phi` (from +X toward +Z).
fn direction(theta: f32, phi: f32) -> Vec3 {
    Vec3::new(
        theta.sin() * phi.cos(),
        theta.cos(),
        theta.sin() * phi.sin(),
    )
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

/// Which part of the head grows hair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ScalpRegion {
    /// The usual hairline: down to the nape and ears at the back and sides, above the forehead
    /// at the front.
    Full,
    /// A strip over the top from front to back (`half_width` metres on each side).
    Strip {
        /// Half width in metres.
        half_width: f32,
    },
    /// Everything down to 150 degrees from the top (fur on a ball).
    All,
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

/// Polar limit of the hairline at azimuth `phi`: low at the back and sides, higher at the
/// forehead (+Z).
fn hairline(phi: f32) -> f32 {
    let front = phi.sin().max(0.0).powf(0.7);
    (108.0f32 + (58.0 - 108.0) * front).to_radians()
}

/// A grid of `n x n` quads over the head, parametrised by an azimuthal equidistant map from the
/// crown (no seam, no pole), keeping quads inside `region`.
pub fn scalp(head: &HeadShape, region: ScalpRegion, n: usize) -> ScalpPatch {
    let n = n.max(2);
    let theta_max = match region {
        ScalpRegion::All => 150f32.to_radians(),
        _ => 112f32.to_radians(),
    };
    let grid = |i: usize, j: usize| -> (Vec2, Vec3, f32, f32) {
        let a = Vec2::new(i as f32 / n as f32, j as f32 / n as f32) * 2.0 - 1.0;
        let r = a.length().min(1.0);
        let theta = r * theta_max;
        let phi = a.y.atan2(a.x);
        let p = head.surface(direction(theta, phi));
        (a * 0.5 + 0.5, p, theta, phi)
    };
    let inside = |p: Vec3, theta: f32, phi: f32| match region {
        ScalpRegion::Full => theta <= hairline(phi),
        ScalpRegion::Strip { half_width } => {
            (p.x - head.centre.x).abs() <= half_width && theta <= 100f32.to_radians()
        }
        ScalpRegion::All => true,
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
            if !corners.iter().all(|&(a, b)| {
                let (_, p, t, f) = grid(a, b);
                inside(p, t, f) && t < theta_max * 0.999
            }) {
                continue;
            }
            let mut quad = [0u32; 4];
            for (q, &(a, b)) in quad.iter_mut().zip(&corners) {
                let k = b * (n + 1) + a;
                if index[k] == u32::MAX {
                    let (uv, p, ..) = grid(a, b);
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

/// Triangles of an ellipsoid around `centre` with `radii`, `rings x segments`.
fn ellipsoid(out: &mut Vec<PropVertex>, centre: Vec3, radii: Vec3, rings: usize, segments: usize) {
    let point = |ring: usize, seg: usize| {
        let theta = std::f32::consts::PI * ring as f32 / rings as f32;
        let phi = std::f32::consts::TAU * seg as f32 / segments as f32;
        let d = direction(theta, phi);
        (centre + d * radii, (d / radii).normalize_or(d))
    };
    for ring in 0..rings {
        for seg in 0..segments {
            let a = point(ring, seg);
            let b = point(ring + 1, seg);
            let c = point(ring + 1, seg + 1);
            let d = point(ring, seg + 1);
            for (p, n) in [a, b, c, a, c, d] {
                out.push(vertex(p, n));
            }
        }
    }
}

/// Triangles of a vertical truncated cone from `(y0, r0)` to `(y1, r1)`, elliptical by
/// `depth` (z radius / x radius).
fn frustum(
    out: &mut Vec<PropVertex>,
    y0: f32,
    r0: f32,
    y1: f32,
    r1: f32,
    depth: f32,
    segments: usize,
) {
    let slope = (r0 - r1) / (y1 - y0);
    let point = |y: f32, r: f32, seg: usize| {
        let phi = std::f32::consts::TAU * seg as f32 / segments as f32;
        let (c, s) = (phi.cos(), phi.sin());
        let p = Vec3::new(r * c, y, r * depth * s);
        let n = Vec3::new(c, slope, s / depth).normalize();
        (p, n)
    };
    for seg in 0..segments {
        let a = point(y0, r0, seg);
        let b = point(y0, r0, seg + 1);
        let c = point(y1, r1, seg + 1);
        let d = point(y1, r1, seg);
        for (p, n) in [a, b, c, a, c, d] {
            out.push(vertex(p, n));
        }
    }
}

fn vertex(p: Vec3, n: Vec3) -> PropVertex {
    PropVertex {
        position: p.extend(1.0).to_array(),
        normal: n.extend(0.0).to_array(),
    }
}

/// A simple standing figure whose head is `head` (slightly inside it, so the scalp and the
/// hair roots sit on the skin): body, shoulders, neck, head.
pub fn body_mesh(head: &HeadShape) -> Vec<PropVertex> {
    let mut out = Vec::new();
    let shoulder_y = head.centre.y - head.radii.y - 0.09;
    frustum(&mut out, 0.0, 0.13, shoulder_y - 0.05, 0.17, 0.6, 24);
    ellipsoid(
        &mut out,
        Vec3::new(0.0, shoulder_y, 0.0),
        Vec3::new(0.2, 0.07, 0.11),
        10,
        24,
    );
    frustum(
        &mut out,
        shoulder_y,
        0.05,
        head.centre.y - head.radii.y * 0.5,
        0.045,
        1.0,
        16,
    );
    ellipsoid(&mut out, head.centre, head.radii * 0.985, 14, 24);
    out
}

/// An ellipsoid prop mesh (a ball, a bare head).
pub fn sphere_mesh(centre: Vec3, radii: Vec3) -> Vec<PropVertex> {
    let mut out = Vec::new();
    ellipsoid(&mut out, centre, radii, 16, 32);
    out
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
    fn scalp_covers_the_top_and_spares_the_face() {
        let head = HeadShape::default();
        let s = scalp(&head, ScalpRegion::Full, 14);
        assert!(s.faces.len() > 80, "{} faces", s.faces.len());
        for p in &s.positions {
            let d = *p - head.centre;
            // Nothing on the face: low front points are excluded.
            assert!(!(d.z > 0.06 && d.y < 0.0), "{p}");
        }
        let strip = scalp(&head, ScalpRegion::Strip { half_width: 0.02 }, 14);
        assert!(!strip.faces.is_empty() && strip.faces.len() < s.faces.len() / 3);
        let body = body_mesh(&head);
        assert_eq!(body.len() % 3, 0);
    }
}
