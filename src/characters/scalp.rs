//! The scalp a hairstyle grows from, as a surface to draw, and how much of it shows through
//! the hair. A real scalp carries 150-200 hairs per cm² and shows only at partings; the
//! measure here says how far a picture is from that.
//!
//! The scalp is the hair mesh's root faces, each cut into `k x k` quads and laid just above
//! the head ([`scalp_triangles`]). Drawn as a prop in two colours, with the hair and without
//! it, it gives each pixel's transmittance through the hair: the hair composites over the scalp
//! as `C = H + T S`, so the two colours' difference is `T` times the bare scalp's difference
//! ([`ShowThrough::measure`]). The scalp's pixels are where the bare frames differ; the share
//! whose `T` is above one half is what a viewer sees as scalp through the hair.

use glam::Vec3;

use super::person::PlacedHead;
use crate::model::hair_mesh::HairMesh;

/// Height of the drawn scalp above the head, metres (over the head mesh, under the roots).
pub const SCALP_LIFT: f32 = 0.0015;

/// The root faces of `mesh`, each cut into `k x k` quads (two triangles each) and laid
/// [`SCALP_LIFT`] above `head`, in the hair's frame.
pub fn scalp_triangles(mesh: &HairMesh, head: &PlacedHead, k: usize) -> Vec<[Vec3; 3]> {
    let roots = &mesh.layers[0];
    let mut tris = Vec::with_capacity(mesh.faces.len() * k * k * 2);
    for f in &mesh.faces {
        let v: Vec<Vec3> = f.vertices().iter().map(|&i| roots[i as usize]).collect();
        let (a, b, c, d) = match v.as_slice() {
            [a, b, c] => (*a, *b, *c, *c),
            [a, b, c, d] => (*a, *b, *c, *d),
            _ => continue,
        };
        let at = |s: f32, t: f32| head.project(a.lerp(b, s).lerp(d.lerp(c, s), t), SCALP_LIFT);
        for i in 0..k {
            for j in 0..k {
                let (s0, s1) = (i as f32 / k as f32, (i + 1) as f32 / k as f32);
                let (t0, t1) = (j as f32 / k as f32, (j + 1) as f32 / k as f32);
                let (p00, p10, p11, p01) = (at(s0, t0), at(s1, t0), at(s1, t1), at(s0, t1));
                tris.push([p00, p10, p11]);
                tris.push([p00, p11, p01]);
            }
        }
    }
    tris
}

/// Least difference between the two bare frames (linear RGB, summed over channels) that marks
/// a pixel as scalp: the drawn scalp is in view there, lit well enough to tell.
pub const SCALP_PIXEL_CONTRAST: f32 = 0.05;

/// Transmittance above which a scalp pixel counts as showing through.
pub const SHOWING_TRANSMITTANCE: f32 = 0.5;

/// How much of a frame's scalp shows through its hair.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShowThrough {
    /// Pixels where the scalp is in view without the hair.
    pub scalp_pixels: usize,
    /// Of those, pixels whose light through the hair is above [`SHOWING_TRANSMITTANCE`].
    pub showing: usize,
    /// Mean transmittance over the scalp's pixels.
    pub mean_transmittance: f32,
}

impl ShowThrough {
    /// From four RGBA8 (sRGB) frames of one view: the scalp drawn in colours a and b, each
    /// with the hair (`hair`) and without it (`bare`).
    pub fn measure(hair: [&[u8]; 2], bare: [&[u8]; 2]) -> Self {
        let linear = |c: u8| crate::shade::srgb_to_linear(c as f32 / 255.0);
        let diff = |a: &[u8], b: &[u8]| -> f32 {
            (0..3).map(|c| (linear(a[c]) - linear(b[c])).abs()).sum()
        };
        let (mut out, mut sum) = (ShowThrough::default(), 0.0f64);
        let pixels = hair[0]
            .chunks_exact(4)
            .zip(hair[1].chunks_exact(4))
            .zip(bare[0].chunks_exact(4).zip(bare[1].chunks_exact(4)));
        for ((ha, hb), (ba, bb)) in pixels {
            let scalp = diff(ba, bb);
            if scalp < SCALP_PIXEL_CONTRAST {
                continue;
            }
            let t = (diff(ha, hb) / scalp).min(1.0);
            out.scalp_pixels += 1;
            out.showing += (t > SHOWING_TRANSMITTANCE) as usize;
            sum += t as f64;
        }
        out.mean_transmittance = (sum / out.scalp_pixels.max(1) as f64) as f32;
        out
    }

    /// The share of the scalp's pixels that show through (0 without scalp in view).
    pub fn share(&self) -> f32 {
        self.showing as f32 / self.scalp_pixels.max(1) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Frames made by compositing hair of known transmittance over a scalp of two colours give
    /// that transmittance back: pixels of T = 0.2, 0.6 and 1 (no hair), and background pixels
    /// where the bare frames agree, which are not scalp.
    #[test]
    fn measure_reads_back_the_transmittance_it_was_made_with() {
        let encode = |l: f32| {
            let l = l.clamp(0.0, 1.0);
            let s = match l <= 0.003_130_8 {
                true => 12.92 * l,
                false => 1.055 * l.powf(1.0 / 2.4) - 0.055,
            };
            (s * 255.0).round() as u8
        };
        let scalp = [[0.8f32, 0.1, 0.1], [0.1, 0.1, 0.8]];
        let hair = [0.05f32, 0.04, 0.03];
        let ts = [0.2f32, 0.6, 1.0, 0.2];
        let frame = |colour: usize, with_hair: bool| -> Vec<u8> {
            let mut v = Vec::new();
            for (i, t) in ts.iter().enumerate() {
                for c in 0..3 {
                    let s = scalp[colour][c];
                    let l = match (i, with_hair) {
                        (3, _) => 0.5, // background: the same in every frame
                        (_, true) => hair[c] * (1.0 - t) + t * s,
                        (_, false) => s,
                    };
                    v.push(encode(l));
                }
                v.push(255);
            }
            v
        };
        let (ha, hb, ba, bb) = (
            frame(0, true),
            frame(1, true),
            frame(0, false),
            frame(1, false),
        );
        let m = ShowThrough::measure([&ha, &hb], [&ba, &bb]);
        assert_eq!(m.scalp_pixels, 3);
        assert_eq!(m.showing, 2, "{m:?}");
        assert!(
            (m.mean_transmittance - (0.2 + 0.6 + 1.0) / 3.0).abs() < 0.01,
            "{m:?}"
        );
        assert!((m.share() - 2.0 / 3.0).abs() < 1e-6);
    }
}
