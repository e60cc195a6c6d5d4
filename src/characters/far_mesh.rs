//! Far versions of prop meshes (bodies, heads) for crowds: vertex clustering (Rossignac and
//! Borrel 1993). Vertices are snapped to a grid of `cell`-sized cubes and merged into their
//! cell's mean; triangles whose corners fall into fewer than three cells vanish, duplicates
//! are dropped, and normals are smoothed again. Every vertex moves less than a cell's
//! diagonal, so a far version drawn where a cell spans about a pixel looks the same.

use std::collections::{HashMap, HashSet};

use glam::Vec3;

use super::human::smooth_prop_mesh;
use crate::render::core::shared::PropVertex;

/// The far version of triangle list `mesh` with vertices clustered into `cell`-sized cubes.
pub fn far_mesh(mesh: &[PropVertex], cell: f32) -> Vec<PropVertex> {
    let cell_of = |v: &PropVertex| {
        (Vec3::from_slice(&v.position[..3]) / cell)
            .floor()
            .as_ivec3()
            .to_array()
    };
    let mut sums: HashMap<[i32; 3], (Vec3, f32)> = HashMap::new();
    for v in mesh {
        let e = sums.entry(cell_of(v)).or_default();
        e.0 += Vec3::from_slice(&v.position[..3]);
        e.1 += 1.0;
    }
    let mut seen = HashSet::new();
    let mut triangles = Vec::new();
    for t in mesh.chunks_exact(3) {
        let cells = [cell_of(&t[0]), cell_of(&t[1]), cell_of(&t[2])];
        if cells[0] == cells[1] || cells[1] == cells[2] || cells[0] == cells[2] {
            continue;
        }
        // The same three cells in the same turning order are one triangle.
        let first = (0..3).min_by_key(|&k| cells[k]).unwrap_or(0);
        let key = [0, 1, 2].map(|k| cells[(first + k) % 3]);
        if !seen.insert(key) {
            continue;
        }
        triangles.push(cells.map(|c| {
            let (sum, n) = sums[&c];
            sum / n
        }));
    }
    smooth_prop_mesh(&triangles)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::characters::person::{body_mesh, head_mesh};

    fn bounds(mesh: &[PropVertex]) -> (Vec3, Vec3) {
        mesh.iter()
            .map(|v| Vec3::from_slice(&v.position[..3]))
            .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), p| (lo.min(p), hi.max(p)))
    }

    /// The people's far body and head keep their extent within a cell and lose most of their
    /// triangles; no triangle is degenerate.
    #[test]
    fn far_meshes_keep_the_shape_with_few_triangles() {
        for (name, mesh, cell) in [
            ("body", body_mesh(), 0.04),
            ("head", head_mesh().unwrap(), 0.025),
        ] {
            let far = far_mesh(&mesh, cell);
            let (lo, hi) = bounds(&mesh);
            let (flo, fhi) = bounds(&far);
            println!(
                "{name}: {} -> {} triangles, extent {} -> {}",
                mesh.len() / 3,
                far.len() / 3,
                hi - lo,
                fhi - flo
            );
            assert!(
                far.len() * 4 < mesh.len(),
                "{name}: {} of {}",
                far.len(),
                mesh.len()
            );
            assert!(
                (lo - flo).abs().max_element() < cell && (hi - fhi).abs().max_element() < cell,
                "{name}: {lo} {hi} vs {flo} {fhi}"
            );
            for t in far.chunks_exact(3) {
                let p = t
                    .iter()
                    .map(|v| Vec3::from_slice(&v.position[..3]))
                    .collect::<Vec<_>>();
                assert!(
                    (p[1] - p[0]).cross(p[2] - p[0]).length() > 0.0,
                    "{name}: degenerate"
                );
            }
        }
    }
}
