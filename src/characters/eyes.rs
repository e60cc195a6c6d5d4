//! Eyes that read as eyes in a portrait: an eyeball banded into pupil, iris (with a darker
//! limbal ring) and sclera, looking along the head's forward axis (+Z), glossy as a wet
//! cornea is, under an upper lid that covers the top of the iris and a lower lid that meets
//! its bottom, the lids' edges darkened as lashes darken them. The lids are skin: they join
//! the bust's mesh (tinted by the person's skin tone); the eyeballs are a mesh of their own.
//!
//! Proportions follow an adult eye: an iris of 11.7 mm on a 24 mm eyeball spans 29 degrees
//! either side of the eye's axis, a daylight pupil of 3.5 mm 8.5 degrees; an open upper lid
//! rests about 1.5 mm over the iris's top, the lower lid at its bottom edge.

use glam::Vec3;

use super::human::Eye;
use crate::render::core::shared::PropVertex;

/// Half-angle of the pupil seen from the eyeball's centre, radians.
pub const PUPIL_HALF_ANGLE: f32 = 0.148;
/// Half-angle of the iris (its outer edge, the limbus), radians.
pub const IRIS_HALF_ANGLE: f32 = 0.506;
/// Elevation of the upper lid's edge above the eye's axis, radians: the lid covers the
/// iris's top by about an eighth of its height.
pub const UPPER_LID_ELEVATION: f32 = 0.38;
/// Elevation of the lower lid's edge (below the axis), radians: at the iris's bottom.
pub const LOWER_LID_ELEVATION: f32 = -0.5;
/// The lids' shell radius in eyeball radii: just outside the eyeball, as lids rest on it.
pub const LID_RADIUS: f32 = 1.02;
// The upper lid covers the iris's top and leaves the pupil open; the lower meets the iris.
const _: () =
    assert!(UPPER_LID_ELEVATION < IRIS_HALF_ANGLE && UPPER_LID_ELEVATION > PUPIL_HALF_ANGLE);
const _: () = assert!(LOWER_LID_ELEVATION <= -IRIS_HALF_ANGLE * 0.95);

/// The eyeball's GGX roughness: a wet cornea, a small sharp highlight.
pub const EYE_ROUGHNESS: f32 = 0.2;

/// Colours (linear RGB) of the eyeball's bands from the front: pupil, inner iris, outer
/// iris, limbal ring, then sclera.
const BANDS: [(f32, [f32; 3]); 5] = [
    (PUPIL_HALF_ANGLE, [0.008, 0.007, 0.007]),
    (0.3, [0.13, 0.08, 0.045]),
    (0.45, [0.105, 0.065, 0.037]),
    (IRIS_HALF_ANGLE, [0.05, 0.035, 0.026]),
    (std::f32::consts::PI, [0.62, 0.58, 0.55]),
];

/// Azimuthal segments of the eyeball and lids.
const SEGMENTS: usize = 28;

/// A triangle of the eyeball with its colour.
pub type ColoredTriangle = ([PropVertex; 3], [f32; 3]);

/// One eyeball, centred on `eye`, its pole on +Z: rings at the bands' edges (and between, so
/// the sclera stays round), each band's triangles in its colour, normals the sphere's.
pub fn eyeball(eye: &Eye) -> Vec<ColoredTriangle> {
    let mut rings = vec![(0.0, BANDS[0].1)];
    let mut from = 0.0;
    for (edge, color) in BANDS {
        let steps = (((edge - from) / 0.25).ceil() as usize).max(1);
        for k in 1..=steps {
            rings.push((from + (edge - from) * k as f32 / steps as f32, color));
        }
        from = edge;
    }
    let vertex = |theta: f32, phi: f32| {
        let d = Vec3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        );
        PropVertex {
            position: (eye.centre + d * eye.radius).extend(1.0).to_array(),
            normal: d.extend(0.0).to_array(),
        }
    };
    let mut out = Vec::new();
    for w in rings.windows(2) {
        let ((t0, _), (t1, color)) = (w[0], w[1]);
        for s in 0..SEGMENTS {
            let (p0, p1) = (phi(s), phi(s + 1));
            let (a, b) = (vertex(t0, p0), vertex(t0, p1));
            let (c, d) = (vertex(t1, p0), vertex(t1, p1));
            if t0 > 0.0 {
                out.push(([a, c, b], color));
            }
            out.push(([b, c, d], color));
        }
    }
    out
}

/// Azimuth of segment `s`.
fn phi(s: usize) -> f32 {
    std::f32::consts::TAU * s as f32 / SEGMENTS as f32
}

