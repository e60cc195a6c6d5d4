//! Multiple scattering between strands: dual scattering (Zinke, Yuksel, Weber and Keyser
//! 2008; seed 000 sec. 3.2, eqs. 3-4) on this crate's Marschner model. The CPU twin of
//! `dual_scattering` in `glsl/hair_shading.glsl`.
//!
//! Light reaching a strand has either crossed no hair (the *direct* fraction the light's maps
//! give) or been scattered forward through `n` strands on its way (*global* scattering).
//! Strands sit at random, so the strands met are Poisson distributed: with `m` expected hits
//! (`-ln(direct)`), the light that arrives after at least one forward scattering is
//! `E[a_f^N; N >= 1] = exp(-m (1 - a_f)) - exp(-m)` ([`LightArrival::scattered`]), spread
//! longitudinally by `m` forward lobe variances (eq. 3's `sigma_F`). Around the strand, light
//! that passed it comes back from the hair behind (*local* back-scattering, eq. 4):
//! `A_b = A_1 + A_3`, the paths with one and with three backward scatterings.
//!
//! The per-lobe energies scattered into the front and back halves of azimuth
//! ([`lobe_energies`]) depend only on the longitudinal angle and one colour channel, so they
//! are tabulated at start-up (seed 001's precomputation; [`super::lut`]).
//!
//! Conventions: longitudinal lobes are `0.5 g(beta, theta_h - alpha)` (normalised over
//! `theta_o`), shifts and widths as in [`super::marschner`]: R `(-a, b)`, TT `(a/2, b/2)`, TRT
//! `(3a/2, 2b)`. Energies are fractions of the light a strand intercepts.

use glam::Vec3;

use super::{
    ENERGY_SCALE, HAIR_ETA, MarschnerParams, azimuthal_factors, fresnel, gaussian, hair_angles,
};

/// Zinke's forward density factor `d_f`: the share of the global path that hair of finite
/// density lets through (0.7 in the paper).
pub const FORWARD_DENSITY: f32 = 0.7;
/// Zinke's backward density factor `d_b` (0.7 in the paper).
pub const BACKWARD_DENSITY: f32 = 0.7;

/// Seed 000's `d_1+` (eq. 10): the share of the gap paths that reach the strand (0.6 in the
/// paper).
pub const GAP_DENSITY: f32 = 0.6;

/// Azimuthal samples of the half-circle in [`lobe_energies`].
const AZIMUTH_SAMPLES: usize = 128;

/// The energy each lobe (R, TT, TRT) sends into the front (`cos(phi) < 0`, away from the
/// light) and back (`cos(phi) > 0`) halves of azimuth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LobeEnergies {
    /// Forward energies of R, TT, TRT.
    pub front: [f32; 3],
    /// Backward energies of R, TT, TRT.
    pub back: [f32; 3],
}

/// [`LobeEnergies`] of a strand of colour channel `c` (transmittance per diameter) for light
/// at longitudinal angle `theta` with `cos(theta) = cos_d`. The longitudinal lobes integrate
/// to one over `theta_o` around `theta_o = -theta_i`, where `cos(theta_d) = cos(theta_i)` and
/// the `cos^2(theta_o) / cos^2(theta_d)` of the furnace integral is one, so each energy is
/// `ENERGY_SCALE * integral of N_p(phi) d phi` over its half.
pub fn lobe_energies(cos_d: f32, c: f32) -> LobeEnergies {
    let cos_d = cos_d.clamp(1e-3, 1.0);
    let sin2 = 1.0 - cos_d * cos_d;
    let c = c.clamp(1e-4, 1.0);
    let f_trt_path = c.powf(0.8 / cos_d);
    let mut e = LobeEnergies {
        front: [0.0; 3],
        back: [0.0; 3],
    };
    let dphi = std::f32::consts::PI / AZIMUTH_SAMPLES as f32;
    for k in 0..AZIMUTH_SAMPLES {
        let phi = (k as f32 + 0.5) * dphi;
        let cos_phi = phi.cos();
        // l.v with theta_o = -theta_i.
        let lv = cos_d * cos_d * cos_phi - sin2;
        let n_r = 0.25 * (0.5 * phi).cos() * fresnel(HAIR_ETA, (0.5 + 0.5 * lv).max(0.0).sqrt());
        let az = azimuthal_factors(cos_phi, cos_d);
        let n_tt = c.powf(az.tt_path / (2.0 * cos_d)) * az.tt;
        let n_trt = f_trt_path * az.trt;
        // Both signs of phi: twice the half-circle.
        let w = 2.0 * dphi * ENERGY_SCALE;
        let half = if cos_phi < 0.0 {
            &mut e.front
        } else {
            &mut e.back
        };
        for (h, n) in half.iter_mut().zip([n_r, n_tt, n_trt]) {
            *h += w * n;
        }
    }
    e
}

