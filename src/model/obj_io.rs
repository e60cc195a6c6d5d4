//! Hair meshes in Wavefront OBJ, parsed with `obj-rs`.
//!
//! # Convention
//! One OBJ file holds every layer. Layer `k` is the group `g layerK` (`layer0` is the scalp).
//! Every layer lists the same number of faces, in the same order, with the same degree; corner
//! `c` of face `f` on layer `k` lies above corner `c` of face `f` on `layer0`. Faces that share a
//! vertex on `layer0` must share the corresponding vertex on every layer. `layer0` faces carry
//! `vt` indices: the root `uv` styling coordinates. `w` is generated from path length unless
//! every `vt` line in the file has three components, in which case the third component of the
//! `vt` used on layer `k` is that vertex's `w`. Faces with more than four corners are split into
//! quads (and one triangle) the same way on every layer.
//!
//! A file without `layerK` groups is a *scalp*: [`load_scalp`] reads it for [`crate::extrude`].

use std::collections::HashMap;
use std::io::Write;
use std::path::Path;

use glam::{Vec2, Vec3};
use obj::raw::object::{Polygon, RawObj};

use crate::error::{HairError, Result};
use crate::model::hair_mesh::{Face, HairMesh, split_polygon};

/// Free-form geometry: curves and surfaces carry shape a hair mesh cannot hold, so a file
/// with them is refused (line named) rather than read without them.
const FREE_FORM_GEOMETRY: &[&str] = &["curv", "curv2", "surf"];

/// Statements that carry no hair-mesh data, ignored (obj-rs 0.7 panics on most of them, or
/// refuses them as unknown): free-form attributes and bodies, which mean nothing without a
/// curve or surface, display and render attributes, and point, line and parameter data.
const IGNORED: &[&str] = &[
    "cstype",
    "deg",
    "bmat",
    "step",
    "parm",
    "trim",
    "hole",
    "scrv",
    "sp",
    "end",
    "con",
    "ctech",
    "stech",
    "bevel",
    "c_interp",
    "d_interp",
    "lod",
    "shadow_obj",
    "trace_obj",
    "maplib",
    "usemap",
    "call",
    "csh",
    "mg",
    "vp",
    "p",
    "l",
];

/// Statements handed to obj-rs.
const PARSED: &[&str] = &[
    "v", "vt", "vn", "f", "fo", "g", "o", "s", "usemtl", "mtllib",
];

/// Largest coordinate magnitude accepted (positions, uv, w): beyond it, 32-bit floats lose
/// the precision the bake needs and areas overflow.
pub const MAX_COORDINATE: f32 = 1e6;

/// Line numbers of statements, gathered before parsing so errors can name lines.
struct LineIndex {
    vertex_lines: Vec<usize>,
    face_lines: Vec<usize>,
    all_vt_have_w: bool,
    /// Line of the first face that comes before any `g layerK` group, if any.
    face_before_layers: Option<usize>,
}

/// `Some(k)` for a layer group name `layerK` (K canonical decimal), `Err` for names that look
/// like one but are not (`layer01`, `layer-1`, `layerX`), `None` otherwise.
fn layer_group(name: &str) -> std::result::Result<Option<usize>, ()> {
    let Some(k) = name.strip_prefix("layer") else {
        return Ok(None);
    };
    let canonical = !k.is_empty()
        && k.bytes().all(|b| b.is_ascii_digit())
        && (k == "0" || !k.starts_with('0'))
        && k.len() <= 6;
    if canonical {
        Ok(k.parse().ok())
    } else {
        Err(())
    }
}

fn check_number(name: &str, line_no: usize, what: &str, a: &str) -> Result<()> {
    match a.parse::<f32>() {
        Ok(x) if x.is_finite() && x.abs() <= MAX_COORDINATE => Ok(()),
        Ok(x) if x.is_finite() => Err(HairError::invalid(
            name,
            format!("line {line_no}: {what} '{a}' is out of range (|x| <= {MAX_COORDINATE:e})"),
        )),
        _ => Err(HairError::invalid(
            name,
            format!("line {line_no}: {what} '{a}' is not a finite number"),
        )),
    }
}

