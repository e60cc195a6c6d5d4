//! What hair cannot enter: ellipsoids, capsules and heads given by a radial map, in the
//! character's frame. `glsl/hair_dynamics.comp` has the same push-outs.

use glam::{Mat4, Vec3};

use crate::model::hair_mesh::HairMesh;

/// A star-shaped surface around `centre`: its distance from the centre per direction, on a
/// grid of polar angle (rows, 0..=pi from +Y) by azimuth (columns, 0..2pi from +X toward +Z).
#[derive(Clone, Debug, PartialEq)]
pub struct RadialMap {
    /// Centre of the map.
    pub centre: Vec3,
    /// Polar rows (at least 2).
    pub rows: usize,
    /// Azimuth columns (at least 1).
    pub cols: usize,
    /// `radius[row * cols + col]`: distance of the surface from the centre.
    pub radius: Vec<f32>,
}

/// Polar angle and azimuth (in `0..2pi`) of unit direction `d`.
pub fn angles(d: Vec3) -> (f32, f32) {
    let theta = d.y.clamp(-1.0, 1.0).acos();
    let phi = d.z.atan2(d.x).rem_euclid(std::f32::consts::TAU);
    (theta, phi)
}

impl RadialMap {
    /// Distance of the surface from the centre in unit direction `d` (bilinear).
    pub fn sample(&self, d: Vec3) -> f32 {
        let (theta, phi) = angles(d);
        let y = theta / std::f32::consts::PI * (self.rows - 1) as f32;
        let x = phi / std::f32::consts::TAU * self.cols as f32;
        let (r0, fy) = ((y.floor() as usize).min(self.rows - 2), y.fract());
        let (c0, fx) = (x.floor() as usize % self.cols, x.fract());
        let c1 = (c0 + 1) % self.cols;
        let at = |r: usize, c: usize| self.radius[r * self.cols + c];
        let top = at(r0, c0) * (1.0 - fx) + at(r0, c1) * fx;
        let bottom = at(r0 + 1, c0) * (1.0 - fx) + at(r0 + 1, c1) * fx;
        top * (1.0 - fy) + bottom * fy
    }

    /// The largest radius of the surface.
    pub fn max_radius(&self) -> f32 {
        self.radius.iter().copied().fold(0.0, f32::max)
    }

    /// Signed radial distance of `p` outside the surface (negative inside).
    pub fn gap(&self, p: Vec3) -> f32 {
        let r = p - self.centre;
        let l = r.length();
        if l < 1e-9 {
            return -self.sample(Vec3::Y);
        }
        l - self.sample(r / l)
    }

    /// `p` moved radially to at least `margin` outside the surface (unchanged if there).
    pub fn push_out(&self, p: Vec3, margin: f32) -> Vec3 {
        let r = p - self.centre;
        let l = r.length();
        let d = if l < 1e-9 { Vec3::Y } else { r / l };
        let min = self.sample(d) + margin;
        if l < min { self.centre + d * min } else { p }
    }
}

/// Something hair cannot enter, in the character's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Collider {
    /// An ellipsoid (heads), axes along the character's.
    Ellipsoid {
        /// Centre.
        centre: Vec3,
        /// Radii.
        radii: Vec3,
    },
    /// A head given by a radial map in its own canonical frame (the human head of
    /// `characters::human`) placed by `to_person` (canonical head to the character's frame;
    /// `to_canonical` its inverse): points are pushed out to `margin` canonical metres
    /// outside it.
    Head {
        /// The head's surface, canonical frame.
        map: &'static RadialMap,
        /// Canonical head to the character's frame.
        to_person: Mat4,
        /// The inverse.
        to_canonical: Mat4,
        /// Distance kept outside the head, canonical metres.
        margin: f32,
    },
    /// A capsule (shoulders, necks).
    Capsule {
        /// One end of the axis.
        a: Vec3,
        /// The other end.
        b: Vec3,
        /// Radius.
        radius: f32,
    },
}

