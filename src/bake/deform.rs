//! Rebuilding the textures of a moving hair mesh (paper 003 sections 3.4 and 4). When the
//! layer vertices move only the hair mesh texture (positions and quadratic Bezier control
//! points) and the u and v textures change; the uv and w textures, the root layout and the
//! bundles stay, and the styling stays attached because it lives in the mesh's own u v w frame.
//!
//! [`DeformBasis`] holds what stays; [`DeformBasis::rebuild`] is the CPU twin of
//! `glsl/hair_mesh_update.comp`, and [`super::bake`] encodes its textures with the same
//! functions ([`encode_columns`], [`StylingBasis::directions`]).

use bytemuck::{Pod, Zeroable};
use glam::{Mat2, Vec3};

use super::curve::column_control_points;
use super::layout::{EMPTY_TEXEL, layout_root_slice};
use super::{BakeOptions, BakedHairMesh, MeshInfo, to_snorm16, to_unorm16};
use crate::error::{HairError, Result};
use crate::model::hair_mesh::{HairMesh, corner_triangle};

/// One corner triangle's contribution to its vertex `i0`'s styling directions (eq. 1-3 with the
/// uv map fixed): `u += u[0] (p[i1] - p[i0]) + u[1] (p[i2] - p[i0])`, `v` likewise. The
/// coefficients are the inverse uv map times the uv area, so they never change while the mesh
/// moves. Shared with GLSL as `StylingTerm` (std430, 24 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct StylingTerm {
    /// Second corner of the triangle.
    pub i1: u32,
    /// Third corner of the triangle.
    pub i2: u32,
    /// Weights of the two edges in `u`.
    pub u: [f32; 2],
    /// Weights of the two edges in `v`.
    pub v: [f32; 2],
}

/// The styling-direction terms of every vertex column, in compressed rows.
#[derive(Clone, Debug, PartialEq)]
pub struct StylingBasis {
    /// `terms[offsets[i]..offsets[i + 1]]` belong to vertex `i`.
    pub offsets: Vec<u32>,
    /// The terms.
    pub terms: Vec<StylingTerm>,
}

impl StylingBasis {
    /// The terms of `mesh` (eq. 2-3: `[u_i v_i] = [p1 - p0, p2 - p0] T_i^-1`, weighted by the
    /// corner triangle's uv area as eq. 1 averages).
    pub fn new(mesh: &HairMesh) -> Self {
        let n = mesh.vertices_per_layer();
        let mut rows: Vec<Vec<StylingTerm>> = vec![Vec::new(); n];
        for face in &mesh.faces {
            let v = face.vertices();
            for c in 0..v.len() {
                let [i0, i1, i2] = corner_triangle(v, c);
                let (uv0, uv1, uv2) = (mesh.uv[i0], mesh.uv[i1], mesh.uv[i2]);
                // Eq. 2: T_i = [uv1 - uv0, uv2 - uv0] as columns.
                let t = Mat2::from_cols(uv1 - uv0, uv2 - uv0);
                let det = t.determinant();
                if det.abs() < 1e-20 {
                    continue; // validated meshes have none
                }
                let inv = t.inverse();
                let area = 0.5 * det.abs();
                rows[i0].push(StylingTerm {
                    i1: i1 as u32,
                    i2: i2 as u32,
                    u: [inv.x_axis.x * area, inv.x_axis.y * area],
                    v: [inv.y_axis.x * area, inv.y_axis.y * area],
                });
            }
        }
        let mut offsets = Vec::with_capacity(n + 1);
        let mut terms = Vec::new();
        offsets.push(0);
        for row in rows {
            terms.extend(row);
            offsets.push(terms.len() as u32);
        }
        StylingBasis { offsets, terms }
    }

    /// Unit styling directions `(u, v)` of every vertex of one layer with positions `p`
    /// (eq. 1: the area-weighted mean, normalised; `X` / `Y` where it vanishes).
    pub fn directions(&self, p: &[Vec3]) -> (Vec<Vec3>, Vec<Vec3>) {
        (0..self.offsets.len() - 1)
            .map(|i| self.vertex_directions(p, i))
            .unzip()
    }

    fn vertex_directions(&self, p: &[Vec3], i: usize) -> (Vec3, Vec3) {
        let (mut su, mut sv) = (Vec3::ZERO, Vec3::ZERO);
        for t in &self.terms[self.offsets[i] as usize..self.offsets[i + 1] as usize] {
            let e1 = p[t.i1 as usize] - p[i];
            let e2 = p[t.i2 as usize] - p[i];
            su += e1 * t.u[0] + e2 * t.u[1];
            sv += e1 * t.v[0] + e2 * t.v[1];
        }
        (
            su.try_normalize().unwrap_or(Vec3::X),
            sv.try_normalize().unwrap_or(Vec3::Y),
        )
    }
}

