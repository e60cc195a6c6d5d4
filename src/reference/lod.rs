//! Level-of-detail maths of paper 003, section 3.6 (eq. 7-12), as plain functions shared by the
//! CPU reference and mirrored in GLSL.

use glam::Vec3;

/// Unit of the bundle LoD pass's demand counters (`FrameStats::soft_demand` and the
/// others): segments or vertex slots, so a crowd's sum stays inside 32 bits.
pub const LOD_DEMAND_UNIT: u32 = 64;
/// The least LoD pressure: a view that cannot fit even one strand a bundle keeps one strand a
/// bundle (and reports what its buffers drop).
pub const LOD_LEAST_PRESSURE: f32 = 1e-6;

/// Eq. 7, perspective: `L = min(1, h R alpha / (d tan theta))` for bundle size `h`, vertical
/// resolution `R` in pixels, distance `d`, vertical field of view `theta` (radians).
pub fn detail_level(h: f32, resolution: f32, distance: f32, fov_y: f32, alpha: f32) -> f32 {
    (h * resolution * alpha / eq7_denominator(distance, fov_y)).clamp(0.0, 1.0)
}

/// Eq. 7's `d tan theta` (GLSL: `bundle_lod.glsl` `eq7_denominator`).
fn eq7_denominator(distance: f32, fov_y: f32) -> f32 {
    distance.max(1e-6) * fov_y.tan()
}

/// Eq. 7's measure of a bundle of size `h` on screen, `h R / (d tan theta)`, before alpha and
/// the clamp: about its size in pixels (GLSL: `bundle_lod.glsl` `strand_level`).
pub fn bundle_extent(h: f32, resolution: f32, distance: f32, fov_y: f32) -> f32 {
    h * resolution / eq7_denominator(distance, fov_y)
}

/// The crowd's area term on eq. 7's strand level: 1 for a bundle whose extent `x`
/// ([`bundle_extent`]) is at least `area_below` (0: off, the paper's eq. 7), below it `x /
/// area_below`. With it, a small bundle's strand count falls with its area on screen rather
/// than its width, and eq. 8's thickness term (`1 / L`) widens the strands left so the bundle
/// keeps its coverage: far characters cost per pixel of hair, not per strand they would show
/// up close.
pub fn area_factor(x: f32, area_below: f32) -> f32 {
    match area_below > 0.0 {
        true => (x / area_below).clamp(0.0, 1.0),
        false => 1.0,
    }
}

/// The pixel cap on a bundle's strand level: at most `per_pixel` strands per square pixel of
/// its extent `x` ([`bundle_extent`]) for a bundle of `n` strands, `per_pixel x^2 / n` (0: no
/// cap, infinity). A bundle's strands then follow the pixels it covers, not its count at full
/// detail: twice the density draws no more strands at crowd distance, and eq. 8's thickness
/// `min(1 / L, N)` widens the strands drawn into the coverage of those it stands for (seed 000:
/// one thick strand for a cluster of fine ones once the fine ones are sub-pixel).
pub fn pixel_cap_level(x: f32, per_pixel: f32, n: u32) -> f32 {
    match per_pixel > 0.0 {
        true => per_pixel * x * x / n.max(1) as f32,
        false => f32::INFINITY,
    }
}

/// Eq. 7, orthographic (shadow maps): `d tan theta` replaced by the view height in world units.
pub fn detail_level_ortho(h: f32, resolution: f32, view_height: f32, alpha: f32) -> f32 {
    (h * resolution * alpha / view_height.max(1e-6)).clamp(0.0, 1.0)
}

/// Eq. 8: strands kept in a bundle of `n` strands at level `l` with random increment
/// `delta` in `[0, 1)`. At least one strand for `l > 0`; never more than `n` (eq. 8 alone
/// could give `n + 1` at `l = 1`).
pub fn strands_at_level(l: f32, n: u32, delta: f32) -> u32 {
    if l <= 0.0 || n == 0 {
        return 0;
    }
    ((l * (n as f32 + delta)).ceil() as u32).clamp(1, n)
}

