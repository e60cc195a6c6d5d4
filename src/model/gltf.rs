//! glTF 2.0 characters in (`.glb`, or `.gltf` with its buffers and images beside it): the
//! skinned meshes of one skin (joints, weights, inverse bind matrices), the joint hierarchy,
//! base colours (factor times a PNG texture sampled at each vertex) and the animation clips
//! that drive the joints (translation, rotation, scale; step, linear, cubic spline).
//!
//! Checked like every reader here: the JSON by the `gltf` crate's validation, then every
//! accessor against its buffer view and buffer before anything is read, the total against the
//! memory budget before anything is allocated, and the values (finite, indices and joints in
//! range, key times increasing). An error is one line naming the file and the accessor, node,
//! mesh, skin or animation at fault.

use std::path::Path;

use glam::{Mat4, Quat, Vec2, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};

use crate::budget::{Estimate, MemoryBudget};
use crate::error::{HairError, Result};
use crate::skin::{
    Channel, ChannelValues, Clip, Interpolation, Joint, Skeleton, SkinVertex, SkinnedMesh, Trs,
};

/// A skinned character: meshes bound to one skeleton, and its clips.
#[derive(Clone, Debug, PartialEq)]
pub struct Character {
    /// The joints.
    pub skeleton: Skeleton,
    /// The skinned meshes (one per primitive).
    pub meshes: Vec<SkinnedMesh>,
    /// The animation clips that drive the skeleton.
    pub clips: Vec<Clip>,
}

impl Character {
    /// The clip called `name`.
    pub fn clip(&self, name: &str) -> Option<&Clip> {
        self.clips.iter().find(|c| c.name == name)
    }
}

/// Most joints a skin may have (joint indices are 16-bit on the GPU).
pub const MAX_JOINTS: usize = 4096;

/// Read the character in `path` (`.glb` or `.gltf`).
pub fn load_character(path: &Path, budget: MemoryBudget) -> Result<Character> {
    let name = path.display().to_string();
    let meta = std::fs::metadata(path).map_err(|e| HairError::io(path, e))?;
    if !meta.is_file() {
        return Err(HairError::invalid(&name, "not a regular file"));
    }
    budget.check(
        &name,
        "reading the file",
        &Estimate::new().with("file", meta.len(), 2),
        "a smaller file",
    )?;
    let bytes = std::fs::read(path).map_err(|e| HairError::io(path, e))?;
    parse_character(&name, &bytes, path.parent(), budget)
}

/// Parse a character from `bytes` (named `name` in errors); external buffers and images are
/// read from `dir` (none when `None`).
pub fn parse_character(
    name: &str,
    bytes: &[u8],
    dir: Option<&Path>,
    budget: MemoryBudget,
) -> Result<Character> {
    let bad = |what: String| HairError::invalid(name, what);
    let gltf = gltf::Gltf::from_slice(bytes)
        .map_err(|e| bad(format!("not a valid glTF 2.0 file: {e}")))?;
    let doc = &gltf.document;
    check_channels(doc.as_json()).map_err(bad)?;
    budget.check(
        name,
        "reading the character",
        &estimate(doc),
        "a smaller model",
    )?;
    let buffers = load_buffers(name, doc, gltf.blob.as_deref(), dir, budget)?;
    let data = Data {
        name,
        buffers: &buffers,
        dir,
        budget,
    };
    let skin = character_skin(doc).map_err(bad)?;
    let read = read_skeleton(&data, doc, &skin)?;
    let mut meshes = Vec::new();
    for node in doc.nodes() {
        let Some(mesh) = node.mesh() else { continue };
        match node.skin() {
            Some(s) if s.index() == skin.index() => {}
            Some(s) => {
                return Err(bad(format!(
                    "node {} uses skin {}, a second skin (one skin per character is read)",
                    node.index(),
                    s.index()
                )));
            }
            None => {
                return Err(bad(format!(
                    "node {} has mesh {} without a skin (only skinned meshes are read)",
                    node.index(),
                    mesh.index()
                )));
            }
        }
        for prim in mesh.primitives() {
            meshes.push(read_primitive(&data, &mesh, &prim, &read.skin_to_sorted)?);
        }
    }
    if meshes.is_empty() {
        return Err(bad("no skinned mesh".into()));
    }
    let clips = doc
        .animations()
        .map(|a| read_clip(&data, &a, &read.joint_of_node))
        .collect::<Result<Vec<_>>>()?;
    Ok(Character {
        skeleton: read.skeleton,
        meshes,
        clips,
    })
}

