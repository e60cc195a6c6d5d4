//! The Utah teapot, tessellated from Martin Newell's public-domain bicubic Bezier patches (the
//! 10-patch form with mirror symmetry: rim, body, lid and bottom are mirrored across both
//! vertical planes, handle and spout across one; 32 patches in all). The paper's 200-teapot
//! scene grows fur on it.
//!
//! Data frame: z up, about 6.5 x 4 x 3.15 units. `Teapot::new` turns it into the crowd frame
//! (+Y up, standing on y = 0) at a given scale.

use glam::{Vec2, Vec3};

use crate::model::hair_mesh::{Face, vertex_normals};
use crate::render::core::shared::PropVertex;

/// Control points of the 10 patch definitions (Newell's data, public domain).
const POINTS: [[f32; 3]; 127] = [
    [0.2, 0.0, 2.7],
    [0.2, -0.112, 2.7],
    [0.112, -0.2, 2.7],
    [0.0, -0.2, 2.7],
    [1.3375, 0.0, 2.53125],
    [1.3375, -0.749, 2.53125],
    [0.749, -1.3375, 2.53125],
    [0.0, -1.3375, 2.53125],
    [1.4375, 0.0, 2.53125],
    [1.4375, -0.805, 2.53125],
    [0.805, -1.4375, 2.53125],
    [0.0, -1.4375, 2.53125],
    [1.5, 0.0, 2.4],
    [1.5, -0.84, 2.4],
    [0.84, -1.5, 2.4],
    [0.0, -1.5, 2.4],
    [1.75, 0.0, 1.875],
    [1.75, -0.98, 1.875],
    [0.98, -1.75, 1.875],
    [0.0, -1.75, 1.875],
    [2.0, 0.0, 1.35],
    [2.0, -1.12, 1.35],
    [1.12, -2.0, 1.35],
    [0.0, -2.0, 1.35],
    [2.0, 0.0, 0.9],
    [2.0, -1.12, 0.9],
    [1.12, -2.0, 0.9],
    [0.0, -2.0, 0.9],
    [-2.0, 0.0, 0.9],
    [2.0, 0.0, 0.45],
    [2.0, -1.12, 0.45],
    [1.12, -2.0, 0.45],
    [0.0, -2.0, 0.45],
    [1.5, 0.0, 0.225],
    [1.5, -0.84, 0.225],
    [0.84, -1.5, 0.225],
    [0.0, -1.5, 0.225],
    [1.5, 0.0, 0.15],
    [1.5, -0.84, 0.15],
    [0.84, -1.5, 0.15],
    [0.0, -1.5, 0.15],
    [-1.6, 0.0, 2.025],
    [-1.6, -0.3, 2.025],
    [-1.5, -0.3, 2.25],
    [-1.5, 0.0, 2.25],
    [-2.3, 0.0, 2.025],
    [-2.3, -0.3, 2.025],
    [-2.5, -0.3, 2.25],
    [-2.5, 0.0, 2.25],
    [-2.7, 0.0, 2.025],
    [-2.7, -0.3, 2.025],
    [-3.0, -0.3, 2.25],
    [-3.0, 0.0, 2.25],
    [-2.7, 0.0, 1.8],
    [-2.7, -0.3, 1.8],
    [-3.0, -0.3, 1.8],
    [-3.0, 0.0, 1.8],
    [-2.7, 0.0, 1.575],
    [-2.7, -0.3, 1.575],
    [-3.0, -0.3, 1.35],
    [-3.0, 0.0, 1.35],
    [-2.5, 0.0, 1.125],
    [-2.5, -0.3, 1.125],
    [-2.65, -0.3, 0.9375],
    [-2.65, 0.0, 0.9375],
    [-2.0, -0.3, 0.9],
    [-1.9, -0.3, 0.6],
    [-1.9, 0.0, 0.6],
    [1.7, 0.0, 1.425],
    [1.7, -0.66, 1.425],
    [1.7, -0.66, 0.6],
    [1.7, 0.0, 0.6],
    [2.6, 0.0, 1.425],
    [2.6, -0.66, 1.425],
    [3.1, -0.66, 0.825],
    [3.1, 0.0, 0.825],
    [2.3, 0.0, 2.1],
    [2.3, -0.25, 2.1],
    [2.4, -0.25, 2.025],
    [2.4, 0.0, 2.025],
    [2.7, 0.0, 2.4],
    [2.7, -0.25, 2.4],
    [3.3, -0.25, 2.4],
    [3.3, 0.0, 2.4],
    [2.8, 0.0, 2.475],
    [2.8, -0.25, 2.475],
    [3.525, -0.25, 2.49375],
    [3.525, 0.0, 2.49375],
    [2.9, 0.0, 2.475],
    [2.9, -0.15, 2.475],
    [3.45, -0.15, 2.5125],
    [3.45, 0.0, 2.5125],
    [2.8, 0.0, 2.4],
    [2.8, -0.15, 2.4],
    [3.2, -0.15, 2.4],
    [3.2, 0.0, 2.4],
    [0.0, 0.0, 3.15],
    [0.8, 0.0, 3.15],
    [0.8, -0.45, 3.15],
    [0.45, -0.8, 3.15],
    [0.0, -0.8, 3.15],
    [0.0, 0.0, 2.85],
    [1.4, 0.0, 2.4],
    [1.4, -0.784, 2.4],
    [0.784, -1.4, 2.4],
    [0.0, -1.4, 2.4],
    [0.4, 0.0, 2.55],
    [0.4, -0.224, 2.55],
    [0.224, -0.4, 2.55],
    [0.0, -0.4, 2.55],
    [1.3, 0.0, 2.55],
    [1.3, -0.728, 2.55],
    [0.728, -1.3, 2.55],
    [0.0, -1.3, 2.55],
    [1.3, 0.0, 2.4],
    [1.3, -0.728, 2.4],
    [0.728, -1.3, 2.4],
    [0.0, -1.3, 2.4],
    [0.0, 0.0, 0.0],
    [1.425, -0.798, 0.0],
    [1.5, 0.0, 0.075],
    [1.425, 0.0, 0.0],
    [0.798, -1.425, 0.0],
    [0.0, -1.5, 0.075],
    [0.0, -1.425, 0.0],
    [1.5, -0.84, 0.075],
    [0.84, -1.5, 0.075],
];