/// Hair mesh texture texels of columns: for each root-slice texel holding a vertex, its
/// column's control points quantised into the box `lo .. lo + extent` (UNORM16); empty texels
/// stay zero. `ctrl[i]` are column `i`'s `4 (L - 1) + 1` control points. The root slice's alpha
/// holds the cube root of each column's root thinning (`HairMesh::root_thinning`): generators
/// cube the interpolated alpha, so that over a root face the thinning gathers toward the vertices
/// that have it (a hairline's fall-off over its last centimetre or two, not the whole bundle);
/// the other slices' alpha is 0.
pub fn encode_columns(
    texels: &[u32],
    ctrl: &[Vec<Vec3>],
    thinning: &[f32],
    lo: Vec3,
    extent: Vec3,
) -> Vec<[u16; 4]> {
    let slice = texels.len();
    let depth = ctrl.first().map_or(0, Vec::len);
    let mut position = vec![[0u16; 4]; slice * depth];
    for (t, &vert) in texels.iter().enumerate() {
        if vert == EMPTY_TEXEL {
            continue;
        }
        for (z, p) in ctrl[vert as usize].iter().enumerate() {
            let q = (*p - lo) / extent;
            let alpha = if z == 0 {
                to_unorm16(thinning[vert as usize].cbrt())
            } else {
                0
            };
            position[z * slice + t] = [to_unorm16(q.x), to_unorm16(q.y), to_unorm16(q.z), alpha];
        }
    }
    position
}

/// u and v texture texels (SNORM16) of every layer from per-layer unit directions.
pub fn encode_directions(texels: &[u32], dirs: &[(Vec<Vec3>, Vec<Vec3>)]) -> [Vec<[i16; 4]>; 2] {
    let slice = texels.len();
    let mut out = [
        vec![[0i16; 4]; slice * dirs.len()],
        vec![[0i16; 4]; slice * dirs.len()],
    ];
    for (k, (us, vs)) in dirs.iter().enumerate() {
        for (t, &vert) in texels.iter().enumerate() {
            if vert == EMPTY_TEXEL {
                continue;
            }
            for (tex, d) in out.iter_mut().zip([us, vs]) {
                let a = d[vert as usize];
                tex[k * slice + t] = [to_snorm16(a.x), to_snorm16(a.y), to_snorm16(a.z), 0];
            }
        }
    }
    out
}

/// What stays fixed while a baked hair mesh moves, and the decode box its positions must stay
/// inside.
#[derive(Clone, Debug)]
pub struct DeformBasis {
    /// Decode constants and sizes of the bake (its box includes the motion margin).
    pub info: MeshInfo,
    /// Root-slice texel -> vertex column (`EMPTY_TEXEL` where none).
    pub texel_vertex: Vec<u32>,
    /// Styling-direction terms.
    pub styling: StylingBasis,
    /// Vertices per layer.
    pub vertices: u32,
    /// Root thinning per vertex column (kept through every pose).
    pub root_thinning: Vec<f32>,
}

/// The rebuilt textures of one pose.
#[derive(Clone, Debug, PartialEq)]
pub struct DeformedTextures {
    /// Hair mesh texture texels (as [`BakedHairMesh::position`]).
    pub position: Vec<[u16; 4]>,
    /// u-texture texels.
    pub u_dir: Vec<[i16; 4]>,
    /// v-texture texels.
    pub v_dir: Vec<[i16; 4]>,
}

impl DeformBasis {
    /// The basis of `mesh` baked as `baked` with `options` (the same root layout is derived
    /// again; a mismatch is an error).
    pub fn new(mesh: &HairMesh, baked: &BakedHairMesh, options: BakeOptions) -> Result<Self> {
        let layout = layout_root_slice(mesh, options.charts);
        if [layout.width, layout.height] != baked.info.root_size
            || baked.info.layers as usize != mesh.layer_count()
        {
            return Err(HairError::invalid(
                &mesh.name,
                "the bake does not belong to this hair mesh (root layout or layers differ)",
            ));
        }
        Ok(DeformBasis {
            info: baked.info,
            texel_vertex: layout.texels,
            styling: StylingBasis::new(mesh),
            vertices: mesh.vertices_per_layer() as u32,
            root_thinning: mesh.root_thinning.clone(),
        })
    }

    /// Textures of the pose `positions` (`layers x vertices`, layer-major, object space).
    /// Points outside the decode box are clamped to it.
    pub fn rebuild(&self, positions: &[Vec3]) -> DeformedTextures {
        let n = self.vertices as usize;
        let layers = self.info.layers as usize;
        assert_eq!(
            positions.len(),
            n * layers,
            "positions of every layer vertex"
        );
        let ctrl: Vec<Vec<Vec3>> = (0..n)
            .map(|i| {
                let column: Vec<Vec3> = (0..layers).map(|k| positions[k * n + i]).collect();
                column_control_points(&column)
            })
            .collect();
        let lo = Vec3::from_slice(&self.info.pos_origin[..3]);
        let extent = Vec3::from_slice(&self.info.pos_extent[..3]);
        let dirs: Vec<_> = (0..layers)
            .map(|k| self.styling.directions(&positions[k * n..(k + 1) * n]))
            .collect();
        let [u_dir, v_dir] = encode_directions(&self.texel_vertex, &dirs);
        DeformedTextures {
            position: encode_columns(&self.texel_vertex, &ctrl, &self.root_thinning, lo, extent),
            u_dir,
            v_dir,
        }
    }
}