/// How the light reaches a point, from the light's maps (and a volume's own march).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightArrival {
    /// Fraction arriving without crossing hair (the maps' transmittance).
    pub direct: f32,
    /// Fraction not blocked by opaque bodies.
    pub open: f32,
    /// Expected strand hits on the way, where open: `-ln` of the hair transmittance.
    pub hits: f32,
}

impl LightArrival {
    /// Light with nothing in the way.
    pub const FULL: LightArrival = LightArrival {
        direct: 1.0,
        open: 1.0,
        hits: 0.0,
    };

    /// Arrival through `hits` expected strand hits, nothing opaque.
    pub fn through(hits: f32) -> LightArrival {
        LightArrival {
            direct: (-hits).exp(),
            open: 1.0,
            hits,
        }
    }

    /// The fraction that arrives after at least one forward scattering, each passing
    /// `a_front` of the light on: `open E[a_f^N; N >= 1]` for Poisson `N` of mean `hits`.
    pub fn scattered(&self, a_front: f32) -> f32 {
        (self.open * (-self.hits * (1.0 - a_front)).exp() - self.direct).max(0.0)
    }
}

/// Longitudinal shift and width of each lobe (R, TT, TRT) for roughness `b` and tilt `a`.
fn lobe_shapes(p: &MarschnerParams) -> [(f32, f32); 3] {
    let (a, b) = (p.tilt, p.roughness);
    [(-a, b), (0.5 * a, 0.5 * b), (1.5 * a, 2.0 * b)]
}

/// Energy-weighted mean shift and variance of one half's lobes: `(total, alpha, beta^2)`.
fn half_moments(energies: &[f32; 3], shapes: &[(f32, f32); 3]) -> (f32, f32, f32) {
    let total: f32 = energies.iter().sum();
    let w = 1.0 / total.max(1e-6);
    let alpha = (0..3).map(|p| energies[p] * shapes[p].0).sum::<f32>() * w;
    let var = (0..3)
        .map(|p| energies[p] * shapes[p].1 * shapes[p].1)
        .sum::<f32>()
        * w;
    (total, alpha, var)
}

