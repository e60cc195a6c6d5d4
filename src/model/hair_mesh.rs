//! The hair mesh model (paper 003, section 2.2): a scalp (root layer) of quads and triangles
//! extruded into `L >= 2` layers that share its topology. Each root face and its extrusions form a
//! *bundle*.
//!
//! Vertex `i` of every layer lies above root vertex `i`, so one index addresses a vertex column.
//! Root vertices are unique (position, uv) pairs: a scalp vertex on a uv seam appears once per side.

use glam::{Vec2, Vec3};

use crate::error::{HairError, Result};

/// Slices of the hair mesh texture per layer segment: the layer slice and the three
/// intermediate quadratic-Bezier slices (paper 003 sec. 3.1); depth is `4 (L - 1) + 1`. The
/// bake's layout; here because it bounds the layers a hair mesh may have.
pub const SLICES_PER_SEGMENT: u32 = 4;

/// Largest texture side accepted (Vulkan guarantees 2048 for 3D images).
pub const MAX_TEXTURE_SIDE: u32 = 2048;

/// A root face: a bundle of the hair mesh. Higher-degree polygons are split on load.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Face {
    /// Three root-vertex indices, counter-clockwise.
    Tri([u32; 3]),
    /// Four root-vertex indices, counter-clockwise around the quad.
    Quad([u32; 4]),
}

impl Face {
    /// The vertex indices of the face, in order.
    pub fn vertices(&self) -> &[u32] {
        match self {
            Face::Tri(v) => v,
            Face::Quad(v) => v,
        }
    }
}

/// A validated hair mesh: per-layer positions, per-vertex `w`, per-root-vertex `uv`, root faces.
#[derive(Clone, Debug)]
pub struct HairMesh {
    /// Name of the source (file path) used in error messages.
    pub name: String,
    /// `layers[k][i]`: object-space position of vertex `i` on layer `k` (layer 0 is the scalp).
    pub layers: Vec<Vec<Vec3>>,
    /// `w[k][i]`: styling coordinate `w` of vertex `i` on layer `k`; 0 on the root layer.
    pub w: Vec<Vec<f32>>,
    /// Root-layer `uv` styling coordinates, one per vertex column.
    pub uv: Vec<Vec2>,
    /// Root faces (bundles).
    pub faces: Vec<Face>,
    /// Per root vertex, the share of strands thinned out there, 0 (all kept, the default)
    /// ..= 1: interpolated over each root face like `uv`, it makes density fall off across a
    /// hairline instead of stopping at a polygon edge (baked into the hair mesh texture's
    /// root-slice alpha).
    pub root_thinning: Vec<f32>,
}

/// Relative tolerance below which a face or uv triangle counts as degenerate.
const DEGENERATE_EPS: f32 = 1e-10;

impl HairMesh {
    /// Number of layers `L` (root layer included).
    pub fn layer_count(&self) -> usize {
        self.layers.len()
    }

    /// Number of vertices per layer.
    pub fn vertices_per_layer(&self) -> usize {
        self.uv.len()
    }

    /// Total number of hair mesh vertices over all layers.
    pub fn vertex_count(&self) -> usize {
        self.layers.len() * self.uv.len()
    }

    /// Build a mesh, generating `w` from path length when `w` is `None`, and validate it.
    pub fn new(
        name: impl Into<String>,
        layers: Vec<Vec<Vec3>>,
        w: Option<Vec<Vec<f32>>>,
        uv: Vec<Vec2>,
        faces: Vec<Face>,
    ) -> Result<Self> {
        let name = name.into();
        let w = match w {
            Some(w) => w,
            None => path_length_w(&layers),
        };
        let root_thinning = vec![0.0; uv.len()];
        let mesh = HairMesh {
            name,
            layers,
            w,
            uv,
            faces,
            root_thinning,
        };
        mesh.validate()?;
        Ok(mesh)
    }

    /// The mesh with `thinning` per root vertex (see [`HairMesh::root_thinning`]).
    pub fn with_root_thinning(mut self, thinning: Vec<f32>) -> Result<Self> {
        self.root_thinning = thinning;
        self.validate()?;
        Ok(self)
    }

    fn err(&self, what: impl Into<String>) -> HairError {
        HairError::invalid(&self.name, what)
    }

