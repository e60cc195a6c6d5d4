//! Shading from a strand density volume (seed 002, vkhr sec. 4-5): the CPU twins of
//! `glsl/volume_shading.glsl`, in the volume's object units.
//!
//! A line of sight of length `d` through density `rho` (strand length per volume) crosses on
//! average `rho * width * d` strands' projected area. Strands sit at random, so the strands a
//! ray meets are Poisson distributed, and with opacity `alpha` each the expected transmittance
//! is `E[(1 - alpha)^k] = exp(-alpha * rho * width * d)`: the optical depth per unit length is
//! `sigma = alpha * rho * width` ([`extinction`]).
//!
//! - **Ambient occlusion** (vkhr sec. 5, after Hernell et al.'s local AO): the ambient light
//!   reaching a point is what crosses the hair within [`AO_RADIUS_CELLS`] cells of it,
//!   `exp(-sigma(p) * R)` with `sigma` from the trilinear density at the point, which near
//!   the hair's surface is about half its inside value ([`ambient_visibility`]).
//! - **Ray marching** (vkhr sec. 4): a view ray is marched front to back in steps of
//!   [`MARCH_STEP_CELLS`]; each step absorbs `1 - exp(-sigma ds)` of what is left. The march
//!   returns the transmittance left and the opacity-weighted mean point and flow, where the
//!   strands are shaded once ([`march`]); toward the light, the transmittance through the
//!   character's own hair ([`light_transmittance`]).

use glam::Vec3;

use crate::reference::volume::{DensityVolume, brick_exit, brick_of, brick_set};

/// Radius of the ambient occlusion neighbourhood, in mean cell sizes.
pub const AO_RADIUS_CELLS: f32 = 2.0;
/// Step of the view and light marches, in mean cell sizes.
pub const MARCH_STEP_CELLS: f32 = 2.0;
/// A march stops once less than this transmittance is left.
pub const MARCH_MIN_TRANSMITTANCE: f32 = 0.01;

/// Optical depth per unit length (`sigma`) of hair of `density` (strand length per volume)
/// whose strands are `width` wide and `opacity` opaque.
pub fn extinction(density: f32, width: f32, opacity: f32) -> f32 {
    opacity * density * width
}

/// The fraction of ambient light reaching `p` through the hair around it, strands `width`
/// wide and `opacity` opaque.
pub fn ambient_visibility(volume: &DensityVolume, p: Vec3, width: f32, opacity: f32) -> f32 {
    let radius = AO_RADIUS_CELLS * volume.mean_cell();
    (-extinction(volume.sample(p), width, opacity) * radius).exp()
}

/// What a march through a volume found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MarchResult {
    /// Transmittance left at the end.
    pub transmittance: f32,
    /// Mean point of the light absorbed (weighted by each step's share of the opacity).
    pub point: Vec3,
    /// Mean flow there (same weights; its direction is the strands' mean tangent).
    pub flow: Vec3,
}

/// March from `from` along the unit direction `dir` for `length`, through strands `width`
/// wide and `opacity` opaque, front to back, stopping at [`MARCH_MIN_TRANSMITTANCE`].
pub fn march(
    volume: &DensityVolume,
    from: Vec3,
    dir: Vec3,
    length: f32,
    strands: (f32, f32),
) -> MarchResult {
    march_masked(volume, &volume.occupancy(), from, dir, length, strands)
}

