//! Bake a [`HairMesh`] into the five textures of paper 003, Table 1.
//!
//! | texture | dims | Vulkan format | bytes/texel | content |
//! |---|---|---|---|---|
//! | hair mesh texture | `W x H x (4(L-1)+1)` | `R16G16B16A16_UNORM` | 8 | positions and quadratic Bezier control points, decoded `origin + extent * t` |
//! | uv-texture | `W x H` | `R16G16_UNORM` | 4 | root `uv`, decoded `origin + extent * t` |
//! | w-texture | `W x H x L` | `R16_UNORM` | 2 | `w`, decoded `w_scale * t` |
//! | u-texture | `W x H x L` | `R16G16B16A16_SNORM` | 8 | unit styling direction `u` (eq. 1-3) |
//! | v-texture | `W x H x L` | `R16G16B16A16_SNORM` | 8 | unit styling direction `v` (eq. 1-3) |
//!
//! 16-bit normalised formats: linear filtering is supported for them on lavapipe and the desktop
//! GPUs we target (checked at device creation), filtering is exact on the decoded values because
//! decoding is affine, and over a bounding box they keep a uniform `extent / 65535` precision
//! (15 micrometres on a 1 m model) where half floats lose precision away from the origin; they
//! take half the memory of 32-bit floats.

pub mod baked_file;
pub mod blue_noise;
pub mod curve;
pub mod deform;
pub mod layout;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::bake::curve::column_control_points;
use crate::bake::layout::{EMPTY_TEXEL, RootLayout, layout_root_slice};
use crate::budget::{Estimate, MemoryBudget, VEC_HEADER};
use crate::error::{HairError, Result};
use crate::model::hair_mesh::{HairMesh, bounds};
use crate::model::style::HairStyle;

/// Texture decode constants and sizes, shared with GLSL as `MeshInfo` (std430, 64 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct MeshInfo {
    /// xyz: position of texel value 0; w: scale of the w-texture.
    pub pos_origin: [f32; 4],
    /// xyz: position extent (texel value 1 maps to origin + extent); w: unused (0).
    pub pos_extent: [f32; 4],
    /// xy: uv origin; zw: uv extent.
    pub uv_origin_extent: [f32; 4],
    /// Root slice width and height in texels.
    pub root_size: [u32; 2],
    /// Number of layers `L`.
    pub layers: u32,
    /// Number of bundles.
    pub bundle_count: u32,
}

impl MeshInfo {
    /// Depth of the hair mesh texture: root/layer slices plus three intermediate slices each.
    pub fn position_depth(&self) -> u32 {
        SLICES_PER_SEGMENT * (self.layers - 1) + 1
    }

    /// Texels in one root slice.
    pub fn slice_texels(&self) -> usize {
        self.root_size[0] as usize * self.root_size[1] as usize
    }
}

/// Per-bundle record shared with GLSL as `BundleDesc` (std430, 32 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct BundleDesc {
    /// Root-slice texel of the cell's corner `(0, 0)`.
    pub origin: [u32; 2],
    /// Bit 0: triangle bundle.
    pub flags: u32,
    /// `h` of eq. 7: longest root edge at rest.
    pub rest_size: f32,
    /// Root area divided by the mean root area (strand density weight).
    pub density: f32,
    /// Padding to 32 bytes.
    pub _pad: [u32; 3],
}

pub use crate::model::hair_mesh::{MAX_TEXTURE_SIDE, SLICES_PER_SEGMENT};

/// `BundleDesc::flags` bit of triangle bundles.
pub const BUNDLE_TRIANGLE: u32 = 1;

impl BundleDesc {
    /// Whether this is a triangle bundle.
    pub fn is_triangle(&self) -> bool {
        self.flags & BUNDLE_TRIANGLE != 0
    }
}

/// One texture of the bake: its name, Vulkan format and encoded bytes.
pub struct TextureView<'a> {
    /// Name as in Table 1.
    pub name: &'static str,
    /// Vulkan format name.
    pub format: &'static str,
    /// `[width, height, depth]` (depth 1 for 2D).
    pub extent: [u32; 3],
    /// Encoded texel bytes, x fastest, then y, then z.
    pub bytes: &'a [u8],
}