fn scan_lines(name: &str, text: &str) -> Result<LineIndex> {
    let mut idx = LineIndex {
        vertex_lines: Vec::new(),
        face_lines: Vec::new(),
        all_vt_have_w: true,
        face_before_layers: None,
    };
    let mut vt_count = 0;
    let mut in_layer = false;
    let mut continued = false;
    for (n, line) in text.lines().enumerate() {
        let line_no = n + 1;
        let (body, continues) = statement_body(line);
        // A line after one ending in a backslash continues that statement.
        let was_continued = std::mem::replace(&mut continued, continues);
        if was_continued {
            continue;
        }
        let mut tok = body.split_whitespace();
        let Some(stmt) = tok.next() else { continue };
        let args: Vec<&str> = tok.collect();
        match stmt {
            "v" => {
                for a in &args {
                    check_number(name, line_no, "vertex coordinate", a)?;
                }
                idx.vertex_lines.push(line_no);
            }
            "g" => in_layer = names_a_layer(name, line_no, &args)?,
            "vt" => {
                vt_count += 1;
                if args.len() != 3 {
                    idx.all_vt_have_w = false;
                }
                for a in &args {
                    check_number(name, line_no, "texture coordinate", a)?;
                }
            }
            "f" | "fo" => {
                if !in_layer && idx.face_before_layers.is_none() {
                    idx.face_before_layers = Some(line_no);
                }
                idx.face_lines.push(line_no);
            }
            s if FREE_FORM_GEOMETRY.contains(&s) => {
                return Err(HairError::invalid(
                    name,
                    format!(
                        "line {line_no}: free-form {} ('{s}') cannot be read as a hair mesh; export polygons",
                        if s == "surf" { "surface" } else { "curve" }
                    ),
                ));
            }
            s if PARSED.contains(&s) || IGNORED.contains(&s) => {}
            s => {
                return Err(HairError::invalid(
                    name,
                    format!(
                        "line {line_no}: unknown OBJ statement '{}'",
                        s.escape_debug()
                    ),
                ));
            }
        }
    }
    idx.all_vt_have_w &= vt_count > 0;
    Ok(idx)
}

/// Whether group line `line_no` (its names `args`) starts a layer: one `layerN` name; names
/// that look like layers but are not, or a layer among other groups, are refused.
fn names_a_layer(name: &str, line_no: usize, args: &[&str]) -> Result<bool> {
    let mut layers = 0;
    for g in args {
        match layer_group(g) {
            Ok(Some(_)) => layers += 1,
            Ok(None) => {}
            Err(()) => {
                return Err(HairError::invalid(
                    name,
                    format!(
                        "line {line_no}: group '{g}' is not a layer name (layer0, layer1, ... without leading zeros)"
                    ),
                ));
            }
        }
    }
    if layers > 0 && args.len() > 1 {
        return Err(HairError::invalid(
            name,
            format!("line {line_no}: a layer group line must name one group"),
        ));
    }
    Ok(layers > 0)
}

/// A line without its comment, and whether it continues on the next line (ends in `\\`).
fn statement_body(line: &str) -> (&str, bool) {
    let body = line.split('#').next().unwrap_or("");
    (body, body.trim_end().ends_with('\\'))
}

/// `text` as obj-rs should see it: ignored statements (and their continuation lines) blanked,
/// a group line reduced to its first name (obj-rs refuses `g a b`; layer groups name one),
/// line numbers kept.
fn for_obj_rs(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut dropping = false;
    for line in text.lines() {
        let (body, continues) = statement_body(line);
        if dropping {
            dropping = continues;
            out.push('\n');
            continue;
        }
        let mut tok = body.split_whitespace();
        match tok.next() {
            Some(s) if IGNORED.contains(&s) => {
                dropping = continues;
            }
            Some("g") => {
                out.push('g');
                if let Some(first) = tok.next() {
                    out.push(' ');
                    out.push_str(first);
                }
            }
            _ => out.push_str(line),
        }
        out.push('\n');
    }
    out
}