/// Upper bound of what reading `doc` allocates: every accessor's elements as f32 (at most 4
/// bytes a component, 16 components), twice (read and converted), plus the buffers.
fn estimate(doc: &gltf::Document) -> Estimate {
    let elements: u64 = doc
        .accessors()
        .map(|a| a.count() as u64 * a.dimensions().multiplicity() as u64 * 4)
        .sum();
    let buffers: u64 = doc.buffers().map(|b| b.length() as u64).sum();
    Estimate::new()
        .with("accessors", elements, 2)
        .with("buffers", buffers, 1)
}

/// What readers of accessors need.
struct Data<'a> {
    name: &'a str,
    buffers: &'a [Vec<u8>],
    dir: Option<&'a Path>,
    budget: MemoryBudget,
}

impl Data<'_> {
    fn bad(&self, what: String) -> HairError {
        HairError::invalid(self.name, what)
    }
}

/// The buffers' bytes: the GLB chunk or files beside the document, each at least as long as
/// it says.
fn load_buffers(
    name: &str,
    doc: &gltf::Document,
    blob: Option<&[u8]>,
    dir: Option<&Path>,
    budget: MemoryBudget,
) -> Result<Vec<Vec<u8>>> {
    let bad = |what: String| HairError::invalid(name, what);
    let mut out = Vec::new();
    for b in doc.buffers() {
        let bytes = match b.source() {
            gltf::buffer::Source::Bin => blob
                .ok_or_else(|| {
                    bad(format!(
                        "buffer {} is the GLB chunk, but there is none",
                        b.index()
                    ))
                })?
                .to_vec(),
            gltf::buffer::Source::Uri(uri) => {
                read_beside(name, dir, uri, budget, &format!("buffer {}", b.index()))?
            }
        };
        if bytes.len() < b.length() {
            return Err(bad(format!(
                "buffer {} holds {} bytes, less than its byteLength {}",
                b.index(),
                bytes.len(),
                b.length()
            )));
        }
        out.push(bytes);
    }
    Ok(out)
}

/// The file `uri` names beside the document (data URIs and absolute or parent paths are
/// refused).
fn read_beside(
    name: &str,
    dir: Option<&Path>,
    uri: &str,
    budget: MemoryBudget,
    what: &str,
) -> Result<Vec<u8>> {
    let bad = |why: &str| HairError::invalid(name, format!("{what}: {why}"));
    if uri.starts_with("data:") {
        return Err(bad(
            "data: URIs are not read (use .glb, or files beside the .gltf)",
        ));
    }
    let rel = Path::new(uri);
    if rel.is_absolute()
        || rel
            .components()
            .any(|c| matches!(c, std::path::Component::ParentDir))
    {
        return Err(bad(&format!("'{uri}' is not a file beside the document")));
    }
    let dir = dir.ok_or_else(|| bad(&format!("'{uri}' is external and no folder was given")))?;
    let path = dir.join(rel);
    let len = std::fs::metadata(&path)
        .map_err(|e| HairError::io(&path, e))?
        .len();
    budget.check(
        name,
        what,
        &Estimate::new().with("file", len, 1),
        "a smaller model",
    )?;
    std::fs::read(&path).map_err(|e| HairError::io(&path, e))
}

/// The skin of the character: the one skin meshes use (or the first).
fn character_skin(doc: &gltf::Document) -> std::result::Result<gltf::Skin<'_>, String> {
    doc.nodes()
        .find_map(|n| n.mesh().and(n.skin()))
        .or_else(|| doc.skins().next())
        .ok_or_else(|| "no skin: the character's meshes must be skinned".to_string())
}