    /// Check every invariant the bake relies on; the error names layer, face or vertex.
    pub fn validate(&self) -> Result<()> {
        let n = self.uv.len();
        if self.faces.is_empty() || n == 0 {
            return Err(self.err("empty hair mesh: no root faces"));
        }
        if self.layers.len() < 2 || self.layers.len() > MAX_LAYERS {
            return Err(self.err(format!(
                "a hair mesh needs 2..={MAX_LAYERS} layers (at least 2 layers), found {}",
                self.layers.len()
            )));
        }
        if self.root_thinning.len() != n {
            return Err(self.err(format!(
                "root thinning has {} values for {n} root vertices",
                self.root_thinning.len()
            )));
        }
        if let Some(i) = self
            .root_thinning
            .iter()
            .position(|t| !(0.0..=1.0).contains(t))
        {
            return Err(self.err(format!(
                "root vertex {i}: thinning {} must be in [0, 1]",
                self.root_thinning[i]
            )));
        }
        if self.w.len() != self.layers.len() {
            return Err(self.err(format!(
                "w has {} layers but positions have {}",
                self.w.len(),
                self.layers.len()
            )));
        }
        for (k, (layer, w)) in self.layers.iter().zip(&self.w).enumerate() {
            if layer.len() != n || w.len() != n {
                return Err(self.err(format!(
                    "layer {k} has {} vertices (w: {}), the root layer has {n}",
                    layer.len(),
                    w.len()
                )));
            }
            for (i, p) in layer.iter().enumerate() {
                if !p.is_finite() {
                    return Err(
                        self.err(format!("layer {k} vertex {i}: non-finite position {p:?}"))
                    );
                }
            }
            for (i, &wi) in w.iter().enumerate() {
                if !wi.is_finite() || wi < 0.0 {
                    return Err(self.err(format!(
                        "layer {k} vertex {i}: w must be finite and >= 0, got {wi}"
                    )));
                }
                if k > 0 && wi < self.w[k - 1][i] {
                    return Err(self.err(format!(
                        "layer {k} vertex {i}: w decreases from the layer below ({} -> {wi})",
                        self.w[k - 1][i]
                    )));
                }
            }
        }
        for (i, uv) in self.uv.iter().enumerate() {
            if !uv.is_finite() {
                return Err(self.err(format!("root vertex {i}: non-finite uv {uv:?}")));
            }
        }
        self.validate_faces()
    }

    /// Every face names root vertices, none twice, with area on the root layer and in uv at
    /// every corner (eq. 2 needs an invertible `T_i`).
    fn validate_faces(&self) -> Result<()> {
        let n = self.uv.len();
        let extent = self.root_extent().max(f32::MIN_POSITIVE);
        let uv_extent = self.uv_extent().max(f32::MIN_POSITIVE);
        for (f, face) in self.faces.iter().enumerate() {
            let v = face.vertices();
            for &i in v {
                if i as usize >= n {
                    return Err(self.err(format!(
                        "face {f}: vertex index {i} out of range (root layer has {n} vertices)"
                    )));
                }
            }
            for a in 0..v.len() {
                for b in a + 1..v.len() {
                    if v[a] == v[b] {
                        return Err(self.err(format!(
                            "face {f}: degenerate, vertex {} appears twice",
                            v[a]
                        )));
                    }
                }
            }
            let area = polygon_area(v.iter().map(|&i| self.layers[0][i as usize]));
            if area <= DEGENERATE_EPS * extent * extent {
                return Err(self.err(format!("face {f}: degenerate, zero area on the root layer")));
            }
            // Eq. 2 needs an invertible T_i for every corner triangle (vertex and its two edges).
            for c in 0..v.len() {
                let [a, b, d] = corner_triangle(v, c);
                let t = uv_triangle_area(self.uv[a], self.uv[b], self.uv[d]);
                if t.abs() <= DEGENERATE_EPS * uv_extent * uv_extent {
                    return Err(self.err(format!(
                        "face {f}: zero-area uv triangle at corner {c} (vertex {a}); eq. 2 of the paper needs non-degenerate uvs"
                    )));
                }
            }
        }
        Ok(())
    }

    /// Largest axis extent of the root layer, used to scale degeneracy tolerances.
    fn root_extent(&self) -> f32 {
        let (lo, hi) = bounds(self.layers[0].iter().copied());
        (hi - lo).max_element()
    }

