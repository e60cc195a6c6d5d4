//! Root-slice layout of the hair mesh texture (paper 003, sections 3.1 and 3.3).
//!
//! Every bundle owns a 2x2 texel *cell* whose texel centres hold its four root corners, so a
//! bilinear sample strictly between those centres touches only that bundle's vertices. Grid-like
//! regions of quads are packed as shared-vertex lattices (*charts*): an `m x n` chart stores
//! `(m+1)(n+1)` texels instead of `4mn`. Remaining quads and all triangles get their own 2x2
//! block; a triangle duplicates its third vertex into the block's top row, as in section 3.3.

use std::collections::HashMap;

use crate::model::hair_mesh::{Face, HairMesh};

/// Marks a root-slice texel that holds no vertex.
pub const EMPTY_TEXEL: u32 = u32::MAX;

/// Largest chart side in cells; keeps charts packable.
const MAX_CHART_CELLS: usize = 64;

/// Where one bundle sits on the root slice.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BundlePlacement {
    /// Texel of the cell's corner `(0, 0)`; the cell spans `origin .. origin + (1, 1)`.
    pub origin: [u32; 2],
    /// Triangle bundle: texels `(0,1)` and `(1,1)` both hold the third vertex.
    pub triangle: bool,
}

/// The root-slice layout: texel -> root vertex, and face -> cell.
#[derive(Clone, Debug)]
pub struct RootLayout {
    /// Width of the root slice in texels.
    pub width: u32,
    /// Height of the root slice in texels.
    pub height: u32,
    /// Root vertex stored at each texel (`EMPTY_TEXEL` if none), row-major.
    pub texels: Vec<u32>,
    /// Placement of each face, in face order.
    pub bundles: Vec<BundlePlacement>,
    /// Number of shared-vertex charts with more than one cell.
    pub charts: usize,
    /// Faces placed inside those charts.
    pub charted_faces: usize,
}

impl RootLayout {
    /// Average root-slice texels per face (4 without charts, towards 1 for large grids).
    pub fn texels_per_face(&self) -> f32 {
        self.texels.len() as f32 / self.bundles.len().max(1) as f32
    }

    /// The vertex at texel `(x, y)`.
    pub fn texel(&self, x: u32, y: u32) -> u32 {
        self.texels[(y * self.width + x) as usize]
    }
}

/// A rectangle of texels to pack: a chart lattice or a single face block.
struct Piece {
    /// `(nx + 1) x (ny + 1)` vertices, row-major.
    verts: Vec<u32>,
    /// `nx x ny` cells: (face, triangle?) row-major.
    cells: Vec<(u32, bool)>,
    nx: usize,
    ny: usize,
}

impl Piece {
    fn vert(&self, i: usize, j: usize) -> u32 {
        self.verts[j * (self.nx + 1) + i]
    }

    /// Rotate by 90 degrees so that the next `extend_right` grows another side.
    fn rotate(&mut self) {
        let (nx, ny) = (self.nx, self.ny);
        let mut verts = vec![0; self.verts.len()];
        for jn in 0..=nx {
            for i_n in 0..=ny {
                verts[jn * (ny + 1) + i_n] = self.verts[(ny - i_n) * (nx + 1) + jn];
            }
        }
        let mut cells = vec![(0, false); self.cells.len()];
        for jn in 0..nx {
            for i_n in 0..ny {
                cells[jn * ny + i_n] = self.cells[(ny - 1 - i_n) * nx + jn];
            }
        }
        self.verts = verts;
        self.cells = cells;
        self.nx = ny;
        self.ny = nx;
    }
}

struct ChartBuilder<'a> {
    faces: &'a [Face],
    edge_faces: HashMap<(u32, u32), Vec<u32>>,
    assigned: Vec<bool>,
}

fn edge_key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

