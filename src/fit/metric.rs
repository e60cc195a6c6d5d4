//! How close a fitted hair mesh comes to the strands it was fitted to: two-sided distances
//! between the strand sets and root coverage, in units of the input's bounding-box diagonal.

use std::collections::HashMap;

use glam::Vec3;

use crate::model::strands::{point_at_length, polyline_length};

/// Points sampled per strand for the distances.
pub const SAMPLES_PER_STRAND: usize = 16;

/// Distances and coverage of one comparison.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Fidelity {
    /// Input strand points to the nearest fitted strand: mean and 95th percentile (fractions
    /// of the diagonal).
    pub input_to_fit: (f32, f32),
    /// Fitted strand points to the nearest input strand: mean and 95th percentile.
    pub fit_to_input: (f32, f32),
    /// Both directions together: mean and 95th percentile.
    pub two_sided: (f32, f32),
    /// Share of input roots within one bundle size of a fitted root.
    pub coverage: f32,
}

impl std::fmt::Display for Fidelity {
    /// Distances in % of the diagonal, then coverage.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let pct = |x: f32| 100.0 * x;
        write!(
            f,
            "two-sided mean {:.2}% p95 {:.2}%; input->fit mean {:.2}% p95 {:.2}%; fit->input mean {:.2}% p95 {:.2}%; coverage {:.1}%",
            pct(self.two_sided.0),
            pct(self.two_sided.1),
            pct(self.input_to_fit.0),
            pct(self.input_to_fit.1),
            pct(self.fit_to_input.0),
            pct(self.fit_to_input.1),
            pct(self.coverage)
        )
    }
}

/// Nearest-point queries over points densely sampled along polylines (spacing at most
/// `spacing`, so a distance is off by at most half of it), hashed into a uniform grid.
struct Nearest {
    cell: f32,
    grid: HashMap<(i32, i32, i32), Vec<Vec3>>,
}

impl Nearest {
    fn new(points: impl Iterator<Item = Vec3>, cell: f32) -> Self {
        let mut grid: HashMap<(i32, i32, i32), Vec<Vec3>> = HashMap::new();
        for p in points {
            grid.entry(Self::key(p, cell)).or_default().push(p);
        }
        Nearest { cell, grid }
    }

    fn key(p: Vec3, cell: f32) -> (i32, i32, i32) {
        let c = (p / cell).floor();
        (c.x as i32, c.y as i32, c.z as i32)
    }

    /// Distance to the nearest point, searching rings of cells outward (up to `max_rings`;
    /// beyond, `f32::MAX`).
    fn distance(&self, p: Vec3, max_rings: i32) -> f32 {
        let (cx, cy, cz) = Self::key(p, self.cell);
        let mut best = f32::MAX;
        for r in 0..=max_rings {
            for dx in -r..=r {
                for dy in -r..=r {
                    for dz in -r..=r {
                        if dx.abs().max(dy.abs()).max(dz.abs()) != r {
                            continue;
                        }
                        if let Some(v) = self.grid.get(&(cx + dx, cy + dy, cz + dz)) {
                            for q in v {
                                best = best.min(p.distance_squared(*q));
                            }
                        }
                    }
                }
            }
            // Points in rings beyond r are at least r cells away.
            if best < f32::MAX && best.sqrt() <= r as f32 * self.cell {
                break;
            }
        }
        best.sqrt()
    }
}

/// `SAMPLES_PER_STRAND` points at equal arc length along each strand.
fn samples(strands: &[Vec<Vec3>]) -> Vec<Vec3> {
    strands
        .iter()
        .flat_map(|s| {
            let len = polyline_length(s);
            (0..SAMPLES_PER_STRAND)
                .map(move |k| point_at_length(s, len * k as f32 / (SAMPLES_PER_STRAND - 1) as f32))
        })
        .collect()
}

/// Points along each strand at most `spacing` apart.
fn dense(strands: &[Vec<Vec3>], spacing: f32) -> Vec<Vec3> {
    let mut out = Vec::new();
    for s in strands {
        out.push(s[0]);
        for w in s.windows(2) {
            let n = (w[0].distance(w[1]) / spacing).ceil().max(1.0) as usize;
            out.extend((1..=n).map(|k| w[0].lerp(w[1], k as f32 / n as f32)));
        }
    }
    out
}

fn mean_p95(mut v: Vec<f32>) -> (f32, f32) {
    if v.is_empty() {
        return (0.0, 0.0);
    }
    let mean = v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64;
    v.sort_by(f32::total_cmp);
    let p95 = v[((v.len() - 1) as f64 * 0.95).round() as usize];
    (mean as f32, p95)
}

/// Compare `fitted` strands with `input` strands (both root first): distances in units of
/// `diagonal`, coverage of input roots within `bundle_size` of a fitted root.
pub fn compare(
    input: &[Vec<Vec3>],
    fitted: &[Vec<Vec3>],
    diagonal: f32,
    bundle_size: f32,
) -> Fidelity {
    let diagonal = diagonal.max(1e-12);
    let spacing = diagonal * 0.002;
    let cell = diagonal * 0.01;
    let rings = 200;
    let to_fit = Nearest::new(dense(fitted, spacing).into_iter(), cell);
    let to_input = Nearest::new(dense(input, spacing).into_iter(), cell);
    let a: Vec<f32> = samples(input)
        .iter()
        .map(|&p| to_fit.distance(p, rings).min(diagonal) / diagonal)
        .collect();
    let b: Vec<f32> = samples(fitted)
        .iter()
        .map(|&p| to_input.distance(p, rings).min(diagonal) / diagonal)
        .collect();
    let both: Vec<f32> = a.iter().chain(&b).copied().collect();
    let fitted_roots = Nearest::new(fitted.iter().map(|s| s[0]), bundle_size.max(1e-9));
    let covered = input
        .iter()
        .filter(|s| fitted_roots.distance(s[0], 2) <= bundle_size)
        .count();
    Fidelity {
        input_to_fit: mean_p95(a),
        fit_to_input: mean_p95(b),
        two_sided: mean_p95(both),
        coverage: covered as f32 / input.len().max(1) as f32,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distances_between_parallel_strands() {
        let line = |x: f32| vec![Vec3::new(x, 0.0, 0.0), Vec3::new(x, 10.0, 0.0)];
        let a = vec![line(0.0), line(1.0)];
        let same = compare(&a, &a, 10.0, 0.5);
        // Dense points 0.2% of the diagonal apart: distances are exact to 0.1%.
        assert!(
            same.two_sided.0 < 1.1e-3 && same.coverage == 1.0,
            "{same:?}"
        );
        // Moved by 0.1: every distance is 0.1 = 1% of the diagonal.
        let b = vec![line(0.1), line(1.1)];
        let f = compare(&a, &b, 10.0, 0.5);
        assert!((f.two_sided.0 - 0.01).abs() < 1.1e-3, "{f:?}");
        assert!((f.two_sided.1 - 0.01).abs() < 1.1e-3, "{f:?}");
        // Roots 0.6 apart are not within a bundle of 0.5.
        let c = vec![line(0.6), line(1.6)];
        assert_eq!(compare(&a, &c, 10.0, 0.5).coverage, 0.5);
    }
}
