//! The Marschner lookup texture (seed 001's idea: precompute the expensive parts of the
//! appearance model into small tables at start-up). The colour-independent azimuthal factors
//! of the TT and TRT lobes ([`super::azimuthal_factors`]: a square root, two Fresnel terms and
//! two exponentials) are tabulated over `(cos(phi), cos(theta_d))`; `glsl/hair_shading.glsl`
//! reads them with bilinear filtering and applies the per-strand colour and the Gaussian
//! longitudinal terms, which are cheap, directly.
//!
//! The same texture holds the dual scattering tables ([`super::scattering::lobe_energies`]):
//! the energy each lobe sends into the front and back halves of azimuth, over
//! `(sqrt(c), cos(theta_d))` for one colour channel `c`, read once per channel.
//!
//! Layout: `SHADING_LUT_WIDTH x SHADING_LUT_HEIGHT` texels of `R16G16B16A16_UNORM`, three
//! tables stacked in rows (a lookup keeps its coordinates between its table's first and last
//! texel centres, so bilinear filtering never mixes tables):
//! - rows `0..MARSCHNER_LUT_D`: texel `(i, j)` holds the Marschner factors at
//!   `cos(phi) = -1 + 2 i / (PHI - 1)`, `cos(theta_d) = j / (D - 1)`: r the TT path, g the TT
//!   attenuation, b the TRT attenuation times `MARSCHNER_LUT_TRT_SCALE`, a 0;
//! - the next `SCATTER_LUT_THETA` rows: texel `(i, j)` holds the front energies of R, TT, TRT
//!   (rgb) at `sqrt(c) = i / (W - 1)`, `cos(theta_d) = j / (THETA - 1)`;
//! - the last `SCATTER_LUT_THETA` rows: the back energies, likewise.

/// Texels over `cos(phi)`.
pub const MARSCHNER_LUT_PHI: u32 = 256;
/// Texels over `cos(theta_d)`.
pub const MARSCHNER_LUT_D: u32 = 64;
/// Scale of the TRT attenuation channel (its largest value is 0.185).
pub const MARSCHNER_LUT_TRT_SCALE: f32 = 5.0;
/// Rows of each dual scattering table (over `cos(theta_d)`); its columns (over `sqrt(c)`)
/// are the texture's width.
pub const SCATTER_LUT_THETA: u32 = 32;
/// Width of the shading lookup texture.
pub const SHADING_LUT_WIDTH: u32 = MARSCHNER_LUT_PHI;
/// Height of the shading lookup texture: the Marschner table and the two scattering tables.
pub const SHADING_LUT_HEIGHT: u32 = MARSCHNER_LUT_D + 2 * SCATTER_LUT_THETA;

/// `(sqrt(c), cos(theta_d))` of texel `(i, j)` of a scattering table.
pub fn scatter_texel(i: u32, j: u32) -> (f32, f32) {
    (
        i as f32 / (SHADING_LUT_WIDTH - 1) as f32,
        j as f32 / (SCATTER_LUT_THETA - 1) as f32,
    )
}

/// `(cos(phi), cos(theta_d))` of texel `(i, j)`.
pub fn texel_angles(i: u32, j: u32) -> (f32, f32) {
    (
        -1.0 + 2.0 * i as f32 / (MARSCHNER_LUT_PHI - 1) as f32,
        j as f32 / (MARSCHNER_LUT_D - 1) as f32,
    )
}

fn unorm(x: f32) -> u16 {
    (x.clamp(0.0, 1.0) * 65535.0).round() as u16
}

/// The whole texture's texels, row by row: the Marschner table, then the front and back
/// scattering tables. Computed once per process (about 20 ms).
pub fn shading_lut() -> &'static [[u16; 4]] {
    static LUT: std::sync::OnceLock<Vec<[u16; 4]>> = std::sync::OnceLock::new();
    LUT.get_or_init(|| {
        let mut texels = marschner_lut();
        let rows: Vec<Vec<super::scattering::LobeEnergies>> = (0..SCATTER_LUT_THETA)
            .map(|j| {
                (0..SHADING_LUT_WIDTH)
                    .map(|i| {
                        let (u, cos_d) = scatter_texel(i, j);
                        super::scattering::lobe_energies(cos_d, u * u)
                    })
                    .collect()
            })
            .collect();
        for half in 0..2 {
            for row in &rows {
                texels.extend(row.iter().map(|e| {
                    let h = if half == 0 { e.front } else { e.back };
                    [unorm(h[0]), unorm(h[1]), unorm(h[2]), 0]
                }));
            }
        }
        texels
    })
}

/// The Marschner table's texels, row by row (`cos(theta_d)` rows).
pub fn marschner_lut() -> Vec<[u16; 4]> {
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
        assert_eq!(
            shading_lut().len() as u32,
            SHADING_LUT_WIDTH * SHADING_LUT_HEIGHT
        );
    }

    /// Bilinear lookups of the scattering tables (as `lobe_energies` in hair_shading.glsl
    /// reads them) stay within 1% of the largest energy of the computed ones, over all
    /// colours and angles.
    #[test]
    fn scattering_tables_match_the_computed_energies() {
        let lut = shading_lut();
        let (w, t) = (SHADING_LUT_WIDTH as usize, SCATTER_LUT_THETA as usize);
        let mut rng = crate::rng::Pcg32::new(5);
        let mut worst = 0.0f32;
        for _ in 0..4000 {
            let c = rng.next_f32();
            let cos_d = 0.05 + 0.95 * rng.next_f32();
            let x = c.sqrt() * (w - 1) as f32;
            let y = cos_d * (t - 1) as f32;
            let (i, j) = ((x as usize).min(w - 2), (y as usize).min(t - 2));
            let (fx, fy) = (x - i as f32, y - j as f32);
            let e = crate::shade::scattering::lobe_energies(cos_d, c);
            for (half, want) in [e.front, e.back].iter().enumerate() {
                let row0 = MARSCHNER_LUT_D as usize + half * t;
                let texel =
                    |i: usize, j: usize| lut[(row0 + j) * w + i].map(|v| v as f32 / 65535.0);
                for (k, want) in want.iter().enumerate() {
                    let top = texel(i, j)[k] * (1.0 - fx) + texel(i + 1, j)[k] * fx;
                    let bottom = texel(i, j + 1)[k] * (1.0 - fx) + texel(i + 1, j + 1)[k] * fx;
                    worst = worst.max((top * (1.0 - fy) + bottom * fy - want).abs());
                }
            }
        }
        println!("worst scattering table error {worst:e}");
        assert!(worst < 0.01, "{worst}");
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