/// Local back-scattering (Zinke 2008 sec. 4.2; seed 000 eqs. 4, 10, 11): its attenuation,
/// mean longitudinal shift and variance, from one channel's forward and backward moments
/// `(a, alpha, beta^2)`, for a strand standing for a cluster whose strands a ray crosses
/// `cluster` times (1 for a single strand).
///
/// - `A_1 = a_b a_f^2 / (1 - a_f^2)` sums the paths into the hair through `k >= 1` strands, one
///   backward scattering and out again (`a_f^2k a_b`); `A_3 = a_b^3 a_f^2 / (1 - a_f^2)^3`
///   those with three (Zinke).
/// - Seed 000's gap paths (eq. 10): light that reached strands behind through gaps and comes
///   back, `A_1+ = d_1+ a_b sum_{i=1}^{n} a_f^(2i-1) = d_1+ a_b a_f (1 - a_f^2n) / (1 - a_f^2)`
///   (closed form, so fractional `n` changes it smoothly). Its paths cross on average
///   `(1 + a_f^2) / (1 - a_f^2)` forward lobes, at most `2n - 1`.
///
/// Each path's shift and variance add its lobes'; the result is their attenuation-weighted
/// mean (eq. 11's "averaged accumulated variance"), widened by `(1 + d_b a_f^2)` as Zinke
/// does.
pub fn back_scattering(
    front: (f32, f32, f32),
    back: (f32, f32, f32),
    cluster: f32,
) -> (f32, f32, f32) {
    let (af, alpha_f, var_f) = front;
    let (ab, alpha_b, var_b) = back;
    let af2 = af * af;
    let q = (1.0 - af2).max(1e-4);
    let a1 = ab * af2 / q;
    let a3 = ab * ab * ab * af2 / (q * q * q);
    let n = cluster.max(1.0);
    let gap = GAP_DENSITY * ab * af * (1.0 - af2.powf(n)) / q;
    let gap_forward = ((1.0 + af2) / q).min(2.0 * n - 1.0);
    let total = a1 + a3 + gap;
    let w = 1.0 / total.max(1e-8);
    let shift = (a1 * (alpha_b + 2.0 * alpha_f)
        + a3 * (3.0 * alpha_b + 2.0 * alpha_f)
        + gap * (alpha_b + gap_forward * alpha_f))
        * w;
    let var = (a1 * (var_b + 2.0 * var_f)
        + a3 * (3.0 * var_b + 2.0 * var_f)
        + gap * (var_b + gap_forward * var_f))
        * w;
    let widen = 1.0 + BACKWARD_DENSITY * af2;
    (total, shift, var * widen * widen)
}