/// What the gltf crate's validation leaves out and its accessors unwrap (a panic the fuzzer
/// found): every animation channel targets a node that exists, with a path glTF 2.0 names.
fn check_channels(root: &gltf::json::Root) -> std::result::Result<(), String> {
    use gltf::json::validation::Checked;
    for (a, anim) in root.animations.iter().enumerate() {
        for (c, ch) in anim.channels.iter().enumerate() {
            let node = ch.target.node.value();
            if node >= root.nodes.len() {
                return Err(format!(
                    "animation {a} channel {c} targets node {node}, which does not exist"
                ));
            }
            if !matches!(ch.target.path, Checked::Valid(_)) {
                return Err(format!(
                    "animation {a} channel {c}: its target path is not translation, rotation, scale or weights"
                ));
            }
        }
    }
    Ok(())
}

/// The parent of every node (`None` for scene roots). A hierarchy that is not a forest is
/// refused (glTF 2.0, 3.5.3 "Transformations": a node is the child of at most one node and no
/// node is its own ancestor): walking up from a node must end.
fn parents(doc: &gltf::Document) -> std::result::Result<Vec<Option<usize>>, String> {
    let mut parent: Vec<Option<usize>> = vec![None; doc.nodes().len()];
    for n in doc.nodes() {
        for c in n.children() {
            if let Some(other) = parent[c.index()].replace(n.index()) {
                return Err(format!(
                    "node {} is a child of nodes {other} and {}",
                    c.index(),
                    n.index()
                ));
            }
        }
    }
    // 0 not seen, 1 on the current walk up, 2 known to reach a root: every node is walked once.
    let mut state = vec![0u8; parent.len()];
    for start in 0..parent.len() {
        let mut at = Some(start);
        let mut walked = Vec::new();
        while let Some(n) = at.filter(|&n| state[n] != 2) {
            if state[n] == 1 {
                return Err(format!("node {n} is its own ancestor"));
            }
            state[n] = 1;
            walked.push(n);
            at = parent[n];
        }
        for n in walked {
            state[n] = 2;
        }
    }
    Ok(parent)
}

/// Local transform of a node.
fn node_trs(node: &gltf::Node) -> Trs {
    let (t, r, s) = node.transform().decomposed();
    Trs {
        t: Vec3::from(t),
        r: Quat::from_array(r),
        s: Vec3::from(s),
    }
}

/// The skeleton of `skin` (joints ordered parents first) and the joint of every node.
fn read_skeleton(data: &Data, doc: &gltf::Document, skin: &gltf::Skin) -> Result<SkeletonRead> {
    let nodes: Vec<usize> = skin.joints().map(|n| n.index()).collect();
    if nodes.is_empty() || nodes.len() > MAX_JOINTS {
        return Err(data.bad(format!(
            "skin {} has {} joints (1..={MAX_JOINTS} are read)",
            skin.index(),
            nodes.len()
        )));
    }
    let parent = parents(doc).map_err(|e| data.bad(e))?;
    let is_joint = |n: usize| nodes.contains(&n);
    let depth = |mut n: usize| {
        let mut d = 0;
        while let Some(p) = parent[n] {
            n = p;
            d += 1;
        }
        d
    };
    let mut order: Vec<usize> = (0..nodes.len()).collect();
    order.sort_by_key(|&k| (depth(nodes[k]), k));
    let inverse_bind = match skin.inverse_bind_matrices() {
        Some(acc) => read_floats(data, &acc, &[Dimensions::Mat4], "inverse bind matrices")?
            .chunks_exact(16)
            .map(Mat4::from_cols_slice)
            .collect(),
        None => vec![Mat4::IDENTITY; nodes.len()],
    };
    if inverse_bind.len() != nodes.len() {
        return Err(data.bad(format!(
            "skin {}: {} inverse bind matrices for {} joints",
            skin.index(),
            inverse_bind.len(),
            nodes.len()
        )));
    }
    let mut joint_of_node = vec![None; parent.len()];
    for (k, &j) in order.iter().enumerate() {
        joint_of_node[nodes[j]] = Some(k);
    }
    let doc_nodes: Vec<gltf::Node> = doc.nodes().collect();
    let mut joints = Vec::with_capacity(nodes.len());
    let mut root = Mat4::IDENTITY;
    for &j in &order {
        let n = nodes[j];
        // The nearest ancestor that is a joint; above a root joint, its ancestors' transforms.
        let mut up = parent[n];
        while let Some(p) = up.filter(|&p| !is_joint(p)) {
            if joints.is_empty() {
                root = Mat4::from_cols_array_2d(&doc_nodes[p].transform().matrix()) * root;
            }
            up = parent[p];
        }
        joints.push(Joint {
            name: doc_nodes[n]
                .name()
                .map_or(format!("joint {k}", k = joints.len()), str::to_string),
            parent: up.and_then(|p| joint_of_node[p]),
            rest: node_trs(&doc_nodes[n]),
            inverse_bind: inverse_bind[j],
        });
    }
    let skeleton = Skeleton { joints, root };
    skeleton
        .validate()
        .map_err(|e| data.bad(format!("skin {}: {e}", skin.index())))?;
    // Meshes index joints in the skin's order; they are remapped to the sorted order.
    let skin_to_sorted = nodes
        .iter()
        .map(|&n| joint_of_node[n].unwrap_or(0))
        .collect();
    Ok(SkeletonRead {
        skeleton,
        joint_of_node,
        skin_to_sorted,
    })
}

