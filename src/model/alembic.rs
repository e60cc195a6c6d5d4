//! Alembic (`.abc`, Ogawa) curves in: every curve object of the archive, at its first sample,
//! placed by the transform hierarchy above it, with widths where the
//! file has them (`StrandModel::from_alembic` joins them into one strand model). Blender,
//! Houdini, Maya and Unreal write grooms this way.
//!
//! The archive, its objects, properties and the curves schema are read with Traverse Research's
//! `ogawa-rs`. What this file adds is what `ogawa-rs` 0.4 lacks or does unsafely:
//! - **Transforms.** Its Xform schema reports only whether a transform is constant; the
//!   operations (`.ops`) and channel values (`.vals`) are read here and composed as Alembic's
//!   `XformSample::getMatrix` does (the first operation is the outermost).
//! - **Sizes.** It trusts the sizes stored in the file: an empty array underflows into a huge
//!   allocation, and an oversized one is allocated before it is read. Every sample is checked
//!   against the file before `ogawa-rs` reads it.
//! - **Panics.** Boolean properties and some malformed files reach `todo!()` or `assert!` in it.
//!   Booleans are never read (so `.inherits` is taken as true, Alembic's default), and any panic
//!   left becomes a one-line error.
//!
//! HDF5-based archives (Alembic before 1.5) get their own one-line error: `ogawa-rs` reads only
//! Ogawa, the default since Alembic 1.5 (2013).

use std::io::{Cursor, Read, Seek, SeekFrom};

use glam::{DMat4, DVec3, Vec3};
use ogawa_rs::{
    Archive, ArchiveReader, BasisType, CurvePeriodicity, CurveType, CurvesSchema, ObjectReader,
    PodArray, PropertyReader,
};

use crate::error::{HairError, Result};

/// First bytes of an HDF5 file (Alembic's storage before Ogawa).
const HDF5_MAGIC: &[u8] = b"\x89HDF\r\n\x1a\n";
/// First bytes of an Ogawa archive.
const OGAWA_MAGIC: &[u8] = b"Ogawa";
/// Deepest object hierarchy read (a file nesting deeper is refused, not recursed into).
pub const MAX_DEPTH: usize = 128;
/// Most objects read from one archive.
pub const MAX_OBJECTS: usize = 1 << 20;

/// Curves read from one Alembic object, in world space.
#[derive(Clone, Debug, PartialEq)]
pub struct CurveObject {
    /// The object's full name in the archive (`/groom/curves`).
    pub name: String,
    /// Its curves, root first.
    pub strands: Vec<Vec<Vec3>>,
    /// Per-point widths (world units), when the object has them.
    pub widths: Option<Vec<Vec<f32>>>,
}

/// Read every curve object of the Alembic archive `bytes` (named `name` in errors).
pub fn read_curves(name: &str, bytes: &[u8]) -> Result<Vec<CurveObject>> {
    let bad = |what: String| HairError::invalid(name, what);
    if bytes.starts_with(HDF5_MAGIC) {
        return Err(bad(
            "an HDF5-based Alembic archive: only Ogawa archives are read (re-export it as Ogawa, Alembic's default since 1.5)".into(),
        ));
    }
    if !bytes.starts_with(OGAWA_MAGIC) {
        return Err(bad("not an Alembic archive (no Ogawa header)".into()));
    }
    check_ogawa(bytes).map_err(|what| bad(format!("malformed archive: {what}")))?;
    // `ogawa-rs` may still panic on malformed files: contain it, quietly, as an error.
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let result = std::panic::catch_unwind(|| {
        let mut reader = BytesReader(Cursor::new(bytes));
        let mut walk = Walk {
            objects: Vec::new(),
            visited: 0,
        };
        walk.archive(&mut reader).map(|()| walk.objects)
    });
    std::panic::set_hook(previous);
    match result {
        Ok(Ok(objects)) if objects.is_empty() => Err(bad("no curve objects".into())),
        Ok(Ok(objects)) => Ok(objects),
        Ok(Err(what)) => Err(bad(format!("malformed archive: {what}"))),
        Err(panic) => {
            let why = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown".into());
            Err(bad(format!(
                "malformed archive (the Ogawa reader stopped: {why})"
            )))
        }
    }
}

