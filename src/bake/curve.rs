//! Strand curves through the layer vertices of one vertex column.
//!
//! Centripetal Catmull-Rom (Yuksel et al. 2009b, as paper 003 section 2.2 uses) is converted to
//! cubic Bezier segments, and each cubic is split into two quadratic Beziers with the method of
//! Truong, Yuksel and Seiler 2020 ("Quadratic Approximation of Cubic Curves"), paper 003
//! section 3.1. A quadratic is evaluated by two linear interpolations (done by the texture
//! filter) followed by one software lerp (de Casteljau).

use glam::Vec3;

/// Knot spacing exponent: 0.5 is the centripetal parameterisation.
pub const CATMULL_ROM_ALPHA: f32 = 0.5;

/// Cubic Bezier control points `[p0, b0+, b1-, p1]` of the Catmull-Rom segment from `p1` to `p2`
/// with neighbours `p0`, `p3` (Barry-Goldman form, non-uniform knots `t_{i+1} = t_i + |dP|^alpha`).
pub fn catmull_rom_to_bezier(p0: Vec3, p1: Vec3, p2: Vec3, p3: Vec3) -> [Vec3; 4] {
    // Knot intervals; a tiny floor keeps coincident points from dividing by zero.
    let knot = |a: Vec3, b: Vec3| a.distance(b).powf(CATMULL_ROM_ALPHA).max(1e-6);
    let d0 = knot(p0, p1);
    let d1 = knot(p1, p2);
    let d2 = knot(p2, p3);
    // Tangents (derivatives w.r.t. the knot parameter) at p1 and p2.
    let m1 = (p1 - p0) / d0 - (p2 - p0) / (d0 + d1) + (p2 - p1) / d1;
    let m2 = (p2 - p1) / d1 - (p3 - p1) / (d1 + d2) + (p3 - p2) / d2;
    [p1, p1 + m1 * (d1 / 3.0), p2 - m2 * (d1 / 3.0), p2]
}

/// Evaluate a cubic Bezier at `t` in `[0, 1]`.
pub fn eval_cubic(b: &[Vec3; 4], t: f32) -> Vec3 {
    let s = 1.0 - t;
    b[0] * (s * s * s) + b[1] * (3.0 * s * s * t) + b[2] * (3.0 * s * t * t) + b[3] * (t * t * t)
}

/// Evaluate a quadratic Bezier by de Casteljau: two lerps (texture filter) and one lerp.
pub fn eval_quadratic(q0: Vec3, q1: Vec3, q2: Vec3, t: f32) -> Vec3 {
    q0.lerp(q1, t).lerp(q1.lerp(q2, t), t)
}

/// Split cubic `b` into two quadratics `[q0 q1 q2]`, `[q2 q3 q4]` joined at `t = 1/2`
/// (Truong et al. 2020 with gamma = 1/2): `q1 = p0 + 3/2 gamma (p1 - p0)`,
/// `q3 = p3 + 3/2 (1 - gamma)(p2 - p3)`, `q2 = (1 - gamma) q1 + gamma q3`. The pair is C1,
/// matches the cubic's end tangents, and its error is `|p3 - 3p2 + 3p1 - p0| / 54` at most.
pub fn cubic_to_quadratics(b: &[Vec3; 4]) -> [Vec3; 5] {
    let gamma = 0.5;
    let q1 = b[0] + (b[1] - b[0]) * (1.5 * gamma);
    let q3 = b[3] + (b[2] - b[3]) * (1.5 * (1.0 - gamma));
    let q2 = q1 * (1.0 - gamma) + q3 * gamma;
    [b[0], q1, q2, q3, b[3]]
}

/// Tight bound of [`cubic_to_quadratics`]'s deviation from the cubic at equal parameters.
pub fn quadratic_error_bound(b: &[Vec3; 4]) -> f32 {
    (b[3] - b[2] * 3.0 + b[1] * 3.0 - b[0]).length() / 54.0
}

/// Phantom end points for a column `p[0..L]`: reflections `2 p0 - p1` and `2 p_{L-1} - p_{L-2}`,
/// which give the end segments a natural (zero-curvature-like) end tangent.
fn column_point(p: &[Vec3], i: isize) -> Vec3 {
    let last = p.len() as isize - 1;
    if i < 0 {
        p[0] * 2.0 - p[1]
    } else if i > last {
        p[last as usize] * 2.0 - p[last as usize - 1]
    } else {
        p[i as usize]
    }
}