/// A skin's skeleton as read.
struct SkeletonRead {
    skeleton: Skeleton,
    /// The joint (sorted order) of every node that is one.
    joint_of_node: Vec<Option<usize>>,
    /// The sorted joint of each of the skin's joints (meshes index the skin's order).
    skin_to_sorted: Vec<usize>,
}

/// Vertex `k`'s four joints (in the skeleton's `order`) and weights (normalised to sum 1),
/// from the primitive's JOINTS_0 and WEIGHTS_0; a weight that is negative or not finite, a
/// weighted joint outside the skin, or no weight at all is an error naming the vertex.
fn vertex_influences(
    data: &Data,
    at: &str,
    k: usize,
    (joints, weights): (&[f32], &[f32]),
    order: &[usize],
) -> Result<([u16; 4], [f32; 4])> {
    let joint_count = order.len();
    let mut j = [0u16; 4];
    let mut w = [0f32; 4];
    for c in 0..4 {
        let joint = joints[k * 4 + c];
        w[c] = weights[k * 4 + c];
        if !(w[c].is_finite() && w[c] >= 0.0) {
            return Err(data.bad(format!(
                "{at}: vertex {k} has weight {} (finite, >= 0 expected)",
                w[c]
            )));
        }
        if w[c] > 0.0 && (joint < 0.0 || joint as usize >= joint_count) {
            return Err(data.bad(format!(
                "{at}: vertex {k} names joint {joint} of {joint_count}"
            )));
        }
        j[c] = order.get(joint as usize).copied().unwrap_or(0) as u16;
    }
    let sum: f32 = w.iter().sum();
    if sum <= 0.0 {
        return Err(data.bad(format!("{at}: vertex {k} has no weight")));
    }
    Ok((j, w.map(|x| x / sum)))
}

/// One primitive as a skinned mesh.
fn read_primitive(
    data: &Data,
    mesh: &gltf::Mesh,
    prim: &gltf::Primitive,
    order: &[usize],
) -> Result<SkinnedMesh> {
    let at = format!("mesh {} primitive {}", mesh.index(), prim.index());
    if prim.mode() != gltf::mesh::Mode::Triangles {
        return Err(data.bad(format!(
            "{at}: {:?} primitives are not read (triangles only)",
            prim.mode()
        )));
    }
    let attr = |s: gltf::Semantic| prim.get(&s);
    let need = |s: gltf::Semantic, what: &str| {
        attr(s).ok_or_else(|| data.bad(format!("{at}: no {what} attribute")))
    };
    let positions = read_vec3(data, &need(gltf::Semantic::Positions, "POSITION")?, &at)?;
    let n = positions.len();
    let joints = read_floats(
        data,
        &need(gltf::Semantic::Joints(0), "JOINTS_0")?,
        &[Dimensions::Vec4],
        &at,
    )?;
    let weights = read_floats(
        data,
        &need(gltf::Semantic::Weights(0), "WEIGHTS_0")?,
        &[Dimensions::Vec4],
        &at,
    )?;
    let indices = match prim.indices() {
        Some(acc) => read_indices(data, &acc, n, &at)?,
        None => (0..n as u32).collect(),
    };
    if indices.len() % 3 != 0 || joints.len() != n * 4 || weights.len() != n * 4 {
        return Err(data.bad(format!(
            "{at}: attribute counts or index count do not make triangles over {n} vertices"
        )));
    }
    let normals = match attr(gltf::Semantic::Normals) {
        Some(acc) => read_vec3(data, &acc, &at)?,
        None => smooth_normals(&positions, &indices),
    };
    if normals.len() != n {
        return Err(data.bad(format!("{at}: {} normals for {n} positions", normals.len())));
    }
    let colors = vertex_colors(data, prim, n, &at)?;
    let roughness = material_roughness(data, prim, &at)?;
    let mut vertices = Vec::with_capacity(n);
    for k in 0..n {
        let (j, w) = vertex_influences(data, &at, k, (&joints, &weights), order)?;
        vertices.push(SkinVertex {
            position: positions[k],
            normal: normals[k].normalize_or(Vec3::Y),
            color: colors[k],
            roughness,
            joints: j,
            weights: w,
        });
    }
    let name = mesh
        .name()
        .or(prim.material().name())
        .map_or(format!("mesh {}", mesh.index()), str::to_string);
    Ok(SkinnedMesh {
        name,
        vertices,
        indices,
    })
}