/// Stable strand LoD: the width share of a bundle's newest strand, eq. 8's fractional part
/// (`L (N + delta) - (strands - 1)`), so strands fade in one at a time as a bundle nears rather
/// than pop; 1 with a single strand (the far cluster keeps its width) and at full detail.
/// Quantised to 16 bits as the GPU carries it (`lod_strand_fade` in `bindings.glsl`).
pub fn newest_strand_fade(l: f32, n: u32, delta: f32) -> f32 {
    let strands = strands_at_level(l, n, delta);
    let wanted = l * (n as f32 + delta);
    let fade = match strands > 1 && wanted < strands as f32 {
        true => wanted - (strands - 1) as f32,
        false => 1.0,
    };
    (fade.clamp(0.0, 1.0) * 65535.0).round() / 65535.0
}

/// Thickness compensation of section 3.6.1: widths grow by `min(1 / L, N)`.
pub fn thickness_scale(l: f32, n: u32) -> f32 {
    (1.0 / l.max(1e-6)).min(n.max(1) as f32)
}

/// The share of every bundle's strands a view keeps when its bundles' LoD asks for `demand`
/// items (segments or vertex slots, in units of [`LOD_DEMAND_UNIT`]) of a buffer that holds
/// `budget` items: 1 when it fits, else `(budget - slack) / demand`, where `slack` is what eq.
/// 8's ceiling can add, one strand per bundle, so the kept strands fit even after rounding up;
/// at least [`LOD_LEAST_PRESSURE`], so every visible bundle keeps a strand (GLSL:
/// `lod_pressure` in `bundle_lod.glsl`).
///
///
pub fn lod_pressure(demand: u32, slack: u32, budget: u32) -> f32 {
    let unit = LOD_DEMAND_UNIT as f32;
    let (demand, slack, budget) = (demand as f32 * unit, slack as f32 * unit, budget as f32);
    match demand <= budget {
        true => 1.0,
        false => ((budget - slack) / demand).clamp(LOD_LEAST_PRESSURE, 1.0),
    }
}

/// Eq. 8's width factor `min(1 / L, N)` for `strands` strands at level `l` of a bundle of `n`,
/// held to the bundle's cross-section: each of `k` strands at most `size_over_width / sqrt(k)`
/// strand widths (`h / sqrt(k)` across, `h` the bundle's size), so `k` thick strands cover the
/// bundle once and no more, as a cluster's footprint does (seed 000). The cap binds only where
/// the strands left would cover the bundle more than `sqrt(k)` times over, opaque either way;
/// at crowd distance, with the pixel cap, it holds thick strands near `1 / sqrt(per_pixel)`
/// pixels wide (GLSL: `eq8_thickness`).
pub fn thickness_at(l: f32, n: u32, strands: u32, size_over_width: f32) -> f32 {
    let t = thickness_scale(l, n);
    t.min(size_over_width / (strands.max(1) as f32).sqrt())
        .max(1.0)
}

/// A bundle's strands at strand level `l` (eq. 7 with its terms), the volume band's `share`
/// and the LoD `pressure` ([`lod_pressure`]): eq. 8's count with increment `delta`, the newest
/// strand's fade, and [`thickness_at`] with the pressed level (the share thins strands without
/// widening them). Returns (strands, fade, thickness).
pub fn strand_lod(
    (l, share, pressure): (f32, f32, f32),
    n: u32,
    delta: f32,
    size_over_width: f32,
) -> (u32, f32, f32) {
    let level = l * pressure;
    let drawn = level * share.clamp(0.0, 1.0);
    let strands = strands_at_level(drawn, n, delta);
    (
        strands,
        newest_strand_fade(drawn, n, delta),
        thickness_at(level, n, strands, size_over_width),
    )
}

/// Eq. 9: vertex level `e` (strands get `2^e + 1` vertices) for `ns` segments at full detail.
/// Clamped to `log2(ns)`, the full-detail level.
pub fn vertex_level(l: f32, ns: u32) -> u32 {
    let full = ns.max(1).ilog2();
    let x = (l * ns as f32).max(1e-30).log2().ceil();
    (x.max(0.0) as u32).min(full)
}