/// The `4 (L - 1) + 1` control points of a vertex column along the hair mesh texture's `r*`
/// axis: each layer vertex followed by three intermediate points `q1 q2 q3` of its segment.
pub fn column_control_points(p: &[Vec3]) -> Vec<Vec3> {
    assert!(p.len() >= 2, "a column needs at least 2 layers");
    let mut out = Vec::with_capacity(4 * (p.len() - 1) + 1);
    for j in 0..p.len() - 1 {
        let j = j as isize;
        let b = catmull_rom_to_bezier(
            column_point(p, j - 1),
            column_point(p, j),
            column_point(p, j + 1),
            column_point(p, j + 2),
        );
        let q = cubic_to_quadratics(&b);
        out.extend_from_slice(&q[..4]);
    }
    out.push(*p.last().unwrap());
    out
}

/// Evaluate a column's control points at curve parameter `r` in `[0, L - 1]` (layer units),
/// exactly as the texture path does: segment `j`, half `h`, local `t`, one quadratic.
pub fn eval_column(ctrl: &[Vec3], r: f32) -> Vec3 {
    let (slice, t) = quadratic_slice(r, (ctrl.len() - 1) / 4 + 1);
    eval_quadratic(ctrl[slice], ctrl[slice + 1], ctrl[slice + 2], t)
}

/// Map curve parameter `r` in `[0, L-1]` to the first slice of its quadratic and the local `t`.
pub fn quadratic_slice(r: f32, layers: usize) -> (usize, f32) {
    let segs = (layers - 1) as f32;
    let r = r.clamp(0.0, segs);
    let j = (r.floor() as usize).min(layers - 2);
    let tau = r - j as f32;
    if tau < 0.5 {
        (4 * j, tau * 2.0)
    } else {
        (4 * j + 2, tau * 2.0 - 1.0)
    }
}