/// Check the Ogawa container before `ogawa-rs` reads it: every group and data chunk reachable
/// from the root lies inside the file (`ogawa-rs` allocates whatever size a chunk claims). A
/// group is a count and that many child words; a child word with the top bit set is a data
/// chunk (a size and the bytes), else a group (0: empty).
fn check_ogawa(bytes: &[u8]) -> std::result::Result<(), String> {
    const DATA: u64 = 1 << 63;
    let len = bytes.len() as u64;
    let word = |at: u64| -> std::result::Result<u64, String> {
        match at.checked_add(8).filter(|end| *end <= len) {
            Some(end) => Ok(u64::from_le_bytes(
                bytes[at as usize..end as usize]
                    .try_into()
                    .expect("8 bytes"),
            )),
            None => Err(format!(
                "a chunk at byte {at} runs past the end ({len} bytes)"
            )),
        }
    };
    // Magic (5), frozen flag (1), version (2), then the root group's position.
    let mut pending = vec![word(8)?];
    let mut seen = std::collections::HashSet::new();
    while let Some(child) = pending.pop() {
        if child == 0 || child == DATA || !seen.insert(child) {
            continue;
        }
        if seen.len() > MAX_OBJECTS * 16 {
            return Err("too many chunks".into());
        }
        let at = child & !DATA;
        let size = word(at)?;
        let end = (at + 8).checked_add(if child & DATA != 0 {
            size
        } else {
            size.saturating_mul(8)
        });
        if end.is_none_or(|e| e > len) {
            return Err(format!(
                "a chunk at byte {at} claims {size} entries past the end ({len} bytes)"
            ));
        }
        if child & DATA == 0 {
            for k in 0..size {
                pending.push(word(at + 8 + 8 * k)?);
            }
        }
    }
    Ok(())
}

/// An in-memory archive for `ogawa-rs` (never a memory map: a file shrinking under one would
/// fault).
struct BytesReader<'b>(Cursor<&'b [u8]>);

impl Read for BytesReader<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        self.0.read(buf)
    }
}

impl Seek for BytesReader<'_> {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        self.0.seek(pos)
    }
}

impl ArchiveReader for BytesReader<'_> {
    fn size(&self) -> u64 {
        self.0.get_ref().len() as u64
    }
}

/// The walk over an archive's objects.
struct Walk {
    objects: Vec<CurveObject>,
    visited: usize,
}

/// Message of an `ogawa-rs` error while doing `what`.
fn ogawa(what: &str) -> impl Fn(ogawa_rs::OgawaError) -> String + '_ {
    move |e| format!("{what}: {e} ({e:?})")
}

impl Walk {
    fn archive(&mut self, reader: &mut BytesReader) -> std::result::Result<(), String> {
        let archive = Archive::new(reader).map_err(ogawa("archive header"))?;
        let root = archive
            .load_root_object(reader)
            .map_err(ogawa("root object"))?;
        self.object(&root, reader, &archive, DMat4::IDENTITY, 0)
    }

    /// Read `object` (placed by `parent`, the world matrix above it) and its children.
    fn object(
        &mut self,
        object: &ObjectReader,
        reader: &mut BytesReader,
        archive: &Archive,
        parent: DMat4,
        depth: usize,
    ) -> std::result::Result<(), String> {
        self.visited += 1;
        if depth > MAX_DEPTH || self.visited > MAX_OBJECTS {
            return Err(format!(
                "more than {MAX_DEPTH} levels or {MAX_OBJECTS} objects"
            ));
        }
        let full_name = &object.header.full_name;
        let schema = schema_name(object, reader, archive)?;
        let mut world = parent;
        match schema.as_deref() {
            Some(s) if s.starts_with("AbcGeom_Xform") => {
                world = parent
                    * xform(object, reader, archive).map_err(|e| format!("{full_name}: {e}"))?;
            }
            Some(s) if s.starts_with("AbcGeom_Curve") => {
                let curves = curves(object, reader, archive, parent)
                    .map_err(|e| format!("{full_name}: {e}"))?;
                self.objects.push(curves);
            }
            _ => {}
        }
        for i in 0..object.child_count() {
            let child = object
                .load_child(
                    i,
                    reader,
                    &archive.indexed_meta_data,
                    &archive.time_samplings,
                )
                .map_err(ogawa(&format!("{full_name}: child {i}")))?;
            self.object(&child, reader, archive, world, depth + 1)?;
        }
        Ok(())
    }
}

/// The schema `object` follows: named in its header, or else (Xforms) in the metadata of its
/// first property, as `ogawa-rs`'s `Schema::parse` looks for it.
fn schema_name(
    object: &ObjectReader,
    reader: &mut BytesReader,
    archive: &Archive,
) -> std::result::Result<Option<String>, String> {
    if let Some(s) = object.header.meta_data.tokens.get("schema") {
        return Ok(Some(s.clone()));
    }
    let has_schema = object
        .properties()
        .is_some_and(|p| p.sub_property_count() > 0);
    if !has_schema {
        return Ok(None);
    }
    Ok(match schema_property(object, reader, archive)? {
        PropertyReader::Compound(c) => c.header.meta_data.tokens.get("schema").cloned(),
        _ => None,
    })
}