/// The lids of `eye`: two caps of a sphere of [`LID_RADIUS`] eyeball radii, the upper from
/// straight up down to [`UPPER_LID_ELEVATION`] in front, the lower from straight down up to
/// [`LOWER_LID_ELEVATION`], each ending in a lash line (the last ring's band). Returns the
/// skin triangles and the lash-line ones (drawn dark).
pub fn lids(eye: &Eye) -> (Vec<[Vec3; 3]>, Vec<[Vec3; 3]>) {
    let r = eye.radius * LID_RADIUS;
    let mut skin = Vec::new();
    let mut lashes = Vec::new();
    for (pole, edge) in [(1.0f32, UPPER_LID_ELEVATION), (-1.0, LOWER_LID_ELEVATION)] {
        // A cap about the pole (+-Y): polar angle from the pole to the edge's elevation
        // along the front (+Z), then the lash band (0.1 rad above, where lashes are thick,
        // 0.04 below).
        let rim = std::f32::consts::FRAC_PI_2 - edge * pole;
        let point = |angle: f32, s: usize| {
            let a = phi(s);
            let d = Vec3::new(
                angle.sin() * a.cos(),
                pole * angle.cos(),
                angle.sin() * a.sin(),
            );
            eye.centre + d * r
        };
        let steps = 8;
        for k in 0..=steps {
            let (t0, t1) = if k < steps {
                (
                    rim * k as f32 / steps as f32,
                    rim * (k + 1) as f32 / steps as f32,
                )
            } else {
                (rim, rim + if pole > 0.0 { 0.1 } else { 0.04 })
            };
            let target = if k < steps { &mut skin } else { &mut lashes };
            for s in 0..SEGMENTS {
                let (a, b) = (point(t0, s), point(t0, s + 1));
                let (c, d) = (point(t1, s), point(t1, s + 1));
                // Outward-facing winding for either pole.
                let (quad0, quad1) = if pole > 0.0 {
                    ([a, b, c], [b, d, c])
                } else {
                    ([a, c, b], [b, c, d])
                };
                if k > 0 {
                    target.push(quad0);
                }
                target.push(quad1);
            }
        }
    }
    (skin, lashes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_eye() -> Eye {
        super::super::human::human_head().unwrap().eyes.unwrap()[0]
    }

    /// The iris looks along the head's forward axis: the pupil's band is centred on +Z within
    /// a hundredth of a radian, and the bands run pupil, iris, sclera from the front.
    #[test]
    fn the_iris_looks_forward() {
        let eye = sample_eye();
        let tris = eyeball(&eye);
        let pupil = BANDS[0].1;
        let (mut sum, mut n) = (Vec3::ZERO, 0);
        for (t, color) in &tris {
            for v in t {
                let d = (Vec3::from_slice(&v.position[..3]) - eye.centre).normalize();
                let theta = d.z.clamp(-1.0, 1.0).acos();
                if *color == pupil {
                    sum += d;
                    n += 1;
                    assert!(theta <= PUPIL_HALF_ANGLE + 1e-4, "pupil vertex at {theta}");
                }
            }
        }
        let axis = (sum / n as f32).normalize();
        let off = axis.angle_between(Vec3::Z);
        assert!(off < 0.01, "pupil axis {axis} is {off} rad off +Z");
        // Every vertex lies on the sphere, with the sphere's normal.
        for (t, _) in &tris {
            for v in t {
                let p = Vec3::from_slice(&v.position[..3]);
                let r = p.distance(eye.centre);
                assert!((r - eye.radius).abs() < 1e-5 * eye.radius.max(1.0));
                let n = Vec3::from_slice(&v.normal[..3]);
                assert!(n.distance((p - eye.centre) / r) < 1e-4);
            }
        }
    }

    /// The lids close the socket: every rim point of the socket above the upper lid's edge
    /// (or below the lower's) lies inside the lid shell, so the lid passes over the skin's
    /// edge with no gap, and no deeper than 0.7 of the shell's radius, so the lid does not
    /// stand far off the skin (measured: rim points at 0.77-0.96 of the shell's radius); the
    /// lids stay outside the eyeball; the upper lid covers the iris's top and leaves the
    /// pupil open, the lower meets the iris's bottom.
    #[test]
    fn the_lids_close_the_socket_rim_and_cover_the_top_of_the_iris() {
        let head = super::super::human::human_head().unwrap();
        let eye = sample_eye();
        let (skin, lashes) = lids(&eye);
        assert!(!skin.is_empty() && !lashes.is_empty());
        for t in skin.iter().chain(&lashes) {
            for p in t {
                assert!(p.distance(eye.centre) > eye.radius * 1.01);
            }
        }
        let rim =
            super::super::human::socket_rim(&head.triangles, &eye).expect("the eye's socket rim");
        let lid = eye.radius * LID_RADIUS;
        let mut covered = 0;
        let (mut lo, mut hi) = (f32::MAX, 0.0f32);
        for p in &rim {
            let d = (*p - eye.centre).normalize();
            let elevation = d.y.asin();
            if !(LOWER_LID_ELEVATION..=UPPER_LID_ELEVATION).contains(&elevation) {
                covered += 1;
                let r = p.distance(eye.centre) / lid;
                (lo, hi) = (lo.min(r), hi.max(r));
            }
        }
        println!("rim under the lids at {lo:.3}-{hi:.3} of the lid shell's radius");
        assert!(lo > 0.7 && hi < 1.0, "{lo}-{hi}");
        assert!(covered >= 3, "{covered} of {} rim points", rim.len());
    }
}
