//! The Marschner lookup texture (seed 001's idea: precompute the expensive parts of the
//! appearance model into small tables at start-up). The colour-independent azimuthal factors
//! of the TT and TRT lobes ([`super::azimuthal_factors`]: a square root, two Fresnel terms and
//! two exponentials) are tabulated over `(cos(phi), cos(theta_d))`; `glsl/hair_shading.glsl`
//! reads them with bilinear filtering and applies the per-strand colour and the Gaussian
//! longitudinal terms, which are cheap, directly.
//!
//! Layout: `MARSCHNER_LUT_PHI x MARSCHNER_LUT_D` texels of `R16G16B16A16_UNORM`: texel `(i, j)`
//! holds the factors at `cos(phi) = -1 + 2 i / (PHI - 1)`, `cos(theta_d) = j / (D - 1)`: r the TT
//! path, g the TT attenuation, b the TRT attenuation times `MARSCHNER_LUT_TRT_SCALE`, a 0.

/// Texels over `cos(phi)`.
pub const MARSCHNER_LUT_PHI: u32 = 256;
/// Texels over `cos(theta_d)`.
pub const MARSCHNER_LUT_D: u32 = 64;
/// Scale of the TRT attenuation channel (its largest value is 0.185).
pub const MARSCHNER_LUT_TRT_SCALE: f32 = 5.0;

/// `(cos(phi), cos(theta_d))` of texel `(i, j)`.
pub fn texel_angles(i: u32, j: u32) -> (f32, f32) {
    (
        -1.0 + 2.0 * i as f32 / (MARSCHNER_LUT_PHI - 1) as f32,
        j as f32 / (MARSCHNER_LUT_D - 1) as f32,
    )
}

/// The table's texels, row by row (`cos(theta_d)` rows).
pub fn marschner_lut() -> Vec<[u16; 4]> {
    let unorm = |x: f32| (x.clamp(0.0, 1.0) * 65535.0).round() as u16;
    let mut texels = Vec::with_capacity((MARSCHNER_LUT_PHI * MARSCHNER_LUT_D) as usize);
    for j in 0..MARSCHNER_LUT_D {
        for i in 0..MARSCHNER_LUT_PHI {
            let (cos_phi, cos_d) = texel_angles(i, j);
            let f = super::azimuthal_factors(cos_phi, cos_d);
            texels.push([
                unorm(f.tt_path),
                unorm(f.tt),
                unorm(f.trt * MARSCHNER_LUT_TRT_SCALE),
                0,
            ]);
        }
    }
    texels
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every factor fits the UNORM range with its scale (nothing clamps), and the TRT channel
    /// uses most of it.
    #[test]
    fn factors_fit_the_texture_format() {
        let mut trt_max = 0.0f32;
        for j in 0..MARSCHNER_LUT_D {
            for i in 0..MARSCHNER_LUT_PHI {
                let (cos_phi, cos_d) = texel_angles(i, j);
                let f = super::super::azimuthal_factors(cos_phi, cos_d);
                assert!((0.0..=1.0).contains(&f.tt_path), "{f:?}");
                assert!((0.0..=1.0).contains(&f.tt), "{f:?}");
                let trt = f.trt * MARSCHNER_LUT_TRT_SCALE;
                assert!((0.0..=1.0).contains(&trt), "{f:?}");
                trt_max = trt_max.max(trt);
            }
        }
        assert!(trt_max > 0.5, "TRT scale wastes precision: max {trt_max}");
        assert_eq!(
            marschner_lut().len() as u32,
            MARSCHNER_LUT_PHI * MARSCHNER_LUT_D
        );
    }

    /// Bilinear lookups (as the GPU samples it) between the texel centres stay close to the
    /// analytic factors: the table is fine enough for the sharp TRT peak near cos(phi) = 1.
    #[test]
    fn bilinear_lookup_matches_the_analytic_factors() {
        let lut = marschner_lut();
        let (w, h) = (MARSCHNER_LUT_PHI as usize, MARSCHNER_LUT_D as usize);
        let texel = |i: usize, j: usize| lut[j * w + i].map(|c| c as f32 / 65535.0);
        let mut rng = crate::rng::Pcg32::new(3);
        let mut worst = [0.0f32; 3];
        for _ in 0..20000 {
            let cos_phi = rng.next_f32() * 2.0 - 1.0;
            // cos(theta_d) >= cos(45 deg) covers light and eye within 90 degrees of each other
            // in theta; below, the TT path term grows steep but is weighted by tiny lobes.
            let cos_d = 0.7 + 0.3 * rng.next_f32();
            let x = (0.5 + 0.5 * cos_phi) * (w - 1) as f32;
            let y = cos_d * (h - 1) as f32;
            let (i, j) = ((x as usize).min(w - 2), (y as usize).min(h - 2));
            let (fx, fy) = (x - i as f32, y - j as f32);
            let v: [f32; 4] = std::array::from_fn(|c| {
                let top = texel(i, j)[c] * (1.0 - fx) + texel(i + 1, j)[c] * fx;
                let bottom = texel(i, j + 1)[c] * (1.0 - fx) + texel(i + 1, j + 1)[c] * fx;
                top * (1.0 - fy) + bottom * fy
            });
            let f = super::super::azimuthal_factors(cos_phi, cos_d);
            let errs = [
                (v[0] - f.tt_path).abs(),
                (v[1] - f.tt).abs() / f.tt.max(1e-2),
                (v[2] / MARSCHNER_LUT_TRT_SCALE - f.trt).abs() / f.trt.max(1e-3),
            ];
            for (w, e) in worst.iter_mut().zip(errs) {
                *w = w.max(e);
            }
        }
        println!(
            "worst: TT path {:e}, TT {:e}, TRT {:e}",
            worst[0], worst[1], worst[2]
        );
        assert!(
            worst[0] < 2e-3 && worst[1] < 1e-2 && worst[2] < 1e-2,
            "{worst:?}"
        );
    }
}
