//! The human head every person of a crowd wears: the Sintel Lite bust (head, neck and
//! shoulders; `hairmeshes/sintel_head.obj`, "Sintel Lite 2.57b" by BenDansie, CC-BY 3.0, see
//! `hairmeshes/SINTEL_LICENSE.md`), in metres and the canonical character frame (feet at the
//! origin, +Y up, facing +Z, the top of the head at [`CANONICAL_TOP`]).
//!
//! Hair needs the head as a surface it can lie on and never enter, cheaply and the same way
//! for the hairstyle generator, the dynamics colliders and the tests: a *radial map*, the
//! head's distance from its centre in every direction (the farthest crossing of the mesh along
//! the ray within [`RADIAL_REACH`], so every point beyond the map lies outside the mesh). The
//! drawn mesh and the map come from the same triangles.

use std::sync::OnceLock;

use glam::Vec3;

use crate::dynamics::RadialMap;
use crate::error::{HairError, Result};
use crate::render::core::shared::PropVertex;

/// The bust file's units (centimetres) to metres.
pub const FILE_SCALE: f32 = 0.01;
/// Height of the top of the head above the feet, metres, before per-person scaling.
pub const CANONICAL_TOP: f32 = 1.70;
/// Top of the head in the file's units.
const FILE_TOP: f32 = 45.52;
/// Centre of the cranium in the file's units (the radial map's origin).
const FILE_CENTRE: Vec3 = Vec3::new(0.0, 33.0, 0.0);
/// Farthest crossing the radial map keeps, metres from the centre (the head, not the
/// shoulders below it).
pub const RADIAL_REACH: f32 = 0.165;
/// Radial map resolution: polar rows (0..=pi) and azimuth columns (0..2pi).
const MAP_ROWS: usize = 72;
const MAP_COLS: usize = 144;

/// The bust file's frame (and that of `hairmeshes/sintel.obj`, fitted on it) to the
/// canonical character frame.
pub fn file_to_canonical() -> glam::Mat4 {
    glam::Mat4::from_translation(Vec3::new(0.0, CANONICAL_TOP - FILE_TOP * FILE_SCALE, 0.0))
        * glam::Mat4::from_scale(Vec3::splat(FILE_SCALE))
}

/// A point of the bust file in the canonical character frame.
fn from_file(p: Vec3) -> Vec3 {
    file_to_canonical().transform_point3(p)
}

/// Direction from polar angle `theta` (from +Y) and azimuth `phi` (from +X toward +Z).
pub fn direction(theta: f32, phi: f32) -> Vec3 {
    Vec3::new(
        theta.sin() * phi.cos(),
        theta.cos(),
        theta.sin() * phi.sin(),
    )
}

/// Polar angle and azimuth (in `0..2pi`) of unit direction `d` (inverse of [`direction`]).
pub use crate::dynamics::angles;

/// An eyeball in a socket of the bust (canonical frame): a sphere that fills the socket's
/// opening, set back so that it bulges at most a third of its radius out of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Eye {
    /// Centre of the sphere.
    pub centre: Vec3,
    /// Radius of the sphere.
    pub radius: f32,
}

/// The canonical head: its triangles and radial map.
pub struct HumanHead {
    /// Triangles, canonical character frame, metres.
    pub triangles: Vec<[Vec3; 3]>,
    /// Triangles closing the mouth's opening (a fan from its centre), drawn with the bust
    /// (none for a head of the user's: [`HumanHead::from_triangles`]).
    pub mouth: Vec<[Vec3; 3]>,
    /// The eyeballs in the two eye sockets (the bust's openings above the mouth), left then
    /// right (`None` for a head of the user's, which brings its own).
    pub eyes: Option<[Eye; 2]>,
    /// Centre of the cranium (origin of the radial map).
    pub centre: Vec3,
    /// The head's surface about [`Self::centre`]: what hair dynamics collide with.
    pub map: RadialMap,
    /// The same map without the ears ([`opened`]).
    cranium: RadialMap,
}

static HEAD: OnceLock<std::result::Result<HumanHead, String>> = OnceLock::new();

/// The canonical head (parsed and mapped once).
pub fn human_head() -> Result<&'static HumanHead> {
    HEAD.get_or_init(|| {
        HumanHead::from_obj(
            "hairmeshes/sintel_head.obj",
            include_bytes!("../../hairmeshes/sintel_head.obj"),
        )
        .map_err(|e| e.to_string())
    })
    .as_ref()
    .map_err(|e| HairError::invalid("hairmeshes/sintel_head.obj", e.clone()))
}