fn parse(name: &str, bytes: &[u8]) -> Result<(RawObj, LineIndex)> {
    let text = std::str::from_utf8(bytes)
        .map_err(|e| HairError::invalid(name, format!("not UTF-8 text: {e}")))?;
    // A UTF-8 byte-order mark (some Windows tools write one) is not part of the first line.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let lines = scan_lines(name, text)?;
    let text = for_obj_rs(text);
    // obj-rs may panic on inputs it does not implement; never let that escape as a crash.
    let parsed = std::panic::catch_unwind(|| obj::raw::parse_obj(text.as_bytes()));
    match parsed {
        Ok(Ok(raw)) => Ok((raw, lines)),
        Ok(Err(e)) => Err(HairError::invalid(name, format!("malformed OBJ: {e}"))),
        Err(_) => Err(HairError::invalid(
            name,
            "malformed OBJ: the parser rejected it",
        )),
    }
}

/// One polygon corner: position index and optional texture-coordinate index.
type Corner = (usize, Option<usize>);

fn corners(p: &Polygon) -> Vec<Corner> {
    match p {
        Polygon::P(v) => v.iter().map(|&p| (p, None)).collect(),
        Polygon::PT(v) => v.iter().map(|&(p, t)| (p, Some(t))).collect(),
        Polygon::PN(v) => v.iter().map(|&(p, _)| (p, None)).collect(),
        Polygon::PTN(v) => v.iter().map(|&(p, t, _)| (p, Some(t))).collect(),
    }
}

fn group_polygons(raw: &RawObj, group: &str) -> Vec<usize> {
    raw.groups
        .get(group)
        .map(|g| g.polygons.iter().flat_map(|r| r.start..r.end).collect())
        .unwrap_or_default()
}

fn layer_group_count(raw: &RawObj) -> usize {
    (0..)
        .take_while(|k| raw.groups.contains_key(&format!("layer{k}")))
        .count()
}

fn position(raw: &RawObj, i: usize) -> Vec3 {
    let p = raw.positions[i];
    Vec3::new(p.0, p.1, p.2)
}

/// Load a hair mesh from an OBJ that follows the layer convention of this module (a regular
/// file of at most [`MAX_MESH_FILE_BYTES`](crate::fsutil::MAX_MESH_FILE_BYTES)).
pub fn load_hair_mesh_obj(path: &Path) -> Result<HairMesh> {
    let bytes = crate::fsutil::read_input(path, crate::fsutil::MAX_MESH_FILE_BYTES)?;
    parse_hair_mesh_obj(&path.display().to_string(), &bytes)
}

/// Parse a hair mesh OBJ held in memory; `name` names it in errors.
pub fn parse_hair_mesh_obj(name: &str, bytes: &[u8]) -> Result<HairMesh> {
    let (raw, lines) = parse(name, bytes)?;
    let layer_count = checked_layer_count(name, &raw, &lines)?;
    let root_polys = group_polygons(&raw, "layer0");
    if root_polys.is_empty() {
        return Err(HairError::invalid(
            name,
            "empty hair mesh: layer0 has no faces",
        ));
    }
    let (root_corners, root_faces) = root_vertices(name, &raw, &lines, &root_polys)?;
    let uv: Vec<Vec2> = root_corners
        .iter()
        .map(|&(_, t)| {
            let t = raw.tex_coords[t.unwrap_or(0)];
            Vec2::new(t.0, t.1)
        })
        .collect();
    let mut layers = Vec::with_capacity(layer_count);
    let mut w_layers = Vec::with_capacity(layer_count);
    for k in 0..layer_count {
        let columns = LayerColumns {
            root_polys: &root_polys,
            root_faces: &root_faces,
            roots: root_corners.len(),
        };
        let (layer, w) = read_layer(name, (&raw, &lines), k, columns)?;
        layers.push(layer);
        w_layers.push(w);
    }
    let mut faces = Vec::new();
    for face in &root_faces {
        for part in split_polygon(face.len()) {
            let v: Vec<u32> = part.iter().map(|&c| face[c]).collect();
            faces.push(match v.len() {
                3 => Face::Tri([v[0], v[1], v[2]]),
                _ => Face::Quad([v[0], v[1], v[2], v[3]]),
            });
        }
    }
    let w = lines.all_vt_have_w.then_some(w_layers);
    HairMesh::new(name.to_string(), layers, w, uv, faces)
}