/// The five textures of a hair mesh plus its bundle table and style.
#[derive(Clone, Debug, PartialEq)]
pub struct BakedHairMesh {
    /// Sizes and decode constants.
    pub info: MeshInfo,
    /// Style the mesh was baked with (renderers may override it).
    pub style: HairStyle,
    /// One record per bundle.
    pub bundles: Vec<BundleDesc>,
    /// Hair mesh texture, `R16G16B16A16_UNORM`.
    pub position: Vec<[u16; 4]>,
    /// uv-texture, `R16G16_UNORM`.
    pub uv: Vec<[u16; 2]>,
    /// w-texture, `R16_UNORM`.
    pub w: Vec<u16>,
    /// u-texture, `R16G16B16A16_SNORM`.
    pub u_dir: Vec<[i16; 4]>,
    /// v-texture, `R16G16B16A16_SNORM`.
    pub v_dir: Vec<[i16; 4]>,
}

impl BakedHairMesh {
    /// The five textures in Table 1 order.
    pub fn textures(&self) -> [TextureView<'_>; 5] {
        let [w, h] = self.info.root_size;
        let l = self.info.layers;
        [
            TextureView {
                name: "hair mesh texture",
                format: "R16G16B16A16_UNORM",
                extent: [w, h, self.info.position_depth()],
                bytes: bytemuck::cast_slice(&self.position),
            },
            TextureView {
                name: "uv-texture",
                format: "R16G16_UNORM",
                extent: [w, h, 1],
                bytes: bytemuck::cast_slice(&self.uv),
            },
            TextureView {
                name: "w-texture",
                format: "R16_UNORM",
                extent: [w, h, l],
                bytes: bytemuck::cast_slice(&self.w),
            },
            TextureView {
                name: "u-texture",
                format: "R16G16B16A16_SNORM",
                extent: [w, h, l],
                bytes: bytemuck::cast_slice(&self.u_dir),
            },
            TextureView {
                name: "v-texture",
                format: "R16G16B16A16_SNORM",
                extent: [w, h, l],
                bytes: bytemuck::cast_slice(&self.v_dir),
            },
        ]
    }

    /// Total bytes of the five textures.
    pub fn texture_bytes(&self) -> usize {
        self.textures().iter().map(|t| t.bytes.len()).sum()
    }
}

/// Options of [`bake`].
#[derive(Clone, Copy, Debug)]
pub struct BakeOptions {
    /// Pack grid-like regions as shared-vertex charts (else one 2x2 block per face).
    pub charts: bool,
    /// Grow the position decode box by this much on every side (object units), so that an
    /// animated mesh ([`deform`]) stays inside it; 0 for static hair.
    pub motion_margin: f32,
    /// Host memory the bake may use ([`memory_estimate`] is checked against it first).
    pub memory_budget: MemoryBudget,
}

impl Default for BakeOptions {
    fn default() -> Self {
        BakeOptions {
            charts: true,
            motion_margin: 0.0,
            memory_budget: MemoryBudget::default(),
        }
    }
}

/// Per-vertex styling directions `u`, `v` of one layer (eq. 1-3): the texture-space-area-weighted
/// average of each corner triangle's linear map of the uv axes, normalised. Shared by every
/// bundle meeting at the vertex, so styling has no seams between bundles.
pub fn styling_directions(mesh: &HairMesh, layer: usize) -> (Vec<Vec3>, Vec<Vec3>) {
    deform::StylingBasis::new(mesh).directions(&mesh.layers[layer])
}

/// Quantise `x` in `[0, 1]` to UNORM16.
pub fn to_unorm16(x: f32) -> u16 {
    (x.clamp(0.0, 1.0) * 65535.0).round() as u16
}

/// Quantise `x` in `[-1, 1]` to SNORM16.
pub fn to_snorm16(x: f32) -> i16 {
    (x.clamp(-1.0, 1.0) * 32767.0).round() as i16
}

