//! Linear hair skinning (LHS), the baseline of the paper's comparison: every strand is stored,
//! and each frame it moves with a few simulated guide strands through precomputed weights.
//!
//! - **Guides:** a fraction of the strands (1% by default, 0.1-10%), chosen by farthest-point
//!   sampling on the roots (deterministic: the first guide is strand 0, each next one is the
//!   strand whose root is farthest from every guide so far), so guides cover the scalp evenly.
//! - **Weights:** every strand follows the 3 guides with the nearest roots, weighted by inverse
//!   root distance `1 / (d + eps)`, normalised to sum 1 (a guide follows itself with weight 1).
//! - **Skinning:** vertex `k` of a strand moves by the weighted displacement of vertex `k` of its
//!   guides: `p = rest + sum_g w_g (guide_now_k - guide_rest_k)`. The GPU twin is
//!   `glsl/lhs_skin.comp`.

use glam::Vec3;

use crate::error::{HairError, Result};

/// Guides each strand follows.
pub const LHS_GUIDES_PER_STRAND: usize = 3;

/// Stored strands with guides and weights.
#[derive(Clone, Debug)]
pub struct LhsModel {
    /// Vertices per strand.
    pub verts_per_strand: usize,
    /// Rest positions of every strand vertex, strand-major.
    pub rest: Vec<Vec3>,
    /// Strand index of each guide.
    pub guides: Vec<u32>,
    /// Per strand: (guide slot, weight) of its guides.
    pub weights: Vec<[(u32, f32); LHS_GUIDES_PER_STRAND]>,
}

impl LhsModel {
    /// Guides and weights for strands `rest` (strand-major, `verts` each) with `fraction` of
    /// the strands as guides (0.001..=0.1).
    pub fn new(rest: Vec<Vec3>, verts: usize, fraction: f32) -> Result<Self> {
        if verts < 2 || rest.is_empty() || !rest.len().is_multiple_of(verts) {
            return Err(HairError::invalid(
                "lhs",
                "strands must have >= 2 vertices each",
            ));
        }
        if !(0.001..=0.1).contains(&fraction) {
            return Err(HairError::invalid(
                "lhs",
                format!("guide fraction {fraction} must be 0.001..=0.1"),
            ));
        }
        let n = rest.len() / verts;
        let roots: Vec<Vec3> = (0..n).map(|s| rest[s * verts]).collect();
        let count = ((n as f32 * fraction).ceil() as usize).clamp(LHS_GUIDES_PER_STRAND.min(n), n);
        // Farthest-point sampling on the roots.
        let mut guides = vec![0u32];
        let mut nearest: Vec<f32> = roots.iter().map(|r| r.distance(roots[0])).collect();
        while guides.len() < count {
            let (far, _) = nearest
                .iter()
                .enumerate()
                .fold(
                    (0, -1.0f32),
                    |best, (i, &d)| if d > best.1 { (i, d) } else { best },
                );
            guides.push(far as u32);
            for (d, r) in nearest.iter_mut().zip(&roots) {
                *d = d.min(r.distance(roots[far]));
            }
        }
        let weights = roots
            .iter()
            .map(|r| {
                let mut by_distance: Vec<(u32, f32)> = guides
                    .iter()
                    .enumerate()
                    .map(|(slot, &g)| (slot as u32, r.distance(roots[g as usize])))
                    .collect();
                by_distance.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
                let mut w = [(0u32, 0.0f32); LHS_GUIDES_PER_STRAND];
                if by_distance[0].1 <= 1e-9 {
                    // The strand is a guide (or on one): it follows it alone.
                    w[0] = (by_distance[0].0, 1.0);
                    for (k, slot) in w.iter_mut().enumerate().skip(1) {
                        *slot = (by_distance[k.min(by_distance.len() - 1)].0, 0.0);
                    }
                    return w;
                }
                let mut sum = 0.0;
                for (k, slot) in w.iter_mut().enumerate() {
                    let (g, d) = by_distance[k.min(by_distance.len() - 1)];
                    let inv = if k < by_distance.len() {
                        1.0 / (d + 1e-6)
                    } else {
                        0.0
                    };
                    *slot = (g, inv);
                    sum += inv;
                }
                for slot in w.iter_mut() {
                    slot.1 /= sum;
                }
                w
            })
            .collect();
        Ok(LhsModel {
            verts_per_strand: verts,
            rest,
            guides,
            weights,
        })
    }

    /// Rest positions of the guides' vertices, guide-major.
    pub fn guide_rest(&self) -> Vec<Vec3> {
        let v = self.verts_per_strand;
        self.guides
            .iter()
            .flat_map(|&g| {
                self.rest[g as usize * v..(g as usize + 1) * v]
                    .iter()
                    .copied()
            })
            .collect()
    }