/// The schema's compound property of `object` (its first property).
fn schema_property(
    object: &ObjectReader,
    reader: &mut BytesReader,
    archive: &Archive,
) -> std::result::Result<PropertyReader, String> {
    let props = object.properties().ok_or("no properties")?;
    if props.sub_property_count() == 0 {
        return Err("no schema properties".into());
    }
    props
        .load_sub_property(0, reader, archive)
        .map_err(ogawa("schema properties"))
}

/// Sample 0 of `property` (scalar or array; never boolean): `None` when it holds nothing.
/// Its stored size lies within the file ([`check_ogawa`]); an empty one is never handed to
/// `ogawa-rs`, whose size arithmetic underflows on it.
fn sample(
    property: &PropertyReader,
    reader: &mut BytesReader,
) -> std::result::Result<Option<PodArray>, String> {
    let what = format!("property {}", property.name());
    // Scalar and array readers have the same methods but no common trait (nor a nameable
    // type): one body for both.
    macro_rules! read_checked {
        ($p:expr) => {{
            unreadable(&$p.header.data_type, &what)?;
            let samples = $p.sample_count();
            let size = match samples {
                0 => 0,
                _ => $p.sample_size(0, reader).map_err(ogawa(&what))?,
            };
            match size > 0 {
                true => Some($p.load_sample(0, reader).map_err(ogawa(&what))?),
                false => None,
            }
        }};
    }
    let read = match property {
        PropertyReader::Scalar(p) => read_checked!(p),
        PropertyReader::Array(p) => read_checked!(p),
        PropertyReader::Compound(_) => {
            return Err(format!("{what}: an indexed (compound) property, not read"));
        }
    };
    Ok(read)
}

/// Refuse the element types `ogawa-rs` 0.4 reaches `todo!()` on (its `DataType` keeps the type
/// private: only its debug text names it).
fn unreadable(data_type: &ogawa_rs::DataType, what: &str) -> std::result::Result<(), String> {
    let text = format!("{data_type:?}");
    match ["Boolean", "WString"].iter().find(|t| text.contains(*t)) {
        Some(t) => Err(format!("{what}: {t} values are not read")),
        None => Ok(()),
    }
}

/// Sample 0 of the sub-property `name` of the compound `parent` (`None`: absent or empty).
fn sub_sample(
    parent: &PropertyReader,
    name: &str,
    reader: &mut BytesReader,
    archive: &Archive,
) -> std::result::Result<Option<PodArray>, String> {
    let PropertyReader::Compound(c) = parent else {
        return Err("the schema is not a compound property".into());
    };
    match c
        .load_sub_property_by_name(name, reader, archive)
        .map_err(ogawa(name))?
    {
        Some(p) => sample(&p, reader),
        None => Ok(None),
    }
}

/// The local matrix of an Xform object (sample 0).
fn xform(
    object: &ObjectReader,
    reader: &mut BytesReader,
    archive: &Archive,
) -> std::result::Result<DMat4, String> {
    let schema = schema_property(object, reader, archive)?;
    let ops = match sub_sample(&schema, ".ops", reader, archive)? {
        Some(PodArray::U8(ops)) => ops,
        None => return Ok(DMat4::IDENTITY),
        Some(_) => return Err("transform operations (.ops) are not bytes".into()),
    };
    let vals: Vec<f64> = match sub_sample(&schema, ".vals", reader, archive)? {
        Some(PodArray::F64(v)) => v,
        Some(PodArray::F32(v)) => v.into_iter().map(f64::from).collect(),
        None => Vec::new(),
        Some(_) => return Err("transform values (.vals) are not floats".into()),
    };
    compose_ops(&ops, &vals)
}

