//! The baked hair mesh file (`.hmb`): versioned, checksummed, written atomically.
//!
//! Layout (little-endian):
//! ```text
//! offset  size  field
//! 0       8     magic "HAIRMESH"
//! 8       4     format version (u32, currently 2; version 1 had no roughness / cuticle tilt)
//! 12      4     CRC-32 (IEEE) of the payload
//! 16      8     payload length in bytes (u64)
//! 24      ...   payload:
//!               MeshInfo   (64 bytes, see src/render/core/shared.rs)
//!               HairStyle  (96 bytes)
//!               BundleDesc x bundle_count (32 bytes each)
//!               hair mesh texture  W*H*(4(L-1)+1) x 8 bytes  (R16G16B16A16_UNORM)
//!               uv-texture         W*H x 4 bytes             (R16G16_UNORM)
//!               w-texture          W*H*L x 2 bytes           (R16_UNORM)
//!               u-texture          W*H*L x 8 bytes           (R16G16B16A16_SNORM)
//!               v-texture          W*H*L x 8 bytes           (R16G16B16A16_SNORM)
//! ```
//! Textures are stored x fastest, then y, then slice. Readers check magic, version, length,
//! checksum and that every size follows from `MeshInfo` before touching the data.

use std::path::Path;

use bytemuck::Pod;

use crate::bake::{BakedHairMesh, BundleDesc, MAX_TEXTURE_SIDE, MeshInfo};
use crate::error::{HairError, Result};
use crate::model::style::HairStyle;

/// File magic.
pub const MAGIC: &[u8; 8] = b"HAIRMESH";
/// Current format version.
pub const VERSION: u32 = 2;
const HEADER: usize = 24;

/// Serialise a bake to bytes.
pub fn to_bytes(baked: &BakedHairMesh) -> Vec<u8> {
    // One buffer of the exact size (the bake's memory estimate counts one copy of the textures).
    let textures = baked.textures();
    let payload_len = size_of::<MeshInfo>()
        + size_of::<HairStyle>()
        + std::mem::size_of_val(baked.bundles.as_slice())
        + textures.iter().map(|t| t.bytes.len()).sum::<usize>();
    let mut out = Vec::with_capacity(HEADER + payload_len);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&0u32.to_le_bytes());
    out.extend_from_slice(&(payload_len as u64).to_le_bytes());
    out.extend_from_slice(bytemuck::bytes_of(&baked.info));
    out.extend_from_slice(bytemuck::bytes_of(&baked.style));
    out.extend_from_slice(bytemuck::cast_slice(&baked.bundles));
    for t in textures {
        out.extend_from_slice(t.bytes);
    }
    debug_assert_eq!(out.len(), HEADER + payload_len);
    let crc = crc32fast::hash(&out[HEADER..]);
    out[12..16].copy_from_slice(&crc.to_le_bytes());
    out
}

/// Write a bake to `path` by the output policy of [`crate::fsutil::OutputPath`].
pub fn save(baked: &BakedHairMesh, path: &Path) -> Result<()> {
    crate::fsutil::OutputPath::check(path, &[])?.write(&to_bytes(baked))
}

/// Read a bake from `path`.
pub fn load(path: &Path) -> Result<BakedHairMesh> {
    let bytes = crate::fsutil::read_input(path, crate::fsutil::MAX_MESH_FILE_BYTES)?;
    from_bytes(&path.display().to_string(), &bytes)
}

struct Reader<'a> {
    name: &'a str,
    data: &'a [u8],
    pos: usize,
}

impl Reader<'_> {
    fn take(&mut self, n: usize, what: &str) -> Result<&[u8]> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.data.len());
        let Some(end) = end else {
            return Err(HairError::invalid(
                self.name,
                format!(
                    "truncated: {what} needs {n} bytes at payload offset {}",
                    self.pos
                ),
            ));
        };
        let s = &self.data[self.pos..end];
        self.pos = end;
        Ok(s)
    }

    fn vec<T: Pod>(&mut self, count: usize, what: &str) -> Result<Vec<T>> {
        let n = count
            .checked_mul(std::mem::size_of::<T>())
            .ok_or_else(|| HairError::invalid(self.name, format!("{what}: absurd size")))?;
        Ok(bytemuck::pod_collect_to_vec(self.take(n, what)?))
    }
}