/// The primitive's material roughness factor (1 where the file gives none, glTF's default);
/// out of 0..=1 or not finite is an error naming the primitive. Kept above 0.05 (a mirror's
/// highlight is a sub-pixel point).
fn material_roughness(data: &Data, prim: &gltf::Primitive, at: &str) -> Result<f32> {
    let r = prim.material().pbr_metallic_roughness().roughness_factor();
    if !(0.0..=1.0).contains(&r) {
        return Err(data.bad(format!("{at}: material roughness {r} is outside 0..=1")));
    }
    Ok(r.max(0.05))
}

/// Per-vertex linear colour: the material's base colour factor times its base colour texture
/// (PNG, sRGB, bilinear at TEXCOORD_0, repeated) where there is one.
fn vertex_colors(data: &Data, prim: &gltf::Primitive, n: usize, at: &str) -> Result<Vec<Vec3>> {
    let pbr = prim.material().pbr_metallic_roughness();
    let factor = Vec4::from(pbr.base_color_factor()).truncate();
    if !factor.is_finite() {
        return Err(data.bad(format!("{at}: base colour factor is not finite")));
    }
    let Some(info) = pbr.base_color_texture() else {
        return Ok(vec![factor; n]);
    };
    let Some(uv_acc) = prim.get(&gltf::Semantic::TexCoords(info.tex_coord())) else {
        return Err(data.bad(format!(
            "{at}: a base colour texture but no TEXCOORD_{}",
            info.tex_coord()
        )));
    };
    let uvs = read_floats(data, &uv_acc, &[Dimensions::Vec2], at)?;
    if uvs.len() != n * 2 {
        return Err(data.bad(format!(
            "{at}: {} texture coordinates for {n} positions",
            uvs.len() / 2
        )));
    }
    let image = read_image(data, &info.texture().source(), at)?;
    Ok(uvs
        .chunks_exact(2)
        .map(|uv| factor * sample_srgb(&image, Vec2::new(uv[0], uv[1])))
        .collect())
}

/// A PNG image of the document, decoded to RGBA8 after its size is checked.
fn read_image(data: &Data, image: &gltf::Image, at: &str) -> Result<image::RgbaImage> {
    let what = format!("{at}: image {}", image.index());
    let bytes: Vec<u8> = match image.source() {
        gltf::image::Source::View { view, .. } => view_bytes(data, &view, &what)?.to_vec(),
        gltf::image::Source::Uri { uri, .. } => {
            read_beside(data.name, data.dir, uri, data.budget, &what)?
        }
    };
    let reader =
        image::ImageReader::with_format(std::io::Cursor::new(&bytes), image::ImageFormat::Png);
    let (w, h) = reader
        .into_dimensions()
        .map_err(|e| data.bad(format!("{what}: not a PNG image: {e}")))?;
    let est = Estimate::new().with("texture", w as u64 * h as u64, 8);
    data.budget
        .check(data.name, &what, &est, "a smaller texture")?;
    image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
        .map(|i| i.to_rgba8())
        .map_err(|e| data.bad(format!("{what}: {e}")))
}

