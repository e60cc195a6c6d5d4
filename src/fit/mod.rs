//! Fitting a hair mesh to a strand model made elsewhere (TressFX `.tfx`, Yuksel's `.hair`):
//! paper 003 names the missing conversion as a limitation of hair meshes. The steps, each
//! deterministic:
//!
//! 1. **Chart.** Roots are mapped to a plane by the azimuthal equidistant projection about a
//!    centre inside the scalp (the point nearest every root's growth line, least squares,
//!    pulled weakly toward the roots' centroid moved back against their mean growth by their
//!    radius) and an axis through the roots' centroid: distances from the axis are angles,
//!    so a scalp cap up to a hemisphere and beyond flattens with little distortion and no
//!    seam (a scalp covering a whole sphere does not: the far pole becomes a circle).
//! 2. **Scalp (layer 0).** A square grid over the chart whose cell size is searched (bisection
//!    on its logarithm) until the cells holding roots number about the target bundle count;
//!    every occupied cell is a quad bundle, corners shared. A corner's root position is where
//!    the ray from the centre through its chart direction meets the head mesh when one is
//!    given (of the surfaces it crosses, the one nearest the nearby roots), else at the
//!    inverse-distance-weighted distance of the nearby roots.
//! 3. **Layers.** Their count comes from the strands' curvature (median total turning angle,
//!    one layer per 30 degrees, plus 3, capped). Each corner's curve is the weighted mean of
//!    the nearby strands (roots within 1.5 cells in the chart, at least 4, weights
//!    `1 / (d^2 + (h/4)^2)`), each resampled at the same fractions of its arc length; the mean
//!    curve is lengthened by `1 / (1 - length_variation / 2)` so the generated strands, which
//!    end between `1 - length_variation` and 1 of their bundle, are as long as the input on
//!    average, resampled at equal arc length into the layers and moved to start at the
//!    corner's root.
//! 4. **Style.** `length_variation` from the spread of nearby strand lengths (1 - the median
//!    of p10 / p90); `clump_strength` from how much the strands of a bundle draw together at
//!    90% of their length beyond what the bundle itself narrows (`clump_power` 1.5 kept);
//!    `frizz_amplitude` from what smoothing removes from the strands (their residual against
//!    a twice-applied [1 2 1] / 4 filter), with a wavelength of four segments; curl radius
//!    and frequency from the strands' median curvature and torsion when they are helical
//!    (`fit_curl`); wave is left at zero (not fitted); strand width from the model's size.
//!
//! [`metric`] measures the result against the input strands.

pub mod metric;
pub mod picture;

use glam::{Vec2, Vec3};

use crate::budget::{Estimate, MemoryBudget, VEC_HEADER};
use crate::error::{HairError, Result};
use crate::model::hair_mesh::{Face, HairMesh, MAX_LAYERS};
use crate::model::strands::{StrandModel, point_at_length, polyline_length};
use crate::model::style::HairStyle;

/// What to aim for.
#[derive(Clone, Copy, Debug)]
pub struct FitOptions {
    /// Target number of bundles (root faces).
    pub bundles: usize,
    /// Layers including the scalp (`None`: from the strands' curvature).
    pub layers: Option<usize>,
    /// Host memory the fit may use ([`memory_estimate`] is checked against it first).
    pub memory_budget: MemoryBudget,
}

/// Peak host memory of fitting `strands` strands of `points` points in all into `bundles`
/// bundles of at most `layers` layers: the strands and the file they came from, about 256 bytes
/// of working set per strand (roots, chart positions, cells, lengths and the neighbour lists:
/// each strand is a neighbour of the corners within 1.5 cells), curvature samples per point, and
/// the hair mesh (at most two corners per bundle) with its bake.
pub fn memory_estimate(
    strands: u64,
    points: u64,
    file_bytes: u64,
    bundles: u64,
    layers: u64,
) -> Estimate {
    let corners = bundles.min(strands).saturating_mul(2);
    Estimate::new()
        .with("the strand file", file_bytes, 1)
        .with("the strands", points, 12)
        .with("strand lists", strands, VEC_HEADER)
        .with("per-strand working set", strands, 256)
        .with("curvature samples", points, 16)
        .with("hair mesh corners", corners, 256)
        .and(crate::bake::memory_estimate(
            corners,
            layers,
            corners.saturating_add(corners / 2),
        ))
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            bundles: 64,
            layers: None,
            memory_budget: MemoryBudget::default(),
        }
    }
}