/// The number of layer groups, numbered 0..N without gaps, 2 to `MAX_LAYERS`, every face in
/// one of them.
fn checked_layer_count(name: &str, raw: &RawObj, lines: &LineIndex) -> Result<usize> {
    let err = |what: String| HairError::invalid(name, what);
    let layer_count = layer_group_count(raw);
    if let Some(extra) = raw
        .groups
        .keys()
        .filter_map(|g| g.strip_prefix("layer")?.parse::<usize>().ok())
        .find(|&k| k >= layer_count)
    {
        return Err(err(format!(
            "group layer{extra} exists but layer{layer_count} is missing (layers must be numbered 0..N without gaps)"
        )));
    }
    if layer_count == 0 {
        return Err(err(if raw.polygons.is_empty() {
            "empty hair mesh: no faces".into()
        } else {
            "no layer groups: expected 'g layer0', 'g layer1', ... (a scalp without layers needs --extrude)".into()
        }));
    }
    if !(2..=crate::model::hair_mesh::MAX_LAYERS).contains(&layer_count) {
        return Err(err(format!(
            "a hair mesh needs 2..={} layers (at least 2 layers), found {layer_count}",
            crate::model::hair_mesh::MAX_LAYERS
        )));
    }
    if let Some(line) = lines.face_before_layers {
        return Err(err(format!(
            "line {line}: face outside any layer group (every face belongs to a 'g layerK')"
        )));
    }
    Ok(layer_count)
}

/// The file line of polygon `p` (0 where unknown).
fn face_line(lines: &LineIndex, p: usize) -> usize {
    lines.face_lines.get(p).copied().unwrap_or(0)
}

/// The root vertices (unique position and uv pairs of layer0) and layer0's faces over them.
fn root_vertices(
    name: &str,
    raw: &RawObj,
    lines: &LineIndex,
    root_polys: &[usize],
) -> Result<(Vec<Corner>, Vec<Vec<u32>>)> {
    let mut root_index: HashMap<Corner, u32> = HashMap::new();
    let mut root_corners: Vec<Corner> = Vec::new();
    let mut root_faces: Vec<Vec<u32>> = Vec::new();
    for &p in root_polys {
        let cs = corners(&raw.polygons[p]);
        let mut face = Vec::with_capacity(cs.len());
        for &c in &cs {
            if c.1.is_none() {
                return Err(HairError::invalid(
                    name,
                    format!(
                        "line {}: layer0 face has no vt index; root vertices need uv coordinates",
                        face_line(lines, p)
                    ),
                ));
            }
            let next = root_corners.len() as u32;
            let id = *root_index.entry(c).or_insert_with(|| {
                root_corners.push(c);
                next
            });
            face.push(id);
        }
        root_faces.push(face);
    }
    Ok((root_corners, root_faces))
}

/// Layer0's polygons, its faces over the root vertices, and how many root vertices there are.
struct LayerColumns<'a> {
    root_polys: &'a [usize],
    root_faces: &'a [Vec<u32>],
    roots: usize,
}