/// One patch definition: 4x4 control point indices (row-major, u rows), and whether it is
/// mirrored across x = 0 as well as y = 0.
struct PatchDef {
    part: Part,
    both: bool,
    cp: [u8; 16],
}

/// Which part of the teapot a patch belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    /// The rim around the opening.
    Rim,
    /// The body.
    Body,
    /// The lid and its knob.
    Lid,
    /// The bottom it stands on.
    Bottom,
    /// The handle.
    Handle,
    /// The spout.
    Spout,
}

const fn def(part: Part, both: bool, cp: [u8; 16]) -> PatchDef {
    PatchDef { part, both, cp }
}

const PATCHES: [PatchDef; 10] = [
    def(
        Part::Rim,
        true,
        [102, 103, 104, 105, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15],
    ),
    def(
        Part::Body,
        true,
        [
            12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27,
        ],
    ),
    def(
        Part::Body,
        true,
        [
            24, 25, 26, 27, 29, 30, 31, 32, 33, 34, 35, 36, 37, 38, 39, 40,
        ],
    ),
    def(
        Part::Lid,
        true,
        [
            96, 96, 96, 96, 97, 98, 99, 100, 101, 101, 101, 101, 0, 1, 2, 3,
        ],
    ),
    def(
        Part::Lid,
        true,
        [
            0, 1, 2, 3, 106, 107, 108, 109, 110, 111, 112, 113, 114, 115, 116, 117,
        ],
    ),
    def(
        Part::Bottom,
        true,
        [
            118, 118, 118, 118, 124, 122, 119, 121, 123, 126, 125, 120, 40, 39, 38, 37,
        ],
    ),
    def(
        Part::Handle,
        false,
        [
            41, 42, 43, 44, 45, 46, 47, 48, 49, 50, 51, 52, 53, 54, 55, 56,
        ],
    ),
    def(
        Part::Handle,
        false,
        [
            53, 54, 55, 56, 57, 58, 59, 60, 61, 62, 63, 64, 28, 65, 66, 67,
        ],
    ),
    def(
        Part::Spout,
        false,
        [
            68, 69, 70, 71, 72, 73, 74, 75, 76, 77, 78, 79, 80, 81, 82, 83,
        ],
    ),
    def(
        Part::Spout,
        false,
        [
            80, 81, 82, 83, 84, 85, 86, 87, 88, 89, 90, 91, 92, 93, 94, 95,
        ],
    ),
];