    fn uv_extent(&self) -> f32 {
        let (lo, hi) = bounds(self.uv.iter().map(|uv| uv.extend(0.0)));
        (hi - lo).max_element()
    }

    /// Rest-shape size `h` of each bundle for strand LoD (eq. 7): the longest root edge.
    pub fn bundle_sizes(&self) -> Vec<f32> {
        self.faces
            .iter()
            .map(|face| {
                let v = face.vertices();
                (0..v.len())
                    .map(|c| {
                        let a = self.layers[0][v[c] as usize];
                        let b = self.layers[0][v[(c + 1) % v.len()] as usize];
                        a.distance(b)
                    })
                    .fold(0.0, f32::max)
            })
            .collect()
    }

    /// Object-space root area of each bundle.
    pub fn bundle_areas(&self) -> Vec<f32> {
        self.faces
            .iter()
            .map(|face| polygon_area(face.vertices().iter().map(|&i| self.layers[0][i as usize])))
            .collect()
    }
}

/// `w` from the path length of each vertex column, 0 at the root (paper 003, section 3.4).
pub fn path_length_w(layers: &[Vec<Vec3>]) -> Vec<Vec<f32>> {
    let mut w: Vec<Vec<f32>> = Vec::with_capacity(layers.len());
    for (k, layer) in layers.iter().enumerate() {
        let row = if k == 0 {
            vec![0.0; layer.len()]
        } else {
            layer
                .iter()
                .enumerate()
                .map(|(i, p)| {
                    let below = layers[k - 1].get(i).copied().unwrap_or(*p);
                    w[k - 1].get(i).copied().unwrap_or(0.0) + p.distance(below)
                })
                .collect()
        };
        w.push(row);
    }
    w
}

/// The corner triangle of polygon `v` at corner `c`: the vertex and its two edges (paper Fig. 5).
pub fn corner_triangle(v: &[u32], c: usize) -> [usize; 3] {
    let n = v.len();
    [
        v[c] as usize,
        v[(c + 1) % n] as usize,
        v[(c + n - 1) % n] as usize,
    ]
}

/// Signed area of a uv triangle.
pub fn uv_triangle_area(a: Vec2, b: Vec2, c: Vec2) -> f32 {
    0.5 * (b - a).perp_dot(c - a)
}

/// Area of a (possibly non-planar) polygon, as the norm of its vector area.
pub fn polygon_area(points: impl Iterator<Item = Vec3>) -> f32 {
    let pts: Vec<Vec3> = points.collect();
    let mut s = Vec3::ZERO;
    for i in 0..pts.len() {
        s += pts[i].cross(pts[(i + 1) % pts.len()]);
    }
    0.5 * s.length()
}

/// Axis-aligned bounds of a point set; `(MAX, MIN)` when empty.
pub fn bounds(points: impl Iterator<Item = Vec3>) -> (Vec3, Vec3) {
    points.fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), p| (lo.min(p), hi.max(p)),
    )
}

/// Split a polygon of any degree `>= 3` into quads and at most one triangle (fan of quads).
/// Returns corner indices into the polygon, so every layer can be split the same way.
pub fn split_polygon(degree: usize) -> Vec<Vec<usize>> {
    match degree {
        3 | 4 => vec![(0..degree).collect()],
        _ => {
            let mut out = Vec::new();
            let mut c = 1;
            while c + 2 < degree {
                out.push(vec![0, c, c + 1, c + 2]);
                c += 2;
            }
            if c + 1 < degree {
                out.push(vec![0, c, c + 1]);
            }
            out
        }
    }
}

/// Most layers of a hair mesh: the hair mesh texture has `4 (L - 1) + 1` slices and a side
/// holds at most [`MAX_TEXTURE_SIDE`] texels.
pub const MAX_LAYERS: usize = (MAX_TEXTURE_SIDE / SLICES_PER_SEGMENT) as usize;

/// How a scalp is extruded into layers by [`extrude`].
#[derive(Clone, Debug)]
pub struct ExtrudeDesc {
    /// Number of layers including the root layer (>= 2).
    pub layers: usize,
    /// Object-space length of each layer step.
    pub step: f32,
    /// 0: follow the scalp normal; 1: turn fully toward `gravity_dir` by the tip layer.
    pub gravity: f32,
    /// Direction gravity pulls toward (normalised internally).
    pub gravity_dir: Vec3,
    /// A sphere (centre, radius) the layers are pushed out of, e.g. the head.
    pub avoid_sphere: Option<(Vec3, f32)>,
}

