//! Far versions of skinned meshes, two ways. [`simplified_mesh`]: edge collapse under
//! quadric error metrics (Garland and Heckbert 1997, meshoptimizer's simplifier) within an
//! error, keeping original vertices; the people's bodies and clothes. [`far_mesh`]: vertex
//! clustering (Rossignac and Borrel 1993), as
//! `characters::far_mesh` does for static props, carrying skinning data. Vertices are snapped
//! to `cell`-sized cubes at bind time; each cell keeps the vertex nearest its mean (its joints
//! and weights, so the far mesh skins like the near one) with the mean colour and roughness of
//! the cell's vertices (a dark lash line or pupil does not paint a whole cell), triangles
//! whose corners fall into fewer than three cells vanish, duplicates are dropped, and normals
//! are the kept vertices' own.

use std::collections::{HashMap, HashSet};

use glam::Vec3;

use super::{SkinVertex, SkinnedMesh};

/// The far version of `mesh` with vertices clustered into `cell`-sized cubes.
pub fn far_mesh(mesh: &SkinnedMesh, cell: f32) -> SkinnedMesh {
    let cell_of = |p: Vec3| (p / cell).floor().as_ivec3().to_array();
    // Per cell: position sum, count, colour sum, roughness sum.
    let mut sums: HashMap<[i32; 3], (Vec3, f32, Vec3, f32)> = HashMap::new();
    for v in &mesh.vertices {
        let e = sums.entry(cell_of(v.position)).or_default();
        e.0 += v.position;
        e.1 += 1.0;
        e.2 += v.color;
        e.3 += v.roughness;
    }
    // The representative of each cell: the vertex nearest its mean (lowest index on ties).
    let mut best: HashMap<[i32; 3], (f32, usize)> = HashMap::new();
    for (k, v) in mesh.vertices.iter().enumerate() {
        let c = cell_of(v.position);
        let (sum, n, ..) = sums[&c];
        let d = v.position.distance_squared(sum / n);
        let e = best.entry(c).or_insert((f32::INFINITY, usize::MAX));
        if d < e.0 {
            *e = (d, k);
        }
    }
    let mut remap: HashMap<usize, u32> = HashMap::new();
    let mut vertices = Vec::new();
    let mut indices = Vec::new();
    let mut seen = HashSet::new();
    for t in mesh.indices.chunks_exact(3) {
        let cells = [0, 1, 2].map(|k| cell_of(mesh.vertices[t[k] as usize].position));
        if cells[0] == cells[1] || cells[1] == cells[2] || cells[0] == cells[2] {
            continue;
        }
        let first = (0..3).min_by_key(|&k| cells[k]).unwrap_or(0);
        if !seen.insert([0, 1, 2].map(|k| cells[(first + k) % 3])) {
            continue;
        }
        for c in cells {
            let rep = best[&c].1;
            let next = vertices.len() as u32;
            let i = *remap.entry(rep).or_insert_with(|| {
                let (_, n, color, roughness) = sums[&c];
                vertices.push(SkinVertex {
                    color: color / n,
                    roughness: roughness / n,
                    ..mesh.vertices[rep]
                });
                next
            });
            indices.push(i);
        }
    }
    SkinnedMesh {
        name: format!("{} (far)", mesh.name),
        vertices,
        indices,
    }
}