/// [`march`] skipping the bricks `mask` marks empty ([`DensityVolume::occupancy`]; all ones:
/// no skipping), as `volume_hair.frag` does: the same samples, so the same result for any
/// mask that marks every brick with strands.
pub fn march_masked(
    volume: &DensityVolume,
    mask: &[u32],
    from: Vec3,
    dir: Vec3,
    length: f32,
    (width, opacity): (f32, f32),
) -> MarchResult {
    let step = MARCH_STEP_CELLS * volume.mean_cell();
    let steps = (length / step).ceil().max(0.0) as u32;
    let mut t = 1.0f32;
    let (mut point, mut flow, mut absorbed) = (Vec3::ZERO, Vec3::ZERO, 0.0f32);
    let (g0, gd) = ((from - volume.origin) / volume.cell, dir / volume.cell);
    let mut i = 0;
    while i < steps {
        let ds = step.min(length - i as f32 * step);
        let at = i as f32 * step + 0.5 * ds;
        let brick = brick_of(volume.dims, g0 + gd * at);
        if !brick_set(mask, volume.dims, brick) {
            // Every sample in an empty brick is 0: on to the first one past it.
            let exit = brick_exit(g0, gd, brick);
            i = (i + 1).max((exit / step - 0.5).ceil().max(0.0) as u32);
            continue;
        }
        i += 1;
        let p = from + dir * at;
        let sigma = extinction(volume.sample(p), width, opacity);
        if sigma <= 0.0 {
            continue;
        }
        let a = t * (1.0 - (-sigma * ds).exp());
        point += p * a;
        flow += volume.sample_flow(p) * a;
        absorbed += a;
        t -= a;
        if t < MARCH_MIN_TRANSMITTANCE {
            break;
        }
    }
    let mean = |v: Vec3| if absorbed > 0.0 { v / absorbed } else { from };
    MarchResult {
        transmittance: t,
        point: mean(point),
        flow: if absorbed > 0.0 {
            flow / absorbed
        } else {
            Vec3::ZERO
        },
    }
}

/// Transmittance of the light from `p` through the volume toward the unit direction `dir`,
/// up to the grid's edge, in whole steps of [`MARCH_STEP_CELLS`] (at most 256) sampled at their
/// middles, through strands `width` wide and `opacity` opaque: `volume_light` in
/// `volume_shading.glsl`, the self-shadow of hair drawn as its volume alone.
pub fn light_transmittance(
    volume: &DensityVolume,
    p: Vec3,
    dir: Vec3,
    (width, opacity): (f32, f32),
) -> f32 {
    let hi = volume.origin + volume.cell * volume.dims.as_vec3();
    let exit = |o: f32, d: f32, lo: f32, hi: f32| match d {
        d if d > 0.0 => (hi - o) / d,
        d if d < 0.0 => (lo - o) / d,
        _ => f32::INFINITY,
    };
    let length = exit(p.x, dir.x, volume.origin.x, hi.x)
        .min(exit(p.y, dir.y, volume.origin.y, hi.y))
        .min(exit(p.z, dir.z, volume.origin.z, hi.z))
        .max(0.0);
    let step = MARCH_STEP_CELLS * volume.mean_cell();
    let steps = ((length / step).ceil() as u32).min(256);
    let depth: f32 = (0..steps)
        .map(|i| volume.sample(p + dir * ((i as f32 + 0.5) * step)))
        .sum();
    (-extinction(depth * step, width, opacity)).exp()
}