fn safe_extent(e: Vec3) -> Vec3 {
    Vec3::select(e.cmpgt(Vec3::splat(1e-12)), e, Vec3::ONE)
}

/// Peak host memory of baking a hair mesh of `vertices` per layer and `layers` layers into a
/// root slice of `slice` texels: the mesh itself, the control points of every column, the five
/// textures and one copy of them (the `.hmb` image or the upload), the styling directions.
pub fn memory_estimate(vertices: u64, layers: u64, slice: u64) -> Estimate {
    let depth = SLICES_PER_SEGMENT as u64 * layers.saturating_sub(1) + 1;
    let textures = Estimate::new()
        .with("hair mesh texture", slice.saturating_mul(depth), 8)
        .with("uv and w textures", slice, 4 + 2 * layers)
        .with("u and v textures", slice.saturating_mul(layers), 16);
    let copy = textures.total();
    textures
        .with("hair mesh layers", vertices.saturating_mul(layers), 16)
        .with("column control points", vertices, VEC_HEADER + 12 * depth)
        .with("styling directions", vertices.saturating_mul(layers), 24)
        // About four 24-byte corner terms per vertex, in rows and then packed.
        .with("styling basis", vertices, VEC_HEADER + 12 * 24)
        .with("root layout", slice, 4)
        .with("the textures' file image", copy, 1)
}

/// Refuse a bake whose textures exceed a side or whose working memory exceeds the budget,
/// before anything is allocated.
fn check_size(mesh: &HairMesh, layout: &RootLayout, options: &BakeOptions) -> Result<()> {
    let layers = mesh.layer_count();
    let depth = SLICES_PER_SEGMENT as usize * (layers - 1) + 1;
    if layout.width > MAX_TEXTURE_SIDE
        || layout.height > MAX_TEXTURE_SIDE
        || depth as u32 > MAX_TEXTURE_SIDE
    {
        return Err(HairError::invalid(
            &mesh.name,
            format!(
                "too large to bake: root slice {}x{} with {depth} slices exceeds {MAX_TEXTURE_SIDE} texels per side",
                layout.width, layout.height
            ),
        ));
    }
    let n = mesh.vertices_per_layer();
    let estimate = memory_estimate(n as u64, layers as u64, layout.texels.len() as u64);
    options.memory_budget.check(
        &mesh.name,
        &format!("baking {n} vertices x {layers} layers"),
        &estimate,
        "use fewer layers or a smaller mesh",
    )
}

/// The uv-texture (each root texel's uv over the mesh's uv box `(lo, extent)`) and the
/// w-texture (every layer's w over `w_scale`), UNORM16.
fn encode_uv_w(
    mesh: &HairMesh,
    layout: &RootLayout,
    (uv_lo, uv_extent): (glam::Vec2, glam::Vec2),
    w_scale: f32,
) -> (Vec<[u16; 2]>, Vec<u16>) {
    let (slice, layers) = (layout.texels.len(), mesh.layer_count());
    let mut uv = vec![[0u16; 2]; slice];
    let mut w = vec![0u16; slice * layers];
    for (t, &vert) in layout.texels.iter().enumerate() {
        if vert == EMPTY_TEXEL {
            continue;
        }
        let vi = vert as usize;
        let q = (mesh.uv[vi] - uv_lo) / uv_extent;
        uv[t] = [to_unorm16(q.x), to_unorm16(q.y)];
        for k in 0..layers {
            w[k * slice + t] = to_unorm16(mesh.w[k][vi] / w_scale);
        }
    }
    (uv, w)
}

/// One entry a bundle: its root cell, shape, rest size and density (area over the mean).
fn bundle_table(mesh: &HairMesh, layout: &RootLayout) -> Vec<BundleDesc> {
    let sizes = mesh.bundle_sizes();
    let areas = mesh.bundle_areas();
    let mean_area = areas.iter().sum::<f32>() / areas.len() as f32;
    layout
        .bundles
        .iter()
        .enumerate()
        .map(|(f, b)| BundleDesc {
            origin: b.origin,
            flags: if b.triangle { BUNDLE_TRIANGLE } else { 0 },
            rest_size: sizes[f],
            density: areas[f] / mean_area,
            _pad: [0; 3],
        })
        .collect()
}

