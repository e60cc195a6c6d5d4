//! Hair on any head: a user's head mesh (an OBJ, or the part of a glTF character that a joint
//! moves) brought into the canonical character frame, where the hairstyle generator grows
//! every family through the same radial map it uses on the Sintel head, and the hair taken
//! back to the user's frame and units.
//!
//! The head is assumed upright (+Y up) and facing +Z, glTF's convention. Normalizing needs
//! only a similarity (uniform scale and translation): the top of the cranium, the cap above
//! the brows and ears, is fitted with a sphere ([`cranium_sphere`]) on the user's head and on
//! the Sintel head alike, and the user's sphere is moved and scaled onto Sintel's. The cuts
//! (hairlines, partings, ties in polar angles about the cranium centre), the face shield and
//! the mannequin's neck and shoulders then sit where they do on Sintel, while the hair lies
//! on the user's own surface (its radial map). What it cannot know: a head tilted or turned
//! in its file, a helmet or hat in the mesh.

use std::path::Path;
use std::sync::OnceLock;

use glam::{DVec3, Mat4, Vec3};

use super::hairstyle::{Hairstyle, StyleFamily, generate_on};
use super::human::{HumanHead, human_head};
use super::person::{GrowthSite, PersonShape};
use crate::error::{HairError, Result};
use crate::model::gltf::Character;

/// Fewest vertices a head must have for its cranium to be fitted.
pub const MIN_HEAD_VERTICES: usize = 50;

/// Depth of the cranium cap the sphere is fitted to, in sphere radii below the top.
const CAP_DEPTH: f32 = 0.7;

/// A user's head, normalized into the canonical frame.
pub struct AnyHead {
    /// Source, for messages.
    pub name: String,
    /// The head in the canonical frame. Leaked: a head is read once and lives as long as the
    /// process, like the Sintel head (the dynamics' head colliders keep `'static` maps).
    pub head: &'static HumanHead,
    /// Canonical frame to the user's frame: a uniform scale, then a translation.
    pub to_user: Mat4,
    /// User units per canonical metre (the scale of [`Self::to_user`]).
    pub scale: f32,
}

impl AnyHead {
    /// Every face of the OBJ at `path` is the head (a bust, or a head with its neck).
    pub fn from_obj(path: &Path) -> Result<Self> {
        let name = path.display().to_string();
        let triangles = crate::model::obj_io::load_triangles(path)?;
        let region: Vec<Vec3> = triangles.iter().flatten().copied().collect();
        Self::from_triangles(&name, &triangles, &region)
    }

    /// The head of a glTF character in its bind pose: the vertices that joint `joint` and
    /// the joints below it move by half or more fit the cranium; every triangle near it is
    /// the surface.
    pub fn from_character(name: &str, character: &Character, joint: &str) -> Result<Self> {
        Self::from_joint(name, character, find_joint(name, character, joint)?)
    }

    /// [`Self::from_character`] with the head joint given by index.
    pub fn from_joint(name: &str, character: &Character, j: usize) -> Result<Self> {
        let under = joints_under(&character.skeleton, j);
        let mut region = Vec::new();
        let mut triangles = Vec::new();
        for m in &character.meshes {
            for v in &m.vertices {
                let w: f32 = (0..4)
                    .filter(|&k| under[v.joints[k] as usize])
                    .map(|k| v.weights[k])
                    .sum();
                if w >= 0.5 {
                    region.push(v.position);
                }
            }
            triangles.extend(
                m.indices
                    .chunks_exact(3)
                    .map(|t| [t[0], t[1], t[2]].map(|i| m.vertices[i as usize].position)),
            );
        }
        Self::from_triangles(name, &triangles, &region)
    }

    /// The head of `triangles` (user frame), its cranium fitted to the `region` points.
    pub fn from_triangles(name: &str, triangles: &[[Vec3; 3]], region: &[Vec3]) -> Result<Self> {
        if region.len() < MIN_HEAD_VERTICES {
            return Err(HairError::invalid(
                name,
                format!(
                    "the head has {} vertices; a cranium needs at least {MIN_HEAD_VERTICES}",
                    region.len()
                ),
            ));
        }
        let (user_centre, user_radius) = cranium_sphere(region)
            .ok_or_else(|| HairError::invalid(name, "no rounded cranium found at its top"))?;
        let (sintel_centre, sintel_radius) = sintel_cranium()?;
        let scale = user_radius / sintel_radius;
        // Canonical q = sintel_centre + (p - user_centre) / scale.
        let to_user = Mat4::from_translation(user_centre)
            * Mat4::from_scale(Vec3::splat(scale))
            * Mat4::from_translation(-sintel_centre);
        let to_canonical = to_user.inverse();
        let canonical: Vec<[Vec3; 3]> = triangles
            .iter()
            .map(|t| t.map(|p| to_canonical.transform_point3(p)))
            .collect();
        let head = HumanHead::from_triangles(name, canonical, human_head()?.centre)?;
        Ok(AnyHead {
            name: name.to_string(),
            head: Box::leak(Box::new(head)),
            to_user,
            scale,
        })
    }