/// A bicubic Bezier patch, oriented so that `du x dv` points out of the teapot.
#[derive(Clone, Copy)]
pub struct Patch {
    /// Part of the teapot.
    pub part: Part,
    /// Control points, row-major (u rows, v columns), data frame.
    pub cp: [Vec3; 16],
}

/// Cubic Bernstein weights and their derivatives at `t`.
fn bernstein(t: f32) -> ([f32; 4], [f32; 4]) {
    let s = 1.0 - t;
    (
        [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t],
        [
            -3.0 * s * s,
            3.0 * s * s - 6.0 * t * s,
            6.0 * t * s - 3.0 * t * t,
            3.0 * t * t,
        ],
    )
}

impl Patch {
    /// Position and (unnormalised) partial derivatives at `(u, v)`.
    pub fn eval(&self, u: f32, v: f32) -> (Vec3, Vec3, Vec3) {
        let (bu, du) = bernstein(u);
        let (bv, dv) = bernstein(v);
        let (mut p, mut pu, mut pv) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
        for i in 0..4 {
            for j in 0..4 {
                let c = self.cp[i * 4 + j];
                p += c * bu[i] * bv[j];
                pu += c * du[i] * bv[j];
                pv += c * bu[i] * dv[j];
            }
        }
        (p, pu, pv)
    }
}

/// The 32 patches of the teapot (mirrored copies included), consistently oriented.
///
/// A mirror flips orientation, so mirrored copies with an odd number of reflections get their
/// v parameter reversed. The data's own orientation is inward; every copy is reversed once
/// more so that normals point out (checked by the tests).
pub fn patches() -> Vec<Patch> {
    let mut out = Vec::with_capacity(32);
    for d in &PATCHES {
        let base: [Vec3; 16] = d.cp.map(|i| Vec3::from_array(POINTS[i as usize]));
        let mirrors: &[(f32, f32)] = if d.both {
            &[(1.0, 1.0), (-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)]
        } else {
            &[(1.0, 1.0), (1.0, -1.0)]
        };
        for &(sx, sy) in mirrors {
            let odd = (sx < 0.0) != (sy < 0.0);
            let mut cp = [Vec3::ZERO; 16];
            for i in 0..4 {
                for j in 0..4 {
                    // Reverse v unless the mirror already reversed the orientation.
                    let jj = if odd { j } else { 3 - j };
                    cp[i * 4 + j] = base[i * 4 + jj] * Vec3::new(sx, sy, 1.0);
                }
            }
            out.push(Patch { part: d.part, cp });
        }
    }
    out
}

/// A tessellated teapot: welded vertices (patch seams and poles shared) and faces.
pub struct TeapotMesh {
    /// Positions, crowd frame.
    pub positions: Vec<Vec3>,
    /// A cylindrical styling coordinate per vertex (azimuth, height), both in [0, 1].
    pub uv: Vec<Vec2>,
    /// Faces, counter-clockwise seen from outside; quads whose corners meet at a pole are
    /// triangles.
    pub faces: Vec<Face>,
}

