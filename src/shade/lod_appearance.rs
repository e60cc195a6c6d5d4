//! Thick-strand appearance under strand LoD: the CPU twin of `glsl/lod_appearance.glsl`
//! (seed 000 sec. 4). A strip standing for `k` strands is drawn at least `sqrt(k)` times one
//! strand's drawn width, the smaller of a pixel and its own (seed 000's cluster diameter
//! `2 r sqrt(n / rho)` with `rho = 1`, capped by the bundle), and its opacity is that of `k`
//! strands lying independently across it.

/// Least drawn width of a strip of `thickness` strands each `single` wide, for pixel size
/// `pixel` and bundle size `cap` (same units); `term` off gives the single-strand one pixel.
pub fn cluster_min_width(pixel: f32, thickness: f32, cap: f32, single: f32, term: bool) -> f32 {
    if !term {
        return pixel;
    }
    pixel.max((thickness.max(1.0).sqrt() * pixel.min(single)).min(cap))
}

/// Opacity of a strip of `thickness` strands whose single-strand opacity over the pixel is
/// `alpha`: `1 - (1 - alpha / k)^k`.
pub fn cluster_opacity(alpha: f32, thickness: f32, term: bool) -> f32 {
    if !term || thickness <= 1.0 {
        return alpha;
    }
    1.0 - (1.0 - alpha / thickness).max(0.0).powf(thickness)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_strand_is_unchanged_and_clusters_saturate() {
        assert_eq!(cluster_opacity(0.7, 1.0, true), 0.7);
        assert_eq!(cluster_opacity(0.7, 8.0, false), 0.7);
        assert_eq!(cluster_min_width(0.01, 1.0, 1.0, 0.02, true), 0.01);
        // Poisson limit exp(-a) from above, monotone in k.
        let mut last = 0.7;
        for k in [2.0, 4.0, 16.0, 256.0, 4096.0] {
            let a = cluster_opacity(0.7, k, true);
            assert!(a < last && a > 1.0 - (-0.7f32).exp() - 1e-4, "k {k}: {a}");
            last = a;
        }
        assert!((last - (1.0 - (-0.7f32).exp())).abs() < 1e-3);
        // sqrt(k) pixels for strands a pixel wide or more, capped by the bundle, never under a
        // pixel; sqrt(k) strand widths for thinner ones.
        assert!((cluster_min_width(0.01, 16.0, 1.0, 0.02, true) - 0.04).abs() < 1e-6);
        assert_eq!(cluster_min_width(0.01, 16.0, 0.02, 0.02, true), 0.02);
        assert_eq!(cluster_min_width(0.01, 16.0, 0.001, 0.02, true), 0.01);
        assert!((cluster_min_width(0.01, 64.0, 1.0, 0.002, true) - 0.016).abs() < 1e-6);
        assert_eq!(cluster_min_width(0.01, 4.0, 1.0, 0.002, true), 0.01);
    }
}