impl Collider {
    /// A head given by `map` placed by `to_person`, kept `margin` canonical metres away.
    pub fn head(map: &'static RadialMap, to_person: Mat4, margin: f32) -> Collider {
        Collider::Head {
            map,
            to_person,
            to_canonical: to_person.inverse(),
            margin,
        }
    }

    /// `p` moved out of the collider (bit-for-bit unchanged if outside).
    pub fn push_out(&self, p: Vec3) -> Vec3 {
        match *self {
            Collider::Ellipsoid { centre, radii } => {
                let q = (p - centre) / radii;
                let l = q.length();
                if (1e-9..1.0).contains(&l) {
                    centre + q / l * radii
                } else {
                    p
                }
            }
            Collider::Head {
                map,
                to_person,
                to_canonical,
                margin,
            } => {
                let q = to_canonical.transform_point3(p);
                let moved = map.push_out(q, margin);
                if moved == q {
                    p
                } else {
                    to_person.transform_point3(moved)
                }
            }
            Collider::Capsule { a, b, radius } => {
                let ab = b - a;
                let t = ((p - a).dot(ab) / ab.length_squared().max(1e-12)).clamp(0.0, 1.0);
                let c = a + ab * t;
                let d = p - c;
                let l = d.length();
                if l >= radius || l < 1e-9 {
                    p
                } else {
                    c + d / l * radius
                }
            }
        }
    }

    /// A sphere (centre, radius) in the character's frame outside which [`Self::push_out`]
    /// leaves every point unchanged: the GPU solver tests it before the exact push-out.
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        match *self {
            Collider::Ellipsoid { centre, radii } => (centre, radii.abs().max_element()),
            Collider::Capsule { a, b, radius } => ((a + b) * 0.5, (b - a).length() * 0.5 + radius),
            Collider::Head {
                map,
                to_person,
                margin,
                ..
            } => {
                let stretch = (0..3)
                    .map(|i| to_person.col(i).truncate().length())
                    .fold(0.0, f32::max);
                let r = (map.max_radius() + margin.max(0.0)) * stretch;
                (to_person.transform_point3(map.centre), r)
            }
        }
    }

    /// A sphere fitted to the scalp (layer 0) of `mesh` by least squares, shrunk to 97% so the
    /// roots start outside it: a head collider for meshes that come without one.
    pub fn fit_scalp(mesh: &HairMesh) -> Collider {
        // |p|^2 = 2 c.p + (r^2 - |c|^2): linear in (c, d); normal equations, then elimination.
        let mut a = [[0.0f64; 5]; 4];
        for p in &mesh.layers[0] {
            let row = [2.0 * p.x as f64, 2.0 * p.y as f64, 2.0 * p.z as f64, 1.0];
            for i in 0..4 {
                for j in 0..4 {
                    a[i][j] += row[i] * row[j];
                }
                a[i][4] += row[i] * p.length_squared() as f64;
            }
        }
        for c in 0..4 {
            let pivot = (c..4)
                .max_by(|&x, &y| a[x][c].abs().total_cmp(&a[y][c].abs()))
                .unwrap_or(c);
            a.swap(c, pivot);
            if a[c][c].abs() < 1e-30 {
                // Degenerate scalp (flat): a sphere at its centre that catches nothing.
                let (lo, hi) = crate::model::hair_mesh::bounds(mesh.layers[0].iter().copied());
                return Collider::Ellipsoid {
                    centre: (lo + hi) * 0.5,
                    radii: Vec3::splat(1e-6),
                };
            }
            let pivot_row = a[c];
            for (r, row) in a.iter_mut().enumerate() {
                if r != c {
                    let f = row[c] / pivot_row[c];
                    for (x, p) in row.iter_mut().zip(pivot_row) {
                        *x -= f * p;
                    }
                }
            }
        }
        let x: Vec<f64> = (0..4).map(|i| a[i][4] / a[i][i]).collect();
        let centre = Vec3::new(x[0] as f32, x[1] as f32, x[2] as f32);
        let r = (x[3] + centre.length_squared() as f64).max(0.0).sqrt() as f32;
        Collider::Ellipsoid {
            centre,
            radii: Vec3::splat(r * 0.97),
        }
    }
}