/// The far version of `mesh` simplified by edge collapse (quadric error metrics, Garland and
/// Heckbert 1997, through meshoptimizer) until its surface would move more than `error` (mesh
/// units): flat parts lose most of their triangles, outlines and limbs keep their place. Its
/// vertices are the original's that remain (joints, weights and colours included), compacted.
pub fn simplified_mesh(mesh: &SkinnedMesh, error: f32) -> SkinnedMesh {
    let positions: Vec<[f32; 3]> = mesh
        .vertices
        .iter()
        .map(|v| v.position.to_array())
        .collect();
    let bytes: &[u8] = bytemuck::cast_slice(&positions);
    let kept = match meshopt::VertexDataAdapter::new(bytes, 12, 0) {
        Ok(adapter) => meshopt::simplify(
            &mesh.indices,
            &adapter,
            0,
            error,
            meshopt::SimplifyOptions::ErrorAbsolute,
            None,
        ),
        Err(_) => mesh.indices.clone(),
    };
    let mut remap: std::collections::HashMap<u32, u32> = std::collections::HashMap::new();
    let mut vertices = Vec::new();
    let indices = kept
        .iter()
        .map(|&i| {
            *remap.entry(i).or_insert_with(|| {
                vertices.push(mesh.vertices[i as usize]);
                vertices.len() as u32 - 1
            })
        })
        .collect();
    SkinnedMesh {
        name: format!("{} (far)", mesh.name),
        vertices,
        indices,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A finely tessellated square loses most of its triangles, keeps its extent within a
    /// cell, every kept vertex is one of the original's (joints and weights included), and a
    /// dark line one vertex wide darkens its cells by its share of their vertices instead of
    /// painting them.
    #[test]
    fn clustering_keeps_skinning_data() {
        let n = 40;
        let mut vertices = Vec::new();
        for y in 0..=n {
            for x in 0..=n {
                vertices.push(SkinVertex {
                    position: Vec3::new(x as f32, y as f32, 0.0) / n as f32,
                    normal: Vec3::Z,
                    color: Vec3::splat(if y == n / 2 { 0.0 } else { 1.0 }),
                    roughness: 0.5,
                    joints: [(x % 3) as u16, 0, 0, 0],
                    weights: [1.0, 0.0, 0.0, 0.0],
                });
            }
        }
        let mut indices = Vec::new();
        for y in 0..n {
            for x in 0..n {
                let a = (y * (n + 1) + x) as u32;
                let (b, c, d) = (a + 1, a + n as u32 + 1, a + n as u32 + 2);
                indices.extend([a, b, d, a, d, c]);
            }
        }
        let mesh = SkinnedMesh {
            name: "square".into(),
            vertices,
            indices,
        };
        let far = far_mesh(&mesh, 0.1);
        assert!(
            far.indices.len() * 8 < mesh.indices.len(),
            "{}",
            far.indices.len()
        );
        assert!(!far.indices.is_empty());
        for v in &far.vertices {
            let same = |w: &&SkinVertex| (w.position, w.joints) == (v.position, v.joints);
            let original = mesh.vertices.iter().find(same).expect("an original vertex");
            assert_eq!((original.normal, original.weights), (v.normal, v.weights));
            // Cells of 4 x 4 vertices (5 x 4 at the line's): the line is at most a quarter.
            assert!(v.color.x >= 0.74 && v.roughness == 0.5, "{v:?}");
        }
        let darkest = far.vertices.iter().map(|v| v.color.x).fold(1.0, f32::min);
        assert!(darkest < 0.9, "the line's cells darken: {darkest}");
        let max = far
            .vertices
            .iter()
            .fold(Vec3::MIN, |m, v| m.max(v.position));
        assert!(max.x > 0.9 && max.y > 0.9, "{max}");
    }

    /// Edge collapse on a unit sphere of 64 x 32 quads at an error of 1 cm: at most a third of
    /// the triangles are left (measured: 853 of 3968), every vertex is an original one with
    /// its skinning data, and the surface stays near the error: the middle of every triangle
    /// left lies at most 2 cm inside the sphere (measured: 1.7 cm; at 4 cm of error it is
    /// far deeper).
    #[test]
    fn edge_collapse_keeps_the_surface_within_the_error() {
        let (cols, rows) = (64u32, 32u32);
        let mut vertices = Vec::new();
        for r in 0..=rows {
            for c in 0..=cols {
                let (theta, phi) = (
                    std::f32::consts::PI * r as f32 / rows as f32,
                    std::f32::consts::TAU * c as f32 / cols as f32,
                );
                let p = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                );
                vertices.push(SkinVertex {
                    position: p,
                    normal: p,
                    color: Vec3::ONE,
                    roughness: 0.5,
                    joints: [(c % 5) as u16, (r % 3) as u16, 0, 0],
                    weights: [0.75, 0.25, 0.0, 0.0],
                });
            }
        }
        let mut indices = Vec::new();
        for r in 0..rows {
            for c in 0..cols {
                let a = r * (cols + 1) + c;
                let (b, d, e) = (a + 1, a + cols + 1, a + cols + 2);
                if r > 0 {
                    indices.extend([a, b, e]);
                }
                if r + 1 < rows {
                    indices.extend([a, e, d]);
                }
            }
        }
        let sphere = SkinnedMesh {
            name: "sphere".into(),
            vertices,
            indices,
        };
        let far = simplified_mesh(&sphere, 0.01);
        let (before, after) = (sphere.indices.len() / 3, far.indices.len() / 3);
        eprintln!("{after} of {before} triangles left");
        assert!(after > 0 && after * 3 <= before, "{after} of {before}");
        for v in &far.vertices {
            let same = |w: &&SkinVertex| (w.position, w.joints) == (v.position, v.joints);
            let original = sphere
                .vertices
                .iter()
                .find(same)
                .expect("an original vertex");
            assert_eq!(original, v);
        }
        let sag = far
            .indices
            .chunks_exact(3)
            .map(|t| {
                let c = t
                    .iter()
                    .map(|&i| far.vertices[i as usize].position)
                    .sum::<Vec3>()
                    / 3.0;
                1.0 - c.length()
            })
            .fold(0.0f32, f32::max);
        eprintln!("deepest triangle middle {sag} inside");
        assert!(sag <= 0.02, "a triangle's middle {sag} inside the sphere");
    }
}