/// Layer `k`'s position and `w` (from its `vt`'s third value, where the file gives one) at
/// every root vertex: its faces must match layer0's corner for corner, each root vertex one
/// vertex of the layer.
fn read_layer(
    name: &str,
    (raw, lines): (&RawObj, &LineIndex),
    k: usize,
    columns: LayerColumns,
) -> Result<(Vec<Vec3>, Vec<f32>)> {
    let err = |what: String| HairError::invalid(name, what);
    let polys = group_polygons(raw, &format!("layer{k}"));
    if polys.len() != columns.root_polys.len() {
        return Err(err(format!(
            "layer{k} has {} faces but layer0 has {} (layers must share face topology)",
            polys.len(),
            columns.root_polys.len()
        )));
    }
    let mut pos_of: Vec<Option<usize>> = vec![None; columns.roots];
    let mut w_of: Vec<f32> = vec![0.0; columns.roots];
    for (f, &p) in polys.iter().enumerate() {
        let cs = corners(&raw.polygons[p]);
        let root_face = &columns.root_faces[f];
        if cs.len() != root_face.len() {
            return Err(err(format!(
                "line {}: layer{k} face {f} has {} corners but layer0 face {f} has {}",
                face_line(lines, p),
                cs.len(),
                root_face.len()
            )));
        }
        for (c, &(pi, ti)) in cs.iter().enumerate() {
            let r = root_face[c] as usize;
            match pos_of[r] {
                Some(prev) if prev != pi => {
                    return Err(err(format!(
                        "line {}: layer{k} face {f} corner {c} uses vertex {} but the same root vertex is vertex {} elsewhere on this layer (inconsistent layer topology)",
                        face_line(lines, p),
                        pi + 1,
                        prev + 1
                    )));
                }
                _ => pos_of[r] = Some(pi),
            }
            if lines.all_vt_have_w && k > 0 {
                let Some(t) = ti else {
                    return Err(err(format!(
                        "line {}: layer{k} face {f} has no vt index, but the file gives w in vt",
                        face_line(lines, p)
                    )));
                };
                w_of[r] = raw.tex_coords[t].2;
            }
        }
    }
    let layer = pos_of
        .iter()
        .map(|p| position(raw, p.unwrap_or(0)))
        .collect();
    Ok((layer, w_of))
}

/// A scalp: positions, uvs and faces of an OBJ without layer groups (input of `extrude`).
pub struct Scalp {
    /// Unique (position, uv) vertices.
    pub positions: Vec<Vec3>,
    /// Per-vertex uv.
    pub uv: Vec<Vec2>,
    /// Faces split into quads and triangles.
    pub faces: Vec<Face>,
}

/// Load a scalp OBJ (every face, any groups) for extrusion into a hair mesh.
pub fn load_scalp(path: &Path) -> Result<Scalp> {
    let bytes = crate::fsutil::read_input(path, crate::fsutil::MAX_MESH_FILE_BYTES)?;
    parse_scalp(&path.display().to_string(), &bytes)
}

/// Parse a scalp OBJ held in memory; `name` names it in errors.
pub fn parse_scalp(name: &str, bytes: &[u8]) -> Result<Scalp> {
    let name = name.to_string();
    let (raw, lines) = parse(&name, bytes)?;
    if raw.polygons.is_empty() {
        return Err(HairError::invalid(&name, "empty scalp: no faces"));
    }
    let mut index: HashMap<Corner, u32> = HashMap::new();
    let mut scalp = Scalp {
        positions: Vec::new(),
        uv: Vec::new(),
        faces: Vec::new(),
    };
    for (p, poly) in raw.polygons.iter().enumerate() {
        let cs = corners(poly);
        let mut face = Vec::new();
        for &c in &cs {
            let Some(t) = c.1 else {
                return Err(HairError::invalid(
                    &name,
                    format!(
                        "line {}: face has no vt index; scalp vertices need uv coordinates",
                        lines.face_lines.get(p).copied().unwrap_or(0)
                    ),
                ));
            };
            let next = scalp.positions.len() as u32;
            let id = *index.entry(c).or_insert_with(|| {
                scalp.positions.push(position(&raw, c.0));
                let tc = raw.tex_coords[t];
                scalp.uv.push(Vec2::new(tc.0, tc.1));
                next
            });
            face.push(id);
        }
        for part in split_polygon(face.len()) {
            let v: Vec<u32> = part.iter().map(|&c| face[c]).collect();
            scalp.faces.push(match v.len() {
                3 => Face::Tri([v[0], v[1], v[2]]),
                _ => Face::Quad([v[0], v[1], v[2], v[3]]),
            });
        }
    }
    Ok(scalp)
}