/// Bilinear sample of an sRGB image at `uv` (repeat), as linear RGB.
fn sample_srgb(image: &image::RgbaImage, uv: Vec2) -> Vec3 {
    let (w, h) = image.dimensions();
    if w == 0 || h == 0 || !uv.is_finite() {
        return Vec3::ONE;
    }
    let x = uv.x.rem_euclid(1.0) * w as f32 - 0.5;
    let y = uv.y.rem_euclid(1.0) * h as f32 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let texel = |dx: f32, dy: f32| {
        let px = ((x0 + dx) as i64).rem_euclid(w as i64) as u32;
        let py = ((y0 + dy) as i64).rem_euclid(h as i64) as u32;
        let p = image.get_pixel(px, py).0;
        Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32) / 255.0
    };
    let c = texel(0.0, 0.0)
        .lerp(texel(1.0, 0.0), fx)
        .lerp(texel(0.0, 1.0).lerp(texel(1.0, 1.0), fx), fy);
    c.map(crate::shade::srgb_to_linear)
}

/// Area-weighted vertex normals of a triangle list.
fn smooth_normals(positions: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    let mut n = vec![Vec3::ZERO; positions.len()];
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| i as usize);
        let f = (positions[b] - positions[a]).cross(positions[c] - positions[a]);
        for i in [a, b, c] {
            n[i] += f;
        }
    }
    n.into_iter().map(|v| v.normalize_or(Vec3::Y)).collect()
}

/// One animation as a clip over the skeleton's joints (channels of other nodes, and morph
/// weights, are left out).
fn read_clip(data: &Data, anim: &gltf::Animation, joint_of_node: &[Option<usize>]) -> Result<Clip> {
    let at = format!("animation {}", anim.index());
    let mut channels = Vec::new();
    for ch in anim.channels() {
        let Some(joint) = joint_of_node
            .get(ch.target().node().index())
            .copied()
            .flatten()
        else {
            continue;
        };
        let s = ch.sampler();
        let cat = format!("{at} channel {}", ch.index());
        let times = read_floats(data, &s.input(), &[Dimensions::Scalar], &cat)?;
        let interpolation = match s.interpolation() {
            gltf::animation::Interpolation::Step => Interpolation::Step,
            gltf::animation::Interpolation::Linear => Interpolation::Linear,
            gltf::animation::Interpolation::CubicSpline => Interpolation::CubicSpline,
        };
        use gltf::animation::Property;
        let values = match ch.target().property() {
            Property::Translation => {
                ChannelValues::Translation(read_vec3(data, &s.output(), &cat)?)
            }
            Property::Scale => ChannelValues::Scale(read_vec3(data, &s.output(), &cat)?),
            Property::Rotation => ChannelValues::Rotation(
                read_floats(data, &s.output(), &[Dimensions::Vec4], &cat)?
                    .chunks_exact(4)
                    .map(Vec4::from_slice)
                    .collect(),
            ),
            Property::MorphTargetWeights => continue,
        };
        let channel = Channel {
            joint,
            times,
            interpolation,
            values,
        };
        channel
            .validate()
            .map_err(|e| data.bad(format!("{cat}: {e}")))?;
        channels.push(channel);
    }
    let duration = channels
        .iter()
        .filter_map(|c| c.times.last().copied())
        .fold(0.0, f32::max);
    Ok(Clip {
        name: anim
            .name()
            .map_or(format!("animation {}", anim.index()), str::to_string),
        duration,
        channels,
    })
}

/// The bytes of a buffer view, checked against its buffer.
fn view_bytes<'d>(data: &'d Data, view: &gltf::buffer::View, at: &str) -> Result<&'d [u8]> {
    let buf = &data.buffers[view.buffer().index()];
    let end = view.offset().checked_add(view.length());
    match end {
        Some(end) if end <= buf.len() => Ok(&buf[view.offset()..end]),
        _ => Err(data.bad(format!(
            "{at}: buffer view {} ({} bytes at {}) runs past buffer {} ({} bytes)",
            view.index(),
            view.length(),
            view.offset(),
            view.buffer().index(),
            buf.len()
        ))),
    }
}