/// How far along the ray `eye + t dir` (unit `dir`, world units) the view `view_proj` puts
/// `depth` (0..1, clip z over w): where a march of `volume_hair.frag` meets the opaque surface
/// the pixel shows, so the hair behind a head or a body is not counted in front of it.
/// `ray_length_to_depth` in `volume_shading.glsl`. Infinite at the cleared depth (1) and
/// where the ray never reaches `depth`.
pub fn ray_length_to_depth(view_proj: glam::Mat4, eye: Vec3, dir: Vec3, depth: f32) -> f32 {
    // Clip space along the ray is a + t b, and depth(t) = (a.z + t b.z) / (a.w + t b.w).
    let a = view_proj * eye.extend(1.0);
    let b = view_proj * dir.extend(0.0);
    let t = (depth * a.w - a.z) / (b.z - depth * b.w);
    if depth < 1.0 && t.is_finite() && t >= 0.0 {
        t
    } else {
        f32::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::UVec3;

    /// A slab of uniform density along z between 1/4 and 3/4 of the box.
    fn slab(density: f32) -> DensityVolume {
        let mut v = DensityVolume::empty(Vec3::ZERO, Vec3::ONE, UVec3::splat(16));
        for z in 4..12 {
            for y in 0..16 {
                for x in 0..16 {
                    let i = v.index(UVec3::new(x, y, z));
                    v.density[i] = density;
                    v.flow[i] = Vec3::X * density;
                }
            }
        }
        v
    }

    #[test]
    fn a_march_through_a_slab_transmits_the_beer_lambert_fraction() {
        let v = slab(100.0);
        let (width, opacity) = (0.01, 0.5);
        let r = march(&v, Vec3::new(0.5, 0.5, 0.0), Vec3::Z, 1.0, (width, opacity));
        // Through 0.5 of density 100 (the trilinear ramps at the slab's faces cancel).
        let expected = (-extinction(100.0, width, opacity) * 0.5).exp();
        assert!(
            (r.transmittance - expected).abs() < 0.02,
            "{} vs {expected}",
            r.transmittance
        );
        // Absorbed in the slab's front half, flowing along x.
        assert!(r.point.z > 0.25 && r.point.z < 0.5, "{}", r.point);
        assert!((r.flow.normalize() - Vec3::X).length() < 1e-4);
        // Nothing absorbed outside the hair.
        let miss = march(&slab(0.0), Vec3::ZERO, Vec3::Z, 1.0, (width, opacity));
        assert_eq!(miss.transmittance, 1.0);
    }

    /// A march that ends inside the hair, after a part of a step, absorbs exactly that part:
    /// 0.33 of uniform hair (two steps of 0.125 and one of 0.08) transmits `exp(-sigma 0.33)`
    /// (a survivor of the fourth mutation sample took the last step whole: `exp(-sigma
    /// 0.375)`, 9% less).
    #[test]
    fn a_march_ending_inside_the_hair_takes_its_last_part_step() {
        let v = slab(400.0);
        let (width, opacity) = (0.01, 0.5);
        let from = Vec3::new(0.5, 0.5, 0.32);
        let r = march(&v, from, Vec3::Z, 0.33, (width, opacity));
        let expected = (-extinction(400.0, width, opacity) * 0.33).exp();
        assert!(
            (r.transmittance / expected - 1.0).abs() < 1e-4,
            "{} vs {expected}",
            r.transmittance
        );
    }

    #[test]
    fn light_through_a_slab_falls_with_the_hair_it_crosses() {
        let v = slab(100.0);
        let (width, opacity) = (0.01, 0.5);
        // From the slab's middle out through its far half (0.25 of hair), and from in front of
        // the slab away from it (no hair).
        let half = light_transmittance(&v, Vec3::new(0.5, 0.5, 0.5), Vec3::Z, (width, opacity));
        let expected = (-extinction(100.0, width, opacity) * 0.25).exp();
        assert!((half - expected).abs() < 0.02, "{half} vs {expected}");
        let away = light_transmittance(&v, Vec3::new(0.5, 0.5, 0.1), -Vec3::Z, (width, opacity));
        assert_eq!(away, 1.0);
        let through = light_transmittance(&v, Vec3::new(0.5, 0.5, 0.05), Vec3::Z, (width, opacity));
        assert!(through < half, "{through} {half}");
        // Slanted 60 degrees from z, from just inside the slab's front: the grid's side (x = 1)
        // ends the path after 0.5 / sin 60 = 0.577 of hair, before the slab's back would.
        let dir = Vec3::new(60f32.to_radians().sin(), 0.0, 60f32.to_radians().cos());
        let slanted = light_transmittance(&v, Vec3::new(0.5, 0.5, 0.3), dir, (width, opacity));
        let expected = (-extinction(100.0, width, opacity) * 0.5 / dir.x).exp();
        // Measured 0.7484 vs 0.7493 (0.11%, the march's steps); the exit as a remainder
        // instead of a quotient (a surviving mutant) gives 0.882.
        assert!(
            (slanted - expected).abs() < 0.01 * expected,
            "{slanted} vs {expected}"
        );
    }

    #[test]
    fn ambient_visibility_falls_inside_the_hair() {
        let v = slab(400.0);
        let (width, opacity) = (0.01, 0.5);
        let outside = ambient_visibility(&v, Vec3::new(0.5, 0.5, 0.05), width, opacity);
        let surface = ambient_visibility(&v, Vec3::new(0.5, 0.5, 0.25), width, opacity);
        let inside = ambient_visibility(&v, Vec3::new(0.5, 0.5, 0.5), width, opacity);
        assert_eq!(outside, 1.0);
        assert!(inside < surface && surface < outside, "{inside} {surface}");
        let expected = (-extinction(400.0, width, opacity) * 2.0 / 16.0).exp();
        assert!((inside - expected).abs() < 1e-5, "{inside} vs {expected}");
    }
}