/// Tangents of a polyline by section 3.5: central differences inside, eq. 5 and 6 at the ends.
pub fn strand_tangents(p: &[Vec3], out: &mut [Vec3]) {
    let m = p.len() - 1;
    if m == 0 {
        out[0] = Vec3::Y;
        return;
    }
    if m == 1 {
        let d = (p[1] - p[0]).normalize_or(Vec3::Y);
        out[0] = d;
        out[1] = d;
        return;
    }
    for k in 1..m {
        out[k] = (p[k + 1] - p[k - 1]).normalize_or(Vec3::Y);
    }
    // Eq. 5: mirror t_{m-1} about the last segment direction q_m.
    let q = (p[m] - p[m - 1]).normalize_or(out[m - 1]);
    out[m] = (q * (2.0 * out[m - 1].dot(q)) - out[m - 1]).normalize_or(q);
    // Eq. 6: mirror t_1 about the first segment direction q_1.
    let q = (p[1] - p[0]).normalize_or(out[1]);
    out[0] = (q * (2.0 * out[1].dot(q)) - out[1]).normalize_or(q);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Direct Barry-Goldman pyramid evaluation of a centripetal Catmull-Rom segment.
    fn barry_goldman(p: [Vec3; 4], u: f32) -> Vec3 {
        let mut t = [0.0f32; 4];
        for i in 1..4 {
            t[i] = t[i - 1] + p[i].distance(p[i - 1]).powf(0.5);
        }
        let tt = t[1] + (t[2] - t[1]) * u;
        let l = |a: Vec3, b: Vec3, ta: f32, tb: f32| {
            a * ((tb - tt) / (tb - ta)) + b * ((tt - ta) / (tb - ta))
        };
        let a1 = l(p[0], p[1], t[0], t[1]);
        let a2 = l(p[1], p[2], t[1], t[2]);
        let a3 = l(p[2], p[3], t[2], t[3]);
        let b1 = l(a1, a2, t[0], t[2]);
        let b2 = l(a2, a3, t[1], t[3]);
        l(b1, b2, t[1], t[2])
    }

    fn rng_points(seed: u32) -> [Vec3; 4] {
        let mut r = crate::rng::Pcg32::new(seed as u64);
        let mut p = [Vec3::ZERO; 4];
        for (i, q) in p.iter_mut().enumerate() {
            *q = Vec3::new(r.next_f32(), r.next_f32(), r.next_f32()) * 2.0 + Vec3::X * i as f32;
        }
        p
    }

    #[test]
    fn bezier_matches_centripetal_catmull_rom() {
        for seed in 0..50 {
            let p = rng_points(seed);
            let b = catmull_rom_to_bezier(p[0], p[1], p[2], p[3]);
            for i in 0..=20 {
                let u = i as f32 / 20.0;
                let d = eval_cubic(&b, u).distance(barry_goldman(p, u));
                assert!(d < 1e-4, "seed {seed} u {u}: bezier off the spline by {d}");
            }
        }
    }

    #[test]
    fn quadratic_pair_within_truong_bound() {
        let mut tight = 0.0f32;
        for seed in 0..200 {
            let p = rng_points(seed);
            let b = catmull_rom_to_bezier(p[0], p[1], p[2], p[3]);
            let q = cubic_to_quadratics(&b);
            let bound = quadratic_error_bound(&b);
            let mut worst = 0.0f32;
            for i in 0..=200 {
                let t = i as f32 / 200.0;
                let approx = if t < 0.5 {
                    eval_quadratic(q[0], q[1], q[2], t * 2.0)
                } else {
                    eval_quadratic(q[2], q[3], q[4], t * 2.0 - 1.0)
                };
                worst = worst.max(approx.distance(eval_cubic(&b, t)));
            }
            assert!(
                worst <= bound * 1.001 + 1e-5,
                "seed {seed}: error {worst} > bound {bound}"
            );
            if bound > 1e-3 {
                tight = tight.max(worst / bound);
            }
        }
        assert!(tight > 0.95, "bound should be attained, best ratio {tight}");
    }

    #[test]
    fn quadratic_pair_is_c1_and_interpolates() {
        let b = catmull_rom_to_bezier(
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(2.0, 1.0, 0.0),
            Vec3::new(2.0, 3.0, 1.0),
        );
        let q = cubic_to_quadratics(&b);
        assert_eq!(q[0], b[0]);
        assert_eq!(q[4], b[3]);
        // Derivative of each half w.r.t. the cubic's t: 2 (q_{i+1} - q_i) / (1/2).
        let c1 = (q[2] - q[1]) - (q[3] - q[2]);
        assert!(c1.length() < 1e-6, "joint must be C1");
        assert!(
            ((q[1] - q[0]) * 4.0 - (b[1] - b[0]) * 3.0).length() < 1e-5,
            "start tangent"
        );
    }

    /// Section 3.5's tangents are exact on a uniformly sampled circular arc: central
    /// differences inside (the chord of two neighbours is parallel to the middle tangent), and
    /// eq. 5 and 6's mirror about the end chords at both ends (the chord's symmetry); a lone
    /// segment gives both ends its direction, a lone point +Y.
    #[test]
    fn tangents_are_exact_on_a_circular_arc() {
        let theta = |k: usize| 0.3 * k as f32 + 0.2;
        let p: Vec<Vec3> = (0..6)
            .map(|k| Vec3::new(theta(k).cos(), theta(k).sin(), 0.5))
            .collect();
        let mut t = vec![Vec3::ZERO; 6];
        strand_tangents(&p, &mut t);
        for (k, t) in t.iter().enumerate() {
            let want = Vec3::new(-theta(k).sin(), theta(k).cos(), 0.0);
            assert!(t.dot(want) > 1.0 - 1e-5, "{k}: {t} vs {want}");
        }
        let mut two = [Vec3::ZERO; 2];
        strand_tangents(&[Vec3::ZERO, Vec3::new(0.0, 0.0, -2.0)], &mut two);
        assert_eq!(two, [Vec3::NEG_Z; 2]);
        let mut one = [Vec3::ZERO];
        strand_tangents(&[Vec3::ONE], &mut one);
        assert_eq!(one, [Vec3::Y]);
    }

    #[test]
    fn column_passes_through_layers() {
        let p = vec![
            Vec3::ZERO,
            Vec3::Y,
            Vec3::new(1.0, 2.0, 0.0),
            Vec3::new(3.0, 2.5, 0.5),
        ];
        let ctrl = column_control_points(&p);
        assert_eq!(ctrl.len(), 13);
        for (k, pk) in p.iter().enumerate() {
            assert!(
                eval_column(&ctrl, k as f32).distance(*pk) < 1e-6,
                "layer {k}"
            );
        }
    }
}