/// Components of `acc` as f32 (floats as they are, normalized integers scaled, other
/// integers converted), checked against its view; its dimensions must be one of `dims`.
fn read_floats(
    data: &Data,
    acc: &gltf::Accessor,
    dims: &[Dimensions],
    at: &str,
) -> Result<Vec<f32>> {
    let what = format!("{at}: accessor {}", acc.index());
    if !dims.contains(&acc.dimensions()) {
        return Err(data.bad(format!(
            "{what}: {:?} where {dims:?} is expected",
            acc.dimensions()
        )));
    }
    if acc.sparse().is_some() {
        return Err(data.bad(format!("{what}: sparse accessors are not read")));
    }
    let comps = acc.dimensions().multiplicity();
    let size = acc.data_type().size();
    let Some(view) = acc.view() else {
        // No view: all zeros (glTF 2.0 section 3.6.2.3).
        return Ok(vec![0.0; acc.count() * comps]);
    };
    let bytes = view_bytes(data, &view, &what)?;
    let elem = comps * size;
    let stride = view.stride().unwrap_or(elem);
    let need = acc
        .count()
        .checked_sub(1)
        .map(|last| last as u128 * stride as u128 + acc.offset() as u128 + elem as u128);
    if stride < elem || need.is_some_and(|n| n > bytes.len() as u128) {
        return Err(data.bad(format!(
            "{what}: {} elements of {elem} bytes (stride {stride}, offset {}) run past buffer view {} ({} bytes)",
            acc.count(),
            acc.offset(),
            view.index(),
            bytes.len()
        )));
    }
    let mut out = Vec::with_capacity(acc.count() * comps);
    for k in 0..acc.count() {
        let base = acc.offset() + k * stride;
        for c in 0..comps {
            let b = &bytes[base + c * size..base + (c + 1) * size];
            out.push(component(acc.data_type(), acc.normalized(), b));
        }
    }
    if !out.iter().all(|x| x.is_finite()) {
        return Err(data.bad(format!("{what}: a value is not finite")));
    }
    Ok(out)
}

/// One component as f32.
fn component(t: DataType, normalized: bool, b: &[u8]) -> f32 {
    let (v, scale) = match t {
        DataType::F32 => return f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        DataType::U8 => (b[0] as f32, 255.0),
        DataType::I8 => ((b[0] as i8) as f32, 127.0),
        DataType::U16 => (u16::from_le_bytes([b[0], b[1]]) as f32, 65535.0),
        DataType::I16 => (i16::from_le_bytes([b[0], b[1]]) as f32, 32767.0),
        DataType::U32 => (
            u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
            u32::MAX as f32,
        ),
    };
    if normalized { (v / scale).max(-1.0) } else { v }
}

/// A VEC3 accessor.
fn read_vec3(data: &Data, acc: &gltf::Accessor, at: &str) -> Result<Vec<Vec3>> {
    Ok(read_floats(data, acc, &[Dimensions::Vec3], at)?
        .chunks_exact(3)
        .map(Vec3::from_slice)
        .collect())
}

/// Triangle indices, each below `vertices`.
fn read_indices(data: &Data, acc: &gltf::Accessor, vertices: usize, at: &str) -> Result<Vec<u32>> {
    if !matches!(
        acc.data_type(),
        DataType::U8 | DataType::U16 | DataType::U32
    ) || acc.normalized()
    {
        return Err(data.bad(format!(
            "{at}: accessor {}: indices must be unsigned integers",
            acc.index()
        )));
    }
    let values = read_floats(data, acc, &[Dimensions::Scalar], at)?;
    // f32 holds every u32 index below 2^24 exactly; larger meshes are refused.
    if vertices >= 1 << 24 {
        return Err(data.bad(format!("{at}: {vertices} vertices (at most 2^24 are read)")));
    }
    values
        .into_iter()
        .map(|v| {
            let i = v as u32;
            if (i as usize) < vertices {
                Ok(i)
            } else {
                Err(data.bad(format!(
                    "{at}: accessor {}: index {i} of {vertices} vertices",
                    acc.index()
                )))
            }
        })
        .collect()
}