/// Index of welded points: a uniform grid of cells of the weld tolerance, searching the 27
/// neighbouring cells so points near a cell boundary still meet.
struct Welder {
    cell: f32,
    map: std::collections::HashMap<[i32; 3], Vec<u32>>,
    points: Vec<Vec3>,
}

impl Welder {
    fn index(&mut self, p: Vec3) -> u32 {
        let key = (p / self.cell).floor().as_ivec3().to_array();
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let k = [key[0] + dx, key[1] + dy, key[2] + dz];
                    if let Some(list) = self.map.get(&k) {
                        for &i in list {
                            if self.points[i as usize].distance(p) <= self.cell {
                                return i;
                            }
                        }
                    }
                }
            }
        }
        let i = self.points.len() as u32;
        self.points.push(p);
        self.map.entry(key).or_default().push(i);
        i
    }
}

/// Tessellate the patches of `parts` into `n x n` quads each, scaled by `scale` into the crowd
/// frame (+Y up, standing on y = 0, spout toward +X).
pub fn tessellate(parts: &[Part], n: usize, scale: f32) -> TeapotMesh {
    let n = n.max(1);
    let mut weld = Welder {
        cell: 1e-4 * scale,
        map: Default::default(),
        points: Vec::new(),
    };
    let mut faces = Vec::new();
    let to_crowd = |p: Vec3| Vec3::new(p.x, p.z, -p.y) * scale;
    for patch in patches().iter().filter(|p| parts.contains(&p.part)) {
        let mut grid = Vec::with_capacity((n + 1) * (n + 1));
        for i in 0..=n {
            for j in 0..=n {
                let (p, ..) = patch.eval(i as f32 / n as f32, j as f32 / n as f32);
                grid.push(weld.index(to_crowd(p)));
            }
        }
        for i in 0..n {
            for j in 0..n {
                let at = |a: usize, b: usize| grid[a * (n + 1) + b];
                // du x dv is outward: (i, j) -> (i+1, j) -> (i+1, j+1) -> (i, j+1) is
                // counter-clockwise seen from outside.
                let quad = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
                let mut distinct: Vec<u32> = Vec::with_capacity(4);
                for (k, &q) in quad.iter().enumerate() {
                    if q != quad[(k + 3) % 4] && !distinct.contains(&q) {
                        distinct.push(q);
                    }
                }
                match distinct.len() {
                    4 => faces.push(Face::Quad([quad[0], quad[1], quad[2], quad[3]])),
                    3 => faces.push(Face::Tri([distinct[0], distinct[1], distinct[2]])),
                    _ => {}
                }
            }
        }
    }
    let height = 3.15 * scale;
    let uv = weld
        .points
        .iter()
        .map(|p| {
            let azimuth = p.z.atan2(p.x) / std::f32::consts::TAU + 0.5;
            Vec2::new(azimuth, (p.y / height).clamp(0.0, 1.0))
        })
        .collect();
    TeapotMesh {
        positions: weld.points,
        uv,
        faces,
    }
}

/// Every part.
pub const ALL_PARTS: [Part; 6] = [
    Part::Rim,
    Part::Body,
    Part::Lid,
    Part::Bottom,
    Part::Handle,
    Part::Spout,
];

/// The parts fur grows on: all but the bottom it stands on.
pub const FURRY_PARTS: [Part; 5] = [Part::Rim, Part::Body, Part::Lid, Part::Handle, Part::Spout];

/// Height of the teapot in the data frame.
const DATA_HEIGHT: f32 = 3.15;

/// A teapot prop of `height` metres: triangles with smooth (welded, area-weighted) normals.
pub fn teapot_mesh(height: f32) -> Vec<PropVertex> {
    let mesh = tessellate(&ALL_PARTS, 10, height / DATA_HEIGHT);
    let normals = vertex_normals(&mesh.positions, &mesh.faces);
    let vertex = |i: u32| PropVertex {
        position: mesh.positions[i as usize].extend(1.0).to_array(),
        normal: normals[i as usize].extend(0.0).to_array(),
    };
    let mut out = Vec::new();
    for f in &mesh.faces {
        match *f {
            Face::Tri([a, b, c]) => out.extend([a, b, c].map(vertex)),
            Face::Quad([a, b, c, d]) => out.extend([a, b, c, a, c, d].map(vertex)),
        }
    }
    out
}