/// The payload of a `.hmb` file after its header's magic, version, length and checksum are
/// checked.
fn checked_payload<'b>(name: &str, bytes: &'b [u8]) -> Result<&'b [u8]> {
    let bad = |what: String| HairError::invalid(name, what);
    if bytes.len() < HEADER {
        return Err(bad(format!(
            "truncated: {} bytes, header needs {HEADER}",
            bytes.len()
        )));
    }
    if &bytes[..8] != MAGIC {
        return Err(bad("not a baked hair mesh (bad magic)".into()));
    }
    let version = u32::from_le_bytes(bytes[8..12].try_into().unwrap());
    if version != VERSION {
        return Err(bad(format!(
            "unsupported format version {version} (this build reads {VERSION}; re-bake the hair mesh)"
        )));
    }
    let crc = u32::from_le_bytes(bytes[12..16].try_into().unwrap());
    let len = u64::from_le_bytes(bytes[16..24].try_into().unwrap());
    let payload = &bytes[HEADER..];
    if payload.len() as u64 != len {
        return Err(bad(format!(
            "truncated or padded: payload is {} bytes, header says {len}",
            payload.len()
        )));
    }
    if crc32fast::hash(payload) != crc {
        return Err(bad("checksum mismatch: the file is corrupt".into()));
    }
    Ok(payload)
}

/// Parse a bake from bytes; `name` is used in errors.
pub fn from_bytes(name: &str, bytes: &[u8]) -> Result<BakedHairMesh> {
    let bad = |what: String| HairError::invalid(name, what);
    let payload = checked_payload(name, bytes)?;
    let mut r = Reader {
        name,
        data: payload,
        pos: 0,
    };
    let info: MeshInfo = bytemuck::pod_read_unaligned(r.take(size_of::<MeshInfo>(), "MeshInfo")?);
    let style: HairStyle =
        bytemuck::pod_read_unaligned(r.take(size_of::<HairStyle>(), "HairStyle")?);
    style.validate(name)?;
    let [w, h] = info.root_size;
    if info.layers < 2
        || info.layers > MAX_TEXTURE_SIDE / 4
        || w == 0
        || h == 0
        || w > MAX_TEXTURE_SIDE
        || h > MAX_TEXTURE_SIDE
        || info.bundle_count == 0
        || info.bundle_count as usize > w as usize * h as usize
    {
        return Err(bad(format!(
            "inconsistent header: root {w}x{h}, {} layers, {} bundles",
            info.layers, info.bundle_count
        )));
    }
    if !info
        .pos_origin
        .iter()
        .chain(&info.pos_extent)
        .chain(&info.uv_origin_extent)
        .all(|x| x.is_finite())
    {
        return Err(bad("non-finite decode constants".into()));
    }
    let slice = info.slice_texels();
    let layers = info.layers as usize;
    let bundles: Vec<BundleDesc> = r.vec(info.bundle_count as usize, "bundle table")?;
    for (i, b) in bundles.iter().enumerate() {
        if b.origin[0] + 1 >= w
            || b.origin[1] + 1 >= h
            || !b.rest_size.is_finite()
            || !b.density.is_finite()
        {
            return Err(bad(format!(
                "bundle {i}: cell {:?} outside the {w}x{h} root slice or bad size",
                b.origin
            )));
        }
    }
    let baked = BakedHairMesh {
        info,
        style,
        bundles,
        position: r.vec(slice * info.position_depth() as usize, "hair mesh texture")?,
        uv: r.vec(slice, "uv-texture")?,
        w: r.vec(slice * layers, "w-texture")?,
        u_dir: r.vec(slice * layers, "u-texture")?,
        v_dir: r.vec(slice * layers, "v-texture")?,
    };
    if r.pos != payload.len() {
        return Err(bad(format!(
            "{} trailing bytes after the v-texture",
            payload.len() - r.pos
        )));
    }
    Ok(baked)
}