/// Alembic's transform operations (`XformOp`: the operation type in the high nibble of each
/// byte) and their channels composed into one matrix; the first operation is the outermost
/// (`XformSample::getMatrix` multiplies each new operation on the point's side).
pub fn compose_ops(ops: &[u8], vals: &[f64]) -> std::result::Result<DMat4, String> {
    let needed: usize = ops.iter().map(|op| op_channels(*op)).sum();
    if vals.len() != needed {
        return Err(format!(
            "{} transform operations need {needed} values, the file has {}",
            ops.len(),
            vals.len()
        ));
    }
    if vals.iter().any(|v| !v.is_finite()) {
        return Err("a transform value is not finite".into());
    }
    let mut m = DMat4::IDENTITY;
    let mut at = 0;
    for &op in ops {
        let n = op_channels(op);
        let c = &vals[at..at + n];
        at += n;
        let deg = |a: f64| a.to_radians();
        let local = match op >> 4 {
            0 => DMat4::from_scale(DVec3::new(c[0], c[1], c[2])),
            1 => DMat4::from_translation(DVec3::new(c[0], c[1], c[2])),
            2 => {
                let axis = DVec3::new(c[0], c[1], c[2]);
                match axis.try_normalize() {
                    Some(a) => DMat4::from_axis_angle(a, deg(c[3])),
                    None => DMat4::IDENTITY,
                }
            }
            // Imath stores row vectors: its rows are our columns.
            3 => DMat4::from_cols_array(c.try_into().expect("16 channels")),
            4 => DMat4::from_rotation_x(deg(c[0])),
            5 => DMat4::from_rotation_y(deg(c[0])),
            _ => DMat4::from_rotation_z(deg(c[0])),
        };
        m *= local;
    }
    Ok(m)
}

/// Channels of one transform operation (unknown types are read as Z rotations: 1 channel).
fn op_channels(op: u8) -> usize {
    match op >> 4 {
        0 | 1 => 3,
        2 => 4,
        3 => 16,
        _ => 1,
    }
}

/// The curves of a curve object (sample 0), placed by `world`.
fn curves(
    object: &ObjectReader,
    reader: &mut BytesReader,
    archive: &Archive,
    world: DMat4,
) -> std::result::Result<CurveObject, String> {
    let schema = schema_property(object, reader, archive)?;
    // Sizes first (ogawa-rs reads without checking them); then ogawa-rs reads.
    let positions = sub_sample(&schema, "P", reader, archive)?;
    let counts = sub_sample(&schema, "nVertices", reader, archive)?;
    let width_sample = sub_sample(&schema, "width", reader, archive)?;
    sub_sample(&schema, "curveBasisAndType", reader, archive)?;
    let curves = CurvesSchema::new_from_object_reader(object, reader, archive)
        .map_err(ogawa("curves schema"))?;
    let (kind, periodicity, basis) = curves
        .load_curve_type_sample(0, reader)
        .map_err(ogawa("curve type"))?;
    if periodicity != CurvePeriodicity::NonPeriodic {
        return Err("periodic (closed) curves are not hair".into());
    }
    let step = match (kind, basis) {
        (CurveType::Linear, _) => 1,
        // Catmull-Rom passes through its points; Bezier through every third.
        (CurveType::Cubic, BasisType::Catmullrom) => 1,
        (CurveType::Cubic, BasisType::Bezier) => 3,
        (k, b) => {
            return Err(format!(
                "{k:?} curves with {b:?} basis are not read (export linear, Catmull-Rom or Bezier curves)"
            ));
        }
    };
    let points = match positions {
        Some(_) => curves
            .load_positions_sample(0, reader)
            .map_err(ogawa("P"))?,
        None => Vec::new(),
    };
    let counts = match counts {
        Some(_) => curves
            .load_n_vertices_sample(0, reader)
            .map_err(ogawa("nVertices"))?,
        None => Vec::new(),
    };
    let widths = match width_sample {
        Some(_) => curves
            .load_widths_sample(0, reader)
            .map_err(ogawa("width"))?,
        None => None,
    };
    place_curves(
        &object.header.full_name,
        (&points, &counts, widths.as_deref()),
        world,
        step,
    )
}