/// Radiance toward `v` per unit irradiance of a directional light toward `l` (so multiply by
/// the light's irradiance), for a strand of tangent `t` and style `p` that the light reaches
/// as `arrival`: single scattering of the direct light, plus with `multiple` on, Zinke's dual
/// scattering per colour channel:
///
/// `F = direct (f_s + d_b f_back) + d_f scattered (f_s^G + d_b f_back^G)`, times `cos(theta_i)`,
///
/// where `f_s^G` is each lobe widened by the global spread and spread evenly over azimuth
/// (light arrives from the whole front half, seed 000 eq. 3), and `f_back` is the local lobe of
/// energy `A_b` with azimuthal distribution `(1 + cos(phi)) / 2 pi` (eq. 4's `I_B / pi`,
/// smoothed so it has no seam at `phi = 90` degrees; same energy).
///
/// A strand standing for a cluster (strand LoD; a ray crosses `cluster` of its strands, 1 for
/// a single strand) gets seed 000's aggregated model (eqs. 7-11) on top, continuous in
/// `cluster`: the inherited single-scattering lobes lose `a_f^(n - 1)` where light leaves the
/// cluster's far side (eq. 8; weighted by `(1 - cos(phi)) / 2` instead of the hemisphere
/// indicator, so there is no seam; eq. 9's widening of their lobes is left out: it moves no
/// energy), and the local lobe gains the gap paths `A_1+` (eq. 10, [`back_scattering`]).
/// Clusters are drawn at packing density 1 (`lod_appearance.glsl`), where eq. 15's
/// shadowing-masking term is 1.
pub fn dual_scattering(
    t: Vec3,
    l: Vec3,
    v: Vec3,
    p: &MarschnerParams,
    arrival: LightArrival,
    multiple: bool,
    cluster: f32,
) -> Vec3 {
    let angles = hair_angles(t, l, v);
    let single = super::marschner_at(angles, l.dot(v), p);
    let [theta_h, cos_d, cos_phi, cos_i] = angles;
    if !multiple {
        return single * (cos_i * arrival.direct);
    }
    let shapes = lobe_shapes(p);
    let inv_cos2 = 1.0 / (cos_d * cos_d);
    let back_azimuth = (1.0 + cos_phi) / std::f32::consts::TAU;
    let channel = |c: f32, single: f32| -> f32 {
        let e = lobe_energies(cos_d, c);
        let front = half_moments(&e.front, &shapes);
        let back = half_moments(&e.back, &shapes);
        let (a_b, shift_b, var_b) = back_scattering(front, back, cluster);
        // Eq. 8: light leaving through the cluster's far side crossed its other strands.
        let inherited = front
            .0
            .powf((cluster.max(1.0) - 1.0) * 0.5 * (1.0 - cos_phi));
        let back_lobe = |spread: f32| {
            a_b * 0.5 * gaussian((var_b + spread).sqrt(), theta_h - shift_b) * back_azimuth
        };
        let scattered = arrival.scattered(front.0);
        // The global spread: the forward variance of the strands crossed (at least one).
        let spread = arrival.hits.max(1.0) * front.2;
        let global: f32 = (0..3)
            .map(|k| {
                let (shift, width) = shapes[k];
                let energy = e.front[k] + e.back[k];
                0.5 * gaussian((width * width + spread).sqrt(), theta_h - shift) * energy
                    / std::f32::consts::TAU
            })
            .sum();
        let direct =
            arrival.direct * (single * inherited + BACKWARD_DENSITY * back_lobe(0.0) * inv_cos2);
        let multiple = FORWARD_DENSITY
            * scattered
            * (global + BACKWARD_DENSITY * back_lobe(spread))
            * inv_cos2;
        (direct + multiple) * cos_i
    };
    Vec3::new(
        channel(p.color.x, single.x),
        channel(p.color.y, single.y),
        channel(p.color.z, single.z),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shade::melanin_color;

    fn params(color: Vec3) -> MarschnerParams {
        MarschnerParams {
            color,
            roughness: 0.25,
            tilt: 3f32.to_radians(),
        }
    }

    /// The tabulated per-lobe energies add up to the single-fibre white furnace integral of
    /// the full model: within 3% for narrow lobes (roughness 0.1), where the approximation
    /// holds; broad lobes (0.25) lose up to 10% more to the `cos^2` factors than it counts.
    /// The lobes go where Marschner says: TT forward, TRT back.
    #[test]
    fn lobe_energies_match_the_furnace_and_the_lobes_directions() {
        for (roughness, tolerance) in [(0.1, 0.03), (0.25, 0.1)] {
            let p = MarschnerParams {
                roughness,
                ..params(Vec3::ONE)
            };
            for deg in [0.0f32, 20.0, 40.0, 60.0] {
                let e = lobe_energies(deg.to_radians().cos(), 1.0);
                let total: f32 = e.front.iter().chain(&e.back).sum();
                let furnace = crate::shade::tests::furnace(deg.to_radians(), &p);
                println!(
                    "roughness {roughness}, theta {deg}: {e:?} total {total:.4} furnace {furnace:.4}"
                );
                assert!(
                    (total - furnace).abs() < tolerance * furnace,
                    "{deg}: {total} {furnace}"
                );
                assert!(e.front[1] > 4.0 * e.back[1], "TT goes forward: {e:?}");
                assert!(e.back[2] > e.front[2], "TRT goes back: {e:?}");
            }
        }
    }

    /// White furnace of the local term: hair that absorbs nothing sends back toward the light
    /// at most all of it (first strand's back half plus `d_b A_b`), and dark hair sends back
    /// less than light hair.
    #[test]
    fn back_scattering_conserves_energy_and_darkens_with_melanin() {
        let shapes = lobe_shapes(&params(Vec3::ONE));
        let mut last = f32::MAX;
        for eumelanin in [0.0f32, 0.3, 1.3, 8.0] {
            let c = melanin_color(eumelanin, 0.0).y;
            for deg in [0.0f32, 30.0, 60.0, 80.0] {
                let e = lobe_energies(deg.to_radians().cos(), c);
                let front = half_moments(&e.front, &shapes);
                let back = half_moments(&e.back, &shapes);
                let (a_b, _, var) = back_scattering(front, back, 1.0);
                // With a cluster of any size the gap paths stay within the budget too.
                let (a_big, _, _) = back_scattering(front, back, 1e4);
                let sent_back = back.0 + BACKWARD_DENSITY * a_big;
                assert!(
                    sent_back <= 1.0 && front.0 + back.0 <= 1.0 && var > 0.0,
                    "melanin {eumelanin}, {deg} deg: {sent_back} {front:?} {back:?}"
                );
                if deg == 0.0 {
                    println!(
                        "melanin {eumelanin}: a_f {:.3} a_b {:.3} A_b {a_b:.3}",
                        front.0, back.0
                    );
                    assert!(a_b < last, "melanin {eumelanin}: A_b {a_b} >= {last}");
                    last = a_b;
                }
            }
        }
        assert!(last < 0.01, "black hair keeps {last} of back-scattering");
    }

    /// The global path never adds light: direct + scattered <= open, and less arrives through
    /// more hair.
    #[test]
    fn global_scattering_never_adds_light() {
        for a_f in [0.0f32, 0.3, 0.7, 0.95] {
            let mut last = 2.0;
            for hits in [0.0f32, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0] {
                let arrival = LightArrival::through(hits);
                let s = arrival.scattered(a_f);
                assert!(arrival.direct + s <= 1.0 + 1e-6, "{a_f} {hits}");
                let total = arrival.direct + s;
                assert!(total <= last + 1e-6, "{a_f} {hits}: {total} > {last}");
                last = total;
            }
        }
        assert_eq!(LightArrival::FULL.scattered(0.9), 0.0);
    }

    /// With multiple scattering off the response is single scattering of the direct light;
    /// with it on, light hair gains much more than dark hair, both lit (local back-scattering:
    /// blond +32%, black +3%) and behind three strand hits (global: blond 23x, black 1.3x).
    #[test]
    fn multiple_scattering_brightens_light_hair_more_than_dark() {
        let t = Vec3::Y;
        let l = Vec3::new(0.3, 0.2, 1.0).normalize();
        let v = Vec3::new(0.5, -0.1, 1.0).normalize();
        for arrival in [LightArrival::FULL, LightArrival::through(3.0)] {
            let gain = |eumelanin: f32| {
                let p = params(melanin_color(eumelanin, 0.0));
                let single = dual_scattering(t, l, v, &p, arrival, false, 1.0);
                let off = crate::shade::marschner(t, l, v, &p)
                    * (hair_angles(t, l, v)[3] * arrival.direct);
                assert!((single - off).abs().max_element() < 1e-6);
                let on = dual_scattering(t, l, v, &p, arrival, true, 1.0);
                assert!(on.cmpge(single).all(), "{on} < {single}");
                on.y / single.y.max(1e-9)
            };
            let (blond, brown, black) = (gain(0.3), gain(1.3), gain(8.0));
            println!(
                "hits {}: gain blond {blond:.2}, brown {brown:.2}, black {black:.3}",
                arrival.hits
            );
            assert!(blond > brown && brown > black, "{blond} {brown} {black}");
            // Behind hair, a little of black hair's TT still gets through.
            let black_most = if arrival.hits == 0.0 { 1.05 } else { 1.5 };
            assert!(black < black_most, "black hair gains {black}");
            assert!(blond > 1.15, "blond hair gains only {blond}");
        }
    }

    /// Seed 000's aggregated model is continuous in the cluster size (a cluster of one is a
    /// strand), dims light leaving through a cluster's far side and adds back-scattering from
    /// its gaps on the light's side, more for larger clusters.
    #[test]
    fn clusters_change_the_look_smoothly() {
        let t = Vec3::Y;
        let l = Vec3::new(0.3, 0.2, 1.0).normalize();
        let p = params(melanin_color(0.3, 0.1));
        let through = Vec3::new(-0.2, -0.1, -1.0).normalize();
        let back = Vec3::new(0.5, -0.1, 1.0).normalize();
        for v in [through, back] {
            let at = |n: f32| dual_scattering(t, l, v, &p, LightArrival::FULL, true, n);
            assert!((at(1.0) - at(1.0001)).abs().max_element() < 1e-4);
            let (one, four, sixteen) = (at(1.0), at(2.0), at(4.0));
            println!("{v}: cluster 1 {one}, 4 strands {four}, 16 strands {sixteen}");
            if v == through {
                assert!(
                    four.y < one.y && sixteen.y < four.y,
                    "{one} {four} {sixteen}"
                );
            } else {
                assert!(
                    four.y > one.y && sixteen.y > four.y,
                    "{one} {four} {sixteen}"
                );
            }
        }
    }
}
