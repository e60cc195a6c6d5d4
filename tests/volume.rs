//! Strand density volumes (`reference::volume`, the CPU twin of the GPU build): the strand
//! length splatted equals the length of the segments generated, nearly all of it lands inside
//! the volume's box, and the density is where the hair is and nowhere else.

mod common;

use glam::{UVec3, Vec3};
use hairmesh::CpuGenerator;
use hairmesh::reference::generate::strands_in_bundle;
use hairmesh::reference::volume::{VolumeSampling, density_volume, volume_box};

#[test]
fn density_volume_keeps_the_strand_length_and_sits_on_the_hair() {
    for name in ["head_long.obj", "sphere_fur.obj", "sintel.obj"] {
        let (baked, style) = common::sample(name);
        let generator = CpuGenerator::new(&baked, style);
        let sampling = VolumeSampling {
            dims: UVec3::new(24, 20, 16),
            ..Default::default()
        };
        let volume = density_volume(&generator, &baked.info, &sampling);
        // The length the sampled strands stand for, summed directly.
        let segments = 1u32 << sampling.segments_log2;
        let verts = segments as usize + 1;
        let (mut p, mut t, mut w) = (
            vec![Vec3::ZERO; verts],
            vec![Vec3::ZERO; verts],
            vec![0.0; verts],
        );
        let mut expected = 0.0f64;
        let mut roots = Vec::new();
        for (bundle, b) in generator.tex.bundles.iter().enumerate() {
            let strands = strands_in_bundle(b, &style, sampling.strands_per_bundle);
            let sampled = strands.min(sampling.strands_sampled);
            for strand in 0..sampled {
                generator.strand(bundle as u32, strand, segments, &mut p, &mut t, &mut w);
                let length: f32 = p.windows(2).map(|s| (s[1] - s[0]).length()).sum();
                expected += (length * strands as f32 / sampled as f32) as f64;
                roots.push(p[verts / 2]);
            }
        }
        let inside = volume.total_length() as f64;
        let total = inside + volume.outside as f64;
        assert!(
            (total - expected).abs() <= 1e-3 * expected,
            "{name}: splatted {total} m of strand, generated {expected}"
        );
        assert!(
            volume.outside as f64 <= 0.01 * expected,
            "{name}: {} of {expected} m outside the box",
            volume.outside
        );
        // Every strand's middle is in hair; the box's corners are not.
        let empty = roots.iter().filter(|r| volume.sample(**r) <= 0.0).count();
        assert_eq!(empty, 0, "{name}: {empty} strand middles in empty cells");
        let (lo, hi) = volume_box(&baked.info);
        for corner in 0..8 {
            let c = Vec3::select(
                glam::BVec3::new(corner & 1 != 0, corner & 2 != 0, corner & 4 != 0),
                hi,
                lo,
            );
            assert_eq!(volume.sample(c), 0.0, "{name}: hair at the box corner {c}");
        }
    }
}