/// Bake `mesh` with `style` into the five textures; `progress(done, total)` is called per layer.
pub fn bake(
    mesh: &HairMesh,
    style: &HairStyle,
    options: BakeOptions,
    mut progress: impl FnMut(usize, usize),
) -> Result<BakedHairMesh> {
    mesh.validate()?;
    style.validate(&mesh.name)?;
    let layout: RootLayout = layout_root_slice(mesh, options.charts);
    let layers = mesh.layer_count();
    let n = mesh.vertices_per_layer();
    check_size(mesh, &layout, &options)?;
    let total_steps = n + layers;

    // Control points of every vertex column along r*.
    let mut ctrl: Vec<Vec<Vec3>> = Vec::with_capacity(n);
    for i in 0..n {
        let column: Vec<Vec3> = mesh.layers.iter().map(|l| l[i]).collect();
        ctrl.push(column_control_points(&column));
        if i % 4096 == 0 {
            progress(i, total_steps);
        }
    }
    if !(options.motion_margin.is_finite() && options.motion_margin >= 0.0) {
        return Err(HairError::invalid(
            &mesh.name,
            format!("motion margin {} must be >= 0", options.motion_margin),
        ));
    }
    let (lo, hi) = bounds(ctrl.iter().flatten().copied());
    let (lo, hi) = (lo - options.motion_margin, hi + options.motion_margin);
    let extent = safe_extent(hi - lo);
    let (uv_lo, uv_hi) = bounds(mesh.uv.iter().map(|uv| uv.extend(0.0)));
    let uv_extent = safe_extent(uv_hi - uv_lo).truncate();
    let w_scale = mesh
        .w
        .iter()
        .flatten()
        .fold(0.0f32, |a, &b| a.max(b))
        .max(1e-12);

    let position = deform::encode_columns(&layout.texels, &ctrl, &mesh.root_thinning, lo, extent);
    let (uv, w) = encode_uv_w(mesh, &layout, (uv_lo.truncate(), uv_extent), w_scale);
    let styling = deform::StylingBasis::new(mesh);
    let mut dirs = Vec::with_capacity(layers);
    for k in 0..layers {
        dirs.push(styling.directions(&mesh.layers[k]));
        progress(n + k + 1, total_steps);
    }
    let [u_dir, v_dir] = deform::encode_directions(&layout.texels, &dirs);

    let bundles = bundle_table(mesh, &layout);

    Ok(BakedHairMesh {
        info: MeshInfo {
            pos_origin: [lo.x, lo.y, lo.z, w_scale],
            pos_extent: [extent.x, extent.y, extent.z, 0.0],
            uv_origin_extent: [uv_lo.x, uv_lo.y, uv_extent.x, uv_extent.y],
            root_size: [layout.width, layout.height],
            layers: layers as u32,
            bundle_count: mesh.faces.len() as u32,
        },
        style: *style,
        bundles,
        position,
        uv,
        w,
        u_dir,
        v_dir,
    })
}