impl ChartBuilder<'_> {
    /// The unassigned quad across edge `(a, b)` other than `not`, with its far vertices
    /// `(next to a, next to b)`.
    fn across(&self, a: u32, b: u32, not: u32) -> Option<(u32, u32, u32)> {
        for &f in self.edge_faces.get(&edge_key(a, b))? {
            if f == not || self.assigned[f as usize] {
                continue;
            }
            let Face::Quad(q) = self.faces[f as usize] else {
                continue;
            };
            let k = q.iter().position(|&v| v == a)?;
            if q[(k + 1) % 4] == b {
                return Some((f, q[(k + 3) % 4], q[(k + 2) % 4]));
            }
            if q[(k + 3) % 4] == b {
                return Some((f, q[(k + 1) % 4], q[(k + 2) % 4]));
            }
        }
        None
    }

    /// Add one column of cells on the right of `piece` if the mesh continues as a grid there.
    fn extend_right(&self, piece: &mut Piece) -> bool {
        if piece.nx >= MAX_CHART_CELLS {
            return false;
        }
        let (nx, ny) = (piece.nx, piece.ny);
        let mut new_faces = Vec::with_capacity(ny);
        let mut new_verts: Vec<u32> = Vec::with_capacity(ny + 1);
        for j in 0..ny {
            let (a, b) = (piece.vert(nx, j), piece.vert(nx, j + 1));
            let inside = piece.cells[j * nx + nx - 1].0;
            let Some((f, na, nb)) = self.across(a, b, inside) else {
                return false;
            };
            if new_faces.contains(&f) || piece.cells.iter().any(|c| c.0 == f) {
                return false;
            }
            if j == 0 {
                new_verts.push(na);
            } else if new_verts[j] != na {
                return false; // neighbouring cells disagree: not a grid here
            }
            new_verts.push(nb);
            new_faces.push(f);
        }
        let mut verts = Vec::with_capacity((nx + 2) * (ny + 1));
        for (row, &v) in piece.verts.chunks(nx + 1).zip(&new_verts) {
            verts.extend_from_slice(row);
            verts.push(v);
        }
        let mut cells = Vec::with_capacity((nx + 1) * ny);
        for (row, &f) in piece.cells.chunks(nx).zip(&new_faces) {
            cells.extend_from_slice(row);
            cells.push((f, false));
        }
        piece.verts = verts;
        piece.cells = cells;
        piece.nx += 1;
        true
    }

    fn grow_chart(&mut self, seed: u32) -> Piece {
        let Face::Quad(q) = self.faces[seed as usize] else {
            unreachable!("charts start from quads")
        };
        let mut piece = Piece {
            verts: vec![q[0], q[1], q[3], q[2]],
            cells: vec![(seed, false)],
            nx: 1,
            ny: 1,
        };
        let mut idle = 0;
        while idle < 4 {
            if self.extend_right(&mut piece) {
                idle = 0;
            } else {
                piece.rotate();
                idle += 1;
            }
        }
        for &(f, _) in &piece.cells {
            self.assigned[f as usize] = true;
        }
        piece
    }
}

/// Build the root-slice layout of `mesh`: charts for grid-like quad regions when `use_charts`,
/// per-face 2x2 blocks otherwise, shelf-packed into a near-square slice.
pub fn layout_root_slice(mesh: &HairMesh, use_charts: bool) -> RootLayout {
    let faces = &mesh.faces;
    let mut builder = ChartBuilder {
        faces,
        edge_faces: HashMap::new(),
        assigned: vec![false; faces.len()],
    };
    for (f, face) in faces.iter().enumerate() {
        let v = face.vertices();
        for c in 0..v.len() {
            builder
                .edge_faces
                .entry(edge_key(v[c], v[(c + 1) % v.len()]))
                .or_default()
                .push(f as u32);
        }
    }
    let mut pieces = Vec::new();
    let mut charts = 0;
    let mut charted_faces = 0;
    for (f, face) in faces.iter().enumerate() {
        if builder.assigned[f] {
            continue;
        }
        let piece = match face {
            Face::Quad(_) if use_charts => builder.grow_chart(f as u32),
            Face::Quad(q) => Piece {
                verts: vec![q[0], q[1], q[3], q[2]],
                cells: vec![(f as u32, false)],
                nx: 1,
                ny: 1,
            },
            Face::Tri(t) => Piece {
                verts: vec![t[0], t[1], t[2], t[2]],
                cells: vec![(f as u32, true)],
                nx: 1,
                ny: 1,
            },
        };
        builder.assigned[f] = true;
        if piece.cells.len() > 1 {
            charts += 1;
            charted_faces += piece.cells.len();
        }
        pieces.push(piece);
    }
    pack(pieces, faces.len(), charts, charted_faces)
}