    /// Skinned positions of every strand vertex for guide vertices `guide_now` (guide-major).
    pub fn skin(&self, guide_now: &[Vec3]) -> Vec<Vec3> {
        let v = self.verts_per_strand;
        let guide_rest = self.guide_rest();
        let mut out = self.rest.clone();
        for (s, w) in self.weights.iter().enumerate() {
            for k in 0..v {
                let mut d = Vec3::ZERO;
                for &(g, weight) in w {
                    let j = g as usize * v + k;
                    d += (guide_now[j] - guide_rest[j]) * weight;
                }
                out[s * v + k] += d;
            }
        }
        out
    }

    /// Bytes LHS stores: strand vertices (position + width, 16 B), weights (24 B per strand),
    /// guide rest vertices (16 B).
    pub fn bytes(&self) -> u64 {
        self.rest.len() as u64 * 16
            + self.weights.len() as u64 * 24
            + (self.guides.len() * self.verts_per_strand) as u64 * 16
    }
}

/// Where each stored strand comes from, in the order the compute path stores them
/// (characters in crowd order, bundles, strands): `(character, bundle, strand)`, from the
/// strand counts of every bundle of every character.
pub fn strand_origins(counts: &[Vec<u32>]) -> Vec<(u32, u32, u32)> {
    let mut out = Vec::new();
    for (c, bundles) in counts.iter().enumerate() {
        for (b, &n) in bundles.iter().enumerate() {
            out.extend((0..n).map(|s| (c as u32, b as u32, s)));
        }
    }
    out
}

/// The guides' vertices now (guide-major, world space): every guide strand generated again
/// from its character's current hair mesh (`generators[character]`, e.g. over a bake whose
/// textures `bake::deform` rebuilt for the current pose) and placed by that character's
/// current transform: this is how the guides follow an animated hair mesh.
pub fn guide_positions(
    model: &LhsModel,
    origins: &[(u32, u32, u32)],
    generators: &[(&crate::reference::generate::CpuGenerator, glam::Mat4)],
) -> Vec<Vec3> {
    let v = model.verts_per_strand;
    let mut pos = vec![Vec3::ZERO; v];
    let mut tan = vec![Vec3::ZERO; v];
    let mut width = vec![0.0; v];
    let mut out = Vec::with_capacity(model.guides.len() * v);
    for &g in &model.guides {
        let (c, b, s) = origins[g as usize];
        let (generator, placement) = &generators[c as usize];
        generator.strand(b, s, (v - 1) as u32, &mut pos, &mut tan, &mut width);
        out.extend(pos.iter().map(|p| placement.transform_point3(*p)));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize, verts: usize) -> Vec<Vec3> {
        (0..n)
            .flat_map(|s| {
                let root = Vec3::new((s % 20) as f32, 0.0, (s / 20) as f32);
                (0..verts).map(move |k| root + Vec3::Y * k as f32)
            })
            .collect()
    }

    #[test]
    fn weights_are_a_partition_of_unity_over_guides_that_are_strands() {
        let m = LhsModel::new(grid(400, 5), 5, 0.01).unwrap();
        assert_eq!(m.guides.len(), 4);
        let mut seen = std::collections::HashSet::new();
        assert!(
            m.guides
                .iter()
                .all(|&g| (g as usize) < 400 && seen.insert(g))
        );
        for w in &m.weights {
            assert!(
                w.iter()
                    .all(|&(g, x)| x >= 0.0 && (g as usize) < m.guides.len())
            );
            assert!((w.iter().map(|p| p.1).sum::<f32>() - 1.0).abs() < 1e-5);
        }
        // Guides at rest: nothing moves; a moved guide moves itself exactly.
        let rest = m.guide_rest();
        assert_eq!(m.skin(&rest), m.rest);
        let mut moved = rest.clone();
        for p in moved.iter_mut().take(5) {
            *p += Vec3::X;
        }
        let out = m.skin(&moved);
        let g0 = m.guides[0] as usize;
        assert!((out[g0 * 5 + 2] - m.rest[g0 * 5 + 2] - Vec3::X).length() < 1e-6);
        assert!(LhsModel::new(grid(10, 5), 5, 0.5).is_err());
        // What LHS stores (the paper's memory comparison): 2,000 vertices of 16 B, 400
        // strands' weights of 24 B, 4 guides' 5 rest vertices of 16 B.
        assert_eq!(m.bytes(), 2000 * 16 + 400 * 24 + 4 * 5 * 16);
    }
}