    /// Where hair grows on this head: the canonical person (height 1) with this head.
    pub fn site(&self) -> GrowthSite {
        PersonShape::default().site_on(self.head)
    }

    /// A hairstyle of `family` from `seed`, grown on this head and returned in the user's
    /// frame and units (mesh and style).
    pub fn grow(&self, family: StyleFamily, seed: u32) -> Result<Hairstyle> {
        let hair = generate_on(family, seed, &self.site())?;
        Ok(transformed(hair, self.to_user, self.scale))
    }
}

/// `hair` moved by the similarity `m` of scale `scale`: positions, arc lengths and the
/// style's lengths.
pub fn transformed(mut hair: Hairstyle, m: Mat4, scale: f32) -> Hairstyle {
    for layer in &mut hair.mesh.layers {
        for p in layer.iter_mut() {
            *p = m.transform_point3(*p);
        }
    }
    for w in hair.mesh.w.iter_mut().flatten() {
        *w *= scale;
    }
    hair.style = hair.style.scaled(scale);
    hair
}

/// Index of the joint called `joint` in `character` (from `name`), or an error naming it.
pub fn find_joint(name: &str, character: &Character, joint: &str) -> Result<usize> {
    character.skeleton.find(joint).ok_or_else(|| {
        HairError::invalid(
            name,
            format!("no joint named '{joint}' (--joint names one)"),
        )
    })
}

/// Whether each joint is `j` or below it.
fn joints_under(s: &crate::skin::Skeleton, j: usize) -> Vec<bool> {
    let mut under = vec![false; s.joints.len()];
    for (k, flag) in under.iter_mut().enumerate() {
        let mut at = Some(k);
        // Parents come before children in a validated skeleton, but walk up regardless.
        for _ in 0..s.joints.len() {
            match at {
                Some(a) if a == j => {
                    *flag = true;
                    break;
                }
                Some(a) => at = s.joints[a].parent,
                None => break,
            }
        }
    }
    under
}

/// The Sintel head's cranium sphere in the canonical frame (fitted once).
fn sintel_cranium() -> Result<(Vec3, f32)> {
    static FIT: OnceLock<Option<(Vec3, f32)>> = OnceLock::new();
    let head = human_head()?;
    FIT.get_or_init(|| {
        let points: Vec<Vec3> = head.triangles.iter().flatten().copied().collect();
        cranium_sphere(&points)
    })
    .ok_or_else(|| HairError::invalid("hairmeshes/sintel_head.obj", "no cranium found"))
}

/// The sphere through the top of a head: fitted to the points within `CAP_DEPTH` (0.7) radii
/// of the highest, the cap refined from the fit four times (the first cap is the top quarter
/// of the points' height). `None` if the points do not round off at the top.
pub fn cranium_sphere(points: &[Vec3]) -> Option<(Vec3, f32)> {
    let top = points.iter().map(|p| p.y).fold(f32::MIN, f32::max);
    let bottom = points.iter().map(|p| p.y).fold(f32::MAX, f32::min);
    let mut depth = 0.25 * (top - bottom);
    let mut fit = None;
    for _ in 0..5 {
        let cap: Vec<Vec3> = points
            .iter()
            .copied()
            .filter(|p| p.y >= top - depth)
            .collect();
        let (c, r) = fit_sphere(&cap)?;
        // The centre must lie below the top, within the sphere's reach of it.
        if !(r > 0.0 && c.y < top && top - c.y < 1.5 * r) {
            return None;
        }
        fit = Some((c, r));
        depth = CAP_DEPTH * r;
    }
    fit
}

/// Least-squares sphere through `points` (the algebraic fit: `|p|^2 = 2 c.p + k`, solved in
/// double precision about the points' mean); `None` for fewer than 10 points or a degenerate
/// (flat, collinear) set.
pub fn fit_sphere(points: &[Vec3]) -> Option<(Vec3, f32)> {
    if points.len() < 10 {
        return None;
    }
    let mean = points.iter().map(|p| p.as_dvec3()).sum::<DVec3>() / points.len() as f64;
    // Normal equations of [2x 2y 2z 1] . [c k] = |p|^2 in centred coordinates.
    let mut a = [[0.0f64; 5]; 4];
    for p in points {
        let q = p.as_dvec3() - mean;
        let row = [2.0 * q.x, 2.0 * q.y, 2.0 * q.z, 1.0];
        let rhs = q.length_squared();
        for i in 0..4 {
            for j in 0..4 {
                a[i][j] += row[i] * row[j];
            }
            a[i][4] += row[i] * rhs;
        }
    }
    let x = solve4(a)?;
    let c = DVec3::new(x[0], x[1], x[2]);
    let r2 = x[3] + c.length_squared();
    if !(r2 > 0.0 && r2.is_finite()) {
        return None;
    }
    Some(((c + mean).as_vec3(), r2.sqrt() as f32))
}