impl ExtrudeDesc {
    /// Extrude `layers` layers of `step` along the normals, no gravity.
    pub fn new(layers: usize, step: f32) -> Self {
        ExtrudeDesc {
            layers,
            step,
            gravity: 0.0,
            gravity_dir: Vec3::NEG_Y,
            avoid_sphere: None,
        }
    }

    /// Bend the layers toward `dir` with strength `amount` in `[0, 1]`.
    pub fn gravity(mut self, amount: f32, dir: Vec3) -> Self {
        self.gravity = amount;
        self.gravity_dir = dir;
        self
    }

    /// Keep layers outside the sphere at `centre` with `radius`.
    pub fn avoid_sphere(mut self, centre: Vec3, radius: f32) -> Self {
        self.avoid_sphere = Some((centre, radius));
        self
    }
}

/// Area-weighted vertex normals of a polygon mesh.
pub fn vertex_normals(positions: &[Vec3], faces: &[Face]) -> Vec<Vec3> {
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for face in faces {
        let v = face.vertices();
        let mut s = Vec3::ZERO;
        for i in 0..v.len() {
            s += positions[v[i] as usize].cross(positions[v[(i + 1) % v.len()] as usize]);
        }
        for &i in v {
            normals[i as usize] += s;
        }
    }
    normals
        .into_iter()
        .map(|n| n.try_normalize().unwrap_or(Vec3::Y))
        .collect()
}