impl HumanHead {
    /// Parse the bust, build its radial map and find its eyes and mouth.
    pub fn from_obj(name: &str, bytes: &[u8]) -> Result<Self> {
        let triangles: Vec<[Vec3; 3]> = crate::model::obj_io::parse_triangles(name, bytes)?
            .into_iter()
            .map(|t| t.map(from_file))
            .collect();
        let mut head = Self::from_triangles(name, triangles, from_file(FILE_CENTRE))?;
        let (eyes, mouth) = face_openings(name, &head.triangles, head.centre)?;
        head.eyes = Some(eyes);
        head.mouth = mouth;
        Ok(head)
    }

    /// A head from its triangles in the canonical frame (metres) and the centre of its
    /// cranium: its radial map (the farthest crossing within [`RADIAL_REACH`] in every
    /// direction), no eyes and no mouth cap. `name` names the source in errors.
    pub fn from_triangles(name: &str, triangles: Vec<[Vec3; 3]>, centre: Vec3) -> Result<Self> {
        let mut radius = vec![f32::NAN; MAP_ROWS * MAP_COLS];
        // Only triangles that reach within RADIAL_REACH can be hit within it.
        let near: Vec<&[Vec3; 3]> = triangles
            .iter()
            .filter(|t| t.iter().any(|p| p.distance(centre) < RADIAL_REACH * 1.2))
            .collect();
        for row in 0..MAP_ROWS {
            for col in 0..MAP_COLS {
                let d = map_direction(row, col);
                radius[row * MAP_COLS + col] = near
                    .iter()
                    .filter_map(|t| crate::model::obj_io::ray_triangle(centre, d, t))
                    .filter(|&t| t <= RADIAL_REACH)
                    .fold(f32::NAN, f32::max);
            }
        }
        fill_missing(&mut radius).ok_or_else(|| {
            HairError::invalid(name, "the head mesh does not surround its centre")
        })?;
        let map = |radius| RadialMap {
            centre,
            rows: MAP_ROWS,
            cols: MAP_COLS,
            radius,
        };
        let cranium = map(opened(&radius, EAR_WINDOW));
        Ok(HumanHead {
            triangles,
            mouth: Vec::new(),
            eyes: None,
            centre,
            map: map(radius),
            cranium,
        })
    }

    /// Distance of the head surface from [`Self::centre`] in unit direction `d` (bilinear in
    /// the map).
    pub fn radius(&self, d: Vec3) -> f32 {
        self.map.sample(d)
    }

    /// [`Self::radial_gap`] to the head without its ears: what hair lying between two columns
    /// over an ear must clear (it passes beside the ear, not over its far side).
    pub fn cranium_gap(&self, p: Vec3) -> f32 {
        self.cranium.gap(p)
    }

    /// Head surface point at polar angle `theta`, azimuth `phi` about the centre.
    pub fn surface(&self, theta: f32, phi: f32) -> Vec3 {
        let d = direction(theta, phi);
        self.centre + d * self.radius(d)
    }

    /// Signed radial distance of `p` outside the head (negative inside), metres.
    pub fn radial_gap(&self, p: Vec3) -> f32 {
        self.map.gap(p)
    }

    /// `p` moved radially to at least `margin` outside the head (unchanged if already there).
    pub fn push_out(&self, p: Vec3, margin: f32) -> Vec3 {
        self.map.push_out(p, margin)
    }

    /// The bust with its mouth closed as a prop mesh (triangle list, normals averaged over
    /// shared positions).
    pub fn prop_mesh(&self) -> Vec<PropVertex> {
        let mut all = self.triangles.clone();
        all.extend_from_slice(&self.mouth);
        smooth_prop_mesh(&all)
    }
}

/// A position to 10 micrometres, as the key that welds a triangle soup's shared corners.
fn position_key(p: Vec3) -> [i32; 3] {
    (p * 1e5).round().as_ivec3().to_array()
}

/// Boundary loops of a triangle soup (edges used by one triangle), as ordered rings of
/// positions.
/// The rim of `eye`'s socket: the boundary loop of `triangles` within two eye radii of its
/// centre (`None` if there is none).
pub fn socket_rim(triangles: &[[Vec3; 3]], eye: &Eye) -> Option<Vec<Vec3>> {
    boundary_loops(triangles).into_iter().find(|ring| {
        ring.iter()
            .all(|p| p.distance(eye.centre) < 2.0 * eye.radius)
    })
}