/// The furry surface of a teapot of `height` metres, `n x n` quads per patch.
pub fn fur_scalp(height: f32, n: usize) -> TeapotMesh {
    tessellate(&FURRY_PARTS, n, height / DATA_HEIGHT)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashSet;

    #[test]
    fn patches_are_oriented_outward() {
        let all = patches();
        assert_eq!(all.len(), 32);
        for p in &all {
            let (pos, du, dv) = p.eval(0.5, 0.5);
            let n = du.cross(dv).normalize();
            // Where the outside is obvious at the centre of a patch.
            let outward = match p.part {
                Part::Body => Vec3::new(pos.x, pos.y, 0.0),
                Part::Bottom => Vec3::NEG_Z,
                Part::Handle => Vec3::new(0.0, pos.y, 0.0),
                // The lower spout; its tip opens upward.
                Part::Spout if pos.z < 2.2 => Vec3::new(0.0, pos.y, 0.0),
                Part::Spout | Part::Rim | Part::Lid => continue,
            };
            assert!(
                n.dot(outward.normalize()) > 0.3,
                "{:?} at {pos}: {n}",
                p.part
            );
        }
    }

    #[test]
    fn welded_mesh_is_consistently_oriented() {
        let mesh = tessellate(&ALL_PARTS, 6, 1.0);
        // Every directed edge is used at most once: neighbouring faces (across patch seams and
        // mirror planes too) wind the same way.
        let mut edges = HashSet::new();
        for f in &mesh.faces {
            let v = f.vertices();
            for k in 0..v.len() {
                let e = (v[k], v[(k + 1) % v.len()]);
                assert!(edges.insert(e), "directed edge {e:?} used twice");
            }
        }
        // Seams are welded: the 32 patches of 7x7 points share most of their borders.
        assert!(
            mesh.positions.len() * 5 < 32 * 49 * 4,
            "{}",
            mesh.positions.len()
        );
        // Signed volume (divergence theorem) is positive: normals point out. The surface is
        // not closed (lid gap, spout end, handle and spout ends meet the body), so only the
        // sign and rough size are checked: a body of radius 2 and height 3 holds about 30.
        let volume: f32 = mesh
            .faces
            .iter()
            .map(|f| {
                let v = f.vertices();
                let p0 = mesh.positions[v[0] as usize];
                (1..v.len() - 1)
                    .map(|k| {
                        let p1 = mesh.positions[v[k] as usize];
                        let p2 = mesh.positions[v[k + 1] as usize];
                        p0.dot(p1.cross(p2)) / 6.0
                    })
                    .sum::<f32>()
            })
            .sum();
        assert!((20.0..45.0).contains(&volume), "volume {volume}");
        // Crowd frame: standing on y = 0, 3.15 tall.
        let (lo, hi) = mesh
            .positions
            .iter()
            .fold((Vec3::MAX, Vec3::MIN), |(a, b), p| (a.min(*p), b.max(*p)));
        assert!(lo.y.abs() < 1e-4 && (hi.y - 3.15).abs() < 1e-3, "{lo} {hi}");
    }

    #[test]
    fn fur_scalp_excludes_the_bottom() {
        let all = tessellate(&ALL_PARTS, 5, 0.1);
        let fur = fur_scalp(0.315, 5);
        assert!(fur.faces.len() < all.faces.len());
        assert!(fur.faces.len() > 500, "{}", fur.faces.len());
        assert!(fur.positions.iter().all(|p| p.y > 0.005));
        assert_eq!(fur.uv.len(), fur.positions.len());
        let prop = teapot_mesh(0.3);
        assert_eq!(prop.len() % 3, 0);
        assert!(prop.iter().all(|v| v.normal.iter().all(|c| c.is_finite())));
    }
}