/// Shelf packing: tallest pieces first, rows of a width near the square root of the total area.
fn pack(
    mut pieces: Vec<Piece>,
    face_count: usize,
    charts: usize,
    charted_faces: usize,
) -> RootLayout {
    pieces.sort_by_key(|p| std::cmp::Reverse((p.ny + 1, p.nx + 1)));
    let area: usize = pieces.iter().map(|p| (p.nx + 1) * (p.ny + 1)).sum();
    let widest = pieces.iter().map(|p| p.nx + 1).max().unwrap_or(1);
    let width = widest.max((area as f64 * 1.05).sqrt().ceil() as usize);
    let mut placed = Vec::with_capacity(pieces.len());
    let (mut x, mut y, mut shelf, mut used_width) = (0usize, 0usize, 0usize, 0usize);
    for p in pieces {
        let (w, h) = (p.nx + 1, p.ny + 1);
        if x + w > width {
            x = 0;
            y += shelf;
            shelf = 0;
        }
        placed.push((x, y, p));
        x += w;
        used_width = used_width.max(x);
        shelf = shelf.max(h);
    }
    let height = y + shelf;
    let width = used_width;
    let mut texels = vec![EMPTY_TEXEL; width * height];
    let mut bundles = vec![
        BundlePlacement {
            origin: [0, 0],
            triangle: false
        };
        face_count
    ];
    for (x0, y0, p) in placed {
        for j in 0..=p.ny {
            for i in 0..=p.nx {
                texels[(y0 + j) * width + x0 + i] = p.vert(i, j);
            }
        }
        for j in 0..p.ny {
            for i in 0..p.nx {
                let (f, triangle) = p.cells[j * p.nx + i];
                bundles[f as usize] = BundlePlacement {
                    origin: [(x0 + i) as u32, (y0 + j) as u32],
                    triangle,
                };
            }
        }
    }
    RootLayout {
        width: width as u32,
        height: height as u32,
        texels,
        bundles,
        charts,
        charted_faces,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec2, Vec3};

    /// A grid of `nx x ny` quads, with a triangle fan on one side.
    fn grid_mesh(nx: usize, ny: usize, with_triangles: bool) -> HairMesh {
        let mut pos = Vec::new();
        let mut uv = Vec::new();
        for j in 0..=ny {
            for i in 0..=nx {
                pos.push(Vec3::new(i as f32, j as f32, 0.0));
                uv.push(Vec2::new(i as f32, j as f32) / 10.0);
            }
        }
        let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
        let mut faces = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                faces.push(Face::Quad([
                    id(i, j),
                    id(i + 1, j),
                    id(i + 1, j + 1),
                    id(i, j + 1),
                ]));
            }
        }
        if with_triangles {
            let apex = pos.len() as u32;
            pos.push(Vec3::new(-1.0, 0.5, 0.0));
            uv.push(Vec2::new(-0.1, 0.05));
            for j in 0..ny {
                faces.push(Face::Tri([apex, id(0, j), id(0, j + 1)]));
            }
        }
        let top: Vec<Vec3> = pos.iter().map(|p| *p + Vec3::Z).collect();
        HairMesh::new("grid", vec![pos, top], None, uv, faces).unwrap()
    }

    /// Every cell's texels hold exactly its face's corners (triangles: third vertex twice).
    fn assert_cells_match_faces(mesh: &HairMesh, layout: &RootLayout) {
        for (f, (face, b)) in mesh.faces.iter().zip(&layout.bundles).enumerate() {
            let [x, y] = b.origin;
            let cell = [
                layout.texel(x, y),
                layout.texel(x + 1, y),
                layout.texel(x + 1, y + 1),
                layout.texel(x, y + 1),
            ];
            match face {
                Face::Quad(q) => {
                    assert!(!b.triangle);
                    let mut a = cell;
                    let mut c = *q;
                    a.sort();
                    c.sort();
                    assert_eq!(a, c, "face {f}");
                    // Corners must go around the cell, not across it.
                    let k = cell.iter().position(|&v| v == q[0]).unwrap();
                    let fwd = cell[(k + 1) % 4] == q[1] && cell[(k + 2) % 4] == q[2];
                    let bwd = cell[(k + 3) % 4] == q[1] && cell[(k + 2) % 4] == q[2];
                    assert!(fwd || bwd, "face {f}: corners not in cyclic order");
                }
                Face::Tri(t) => {
                    assert!(b.triangle);
                    assert_eq!(
                        [cell[0], cell[1], cell[2], cell[3]],
                        [t[0], t[1], t[2], t[2]]
                    );
                }
            }
        }
    }

    #[test]
    fn grid_becomes_one_chart() {
        let mesh = grid_mesh(6, 5, false);
        let layout = layout_root_slice(&mesh, true);
        assert_eq!(layout.charts, 1);
        assert_eq!(layout.charted_faces, 30);
        assert!(
            layout.texels_per_face() < 1.5,
            "{}",
            layout.texels_per_face()
        );
        assert_cells_match_faces(&mesh, &layout);
    }

    /// A quad wound the other way round still joins its neighbours' chart: `across` reads its
    /// far vertices in either direction (the reversed branch was never reached by a test: its
    /// index mutant survived the 2026-12-06 sample).
    #[test]
    fn a_quad_wound_backwards_joins_the_chart() {
        let mut mesh = grid_mesh(6, 5, false);
        if let Face::Quad(q) = &mut mesh.faces[13] {
            q.reverse();
        }
        let layout = layout_root_slice(&mesh, true);
        assert_eq!(layout.charts, 1);
        assert_eq!(layout.charted_faces, 30);
        assert_cells_match_faces(&mesh, &layout);
    }

    /// Quads listed from any of their corners, wound either way, still make one chart: `across`
    /// finds the shared edge's vertices at every index (a survivor of the fourth mutation
    /// sample read `k - 2` for `k + 2`, which only the first two corners tell apart).
    #[test]
    fn quads_listed_from_any_corner_join_the_chart() {
        let mut mesh = grid_mesh(6, 5, false);
        for (f, face) in mesh.faces.iter_mut().enumerate() {
            if let Face::Quad(q) = face {
                q.rotate_left(f % 4);
                if f % 3 == 0 {
                    q.reverse();
                }
            }
        }
        let layout = layout_root_slice(&mesh, true);
        assert_eq!(layout.charts, 1);
        assert_eq!(layout.charted_faces, 30);
        assert_cells_match_faces(&mesh, &layout);
    }

    #[test]
    fn blocks_without_charts_and_triangles() {
        let mesh = grid_mesh(3, 4, true);
        let blocks = layout_root_slice(&mesh, false);
        assert_cells_match_faces(&mesh, &blocks);
        let used = blocks.texels.iter().filter(|&&t| t != EMPTY_TEXEL).count();
        assert_eq!(used, 4 * mesh.faces.len());
        let charted = layout_root_slice(&mesh, true);
        assert_cells_match_faces(&mesh, &charted);
        assert!(charted.texels.len() < blocks.texels.len());
    }

    #[test]
    fn cells_never_overlap() {
        let mesh = grid_mesh(9, 7, true);
        let layout = layout_root_slice(&mesh, true);
        let mut owner = vec![None; (layout.width * layout.height) as usize];
        for (f, b) in layout.bundles.iter().enumerate() {
            // The open square between the four texel centres belongs to one face only.
            let key = (b.origin[1] * layout.width + b.origin[0]) as usize;
            assert!(
                owner[key].is_none(),
                "faces {:?} and {f} share a cell",
                owner[key]
            );
            owner[key] = Some(f);
            assert!(b.origin[0] + 1 < layout.width && b.origin[1] + 1 < layout.height);
        }
    }
}