/// Eq. 10 and 12: the next-lower level `e~` and the geomorph factor `gamma` in `[0, 1]` for a
/// transition window `lambda` in `(0, 1]`. `gamma = 0` outside the window (no morphing).
pub fn geomorph(l: f32, ns: u32, lambda: f32) -> (u32, f32) {
    let e = vertex_level(l, ns);
    let x = (l * ns as f32).max(1e-30).log2();
    let lambda = lambda.clamp(1e-6, 1.0);
    let e_next = (x - lambda).ceil().max(0.0) as u32;
    if e > e_next && e > 0 {
        let gamma = 1.0 - (x - e_next as f32) / lambda;
        (e_next.min(e - 1), gamma.clamp(0.0, 1.0))
    } else {
        (e, 0.0)
    }
}

/// Eq. 11 and the tangent morph of section 3.6.2, in place: odd vertices move toward the
/// midpoint of their neighbours by `gamma`, tangents blend toward the even-only tangents
/// (odd ones the average of their even neighbours).
pub fn apply_geomorph(p: &mut [Vec3], t: &mut [Vec3], gamma: f32) {
    let m = p.len() - 1;
    if gamma <= 0.0 || m < 2 {
        return;
    }
    let even: Vec<Vec3> = p.iter().step_by(2).copied().collect();
    let mut t_even = vec![Vec3::ZERO; even.len()];
    crate::bake::curve::strand_tangents(&even, &mut t_even);
    for k in (1..m).step_by(2) {
        p[k] = p[k] * (1.0 - gamma) + (p[k - 1] + p[k + 1]) * (0.5 * gamma);
    }
    for k in 0..=m {
        let coarse = if k % 2 == 0 {
            t_even[k / 2]
        } else {
            (t_even[k / 2] + t_even[k / 2 + 1]) * 0.5
        };
        t[k] = (t[k] * (1.0 - gamma) + coarse * gamma).normalize_or(t[k]);
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Eq. 11: an odd vertex moves toward the midpoint of its even neighbours by `gamma` (a
    /// bent three-vertex strand: halfway at 0.5, onto the chord at 1), even vertices stay, and
    /// the odd tangent turns toward the even-only one.
    #[test]
    fn geomorph_moves_odd_vertices_toward_their_neighbours_midpoint() {
        let bent = [
            Vec3::ZERO,
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
        ];
        for (gamma, want) in [
            (0.5, Vec3::new(1.0, 0.5, 0.0)),
            (1.0, Vec3::new(1.0, 0.0, 0.0)),
        ] {
            let (mut p, mut t) = (bent, [Vec3::X; 3]);
            t[1] = Vec3::Y;
            apply_geomorph(&mut p, &mut t, gamma);
            assert!(p[1].distance(want) < 1e-6, "gamma {gamma}: {}", p[1]);
            assert_eq!((p[0], p[2]), (bent[0], bent[2]));
            assert!(t[1].x > 0.0 && t[1].is_normalized(), "{}", t[1]);
        }
    }

    /// Eq. 8's per-bundle increment `delta_i` is uniform in [0, 1) and differs between
    /// bundles: 4096 bundles give at least 4000 distinct values (24-bit values: a collision or
    /// two is chance) with a mean within 0.02 of 0.5, and a seed changes them (the GPU's
    /// `bundle_lod.glsl` hashes the same way).
    #[test]
    fn bundle_delta_is_uniform_and_per_bundle() {
        let d: Vec<f32> = (0..4096).map(|b| bundle_delta(b, 7)).collect();
        let mut sorted = d.clone();
        sorted.sort_by(f32::total_cmp);
        sorted.dedup();
        assert!(sorted.len() >= 4000, "{} distinct increments", sorted.len());
        let mean = d.iter().sum::<f32>() / d.len() as f32;
        assert!((mean - 0.5).abs() < 0.02, "mean {mean}");
        assert!(d.iter().all(|x| (0.0..1.0).contains(x)));
        assert_ne!(bundle_delta(3, 7), bundle_delta(3, 8));
    }

    #[test]
    fn detail_level_falls_with_distance_and_clamps() {
        let near = detail_level(0.02, 720.0, 0.5, 0.5, 0.05);
        let far = detail_level(0.02, 720.0, 50.0, 0.5, 0.05);
        assert_eq!(near, 1.0);
        assert!((far - 0.02 * 720.0 * 0.05 / (50.0 * 0.5f32.tan())).abs() < 1e-6);
        assert!((detail_level_ortho(0.1, 1000.0, 10.0, 0.01) - 0.1).abs() < 1e-6);
    }

    #[test]
    fn strands_never_zero_never_above_n() {
        assert_eq!(strands_at_level(1.0, 64, 0.9), 64);
        assert_eq!(strands_at_level(1e-4, 64, 0.0), 1);
        assert_eq!(strands_at_level(0.5, 64, 0.5), 33);
        assert_eq!(strands_at_level(0.0, 64, 0.5), 0);
        // Monotone in L for a fixed delta.
        let mut prev = 0;
        for i in 1..=100 {
            let c = strands_at_level(i as f32 / 100.0, 50, 0.37);
            assert!(c >= prev);
            prev = c;
        }
        assert_eq!(thickness_scale(0.25, 64), 4.0);
        assert_eq!(thickness_scale(0.001, 3), 3.0);
    }

    /// Stable LoD: the drawn width of a bundle, `(strands - 1 + fade) * thickness`, changes
    /// continuously with L (no jump when a strand is added), where the whole-strand count
    /// alone jumps by a strand's width.
    #[test]
    fn newest_strand_fades_in_without_a_jump() {
        let (n, delta) = (32u32, 0.4f32);
        let drawn = |l: f32| {
            let s = strands_at_level(l, n, delta) as f32;
            (s - 1.0 + newest_strand_fade(l, n, delta)) * thickness_scale(l, n)
        };
        let whole = |l: f32| strands_at_level(l, n, delta) as f32 * thickness_scale(l, n);
        let (mut worst, mut worst_whole) = (0.0f32, 0.0f32);
        for i in 200..2000 {
            let (a, b) = (i as f32 / 2000.0, (i + 1) as f32 / 2000.0);
            worst = worst.max((drawn(b) - drawn(a)).abs());
            worst_whole = worst_whole.max((whole(b) - whole(a)).abs());
        }
        assert!(worst < 0.05, "drawn width jumps by {worst} strands");
        assert!(worst_whole > 0.9, "whole strands jump by {worst_whole}");
        assert_eq!(newest_strand_fade(1.0, n, delta), 1.0);
        assert_eq!(newest_strand_fade(1e-4, n, delta), 1.0);
    }

    /// `hairmeshes/small_patch.obj` baked with the default style.
    pub(crate) fn small_patch() -> (crate::BakedHairMesh, crate::HairStyle) {
        let mesh = crate::model::obj_io::parse_hair_mesh_obj(
            "hairmeshes/small_patch.obj",
            include_bytes!("../../hairmeshes/small_patch.obj"),
        )
        .unwrap();
        let style = crate::HairStyle::default();
        let baked = crate::bake(&mesh, &style, Default::default(), |_, _| {}).unwrap();
        (baked, style)
    }

    /// In the volume tier's band the strands thin out in proportion to their share, one by
    /// one and without widening (the volume comes in under them): a bundle's drawn width,
    /// `(strands - 1 + fade) * thickness`, is its full width times the share (within one
    /// strand), continuous in the share, with the thickness of the full level.
    #[test]
    fn the_band_thins_strands_by_their_share_without_widening_them() {
        let (baked, style) = small_patch();
        let view = |share: f32| LodView {
            eye: Vec3::new(0.0, 0.0, 3.0),
            resolution: 720.0,
            fov_y: 0.8,
            alpha_strands: 1.0,
            area_below: 0.0,
            strands_per_pixel: 0.0,
            alpha_verts: 1.0,
            lambda: 0.5,
            strand_share: share,
            pressure: 1.0,
        };
        let width = |l: &BundleLod| (l.strands as f32 - 1.0 + l.fade) * l.thickness;
        let full = bundle_lod(&baked, &style, 0, 64, 4, &view(1.0));
        assert!(full.strands > 8, "{full:?}");
        let mut prev = width(&full);
        for k in (0..100).rev() {
            let share = k as f32 / 100.0 + 0.005;
            let l = bundle_lod(&baked, &style, 0, 64, 4, &view(share));
            assert_eq!(l.thickness, full.thickness);
            let w = width(&l);
            assert!(
                (w - width(&full) * share).abs() <= full.thickness * 1.01,
                "{share}: {w}"
            );
            // A 1% step of the share takes about 1% of the width off, never adds any.
            let step = prev - w;
            assert!(
                step > -1e-4 && step < width(&full) * 0.011 + 0.05 * full.thickness,
                "{share}: {prev} -> {w}"
            );
            prev = w;
        }
    }

    /// The crowd's area term: below `area_below` a bundle's level is eq. 7's times `x /
    /// area_below`, so twice the distance leaves a quarter of the strands where eq. 7 alone
    /// leaves half (the level ratio squared), while the strands left widen so that the
    /// bundle's drawn width, `(strands - 1 + fade) * thickness`, stays `N + delta` (its full
    /// coverage) in both; at or above `area_below` nothing changes. (Strands 0.1 mm wide:
    /// the sample's 2 mm would cover its bundles several times over, where the cross-section
    /// cap, [`thickness_at`], holds the strands to the bundle.)
    #[test]
    fn the_area_term_thins_small_bundles_and_keeps_their_coverage() {
        let (baked, style) = small_patch();
        let style = crate::HairStyle {
            strand_width: 1e-4,
            ..style
        };
        let n = 64;
        let delta = bundle_delta(0, style.seed);
        let lod = |z: f32, area_below: f32| {
            let view = LodView {
                eye: Vec3::new(0.0, 0.0, z),
                resolution: 720.0,
                fov_y: 0.8,
                alpha_strands: 0.05,
                area_below,
                strands_per_pixel: 0.0,
                alpha_verts: 1.0,
                lambda: 0.5,
                strand_share: 1.0,
                pressure: 1.0,
            };
            bundle_lod(&baked, &style, 0, n, 4, &view)
        };
        let level = |l: &BundleLod| 1.0 / l.thickness;
        let width = |l: &BundleLod| (l.strands as f32 - 1.0 + l.fade) * l.thickness;
        let (near_off, far_off) = (lod(6.0, 0.0), lod(12.0, 0.0));
        // Eq. 7's extent here is 4.7 and 2.3: both under the crowd's 8.
        let (near_on, far_on) = (lod(6.0, 8.0), lod(12.0, 8.0));
        for l in [&near_off, &far_off, &near_on, &far_on] {
            assert!(l.thickness < n as f32 && l.strands >= 1, "{l:?}");
            let w = width(l);
            assert!(
                (w - (n as f32 + delta)).abs() < 1e-2 * n as f32,
                "{l:?}: {w}"
            );
        }
        // The factor is eq. 7's own extent (its level over alpha) over 8 (a survivor of the
        // fourth mutation sample scaled the extent by tan^2: the ratio below still held).
        let extent = level(&near_off) / 0.05;
        let factor = level(&near_on) / level(&near_off);
        assert!(
            (factor - extent / 8.0).abs() < 1e-4,
            "{factor} vs {extent} / 8"
        );
        let off = level(&near_off) / level(&far_off);
        let on = level(&near_on) / level(&far_on);
        assert!(off > 1.5 && off < 2.5, "eq. 7 alone: {off}");
        assert!(
            (on / (off * off) - 1.0).abs() < 1e-3,
            "area term {on}, eq. 7 {off}"
        );
        // 3 strands against 8 at the far distance.
        assert!(
            far_on.strands * 2 < far_off.strands,
            "{far_on:?} {far_off:?}"
        );
        // A bundle at or above the extent keeps eq. 7's decision.
        assert_eq!(lod(12.0, 1e-3), far_off);
    }

    /// LoD pressure: a view whose bundles ask for more segments than the budget keeps the
    /// same share of every bundle's strands, and what is kept fits the budget even after
    /// eq. 8's ceiling (random bundles of 1..4096 strands at levels 0..6, budgets of 5% to
    /// 120% of the demand); a view that fits is left alone.
    #[test]
    fn pressure_fits_the_budget_and_thins_every_bundle_alike() {
        use super::LOD_DEMAND_UNIT as UNIT;
        let mut rng = crate::rng::Pcg32::new(11);
        let wide = 1e9; // no cross-section cap
        for round in 0..40 {
            // (level, N, delta, e)
            let bundles: Vec<(f32, u32, f32, u32)> = (0..200 + round * 30)
                .map(|_| {
                    let n = 1 + (rng.next_f32() * 4095.0) as u32;
                    let l = rng.next_f32().powi(2).max(1e-4);
                    (l, n, rng.next_f32(), (rng.next_f32() * 6.99) as u32)
                })
                .collect();
            let at = |&(l, n, delta, _): &(f32, u32, f32, u32), p: f32| {
                strand_lod((l, 1.0, p), n, delta, wide)
            };
            // The GPU's sums: per bundle strands x 2^e and 2^e, rounded up per 64 bundles.
            let units = |v: &[u32]| -> u32 {
                v.chunks(64)
                    .map(|c| c.iter().sum::<u32>().div_ceil(UNIT))
                    .sum()
            };
            let need: Vec<u32> = bundles.iter().map(|b| at(b, 1.0).0 << b.3).collect();
            let slack: Vec<u32> = bundles.iter().map(|b| 1 << b.3).collect();
            let (demand, slack) = (units(&need), units(&slack));
            let total: u32 = need.iter().sum();
            let budget = (total as f32 * (0.05 + 1.15 * rng.next_f32())) as u32;
            let p = lod_pressure(demand, slack, budget);
            if demand * UNIT <= budget {
                assert_eq!(p, 1.0, "a view that fits keeps its LoD");
                continue;
            }
            assert!(p < 1.0);
            let kept: u32 = bundles.iter().map(|b| at(b, p).0 << b.3).sum();
            let floor: u32 = slack * UNIT; // one strand a bundle is the least a view draws
            assert!(
                kept <= budget.max(floor),
                "round {round}: {kept} > {budget} (p {p})"
            );
            // Every bundle keeps the same share of the strands it wanted (eq. 8 before its
            // ceiling: strands - 1 + fade), down to its last strand.
            for b in &bundles {
                let (strands, fade, _) = at(b, p);
                let wanted = b.0 * (b.1 as f32 + b.2);
                let share = (strands - 1) as f32 + fade;
                let want = (p * wanted).min(b.1 as f32);
                assert!(
                    (share - want).abs() <= 1e-3 * (1.0 + wanted) || strands == 1,
                    "{b:?}: {share} of {wanted} at {p}"
                );
            }
        }
        assert_eq!(lod_pressure(10, 1, 640), 1.0);
        assert_eq!(lod_pressure(20, 2, 640), (640.0 - 128.0) / 1280.0);
    }

    /// A pressed bundle keeps its coverage: the width it draws, `(strands - 1 + fade) *
    /// thickness`, is what it drew before (eq. 8's thickness grows as the strands fall), until
    /// one strand is left or the thickness reaches N.
    #[test]
    fn pressure_keeps_a_bundles_coverage() {
        let width = |(s, fade, t): (u32, f32, f32)| ((s - 1) as f32 + fade) * t;
        let (n, delta, wide) = (3000, 0.37, 1e9);
        let before = strand_lod((0.1, 1.0, 1.0), n, delta, wide);
        for p in [0.9, 0.5, 0.1, 0.02] {
            let after = strand_lod((0.1, 1.0, p), n, delta, wide);
            assert!(after.0 < before.0, "{after:?}");
            let (w0, w1) = (width(before), width(after));
            assert!((w1 - w0).abs() < 2e-3 * w0, "{p}: {w0} -> {w1}");
        }
        // The thickness stops at N; one strand at least.
        let last = strand_lod((0.1, 1.0, 1e-6), n, delta, wide);
        assert_eq!((last.0, last.2), (1, 3000.0));
    }

    /// The cross-section cap: k thick strands are each at most `h / sqrt(k)` wide, so they
    /// cover the bundle about once where eq. 8's thickness would pile them up (a 5 cm bundle
    /// of 3,600 strands 0.1 mm wide, 36 thick strands: 1/L would make each 1 cm wide, 7 times
    /// the bundle's width together; the cap holds them at 8.3 mm, 6 bundle widths... of their
    /// own row); it never narrows a strand below its own width, and leaves thin hair alone.
    #[test]
    fn the_cross_section_cap_holds_thick_strands_to_their_bundle() {
        let size_over_width = 0.05 / 1e-4;
        let t = thickness_at(36.0 / 3600.0, 3600, 36, size_over_width);
        assert!((t * 1e-4 - 0.05 / 6.0).abs() < 1e-6, "{t}");
        assert_eq!(thickness_at(36.0 / 3600.0, 3600, 36, 1e9), 100.0);
        assert_eq!(thickness_at(1.0, 3600, 3600, size_over_width), 1.0);
        assert_eq!(thickness_at(0.01, 3600, 36, 1.0), 1.0);
        // The old density's strands (96 a bundle, 1 mm wide): untouched down to 2 strands.
        assert_eq!(thickness_at(0.5, 96, 48, 50.0), 2.0);
        assert!((thickness_at(2.0 / 96.0, 96, 2, 50.0) - 50.0 / 2f32.sqrt()).abs() < 1e-4);
    }

    #[test]
    fn vertex_level_is_power_of_two_plus_one() {
        assert_eq!(vertex_level(1.0, 32), 5);
        assert_eq!(vertex_level(0.5, 32), 4);
        assert_eq!(vertex_level(0.3, 32), 4); // ceil(log2(9.6)) = 4
        assert_eq!(vertex_level(0.01, 32), 0);
    }

    #[test]
    fn geomorph_is_continuous_across_levels() {
        // Just above a level boundary gamma -> 1 (fully morphed), far from it gamma = 0.
        let ns = 32;
        let (_, g_hi) = geomorph(0.5 + 1e-4, ns, 0.5);
        assert!(g_hi > 0.99, "{g_hi}");
        let (e, g) = geomorph(0.99, ns, 0.5);
        assert_eq!((e, g), (5, 0.0));
        // Morphing odd vertices fully gives the coarse polyline's midpoints.
        let mut p: Vec<Vec3> = (0..5)
            .map(|i| Vec3::new(i as f32, (i % 2) as f32, 0.0))
            .collect();
        let mut t = vec![Vec3::X; 5];
        apply_geomorph(&mut p, &mut t, 1.0);
        assert!(p[1].y.abs() < 1e-6 && p[3].y.abs() < 1e-6);
    }
}

/// The view a LoD decision is made for (mirrors the `Frame` fields `bundle_lod.glsl` reads).
#[derive(Clone, Copy, Debug)]
pub struct LodView {
    /// Eye position (object space of the mesh; the CPU reference uses identity transforms).
    pub eye: Vec3,
    /// Vertical resolution `R` in pixels.
    pub resolution: f32,
    /// Vertical field of view `theta` of eq. 7, radians.
    pub fov_y: f32,
    /// Alpha for strand LoD.
    pub alpha_strands: f32,
    /// The strand level's area term below this extent ([`area_factor`]; 0: off).
    pub area_below: f32,
    /// The pixel cap: strands per square pixel of a bundle's extent ([`pixel_cap_level`]; 0:
    /// off).
    pub strands_per_pixel: f32,
    /// Alpha for vertex LoD.
    pub alpha_verts: f32,
    /// Geomorph window lambda.
    pub lambda: f32,
    /// The LoD pressure on this view's bundles ([`lod_pressure`]; 1: none).
    pub pressure: f32,
    /// Share of the character's strands drawn: 1, or 1 minus the volume tier's weight in its
    /// switch band, where strands thin out one by one (eq. 8's level times the share; widths
    /// keep eq. 8's thickness) while the density volume comes in.
    pub strand_share: f32,
}

/// One bundle's LoD decision (GLSL: `BundleLod`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BundleLod {
    /// Strands generated (eq. 8).
    pub strands: u32,
    /// Vertex level: `2^e` segments (eq. 9).
    pub e: u32,
    /// Geomorph factor toward level `e - 1` (eq. 12); 0 for none.
    pub gamma: f32,
    /// Width factor `min(1/L, N)`.
    pub thickness: f32,
    /// Width share of the newest strand ([`newest_strand_fade`]).
    pub fade: f32,
}

/// Per-bundle random increment `delta_i` of eq. 8 (GLSL: in `bundle_lod`).
pub fn bundle_delta(bundle: u32, seed: u32) -> f32 {
    use crate::rng::{hash_f32, hash_u32};
    hash_f32(hash_u32(bundle ^ 0x2545_f491) ^ seed)
}

/// Bounds of bundle `b`: its Bezier control points (decoded texels) grown by `margin`.
pub fn bundle_bounds(baked: &crate::BakedHairMesh, b: usize, margin: f32) -> (Vec3, Vec3) {
    let info = &baked.info;
    let [w, _] = info.root_size;
    let o = Vec3::from_slice(&info.pos_origin[..3]);
    let e = Vec3::from_slice(&info.pos_extent[..3]);
    let [x0, y0] = baked.bundles[b].origin;
    let mut lo = Vec3::splat(f32::MAX);
    let mut hi = Vec3::splat(f32::MIN);
    for z in 0..info.position_depth() as usize {
        for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let t = baked.position[z * info.slice_texels() + ((y0 + dy) * w + x0 + dx) as usize];
            let p = o + e * Vec3::new(t[0] as f32, t[1] as f32, t[2] as f32) / 65535.0;
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    (lo - margin, hi + margin)
}

/// LoD decision of bundle `b` with `n` strands before LoD and full vertex level `e_max`
/// (culling not included): eq. 7-10 and 12, the CPU twin of `bundle_lod.glsl`.
pub fn bundle_lod(
    baked: &crate::BakedHairMesh,
    style: &crate::HairStyle,
    b: usize,
    n: u32,
    e_max: u32,
    view: &LodView,
) -> BundleLod {
    let margin =
        style.curl_radius + style.wave_amplitude + style.frizz_amplitude + style.strand_width;
    let (lo, hi) = bundle_bounds(baked, b, margin);
    let d = view.eye.distance(view.eye.clamp(lo, hi));
    let h = baked.bundles[b].rest_size;
    let x = bundle_extent(h, view.resolution, d, view.fov_y);
    let ls = (detail_level(h, view.resolution, d, view.fov_y, view.alpha_strands)
        * area_factor(x, view.area_below))
    .min(pixel_cap_level(x, view.strands_per_pixel, n));
    let delta = bundle_delta(b as u32, style.seed);
    let size_over_width = h / style.strand_width.max(1e-12);
    let levels = (ls, view.strand_share, view.pressure);
    let (strands, fade, thickness) = strand_lod(levels, n, delta, size_over_width);
    let lv = detail_level(h, view.resolution, d, view.fov_y, view.alpha_verts);
    let ns = 1u32 << e_max;
    let e = vertex_level(lv, ns);
    let (_, gamma) = geomorph(lv, ns, view.lambda);
    BundleLod {
        strands,
        e,
        gamma,
        thickness,
        fade,
    }
}