/// Programmatic builder: extrude a scalp (root positions, uvs, faces) into a hair mesh whose
/// layers grow along the vertex normals and bend toward a gravity direction.
pub fn extrude(
    name: impl Into<String>,
    scalp: &[Vec3],
    uv: &[Vec2],
    faces: &[Face],
    desc: &ExtrudeDesc,
) -> Result<HairMesh> {
    let name = name.into();
    if !(2..=MAX_LAYERS).contains(&desc.layers) {
        return Err(HairError::invalid(
            &name,
            format!(
                "extrusion needs 2..={MAX_LAYERS} layers, got {}",
                desc.layers
            ),
        ));
    }
    if !(desc.step.is_finite() && desc.step > 0.0 && desc.step <= 1e3) {
        return Err(HairError::invalid(
            &name,
            format!("extrusion step must be in (0, 1000], got {}", desc.step),
        ));
    }
    let gravity_ok = desc.gravity.is_finite()
        && (0.0..=1.0).contains(&desc.gravity)
        && desc.gravity_dir.is_finite();
    if !gravity_ok {
        return Err(HairError::invalid(
            &name,
            format!("gravity must be in [0, 1], got {}", desc.gravity),
        ));
    }
    let normals = vertex_normals(scalp, faces);
    let down = desc.gravity_dir.try_normalize().unwrap_or(Vec3::NEG_Y);
    let mut layers = vec![scalp.to_vec()];
    let mut dirs = normals.clone();
    for k in 1..desc.layers {
        let f = desc.gravity * k as f32 / (desc.layers - 1) as f32;
        let prev = layers[k - 1].clone();
        let next: Vec<Vec3> = prev
            .iter()
            .zip(dirs.iter_mut())
            .zip(&normals)
            .map(|((p, d), n)| {
                let target = (*n * (1.0 - f) + down * f).try_normalize().unwrap_or(*n);
                *d = (*d + target).try_normalize().unwrap_or(target);
                let mut q = *p + *d * desc.step;
                if let Some((c, r)) = desc.avoid_sphere {
                    let lift = r + desc.step * k as f32 * 0.35;
                    let off = q - c;
                    if off.length() < lift {
                        q = c + off.try_normalize().unwrap_or(*n) * lift;
                    }
                }
                q
            })
            .collect();
        layers.push(next);
    }
    HairMesh::new(name, layers, None, uv.to_vec(), faces.to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad_mesh(layers: Vec<Vec<Vec3>>) -> Result<HairMesh> {
        let uv = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ];
        HairMesh::new("test", layers, None, uv, vec![Face::Quad([0, 1, 2, 3])])
    }

    fn square(z: f32) -> Vec<Vec3> {
        vec![
            Vec3::new(0.0, 0.0, z),
            Vec3::new(1.0, 0.0, z),
            Vec3::new(1.0, 1.0, z),
            Vec3::new(0.0, 1.0, z),
        ]
    }

    #[test]
    fn w_is_path_length() {
        let m = quad_mesh(vec![square(0.0), square(2.0), square(5.0)]).unwrap();
        assert_eq!(m.w[2][1], 5.0);
        assert_eq!(m.w[0][3], 0.0);
    }

    #[test]
    fn rejects_single_layer() {
        let e = quad_mesh(vec![square(0.0)]).unwrap_err().to_string();
        assert!(e.contains("at least 2 layers"), "{e}");
    }

    #[test]
    fn rejects_nan() {
        let mut l1 = square(1.0);
        l1[2].y = f32::NAN;
        let e = quad_mesh(vec![square(0.0), l1]).unwrap_err().to_string();
        assert!(
            e.contains("layer 1 vertex 2") && e.contains("non-finite"),
            "{e}"
        );
    }

    #[test]
    fn rejects_layer_vertex_mismatch() {
        let mut l1 = square(1.0);
        l1.pop();
        let e = quad_mesh(vec![square(0.0), l1]).unwrap_err().to_string();
        assert!(e.contains("layer 1 has 3 vertices"), "{e}");
    }

    #[test]
    fn rejects_degenerate_face() {
        let mut l0 = square(0.0);
        l0[2] = l0[1];
        l0[3] = l0[0];
        let e = quad_mesh(vec![l0, square(1.0)]).unwrap_err().to_string();
        assert!(e.contains("face 0: degenerate"), "{e}");
    }

    #[test]
    fn rejects_zero_area_uv() {
        let uv = vec![Vec2::ZERO, Vec2::X, Vec2::new(2.0, 0.0), Vec2::Y];
        let e = HairMesh::new(
            "t",
            vec![square(0.0), square(1.0)],
            None,
            uv,
            vec![Face::Quad([0, 1, 2, 3])],
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("zero-area uv triangle"), "{e}");
    }

    #[test]
    fn rejects_empty() {
        let e = HairMesh::new("t", vec![vec![], vec![]], None, vec![], vec![])
            .unwrap_err()
            .to_string();
        assert!(e.contains("empty"), "{e}");
    }

    #[test]
    fn splits_polygons_into_quads_and_tri() {
        assert_eq!(split_polygon(5), vec![vec![0, 1, 2, 3], vec![0, 3, 4]]);
        assert_eq!(split_polygon(6), vec![vec![0, 1, 2, 3], vec![0, 3, 4, 5]]);
        let total: usize = split_polygon(9).iter().map(|p| p.len() - 2).sum();
        assert_eq!(
            total, 7,
            "a fan split covers the n-gon with n-2 triangles' worth"
        );
    }

    #[test]
    fn root_thinning_is_checked() {
        let m = HairMesh::new(
            "t",
            vec![square(0.0), square(1.0)],
            None,
            vec![Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y],
            vec![Face::Quad([0, 1, 2, 3])],
        )
        .unwrap();
        assert_eq!(m.root_thinning, vec![0.0; 4]);
        for (bad, what) in [
            (vec![0.0; 3], "3 values for 4"),
            (vec![0.0, 0.5, f32::NAN, 0.0], "root vertex 2"),
            (vec![0.0, 1.5, 0.0, 0.0], "root vertex 1"),
        ] {
            let err = m.clone().with_root_thinning(bad).unwrap_err().to_string();
            assert!(err.contains(what), "{err}");
        }
        assert!(m.with_root_thinning(vec![1.0, 0.0, 0.25, 0.0]).is_ok());
    }

    #[test]
    fn extrude_follows_gravity() {
        let m = extrude(
            "t",
            &square(0.0),
            &[Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y],
            &[Face::Quad([0, 1, 2, 3])],
            &ExtrudeDesc::new(6, 0.5).gravity(1.0, Vec3::NEG_Y),
        )
        .unwrap();
        let tip = m.layers[5][0] - m.layers[4][0];
        assert!(tip.y < -0.2, "tip segment should point down, got {tip:?}");
    }
}