/// Split `points` into curves of `counts` points, keep every `step`-th (Bezier), move them by
/// `world`, and spread `widths` (one per point, per curve or for all) to the points kept,
/// scaled by `world`.
pub fn place_curves(
    name: &str,
    (points, counts, widths): (&[[f32; 3]], &[i32], Option<&[f32]>),
    world: DMat4,
    step: usize,
) -> std::result::Result<CurveObject, String> {
    let total: i64 = counts.iter().map(|&c| c as i64).sum();
    if counts.iter().any(|&c| c < 0) || total != points.len() as i64 {
        return Err(format!(
            "{} curves count {total} points (negative counts?), the positions hold {}",
            counts.len(),
            points.len()
        ));
    }
    let n = points.len();
    let width_of: Box<dyn Fn(usize, usize) -> f32> = match widths {
        None => Box::new(|_, _| 0.0),
        Some(w) if w.len() == n => {
            let w = w.to_vec();
            Box::new(move |_, p| w[p])
        }
        Some(w) if w.len() == counts.len() => {
            let w = w.to_vec();
            Box::new(move |c, _| w[c])
        }
        Some(w) if w.len() == 1 => {
            let w = w[0];
            Box::new(move |_, _| w)
        }
        Some(w) => {
            return Err(format!(
                "{} widths for {} curves of {n} points",
                w.len(),
                counts.len()
            ));
        }
    };
    let scale = world.determinant().abs().cbrt();
    let mut strands = Vec::with_capacity(counts.len());
    let mut strand_widths = Vec::with_capacity(counts.len());
    let mut at = 0usize;
    for (c, &count) in counts.iter().enumerate() {
        let count = count as usize;
        let mut strand = Vec::with_capacity(count.div_ceil(step));
        let mut w = Vec::with_capacity(count.div_ceil(step));
        for p in (at..at + count).step_by(step) {
            let q = world.transform_point3(DVec3::from(points[p].map(f64::from)));
            let width = width_of(c, p) as f64 * scale;
            if !q.is_finite() || !width.is_finite() || width < 0.0 {
                return Err(format!(
                    "curve {c} point {}: position {:?} or width {width} is not finite",
                    p - at,
                    points[p]
                ));
            }
            strand.push(q.as_vec3());
            w.push(width as f32);
        }
        at += count;
        strands.push(strand);
        strand_widths.push(w);
    }
    Ok(CurveObject {
        name: name.to_string(),
        strands,
        widths: widths.map(|_| strand_widths),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn operations_compose_outermost_first() {
        // translate (1,2,3), then rotate 90 degrees about Z, then scale 2: a point at x = 1
        // scales to 2, turns to y = 2, moves to (1, 4, 3).
        let ops = [0x10, 0x60, 0x00];
        let vals = [1.0, 2.0, 3.0, 90.0, 2.0, 2.0, 2.0];
        let m = compose_ops(&ops, &vals).unwrap();
        let p = m.transform_point3(DVec3::X);
        assert!((p - DVec3::new(1.0, 4.0, 3.0)).length() < 1e-12, "{p}");
        // The same as one matrix operation (Imath rows: translation in the last row).
        let mut rows = [0.0; 16];
        rows.copy_from_slice(&m.to_cols_array());
        let again = compose_ops(&[0x30], &rows).unwrap();
        assert!(again.abs_diff_eq(m, 1e-12));
        // Axis-angle: 90 degrees about X takes Y to Z.
        let r = compose_ops(&[0x20], &[1.0, 0.0, 0.0, 90.0]).unwrap();
        assert!((r.transform_vector3(DVec3::Y) - DVec3::Z).length() < 1e-12);
        assert!(compose_ops(&[0x10], &[1.0, 2.0]).is_err());
        assert!(compose_ops(&[0x10], &[1.0, f64::NAN, 0.0]).is_err());
    }

    #[test]
    fn curves_split_place_and_carry_widths() {
        let pts = [
            [0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [1.0, 2.0, 0.0],
        ];
        let world = DMat4::from_scale(DVec3::splat(2.0));
        let c = place_curves("o", (&pts, &[2, 3], Some(&[0.5, 0.25])), world, 1).unwrap();
        assert_eq!(c.strands.len(), 2);
        assert_eq!(c.strands[1][2], Vec3::new(2.0, 4.0, 0.0));
        // Per-curve widths spread to points, scaled with the transform.
        assert_eq!(c.widths.as_ref().unwrap()[1], vec![0.5; 3]);
        assert!(place_curves("o", (&pts, &[2, 2], None), world, 1).is_err());
        assert!(place_curves("o", (&pts, &[2, 3], Some(&[1.0; 4])), world, 1).is_err());
        assert!(place_curves("o", (&pts, &[-1, 6], None), world, 1).is_err());
        // Bezier: every third point is on the curve.
        let bez = place_curves("o", (&pts[..4], &[4], None), DMat4::IDENTITY, 3).unwrap();
        assert_eq!(bez.strands[0], vec![Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0)]);
    }

    #[test]
    fn refuses_other_files_in_one_line() {
        let hdf5 = [HDF5_MAGIC, &[0u8; 64]].concat();
        for (bytes, says) in [
            (&hdf5[..], "HDF5"),
            (&b"not alembic"[..], "no Ogawa header"),
            (&b"Ogawa\xff\x01\x00"[..], "malformed"),
        ] {
            let e = read_curves("x.abc", bytes).unwrap_err().to_string();
            assert!(
                e.starts_with("x.abc: ") && e.contains(says) && !e.contains('\n'),
                "{e}"
            );
        }
    }
}