/// Write a hair mesh as OBJ in the layer convention (positions per layer, shared root `vt`).
pub fn write_hair_mesh_obj(mesh: &HairMesh, path: &Path, comment: &str) -> Result<()> {
    let out = hair_mesh_obj_bytes(mesh, comment).map_err(|e| HairError::io(path, e))?;
    crate::fsutil::OutputPath::check(path, &[])?.write(&out)
}

/// The OBJ text of a hair mesh in the layer convention, with `comment` lines on top.
pub fn hair_mesh_obj_bytes(mesh: &HairMesh, comment: &str) -> std::io::Result<Vec<u8>> {
    let mut out = Vec::new();
    let n = mesh.vertices_per_layer();
    let io = |e| e;
    writeln!(
        out,
        "# hair mesh: {} layers, {} faces",
        mesh.layer_count(),
        mesh.faces.len()
    )
    .map_err(io)?;
    for line in comment.lines() {
        writeln!(out, "# {line}").map_err(io)?;
    }
    for layer in &mesh.layers {
        for p in layer {
            writeln!(out, "v {} {} {}", p.x, p.y, p.z).map_err(io)?;
        }
    }
    for uv in &mesh.uv {
        writeln!(out, "vt {} {}", uv.x, uv.y).map_err(io)?;
    }
    for k in 0..mesh.layer_count() {
        writeln!(out, "g layer{k}").map_err(io)?;
        for face in &mesh.faces {
            write!(out, "f").map_err(io)?;
            for &v in face.vertices() {
                write!(out, " {}/{}", k * n + v as usize + 1, v + 1).map_err(io)?;
            }
            writeln!(out).map_err(io)?;
        }
    }
    Ok(out)
}

/// Load the triangles of any OBJ (every face, any groups, fanned into triangles): a head mesh
/// for `fit`. Positions must be finite (checked by the parser).
pub fn load_triangles(path: &Path) -> Result<Vec<[Vec3; 3]>> {
    let bytes = crate::fsutil::read_input(path, crate::fsutil::MAX_MESH_FILE_BYTES)?;
    parse_triangles(&path.display().to_string(), &bytes)
}

/// The triangles of OBJ text `bytes` named `name` in errors (as [`load_triangles`]).
pub fn parse_triangles(name: &str, bytes: &[u8]) -> Result<Vec<[Vec3; 3]>> {
    let (raw, _) = parse(name, bytes)?;
    let mut out = Vec::new();
    for poly in &raw.polygons {
        let cs = corners(poly);
        for k in 1..cs.len().saturating_sub(1) {
            out.push([
                position(&raw, cs[0].0),
                position(&raw, cs[k].0),
                position(&raw, cs[k + 1].0),
            ]);
        }
    }
    if out.is_empty() {
        return Err(HairError::invalid(name, "no faces"));
    }
    Ok(out)
}

/// Möller-Trumbore: distance along `dir` from `origin` to triangle `t`.
pub fn ray_triangle(origin: Vec3, dir: Vec3, t: &[Vec3; 3]) -> Option<f32> {
    let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let inv = 1.0 / det;
    let s = origin - t[0];
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = dir.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let d = e2.dot(q) * inv;
    (d > 0.0).then_some(d)
}