/// A fitted hair mesh and style.
pub struct Fitted {
    /// The hair mesh (validated).
    pub mesh: HairMesh,
    /// The fitted style.
    pub style: HairStyle,
    /// Mean edge length of the root faces (object units): the bundle size.
    pub bundle_size: f32,
}

/// Chart positions hashed into square cells, for neighbour queries.
struct ChartGrid {
    cell: f32,
    cells: std::collections::HashMap<(i64, i64), Vec<u32>>,
}

impl ChartGrid {
    fn new(points: &[Vec2], cell: f32) -> Self {
        let cell = cell.max(1e-12);
        let mut cells: std::collections::HashMap<(i64, i64), Vec<u32>> = Default::default();
        for (i, p) in points.iter().enumerate() {
            cells.entry(Self::key(*p, cell)).or_default().push(i as u32);
        }
        ChartGrid { cell, cells }
    }

    fn key(p: Vec2, cell: f32) -> (i64, i64) {
        ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64)
    }

    /// The points within `radius` of `g`, or its `least` nearest if fewer lie there (all of
    /// them if there are fewer than `least`), with squared distances.
    fn nearest(&self, points: &[Vec2], g: Vec2, radius: f32, least: usize) -> Vec<(usize, f32)> {
        let (cx, cy) = Self::key(g, self.cell);
        let least = least.min(points.len());
        let mut found: Vec<(usize, f32)> = Vec::new();
        // Rings of cells around g's cell: after ring k every point within k cells is found.
        let max_ring = self.cells.len() as i64 + 2;
        for k in 0..=max_ring {
            for dy in -k..=k {
                for dx in -k..=k {
                    if dx.abs().max(dy.abs()) != k {
                        continue;
                    }
                    if let Some(ids) = self.cells.get(&(cx + dx, cy + dy)) {
                        found.extend(
                            ids.iter()
                                .map(|&i| (i as usize, points[i as usize].distance_squared(g))),
                        );
                    }
                }
            }
            let reach = k as f32 * self.cell;
            let within = found
                .iter()
                .filter(|(_, d2)| *d2 <= radius * radius)
                .count();
            let complete = reach >= radius;
            let enough = within >= least
                || (found.len() >= least && {
                    let mut d: Vec<f32> = found.iter().map(|f| f.1).collect();
                    d.select_nth_unstable_by(least - 1, f32::total_cmp);
                    d[least - 1] <= reach * reach
                });
            if (complete && enough) || found.len() == points.len() {
                break;
            }
        }
        let within = found
            .iter()
            .filter(|(_, d2)| *d2 <= radius * radius)
            .count()
            .max(least)
            .min(found.len());
        if within > 0 && within < found.len() {
            found.select_nth_unstable_by(within - 1, |a, b| a.1.total_cmp(&b.1));
            found.truncate(within);
        }
        // Index order: the weighted sums over them do not depend on the search.
        found.sort_unstable_by_key(|f| f.0);
        found.shrink_to_fit();
        found
    }
}

/// The chart of step 1.
struct Chart {
    centre: Vec3,
    axis: Vec3,
    e1: Vec3,
    e2: Vec3,
}