/// Gaussian elimination with partial pivoting on an augmented 4x5 system.
fn solve4(mut a: [[f64; 5]; 4]) -> Option<[f64; 4]> {
    let scale = a.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    for col in 0..4 {
        let pivot = (col..4).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[pivot][col].abs() <= 1e-12 * scale {
            return None;
        }
        a.swap(col, pivot);
        let pivot_row = a[col];
        for row in a.iter_mut().skip(col + 1) {
            let f = row[col] / pivot_row[col];
            for (x, p) in row.iter_mut().zip(pivot_row).skip(col) {
                *x -= f * p;
            }
        }
    }
    let mut x = [0.0; 4];
    for row in (0..4).rev() {
        let s: f64 = (row + 1..4).map(|k| a[row][k] * x[k]).sum();
        x[row] = (a[row][4] - s) / a[row][row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sphere_fits_itself() {
        let c = Vec3::new(0.3, 1.2, -0.4);
        let points: Vec<Vec3> = (0..200)
            .map(|k| {
                let (t, p) = (k as f32 * 0.37 % 1.2, k as f32 * 2.39);
                c + super::super::human::direction(t, p) * 0.09
            })
            .collect();
        let (fc, r) = fit_sphere(&points).unwrap();
        assert!(fc.distance(c) < 1e-4 && (r - 0.09).abs() < 1e-4, "{fc} {r}");
        assert!(fit_sphere(&points[..5]).is_none());
        let flat: Vec<Vec3> = (0..50).map(|k| Vec3::new(k as f32, 0.0, 0.0)).collect();
        assert!(fit_sphere(&flat).is_none());
    }

    /// The Sintel bust moved to another frame and unit (centimetres, shifted) normalizes back
    /// onto the canonical head: the similarity is recovered and the radial maps agree.
    #[test]
    fn a_moved_and_scaled_sintel_head_normalizes_back() {
        let sintel = human_head().unwrap();
        let user = Mat4::from_translation(Vec3::new(12.0, -30.0, 5.0))
            * Mat4::from_scale(Vec3::splat(100.0));
        let tris: Vec<[Vec3; 3]> = sintel
            .triangles
            .iter()
            .map(|t| t.map(|p| user.transform_point3(p)))
            .collect();
        let region: Vec<Vec3> = tris.iter().flatten().copied().collect();
        let any = AnyHead::from_triangles("moved", &tris, &region).unwrap();
        assert!((any.scale - 100.0).abs() < 0.01, "{}", any.scale);
        let back = any.to_user.transform_point3(sintel.centre);
        let want = user.transform_point3(sintel.centre);
        assert!(back.distance(want) < 0.01, "{back} vs {want}");
        for (t, p) in [(0.3f32, 1.0f32), (1.0, 4.0), (1.4, 2.0)] {
            let d = super::super::human::direction(t, p);
            let (a, b) = (any.head.radius(d), sintel.radius(d));
            assert!((a - b).abs() < 1e-3, "{t} {p}: {a} vs {b}");
        }
    }

    /// The example character's own head (MakeHuman's) normalizes to a head the size of
    /// Sintel's, and every family grows on it: roots on its scalp (within 2 mm of its surface
    /// in the character's frame), no hair vertex deep inside it.
    #[test]
    fn every_family_grows_on_the_example_characters_head() {
        let path = "hairmeshes/people/character.glb";
        let c = crate::model::gltf::load_character(
            Path::new(path),
            crate::budget::MemoryBudget::default(),
        )
        .unwrap();
        let any = AnyHead::from_character(path, &c, "head").unwrap();
        println!("scale {} to_user {}", any.scale, any.to_user);
        assert!((0.8..1.25).contains(&any.scale), "{}", any.scale);
        let to_canonical = any.to_user.inverse();
        for family in StyleFamily::PEOPLE {
            let hair = any.grow(family, 5).unwrap();
            let gap = |p: Vec3| any.head.radial_gap(to_canonical.transform_point3(p));
            let roots = hair.mesh.layers[0].iter().map(|p| gap(*p).abs());
            let worst_root = roots.fold(0.0f32, f32::max);
            let deepest = hair.mesh.layers[1..]
                .iter()
                .flatten()
                .map(|p| gap(*p))
                .fold(0.0f32, f32::min);
            println!("{family:?}: roots within {worst_root:.4} m, deepest {deepest:.4} m");
            assert!(
                worst_root < 0.002,
                "{family:?}: a root {worst_root} m off the scalp"
            );
            assert!(
                deepest > -0.01,
                "{family:?}: hair {deepest} m inside the head"
            );
        }
        assert!(AnyHead::from_character(path, &c, "nose").is_err());
    }
}