fn boundary_loops(triangles: &[[Vec3; 3]]) -> Vec<Vec<Vec3>> {
    let key = position_key;
    let mut count: std::collections::HashMap<([i32; 3], [i32; 3]), i32> = Default::default();
    let mut at: std::collections::HashMap<[i32; 3], Vec3> = Default::default();
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (key(t[k]), key(t[(k + 1) % 3]));
            at.insert(a, t[k]);
            // Directed edge a -> b; a boundary edge has no b -> a.
            *count.entry((a, b)).or_default() += 1;
        }
    }
    let mut next: std::collections::HashMap<[i32; 3], [i32; 3]> = Default::default();
    for (&(a, b), _) in count
        .iter()
        .filter(|(e, _)| !count.contains_key(&(e.1, e.0)))
    {
        next.insert(b, a);
    }
    let mut loops = Vec::new();
    let mut starts: Vec<[i32; 3]> = next.keys().copied().collect();
    starts.sort();
    let mut used = std::collections::HashSet::new();
    for start in starts {
        let mut ring = Vec::new();
        let mut v = start;
        while used.insert(v) {
            ring.push(at[&v]);
            match next.get(&v) {
                Some(&n) => v = n,
                None => break,
            }
        }
        if ring.len() >= 3 {
            loops.push(ring);
        }
    }
    loops
}

/// The eyeballs and the mouth's cap from the bust's openings: the three small openings in
/// front of the centre, the lowest being the mouth.
fn face_openings(
    name: &str,
    triangles: &[[Vec3; 3]],
    centre: Vec3,
) -> Result<([Eye; 2], Vec<[Vec3; 3]>)> {
    let mut face: Vec<(Vec3, f32, Vec<Vec3>)> = boundary_loops(triangles)
        .into_iter()
        .map(|ring| {
            let c = ring.iter().copied().sum::<Vec3>() / ring.len() as f32;
            let r = ring.iter().map(|p| p.distance(c)).fold(0.0, f32::max);
            (c, r, ring)
        })
        .filter(|(c, r, _)| c.z > centre.z && *r < 0.04 && c.distance(centre) < RADIAL_REACH)
        .collect();
    if face.len() != 3 {
        return Err(HairError::invalid(
            name,
            format!(
                "expected two eye openings and a mouth, found {} openings",
                face.len()
            ),
        ));
    }
    face.sort_by(|a, b| a.0.y.total_cmp(&b.0.y));
    let (mouth_centre, _, mouth_ring) = &face[0];
    // Each ring runs against the mesh's boundary edges, so the fan turns like its neighbours.
    let mouth = (0..mouth_ring.len())
        .map(|k| {
            [
                *mouth_centre,
                mouth_ring[k],
                mouth_ring[(k + 1) % mouth_ring.len()],
            ]
        })
        .collect();
    // The sphere's section in the opening's plane has the opening's radius r: with the centre
    // set back by 0.6 R, that section is 0.8 R, so R = 1.25 r and it bulges 0.4 R.
    let eye = |(c, r, _): &(Vec3, f32, Vec<Vec3>)| {
        let radius = 1.25 * r;
        Eye {
            centre: *c - (*c - centre).normalize_or(Vec3::Z) * 0.6 * radius,
            radius,
        }
    };
    let (a, b) = (eye(&face[1]), eye(&face[2]));
    Ok(if a.centre.x < b.centre.x {
        ([a, b], mouth)
    } else {
        ([b, a], mouth)
    })
}

/// Half-width, in map cells (2.5 degrees each), of the window that removes the ears from the
/// radial map: an ear spans about 35 x 17 degrees seen from the centre.
const EAR_WINDOW: usize = 8;

/// Morphological opening of the radial map over `(2 w + 1)^2` cells (minimum, then maximum):
/// removes bumps narrower than the window (the ears) and keeps the broad shape, lowering a
/// smooth dome by the little it varies within the window.
fn opened(map: &[f32], w: usize) -> Vec<f32> {
    let filter = |src: &[f32], pick: fn(f32, f32) -> f32| -> Vec<f32> {
        let mut out = vec![0.0; src.len()];
        for row in 0..MAP_ROWS {
            for col in 0..MAP_COLS {
                let mut v = src[row * MAP_COLS + col];
                for r in row.saturating_sub(w)..(row + w + 1).min(MAP_ROWS) {
                    for dc in 0..2 * w + 1 {
                        let c = (col + MAP_COLS + dc - w) % MAP_COLS;
                        v = pick(v, src[r * MAP_COLS + c]);
                    }
                }
                out[row * MAP_COLS + col] = v;
            }
        }
        out
    };
    filter(&filter(map, f32::min), f32::max)
}