impl Chart {
    fn new(roots: &[Vec3], dirs: &[Vec3]) -> Self {
        let centroid = roots.iter().copied().sum::<Vec3>() / roots.len() as f32;
        let radius = roots
            .iter()
            .map(|r| r.distance(centroid))
            .fold(0.0f32, f32::max)
            .max(1e-6);
        let growth: Vec3 = dirs.iter().copied().sum();
        let guess = centroid - growth.normalize_or(Vec3::Y) * radius;
        // The point nearest every root's growth line (least squares), pulled weakly toward
        // the guess so that parallel strands (a flat patch) stay well posed.
        let mut m = glam::Mat3::ZERO;
        let mut rhs = Vec3::ZERO;
        for (r, d) in roots.iter().zip(dirs) {
            let p = glam::Mat3::IDENTITY - glam::Mat3::from_cols(*d * d.x, *d * d.y, *d * d.z);
            m += p;
            rhs += p * *r;
        }
        let lambda = 0.05 * roots.len() as f32;
        m += glam::Mat3::IDENTITY * lambda;
        rhs += guess * lambda;
        let centre = if m.determinant().abs() > 1e-12 {
            m.inverse() * rhs
        } else {
            guess
        };
        let centre = if centre.is_finite() { centre } else { guess };
        let axis = (centroid - centre).normalize_or(Vec3::Y);
        let e1 = axis.any_orthonormal_vector();
        let e2 = axis.cross(e1);
        Chart {
            centre,
            axis,
            e1,
            e2,
        }
    }

    fn to_chart(&self, p: Vec3) -> Vec2 {
        let q = (p - self.centre).normalize_or(self.axis);
        let theta = q.dot(self.axis).clamp(-1.0, 1.0).acos();
        let t = q - self.axis * q.dot(self.axis);
        let len = t.length();
        if len < 1e-9 {
            return Vec2::ZERO;
        }
        theta * Vec2::new(t.dot(self.e1), t.dot(self.e2)) / len
    }

    fn direction(&self, x: Vec2) -> Vec3 {
        let theta = x.length();
        if theta < 1e-9 {
            return self.axis;
        }
        let d = x / theta;
        self.axis * theta.cos() + (self.e1 * d.x + self.e2 * d.y) * theta.sin()
    }
}

/// Number of grid cells of size `h` (from `lo`) that hold points.
fn occupied(points: &[Vec2], lo: Vec2, h: f32) -> usize {
    let mut cells: Vec<(i64, i64)> = points
        .iter()
        .map(|p| {
            let c = ((*p - lo) / h).floor();
            (c.x as i64, c.y as i64)
        })
        .collect();
    cells.sort_unstable();
    cells.dedup();
    cells.len()
}

/// Total turning angle of a polyline (radians).
fn turning(p: &[Vec3]) -> f32 {
    p.windows(3)
        .map(|w| {
            let (a, b) = (
                (w[1] - w[0]).normalize_or_zero(),
                (w[2] - w[1]).normalize_or_zero(),
            );
            a.dot(b).clamp(-1.0, 1.0).acos()
        })
        .sum()
}

fn median(mut v: Vec<f32>) -> f32 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f32::total_cmp);
    v[v.len() / 2]
}

fn percentile(v: &mut [f32], q: f32) -> f32 {
    v.sort_by(f32::total_cmp);
    v[((v.len() - 1) as f32 * q).round() as usize]
}

/// The root width and tip-to-root ratio of the style from the model's widths (medians over the
/// strands; `None` without widths or when they are all zero).
fn fit_widths(model: &StrandModel) -> Option<(f32, f32)> {
    let widths = model.widths.as_ref()?;
    let root = median(widths.iter().filter_map(|w| w.first().copied()).collect());
    let ratio = median(
        widths
            .iter()
            .filter(|w| w.first().is_some_and(|r| *r > 0.0))
            .map(|w| w[w.len() - 1] / w[0])
            .collect(),
    );
    (root > 0.0 && root.is_finite()).then_some((root, ratio.clamp(0.0, 1.0)))
}

