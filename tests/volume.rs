//! Strand density volumes (`reference::volume`, the CPU twin of the GPU build): the strand
//! length splatted equals the length of the segments generated, nearly all of it lands inside
//! the volume's box, and the density is where the hair is and nowhere else.

mod common;

use glam::{UVec3, Vec3};
use hairmesh::CpuGenerator;
use hairmesh::reference::generate::strands_in_bundle;
use hairmesh::reference::volume::{VolumeSampling, density_volume, occupancy_of, volume_box};
use hairmesh::shade::volume::march_masked;

#[test]
fn density_volume_keeps_the_strand_length_and_sits_on_the_hair() {
    for name in ["head_long.obj", "sphere_fur.obj", "sintel.obj"] {
        let (baked, style) = common::sample(name);
        let generator = CpuGenerator::new(&baked, style);
        let sampling = VolumeSampling {
            dims: UVec3::new(24, 20, 16),
            ..Default::default()
        };
        let n = 64;
        let volume = density_volume(&generator, &baked.info, n, &sampling);
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
            let strands = strands_in_bundle(b, &style, n);
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

/// Empty-space skipping (`DensityVolume::occupancy`, `shade::volume::march_masked`, the twin
/// of `volume_hair.frag`'s march): over 4,000 rays through head_long's and sphere_fur's
/// volumes, in every direction and from every side, the march that skips empty bricks gives
/// exactly the march that skips nothing (the same samples; skipped ones are exactly 0), and
/// the mask does skip: a large share of each volume's bricks is empty.
#[test]
fn skipping_empty_bricks_changes_no_march() {
    for name in ["head_long.obj", "sphere_fur.obj"] {
        let (baked, style) = common::sample(name);
        let generator = CpuGenerator::new(&baked, style);
        let sampling = VolumeSampling {
            dims: UVec3::new(24, 20, 16),
            ..Default::default()
        };
        let volume = density_volume(&generator, &baked.info, 64, &sampling);
        let mask = volume.occupancy();
        let set: u32 = mask.iter().map(|w| w.count_ones()).sum();
        let b = hairmesh::reference::volume::bricks(volume.dims);
        let total = b.x * b.y * b.z;
        eprintln!("{name}: {set} of {total} bricks hold strands");
        // Measured: head_long 753 of 960 marked, sphere_fur 741 (24 x 20 x 16 cells).
        assert!(
            set < total && set > 0,
            "{name}: {set} of {total} bricks marked"
        );
        let (lo, hi) = volume_box(&baked.info);
        let (centre, reach) = ((lo + hi) * 0.5, (hi - lo).length());
        let everything = vec![u32::MAX; mask.len()];
        let mut rng = hairmesh::rng::Pcg32::new(7);
        let (mut differ, mut skipped) = (0, 0);
        for _ in 0..4000 {
            let on_sphere = |rng: &mut hairmesh::rng::Pcg32| {
                let v = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0;
                v.normalize_or(Vec3::Y)
            };
            let from = centre + on_sphere(&mut rng) * reach * 0.6;
            // Aimed at a random point of the box: rays through hair, past it and grazing it.
            let target = lo + (hi - lo) * Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
            let dir = (target - from).normalize();
            let strands = (0.002, 1.0);
            let all = march_masked(&volume, &everything, from, dir, reach * 1.2, strands);
            let fast = march_masked(&volume, &mask, from, dir, reach * 1.2, strands);
            differ += usize::from(all != fast);
            skipped += usize::from(all.transmittance == 1.0);
        }
        assert_eq!(
            differ, 0,
            "{name}: {differ} of 4000 marches changed by the skip"
        );
        assert!(
            skipped > 0 && skipped < 4000,
            "{name}: {skipped} rays missed all hair"
        );
        // The mask from cell contents alone (what the GPU's dispatch computes) is the same.
        assert_eq!(occupancy_of(volume.dims, |i| volume.density[i] > 0.0), mask);
    }
}

/// The GPU build (`glsl/density_volume.comp`) against its CPU twin: the same strand length in
/// total (within 0.1%), and cell by cell, length and flow, within 0.5% of the hair's length
/// (fixed point and float rounding; measured 0.018% and 0.036% for head_long, 0.072% and
/// 0.155% for sphere_fur). Validation on.
#[test]
fn gpu_density_volume_equals_the_cpu_twin() {
    let ctx = common::context();
    let mut r = common::renderer(&ctx, 64);
    let mut ids = Vec::new();
    let mut twins = Vec::new();
    let sampling = VolumeSampling {
        dims: UVec3::new(24, 20, 16),
        ..Default::default()
    };
    for name in ["head_long.obj", "sphere_fur.obj"] {
        let (baked, style) = common::sample(name);
        // 64 strands per bundle, 16 of them sampled: each stands for 4.
        let n = 64;
        let id = common::upload(&mut r, &baked, &style, n, 3);
        r.request_density_volume(id, sampling).unwrap();
        ids.push(id);
        let generator = CpuGenerator::new(&baked, style);
        twins.push(density_volume(&generator, &baked.info, n, &sampling));
    }
    let (baked, _) = common::sample("head_long.obj");
    common::render(&mut r, &common::framing(&baked), &common::compute_full());
    for (id, cpu) in ids.into_iter().zip(&twins) {
        let gpu = r.read_density_volume(id).unwrap();
        assert_eq!(
            (gpu.origin, gpu.cell, gpu.dims),
            (cpu.origin, cpu.cell, cpu.dims)
        );
        let (g, c) = (
            gpu.total_length() + gpu.outside,
            cpu.total_length() + cpu.outside,
        );
        // Measured 3.8e-5 (head_long) and 2.4e-4 relative (float atomics summing in another
        // order); a missed segment of a strand is far above 1e-3.
        assert!((g - c).abs() <= 1e-3 * c, "GPU {g} m of strand, CPU {c}");
        let volume = cpu.cell.x * cpu.cell.y * cpu.cell.z;
        let off: f32 = gpu
            .density
            .iter()
            .zip(&cpu.density)
            .map(|(a, b)| (a - b).abs() * volume)
            .sum();
        let flow_off: f32 = gpu
            .flow
            .iter()
            .zip(&cpu.flow)
            .map(|(a, b)| (*a - *b).length() * volume)
            .sum();
        eprintln!("GPU {g} m, CPU {c} m of strand; cells differ by {off} m, flows by {flow_off} m");
        // Measured 1.8e-4 and 7.2e-4 of the total (segments on cell borders); bound ~7x.
        assert!(off <= 0.005 * c, "cells differ by {off} m of strand in {c}");
        assert!(
            flow_off <= 0.005 * c,
            "flows differ by {flow_off} m of strand in {c}"
        );
        // The GPU's occupancy mask (the density build's second dispatch) is the CPU twin's of
        // the GPU's own cells: bit for bit.
        let mask = r.read_density_occupancy(id).unwrap();
        assert_eq!(mask, gpu.occupancy(), "the GPU's occupancy mask");
        // The flow is the strands' direction: never longer than the length it sums.
        let longer = cpu
            .flow
            .iter()
            .zip(&cpu.density)
            .filter(|(f, d)| f.length() > **d * 1.0001 + 1e-6)
            .count();
        assert_eq!(longer, 0, "{longer} cells flow more than their length");
    }
    common::assert_no_validation_errors(&ctx);
}

/// Absurd samplings are refused with an error that says what is wrong, before anything is
/// allocated; so is a character that does not exist.
#[test]
fn bad_density_volume_requests_are_errors() {
    let ctx = common::context();
    let mut r = common::renderer(&ctx, 32);
    let (baked, style) = common::sample("small_patch.obj");
    let id = common::upload(&mut r, &baked, &style, 4, 2);
    let bad = [
        (UVec3::new(0, 8, 8), 16, 4, "cells"),
        (UVec3::splat(1024), 16, 4, "cells"),
        (UVec3::splat(8), 0, 4, "strands"),
        (UVec3::splat(8), 16, 20, "segments"),
    ];
    for (dims, strands_sampled, segments_log2, word) in bad {
        let sampling = VolumeSampling {
            dims,
            strands_sampled,
            segments_log2,
        };
        let e = r
            .request_density_volume(id, sampling)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(word),
            "{dims} {strands_sampled} {segments_log2}: {e}"
        );
    }
    assert!(r.read_density_volume(id).is_err(), "nothing was requested");
    r.remove_character(id).unwrap();
    assert!(
        r.request_density_volume(id, VolumeSampling::default())
            .is_err()
    );
    common::assert_no_validation_errors(&ctx);
}