/// Root-slice statistics of a bake, for reports.
pub fn texels_per_face(baked: &BakedHairMesh) -> f32 {
    baked.info.slice_texels() as f32 / baked.bundles.len().max(1) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::hair_mesh::Face;

    /// `count` layers of a unit square, 0.1 apart along y.
    fn square_layers(count: usize) -> Vec<Vec<Vec3>> {
        (0..count)
            .map(|k| {
                let y = k as f32 * 0.1;
                vec![
                    Vec3::new(0.0, y, 0.0),
                    Vec3::new(1.0, y, 0.0),
                    Vec3::new(1.0, y, 1.0),
                    Vec3::new(0.0, y, 1.0),
                ]
            })
            .collect()
    }

    /// The uv texture decodes to the mesh's uvs: every texel (through the mesh's uv box) lies
    /// within one 16-bit step of a vertex's uv, and every vertex's uv is in some texel. The uvs
    /// sit in [0.25, 0.75], off the origin, so an encoding that loses the box's corner shows.
    #[test]
    fn uv_texture_decodes_to_the_mesh_uvs() {
        let layers = square_layers(3);
        let uv: Vec<glam::Vec2> = [(0.25, 0.25), (0.75, 0.3), (0.7, 0.75), (0.3, 0.7)]
            .map(|(u, v)| glam::Vec2::new(u, v))
            .to_vec();
        let faces = vec![Face::Quad([0, 1, 2, 3])];
        let mesh = HairMesh::new("quad", layers, None, uv.clone(), faces).unwrap();
        let baked = bake(
            &mesh,
            &HairStyle::default(),
            BakeOptions::default(),
            |_, _| {},
        )
        .unwrap();
        let [ox, oy, ex, ey] = baked.info.uv_origin_extent;
        let decode = |t: [u16; 2]| {
            glam::Vec2::new(
                ox + ex * t[0] as f32 / 65535.0,
                oy + ey * t[1] as f32 / 65535.0,
            )
        };
        let step = 0.5 / 65535.0 + 1e-6;
        let near = |a: glam::Vec2, b: glam::Vec2| (a - b).abs().max_element() <= step;
        for (i, t) in baked.uv.iter().enumerate() {
            let got = decode(*t);
            assert!(uv.iter().any(|&u| near(u, got)), "texel {i}: {got}");
        }
        for u in &uv {
            assert!(
                baked.uv.iter().any(|t| near(*u, decode(*t))),
                "{u} in no texel"
            );
        }
    }

    /// The estimate's column control points are what the bake allocates for them: one vector
    /// of `4 (L - 1) + 1` points per vertex column (measured equal to the byte for a quad of 5
    /// layers: 4 x (24 + 17 x 12) = 912 bytes).
    /// The deepest mesh the format takes (MAX_LAYERS layers: 2,045 slices of the 2,048 a
    /// texture may have) bakes, and progress rises step by step to its total. A depth bound
    /// counted from `layers + 1` refuses it (2,053 slices); progress counted from `n + k - 1`
    /// ends two steps short and repeats a step.
    #[test]
    fn the_deepest_mesh_bakes_and_progress_reaches_its_total() {
        let layers = square_layers(crate::model::hair_mesh::MAX_LAYERS);
        let uv = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
            .map(|(u, v)| glam::Vec2::new(u, v))
            .to_vec();
        let mesh = HairMesh::new("deep", layers, None, uv, vec![Face::Quad([0, 1, 2, 3])]).unwrap();
        let mut steps = Vec::new();
        let baked = bake(
            &mesh,
            &HairStyle::default(),
            BakeOptions::default(),
            |done, total| steps.push((done, total)),
        )
        .unwrap();
        assert_eq!(baked.info.position_depth(), 2045);
        let total = 4 + crate::model::hair_mesh::MAX_LAYERS;
        assert_eq!(steps.last(), Some(&(total, total)));
        assert!(steps.iter().all(|&(_, t)| t == total));
        assert!(steps.windows(2).all(|w| w[1].0 > w[0].0), "{steps:?}");
    }

    #[test]
    fn column_control_points_estimate_is_the_allocation() {
        let layers = square_layers(5);
        let uv = vec![
            glam::Vec2::new(0.0, 0.0),
            glam::Vec2::new(1.0, 0.0),
            glam::Vec2::new(1.0, 1.0),
            glam::Vec2::new(0.0, 1.0),
        ];
        let mesh = HairMesh::new("quad", layers, None, uv, vec![Face::Quad([0, 1, 2, 3])]).unwrap();
        let n = mesh.vertices_per_layer();
        let allocated: u64 = (0..n)
            .map(|i| {
                let column: Vec<Vec3> = mesh.layers.iter().map(|l| l[i]).collect();
                let ctrl = column_control_points(&column);
                (size_of::<Vec<Vec3>>() + ctrl.capacity() * size_of::<Vec3>()) as u64
            })
            .sum();
        let estimate = memory_estimate(n as u64, mesh.layer_count() as u64, 1);
        assert_eq!(estimate.part("column control points"), allocated);
        assert_eq!(allocated, 912);
    }
}