/// Fit a hair mesh and style to `model`; `head` (triangles) places the scalp on its surface.
pub fn fit(model: &StrandModel, head: Option<&[[Vec3; 3]]>, opts: &FitOptions) -> Result<Fitted> {
    let layers = checked_layer_count(model, opts)?;
    let strands = &model.strands;
    let roots: Vec<Vec3> = strands.iter().map(|s| s[0]).collect();
    let dirs: Vec<Vec3> = strands
        .iter()
        .map(|s| (s[1] - s[0]).normalize_or_zero())
        .collect();
    let chart = Chart::new(&roots, &dirs);
    let x: Vec<Vec2> = roots.iter().map(|&r| chart.to_chart(r)).collect();
    let (lo, hi) = x.iter().fold(
        (Vec2::splat(f32::MAX), Vec2::splat(f32::MIN)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let extent = (hi - lo).max_element().max(1e-6);
    // Step 2: the cell size whose occupied cells come closest to the target.
    let target = opts.bundles.min(strands.len());
    // Cells no smaller than 1/1024 of the chart (65,536 bundles need 1/256 when they fill it):
    // with fewer strands than bundles asked for, every strand already has its own cell well
    // before that, and smaller cells only make root faces too small to be told from a point
    // (the hair mesh's degenerate-face test).
    let h = cell_size(&x, lo, extent, target);
    let cell_of = |p: Vec2| {
        let c = ((p - lo) / h).floor();
        (c.x as i64, c.y as i64)
    };
    let mut cells: Vec<(i64, i64)> = x.iter().map(|&p| cell_of(p)).collect();
    cells.sort_unstable();
    cells.dedup();
    let (corners, faces) = cell_faces(&cells);
    let corner_chart: Vec<Vec2> = corners
        .iter()
        .map(|&(i, j)| lo + Vec2::new(i as f32, j as f32) * h)
        .collect();
    let neighbours = corner_neighbours(&x, &corner_chart, h);
    // Corner roots: on the head, else at the weighted distance of the nearby roots.
    let root_of = |k: usize| -> Vec3 {
        let dir = chart.direction(corner_chart[k]);
        let (s, w) = neighbours[k].iter().fold((0.0, 0.0), |(s, w), &(i, wi)| {
            (s + wi * roots[i].distance(chart.centre), w + wi)
        });
        let from_roots = s / w;
        // On the head: of the surfaces the ray crosses, the one nearest the roots around.
        let hit = head.and_then(|tris| {
            tris.iter()
                .filter_map(|t| crate::model::obj_io::ray_triangle(chart.centre, dir, t))
                .min_by(|a, b| (a - from_roots).abs().total_cmp(&(b - from_roots).abs()))
        });
        chart.centre + dir * hit.unwrap_or(from_roots)
    };
    // Step 3: layers.
    let lengths: Vec<f32> = strands.iter().map(|s| polyline_length(s)).collect();
    let length_variation = fit_length_variation(&neighbours, &lengths);
    let mut layer_pos = vec![vec![Vec3::ZERO; corners.len()]; layers];
    for k in 0..corners.len() {
        let (curve, wsum, len) = mean_curve(strands, &lengths, &neighbours[k]);
        let bundle_len = len / wsum / (1.0 - 0.5 * length_variation);
        let mean_len = polyline_length(&curve).max(1e-12);
        let root = root_of(k);
        for (l, layer) in layer_pos.iter_mut().enumerate() {
            let s =
                l as f32 / (layers - 1) as f32 * bundle_len * (mean_len / (len / wsum).max(1e-12));
            layer[k] = point_at_length(&curve, s) - curve[0] + root;
        }
    }
    let uv: Vec<Vec2> = corner_chart.iter().map(|&g| (g - lo) / extent).collect();
    let mesh = HairMesh::new(model.name.clone(), layer_pos, None, uv, faces)?;
    // Step 4: style.
    let bundle_size = mean_root_edge(&mesh);
    let clump_strength = fit_clump(strands, &lengths, &x, &cells, &cell_of, &mesh);
    let style = fit_style(model, &lengths, length_variation, clump_strength);
    style.validate(&model.name)?;
    Ok(Fitted {
        mesh,
        style,
        bundle_size,
    })
}

/// Neighbour strands of every corner (at `corner_chart`, cells `h` wide) with weights: found
/// through a grid of the roots' chart positions `x`, so the work and memory grow with strands
/// + corners, not their product.
fn corner_neighbours(x: &[Vec2], corner_chart: &[Vec2], h: f32) -> Vec<Vec<(usize, f32)>> {
    let grid = ChartGrid::new(x, 1.5 * h);
    corner_chart
        .iter()
        .map(|&g| {
            let soft = (0.25 * h) * (0.25 * h);
            grid.nearest(x, g, 1.5 * h, 4)
                .into_iter()
                .map(|(i, d2)| (i, 1.0 / (d2 + soft)))
                .collect()
        })
        .collect()
}

/// How much strand lengths vary inside a bundle: one less the median over corners with four
/// neighbours or more of their 10th over 90th length percentile (at most 0.8).
fn fit_length_variation(neighbours: &[Vec<(usize, f32)>], lengths: &[f32]) -> f32 {
    let ratios: Vec<f32> = neighbours
        .iter()
        .filter(|n| n.len() >= 4)
        .map(|n| {
            let mut l: Vec<f32> = n.iter().map(|&(i, _)| lengths[i]).collect();
            percentile(&mut l, 0.1) / percentile(&mut l, 0.9).max(1e-12)
        })
        .collect();
    (1.0 - median(ratios)).clamp(0.0, 0.8)
}

/// The weighted mean of a corner's `neighbours` strands, each resampled at 33 points by
/// length; with the sum of weights and the weighted sum of lengths.
fn mean_curve(
    strands: &[Vec<Vec3>],
    lengths: &[f32],
    neighbours: &[(usize, f32)],
) -> (Vec<Vec3>, f32, f32) {
    const SAMPLES: usize = 33;
    let (mut curve, mut wsum, mut len) = (vec![Vec3::ZERO; SAMPLES], 0.0, 0.0);
    for &(i, wi) in neighbours {
        for (j, c) in curve.iter_mut().enumerate() {
            let f = j as f32 / (SAMPLES - 1) as f32;
            *c += wi * point_at_length(&strands[i], f * lengths[i]);
        }
        wsum += wi;
        len += wi * lengths[i];
    }
    curve.iter_mut().for_each(|c| *c /= wsum);
    (curve, wsum, len)
}

/// Step 3's layer count (from the strands' turning where not given), after the bundle count
/// and the memory estimate are checked: the estimate needs it.
fn checked_layer_count(model: &StrandModel, opts: &FitOptions) -> Result<usize> {
    if !(1..=65536).contains(&opts.bundles) {
        return Err(HairError::invalid(
            &model.name,
            format!("{} bundles: 1..=65536", opts.bundles),
        ));
    }
    let strands = &model.strands;
    let layers = match opts.layers {
        Some(l) => l,
        None => {
            let t = median(strands.iter().map(|s| turning(s)).collect());
            (t / 30f32.to_radians()).round() as usize + 3
        }
    }
    .clamp(2, MAX_LAYERS.min(16));
    let estimate = memory_estimate(
        strands.len() as u64,
        model.point_count() as u64,
        model.file_bytes,
        opts.bundles as u64,
        layers as u64,
    );
    opts.memory_budget.check(
        &model.name,
        &format!(
            "fitting {} strands into {} bundles",
            strands.len(),
            opts.bundles
        ),
        &estimate,
        "lower --bundles or --layers",
    )?;
    Ok(layers)
}

/// Step 2: the cell size whose occupied cells (of the roots' chart positions `x`) come
/// closest to `target`, found by bisection between 1/1024 of the chart's `extent` and all of
/// it.
fn cell_size(x: &[Vec2], lo: Vec2, extent: f32, target: usize) -> f32 {
    let (mut a, mut b) = ((extent / 1024.0).ln(), (extent * 1.01).ln());
    for _ in 0..40 {
        let mid = 0.5 * (a + b);
        if occupied(x, lo, mid.exp()) > target {
            a = mid;
        } else {
            b = mid;
        }
    }
    b.exp()
}

/// A quad face a occupied cell, over the cells' corners (shared between neighbours).
fn cell_faces(cells: &[(i64, i64)]) -> (Vec<(i64, i64)>, Vec<Face>) {
    let mut corner_index = std::collections::HashMap::new();
    let mut corners: Vec<(i64, i64)> = Vec::new();
    let mut faces = Vec::with_capacity(cells.len());
    for &(i, j) in cells {
        let mut v = [0u32; 4];
        for (k, c) in [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
            .into_iter()
            .enumerate()
        {
            v[k] = *corner_index.entry(c).or_insert_with(|| {
                corners.push(c);
                (corners.len() - 1) as u32
            });
        }
        faces.push(Face::Quad(v));
    }
    (corners, faces)
}

/// The mean edge length of the root faces: the fitted bundles' size.
fn mean_root_edge(mesh: &HairMesh) -> f32 {
    let edges: Vec<f32> = mesh
        .faces
        .iter()
        .flat_map(|f| {
            let v = f.vertices();
            (0..v.len()).map(move |c| (v[c], v[(c + 1) % v.len()]))
        })
        .map(|(a, b)| mesh.layers[0][a as usize].distance(mesh.layers[0][b as usize]))
        .collect();
    edges.iter().sum::<f32>() / edges.len().max(1) as f32
}

/// Step 4: the style the strands show: widths, curl, frizz (what smoothing removes, less
/// what a fitted curl explains), with the length variation and clumping already fitted.
fn fit_style(
    model: &StrandModel,
    lengths: &[f32],
    length_variation: f32,
    clump_strength: f32,
) -> HairStyle {
    let strands = &model.strands;
    let diag = model.diagonal();
    let mean_segment = lengths.iter().sum::<f32>()
        / model.point_count().saturating_sub(strands.len()).max(1) as f32;
    let curl = fit_curl(strands);
    // x3: calibrated on the round trips (smoothing keeps much of slow noise).
    let residual = median(strands.iter().map(|s| residual_rms(s)).collect()) * 3.0;
    let frizz_amplitude = match curl {
        Some(_) => 0.25 * residual,
        None => residual,
    };
    let (strand_width, tip_width_ratio) = fit_widths(model).unwrap_or((diag * 0.0015, 0.3));
    HairStyle {
        strand_width,
        tip_width_ratio,
        length_variation,
        clump_strength,
        frizz_amplitude,
        frizz_frequency: 1.0 / (4.0 * mean_segment.max(1e-6)),
        curl_radius: curl.map_or(0.0, |c| c.0),
        curl_frequency: curl.map_or(0.0, |c| c.1),
        wave_amplitude: 0.0,
        wave_frequency: 0.0,
        root_ramp: 0.05 * diag,
        ..HairStyle::default()
    }
}

/// Curl (radius, turns per unit length) when the strands are helices: a helix of radius r
/// and pitch 2 pi c has curvature k = r / (r^2 + c^2) and torsion t = c / (r^2 + c^2), so
/// r = k / (k^2 + t^2) and one turn takes 2 pi c = 2 pi t / (k^2 + t^2) of its axis. From the
/// discrete curvature and torsion of every inner point (Frenet frames of the polylines);
/// helical when the torsion keeps one sign at 80% of the points and is at least a fifth of
/// the curvature (a bend or a planar wave has torsion near zero, noise has both signs).
fn fit_curl(strands: &[Vec<Vec3>]) -> Option<(f32, f32)> {
    let (mut kappa, mut tau) = (Vec::new(), Vec::new());
    for s in strands {
        for w in s.windows(4) {
            let (a, b, c) = (w[1] - w[0], w[2] - w[1], w[3] - w[2]);
            let ds = (a.length() + b.length() + c.length()) / 3.0;
            if ds <= 0.0 {
                continue;
            }
            let (n1, n2) = (a.cross(b), b.cross(c));
            if n1.length() < 1e-12 || n2.length() < 1e-12 {
                continue;
            }
            let k = a.normalize().dot(b.normalize()).clamp(-1.0, 1.0).acos() / ds;
            let (n1, n2) = (n1.normalize(), n2.normalize());
            let mut t = n1.dot(n2).clamp(-1.0, 1.0).acos() / ds;
            if n1.cross(n2).dot(b) < 0.0 {
                t = -t;
            }
            kappa.push(k);
            tau.push(t);
        }
    }
    if tau.len() < 16 {
        return None;
    }
    let positive = tau.iter().filter(|&&t| t > 0.0).count() as f32 / tau.len() as f32;
    let sign = if positive >= 0.5 { 1.0 } else { -1.0 };
    let consistent = positive.max(1.0 - positive);
    let k = median(kappa);
    let t = median(tau.iter().map(|&t| t * sign).collect());
    if consistent < 0.8 || t < 0.2 * k || k <= 0.0 {
        return None;
    }
    let d = k * k + t * t;
    Some((k / d, d / (2.0 * std::f32::consts::PI * t)))
}

/// RMS distance of a strand's inner points from its twice-smoothed self.
fn residual_rms(s: &[Vec3]) -> f32 {
    if s.len() < 5 {
        return 0.0;
    }
    let smooth = |p: &[Vec3]| -> Vec<Vec3> {
        (0..p.len())
            .map(|i| {
                if i == 0 || i + 1 == p.len() {
                    p[i]
                } else {
                    0.25 * p[i - 1] + 0.5 * p[i] + 0.25 * p[i + 1]
                }
            })
            .collect()
    };
    let sm = smooth(&smooth(s));
    let inner = &s[2..s.len() - 2];
    let sum: f32 = inner
        .iter()
        .zip(&sm[2..s.len() - 2])
        .map(|(a, b)| a.distance_squared(*b))
        .sum();
    (sum / inner.len() as f32).sqrt()
}

/// Clump strength (step 4): per bundle with at least 3 strands, the strands' spread about
/// their centroid at 90% of their length over the spread at the root, divided by how much the
/// bundle's own face shrinks there; `1 - ratio` over `0.9^1.5` (the default clump power).
fn fit_clump(
    strands: &[Vec<Vec3>],
    lengths: &[f32],
    x: &[Vec2],
    cells: &[(i64, i64)],
    cell_of: &dyn Fn(Vec2) -> (i64, i64),
    mesh: &HairMesh,
) -> f32 {
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); cells.len()];
    for (i, &p) in x.iter().enumerate() {
        if let Ok(f) = cells.binary_search(&cell_of(p)) {
            members[f].push(i);
        }
    }
    let spread = |pts: &[Vec3]| -> f32 {
        let c = pts.iter().copied().sum::<Vec3>() / pts.len() as f32;
        (pts.iter().map(|p| p.distance_squared(c)).sum::<f32>() / pts.len() as f32).sqrt()
    };
    let top = ((mesh.layer_count() - 1) as f32 * 0.9).round() as usize;
    let ratios: Vec<f32> = members
        .iter()
        .zip(&mesh.faces)
        .filter(|(m, _)| m.len() >= 3)
        .filter_map(|(m, f)| {
            let at = |frac: f32| -> Vec<Vec3> {
                m.iter()
                    .map(|&i| point_at_length(&strands[i], frac * lengths[i]))
                    .collect()
            };
            let (s0, s9) = (spread(&at(0.0)), spread(&at(0.9)));
            let face = |l: usize| -> Vec<Vec3> {
                f.vertices()
                    .iter()
                    .map(|&v| mesh.layers[l][v as usize])
                    .collect()
            };
            let (f0, f9) = (spread(&face(0)), spread(&face(top)));
            (s0 > 1e-9 && f0 > 1e-9 && f9 > 1e-9).then(|| (s9 / s0) / (f9 / f0))
        })
        .collect();
    if ratios.is_empty() {
        return HairStyle::default().clump_strength;
    }
    ((1.0 - median(ratios)) / 0.9f32.powf(1.5)).clamp(0.0, 0.95)
}
