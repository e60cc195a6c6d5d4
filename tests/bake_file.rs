//! Bake round trip and rejection of corrupt, truncated or foreign baked files.

use std::path::Path;

use hairmesh::bake::baked_file;
use hairmesh::model::obj_io::load_hair_mesh_obj;
use hairmesh::{BakeOptions, HairStyle, bake};

fn baked(name: &str) -> hairmesh::BakedHairMesh {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("hairmeshes")
        .join(name);
    let mesh = load_hair_mesh_obj(&path).unwrap();
    let style = HairStyle::load(&path.with_extension("toml")).unwrap();
    bake(&mesh, &style, BakeOptions::default(), |_, _| {}).unwrap()
}

#[test]
fn round_trip_is_exact() {
    for name in ["small_patch.obj", "triangle_tuft.obj", "head_long.obj"] {
        let b = baked(name);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.hmb");
        baked_file::save(&b, &path).unwrap();
        let back = baked_file::load(&path).unwrap();
        assert_eq!(back, b, "{name}");
        // No temporary file left behind by the atomic write.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}

#[test]
fn small_mesh_fits_paper_budget() {
    let b = baked("small_patch.obj");
    assert_eq!(
        b.info.layers as usize * b.info.slice_texels(),
        180,
        "36 texels x 5 layers"
    );
    assert!(
        b.texture_bytes() <= 13 * 1024,
        "{} bytes",
        b.texture_bytes()
    );
}

#[test]
fn rejects_damaged_files() {
    let bytes = baked_file::to_bytes(&baked("small_patch.obj"));
    let err = |b: &[u8]| baked_file::from_bytes("x.hmb", b).unwrap_err().to_string();

    let mut flipped = bytes.clone();
    let n = flipped.len();
    flipped[n / 2] ^= 0x40;
    assert!(
        err(&flipped).contains("checksum mismatch"),
        "{}",
        err(&flipped)
    );

    assert!(err(&bytes[..bytes.len() - 7]).contains("truncated"));
    assert!(err(&bytes[..10]).contains("truncated"));

    let mut magic = bytes.clone();
    magic[0] = b'X';
    assert!(err(&magic).contains("bad magic"));

    let mut version = bytes.clone();
    version[8] = 99;
    assert!(err(&version).contains("version 99"));

    // A consistent checksum over an absurd header must still be rejected before allocating.
    let mut absurd = bytes.clone();
    absurd[24 + 48..24 + 52].copy_from_slice(&100_000u32.to_le_bytes()); // root width
    let crc = crc32fast::hash(&absurd[24..]);
    absurd[12..16].copy_from_slice(&crc.to_le_bytes());
    assert!(
        err(&absurd).contains("inconsistent header"),
        "{}",
        err(&absurd)
    );
    // Consistent files (checksums right) with one bad bundle each: its cell outside the root
    // slice across or down, a NaN size or density. (Each alone must do: two of the checks
    // joined by `&&` instead of `||` survived the 2026-12-06 mutation sample.)
    let good = baked("small_patch.obj");
    let bad_bundle = |change: &dyn Fn(&mut hairmesh::BundleDesc)| {
        let mut b = good.clone();
        change(&mut b.bundles[0]);
        b
    };
    let [w, h] = good.info.root_size;
    for bad in [
        bad_bundle(&|b| b.origin[0] = w),
        bad_bundle(&|b| b.origin[1] = h),
        // A cell is 2x2 texels: one at the last column or row has none beyond it (the
        // fourth mutation sample's survivor took `x * 1` for `x + 1`).
        bad_bundle(&|b| b.origin[0] = w - 1),
        bad_bundle(&|b| b.origin[1] = h - 1),
        bad_bundle(&|b| b.rest_size = f32::NAN),
        bad_bundle(&|b| b.density = f32::NAN),
    ] {
        let e = err(&baked_file::to_bytes(&bad));
        assert!(e.contains("bundle 0:"), "{e}");
    }
    for e in [err(&flipped), err(&absurd)] {
        assert!(
            e.starts_with("x.hmb: ") && !e.contains('\n'),
            "one line naming the file: {e}"
        );
    }
}

/// The bake's memory estimate counts each of the five textures at exactly the bytes the bake
/// makes (the parts a budget is checked against before the bake allocates them).
#[test]
fn memory_estimate_counts_the_textures_exactly() {
    for name in ["small_patch.obj", "triangle_tuft.obj", "head_long.obj"] {
        let b = baked(name);
        let slice = b.info.slice_texels() as u64;
        let e = hairmesh::bake::memory_estimate(1, b.info.layers as u64, slice);
        let bytes = |n: usize, each: usize| (n * each) as u64;
        assert_eq!(
            e.part("hair mesh texture"),
            bytes(b.position.len(), 8),
            "{name}"
        );
        assert_eq!(
            e.part("uv and w textures"),
            bytes(b.uv.len(), 4) + bytes(b.w.len(), 2),
            "{name}"
        );
        assert_eq!(
            e.part("u and v textures"),
            bytes(b.u_dir.len(), 8) + bytes(b.v_dir.len(), 8),
            "{name}"
        );
    }
}