/// Direction of radial map cell `(row, col)`.
fn map_direction(row: usize, col: usize) -> Vec3 {
    let theta = std::f32::consts::PI * row as f32 / (MAP_ROWS - 1) as f32;
    let phi = std::f32::consts::TAU * col as f32 / MAP_COLS as f32;
    direction(theta, phi)
}

/// Fill map cells without a crossing (down the neck) from the row above, smoothed around the
/// row; `None` if the top row has none (the mesh does not surround the centre).
fn fill_missing(radius: &mut [f32]) -> Option<()> {
    if radius[..MAP_COLS].iter().any(|r| r.is_nan()) {
        return None;
    }
    for row in 1..MAP_ROWS {
        for col in 0..MAP_COLS {
            let k = row * MAP_COLS + col;
            if radius[k].is_nan() {
                let up = |c: usize| radius[(row - 1) * MAP_COLS + c % MAP_COLS];
                radius[k] = (up(col + MAP_COLS - 1) + 2.0 * up(col) + up(col + 1)) * 0.25;
            }
        }
    }
    Some(())
}

/// A triangle list with normals averaged over the triangles sharing each position (area
/// weighted), so a faceted mesh shades smoothly.
pub fn smooth_prop_mesh(triangles: &[[Vec3; 3]]) -> Vec<PropVertex> {
    let key = position_key;
    let mut normals: std::collections::HashMap<[i32; 3], Vec3> = Default::default();
    for t in triangles {
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        for p in t {
            *normals.entry(key(*p)).or_default() += n;
        }
    }
    triangles
        .iter()
        .flat_map(|t| {
            let face = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or(Vec3::Y);
            t.map(|p| {
                let n = normals[&key(p)].normalize_or(face);
                PropVertex {
                    position: p.extend(1.0).to_array(),
                    normal: n.extend(0.0).to_array(),
                }
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The eyeballs fill their sockets (every rim point within the sphere) without standing
    /// far out of them, sit left and right of the face's middle at the same height; the mouth's
    /// cap faces forward like the face around it.
    #[test]
    fn the_eyes_fill_their_sockets_and_the_mouth_is_closed() {
        let head = human_head().unwrap();
        for eye in head.eyes.unwrap() {
            let rim = socket_rim(&head.triangles, &eye).expect("the eye's socket");
            let c = rim.iter().copied().sum::<Vec3>() / rim.len() as f32;
            let worst = rim
                .iter()
                .map(|p| p.distance(eye.centre) / eye.radius)
                .fold(0.0, f32::max);
            let bulge = eye.radius - eye.centre.distance(c);
            println!(
                "eye at {}, radius {:.4}: rim within {worst:.3} radii",
                eye.centre, eye.radius
            );
            assert!(worst <= 1.02, "the rim reaches {worst} radii");
            assert!(bulge < 0.5 * eye.radius && eye.radius < 0.04, "{eye:?}");
        }
        let [l, r] = head.eyes.unwrap();
        assert!(l.centre.x < -0.01 && r.centre.x > 0.01 && (l.centre.y - r.centre.y).abs() < 1e-3);
        assert!(!head.mouth.is_empty());
        let forward = head
            .mouth
            .iter()
            .map(|t| (t[1] - t[0]).cross(t[2] - t[0]))
            .sum::<Vec3>();
        assert!(forward.z > 0.0, "the mouth's cap faces {forward}");
    }

    #[test]
    fn the_radial_map_follows_the_mesh() {
        let head = human_head().unwrap();
        // Top of the head at CANONICAL_TOP, about 12.5 cm above the cranium centre.
        let top = head.surface(0.0, 0.0);
        assert!((top.y - CANONICAL_TOP).abs() < 0.005, "{top}");
        // Every mapped point lies on the mesh: a ray from the centre meets a triangle there.
        for (theta, phi) in [(0.4f32, 1.0f32), (1.2, 2.0), (1.0, 4.5), (1.5, 0.3)] {
            let d = direction(theta, phi);
            let r = head.radius(d);
            let hit = head
                .triangles
                .iter()
                .filter_map(|t| crate::model::obj_io::ray_triangle(head.centre, d, t))
                .filter(|&t| t <= RADIAL_REACH)
                .fold(0.0f32, f32::max);
            assert!(
                (hit - r).abs() < 0.004,
                "theta {theta} phi {phi}: {hit} vs {r}"
            );
        }
        let p = head.surface(1.0, 1.0);
        assert!(head.radial_gap(p).abs() < 1e-4);
        assert!(
            head.radial_gap(head.push_out(head.centre + (p - head.centre) * 0.9, 0.01)) > 0.0099
        );
        assert_eq!(
            head.prop_mesh().len(),
            (head.triangles.len() + head.mouth.len()) * 3
        );
    }
}
