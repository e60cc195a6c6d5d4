//! The crowd's bodies: two skinned, clothed figures (`hairmeshes/people/man.glb` and
//! `woman.glb`, MakeHuman CC0, made by `tools/people/make_people.sh`), read through the glTF
//! reader, and per person an outfit (figure, clothes and their colours) and a gait (walk or
//! idle clip, phase). The figures carry no head: each person wears the Sintel head of
//! [`super::human`], bound to the skeleton's `head` joint (the canonical head frame is the
//! figures' bind frame, their neck joint where the bust's neck meets it).

use std::sync::{Arc, OnceLock};

use glam::{Mat4, Vec3};

use crate::budget::MemoryBudget;
use crate::error::{HairError, Result};
use crate::model::gltf::{Character, parse_character};
use crate::rng::Pcg32;
use crate::shade::PROP_ROUGHNESS;

/// Pixels a far mesh's cell spans where the switch to it happens: the far version is drawn
/// once a cell is under two pixels.
pub const FAR_CELL_PIXELS: f32 = 2.0;

/// The two figures, in [`Figure`] order.
static FIGURES: OnceLock<std::result::Result<[Arc<Character>; 2], String>> = OnceLock::new();

/// Which figure a person has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Figure {
    /// `man.glb`.
    Man = 0,
    /// `woman.glb`.
    Woman = 1,
}

/// The clothing and skin meshes every figure has, in this order.
pub const PARTS: [&str; 6] = ["skin", "shirt", "sleeves", "trousers", "shoes", "skirt"];

/// The two figures (parsed once).
pub fn figures() -> Result<&'static [Arc<Character>; 2]> {
    FIGURES
        .get_or_init(|| {
            let read = |name: &str, bytes: &[u8]| {
                let c = parse_character(name, bytes, None, MemoryBudget::default())
                    .map_err(|e| e.to_string())?;
                for part in PARTS {
                    if !c.meshes.iter().any(|m| m.name == part) {
                        return Err(format!("{name}: no mesh '{part}'"));
                    }
                }
                Ok(Arc::new(c))
            };
            Ok([
                read(
                    "hairmeshes/people/man.glb",
                    include_bytes!("../../hairmeshes/people/man.glb"),
                )?,
                read(
                    "hairmeshes/people/woman.glb",
                    include_bytes!("../../hairmeshes/people/woman.glb"),
                )?,
            ])
        })
        .as_ref()
        .map_err(|e| HairError::invalid("hairmeshes/people", e.clone()))
}

/// Index of the head meshes (the bust, then the eyes) in [`skinned_meshes`], after both
/// figures' parts.
pub const HEAD_MESH: usize = 2 * PARTS.len();
/// Index of the first far mesh in [`skinned_meshes`]: far versions follow the near ones in
/// the same order, level after level ([`FAR_LEVELS`]), so mesh `k`'s level `j` is at
/// `j * FAR_MESHES + k`.
pub const FAR_MESHES: usize = HEAD_MESH + 2;
/// Far levels of every skinned mesh: level `j` (1 the first) is made at the mesh's far cell
/// times `2^(j-1)` ([`FarMethod`]), so each level is drawn where its cell spans about
/// [`FAR_CELL_PIXELS`] and a crowd's far people cost what they cover.
pub const FAR_LEVELS: usize = 4;
/// Cell of the first far level of every skinned mesh (bodies, clothes, heads and eyes),
/// metres.
pub const FAR_CELL: f32 = 0.02;
/// Far levels of the people's heads and eyes: one. Coarser heads shrink inside the body's
/// own head and lose the lids, which then show through the face as dark bands (measured at
/// 1000 people with four levels).
pub const HEAD_FAR_LEVELS: usize = 1;

/// The joint the head meshes are bound to: one past the figure's skeleton, a matrix of each
/// person's own (the head joint's, then the person's head proportions about the cranium).
pub fn head_shape_joint() -> Result<usize> {
    Ok(figures()?[0].skeleton.joints.len())
}

/// Far plan of mesh `k` of [`skinned_meshes`]: its first far cell, its far levels, and how
/// they are made: the bodies and clothes simplified by edge collapse, the heads clustered.
fn far_plan(k: usize) -> FarPlan {
    let head = k >= HEAD_MESH;
    FarPlan {
        cell: FAR_CELL,
        levels: if head { HEAD_FAR_LEVELS } else { FAR_LEVELS },
        method: if head {
            FarMethod::Cluster
        } else {
            FarMethod::Simplify
        },
    }
}

/// How a mesh's far versions are made: level `j` (1 the first) from `cell * 2^(j-1)`, up to
/// `levels` (at most [`FAR_LEVELS`]; the levels beyond repeat the last and are never
/// switched to).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FarPlan {
    /// Cell of the first far level, in the mesh's units: it switches where a cell spans
    /// [`FAR_CELL_PIXELS`].
    pub cell: f32,
    /// Far levels drawn.
    pub levels: usize,
    /// How each level is made from the near mesh.
    pub method: FarMethod,
}

/// How a far level is made from the near mesh, given the level's cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FarMethod {
    /// Vertex clustering into cells (`skin::far::far_mesh`): every triangle left is a chord of
    /// the surface, so a convex part only shrinks. For scalps: hair lies 0.3-1.2 mm above
    /// them, and a head that bulges out by more shows through it.
    Cluster,
    /// Edge collapse until the surface would move [`SIMPLIFY_ERROR_CELLS`] of a cell
    /// (`skin::far::simplified_mesh`): 4-6x fewer triangles than clustering for bodies and
    /// clothes, outlines kept. The error is small enough that layered clothes do not show
    /// through each other (at half a cell a shirt's hem frayed over the trousers).
    Simplify,
}

/// Edge collapse's error for a far level, in cells of the level (a cell spans
/// [`FAR_CELL_PIXELS`] where the level is switched to: half a pixel).
pub const SIMPLIFY_ERROR_CELLS: f32 = 0.25;

impl FarMethod {
    /// `mesh`'s far version for a level of cells `cell` wide.
    pub fn apply(self, mesh: &crate::skin::SkinnedMesh, cell: f32) -> crate::skin::SkinnedMesh {
        match self {
            FarMethod::Cluster => crate::skin::far::far_mesh(mesh, cell),
            FarMethod::Simplify => {
                crate::skin::far::simplified_mesh(mesh, SIMPLIFY_ERROR_CELLS * cell)
            }
        }
    }
}

/// Every figure's meshes, figure after figure (mesh `k` of figure `f` at
/// `f * PARTS.len() + k`), the head's bust and eyes ([`HEAD_MESH`]), then [`FAR_LEVELS`] far
/// versions of each in the same order ([`FAR_MESHES`]): what `Renderer::set_skinned_meshes`
/// takes.
pub fn skinned_meshes() -> Result<Vec<crate::skin::SkinnedMesh>> {
    let mut near = Vec::new();
    for c in figures()? {
        for part in PARTS {
            let m = c.meshes.iter().find(|m| m.name == part);
            near.extend(m.cloned());
        }
    }
    near.extend(head_meshes()?);
    Ok(with_far_levels(near, far_plan))
}

/// `near` followed by [`FAR_LEVELS`] levels of far versions of every mesh, made as `plan(k)`
/// says for mesh `k`. Where a level empties a mesh (an eye smaller than a cell) the level
/// draws nothing (one zero-area triangle): a finer version kept instead would stand out of
/// the coarser head around it.
pub fn with_far_levels(
    near: Vec<crate::skin::SkinnedMesh>,
    plan: impl Fn(usize) -> FarPlan,
) -> Vec<crate::skin::SkinnedMesh> {
    let n = near.len();
    let mut all = near;
    for level in 1..=FAR_LEVELS {
        for k in 0..n {
            let FarPlan {
                cell,
                levels,
                method,
            } = plan(k);
            if level > levels {
                all.push(all[(level - 1) * n + k].clone());
                continue;
            }
            let coarser = (1u32 << (level - 1)) as f32;
            let far = method.apply(&all[k], cell * coarser);
            let kept = match far.indices.is_empty() {
                true => crate::skin::SkinnedMesh {
                    name: format!("{} (far, empty)", all[k].name),
                    vertices: all[k].vertices.iter().take(1).copied().collect(),
                    indices: vec![0; 3],
                },
                false => far,
            };
            all.push(kept);
        }
    }
    all
}

/// When each level of [`with_far_levels`]'s `meshes` (`n` near ones, made as `plan` says)
/// switches to the next: once the next level's cell spans under
/// [`FAR_CELL_PIXELS`].
pub fn far_level_lods(
    meshes: &[crate::skin::SkinnedMesh],
    n: usize,
    plan: impl Fn(usize) -> FarPlan,
) -> Vec<crate::render::prop_table::PropLod> {
    let mut out = Vec::new();
    for level in 0..FAR_LEVELS {
        for (k, mesh) in meshes.iter().take(n).enumerate() {
            let FarPlan { cell, levels, .. } = plan(k);
            if level >= levels {
                continue;
            }
            let coarser = (1u32 << level) as f32;
            let to = ((level * n + k), ((level + 1) * n + k));
            out.push(far_lod(mesh, to, cell * coarser));
        }
    }
    out
}

/// Far versions of [`skinned_meshes`]: a mesh switches to its next far level where that
/// level's cell spans under [`FAR_CELL_PIXELS`] (as the static props do).
pub fn skinned_lods(
    meshes: &[crate::skin::SkinnedMesh],
) -> Vec<crate::render::prop_table::PropLod> {
    far_level_lods(meshes, FAR_MESHES, far_plan)
}

/// Bind-pose box of `mesh`.
pub fn mesh_bounds(mesh: &crate::skin::SkinnedMesh) -> (Vec3, Vec3) {
    crate::model::hair_mesh::bounds(mesh.vertices.iter().map(|v| v.position))
}

/// When skinned mesh `mesh` (index `k`, far version at `far`, clustered at `cell`) switches
/// to its far version: once a cell spans under [`FAR_CELL_PIXELS`].
pub fn far_lod(
    mesh: &crate::skin::SkinnedMesh,
    (k, far): (usize, usize),
    cell: f32,
) -> crate::render::prop_table::PropLod {
    let (lo, hi) = mesh_bounds(mesh);
    crate::render::prop_table::PropLod {
        mesh: k,
        far_mesh: far,
        below_pixels: FAR_CELL_PIXELS * (hi - lo).length() / cell,
    }
}

/// The Sintel head above the neck and its eyes as skinned meshes bound wholly to
/// [`head_shape_joint`] (canonical frame): the bust with the eyelids white (the person's skin
/// tone tints it; the lash lines dark), the eyeballs banded pupil, iris and sclera, wet
/// ([`super::eyes`]).
fn head_meshes() -> Result<[crate::skin::SkinnedMesh; 2]> {
    let joint = head_shape_joint()? as u16;
    let head = super::human::human_head()?;
    let mut bust = super::person::neck_up_mesh()?;
    let mut bust_colors = vec![Vec3::ONE; bust.len()];
    let mut eyes = Vec::new();
    let mut eye_colors = Vec::new();
    let head_eyes = head
        .eyes
        .ok_or_else(|| HairError::invalid("hairmeshes/sintel_head.obj", "no eye sockets"))?;
    for eye in head_eyes {
        for (tri, color) in super::eyes::eyeball(&eye) {
            eyes.extend(tri);
            eye_colors.extend([Vec3::from(color); 3]);
        }
        let (skin, lashes) = super::eyes::lids(&eye);
        for (tris, shade) in [(skin, 1.0), (lashes, LASH_LINE)] {
            let verts = super::human::smooth_prop_mesh(&tris);
            bust_colors.extend(std::iter::repeat_n(Vec3::splat(shade), verts.len()));
            bust.extend(verts);
        }
    }
    Ok([
        welded("head", &bust, &bust_colors, (joint, PROP_ROUGHNESS)),
        welded(
            "eyes",
            &eyes,
            &eye_colors,
            (joint, super::eyes::EYE_ROUGHNESS),
        ),
    ])
}

/// The lash line's shade of the skin tone: lashes and the lid's shadowed edge.
const LASH_LINE: f32 = 0.12;

/// A triangle list of prop vertices as an indexed skinned mesh bound to `joint`, of GGX
/// `roughness` (corners with the same position, normal and colour welded).
fn welded(
    name: &str,
    list: &[crate::render::core::shared::PropVertex],
    colors: &[Vec3],
    (joint, roughness): (u16, f32),
) -> crate::skin::SkinnedMesh {
    use std::collections::HashMap;
    let mut index: HashMap<[u32; 9], u32> = HashMap::new();
    let mut vertices = Vec::new();
    let mut indices = Vec::with_capacity(list.len());
    for (v, c) in list.iter().zip(colors) {
        let p = Vec3::from_slice(&v.position[..3]);
        let n = Vec3::from_slice(&v.normal[..3]);
        let key = [p.x, p.y, p.z, n.x, n.y, n.z, c.x, c.y, c.z].map(f32::to_bits);
        let next = vertices.len() as u32;
        let i = *index.entry(key).or_insert_with(|| {
            vertices.push(crate::skin::SkinVertex {
                position: p,
                normal: n,
                color: *c,
                roughness,
                joints: [joint, 0, 0, 0],
                weights: [1.0, 0.0, 0.0, 0.0],
            });
            next
        });
        indices.push(i);
    }
    crate::skin::SkinnedMesh {
        name: name.into(),
        vertices,
        indices,
    }
}

/// What one person wears, and how they move.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outfit {
    /// Figure.
    pub figure: Figure,
    /// Shirt colour (linear RGB).
    pub shirt: [f32; 3],
    /// Trousers or skirt colour.
    pub legs: [f32; 3],
    /// Shoe colour.
    pub shoes: [f32; 3],
    /// Long sleeves (else the forearms show).
    pub long_sleeves: bool,
    /// A long skirt instead of trousers (only people who stand: a long skirt skinned to the
    /// legs tears when they walk).
    pub skirt: bool,
    /// Walks (else stands, the idle clip).
    pub walks: bool,
    /// Seconds into the clip at time 0.
    pub phase: f32,
}

/// Shirt colours (linear RGB): muted everyday fabrics.
const SHIRTS: [[f32; 3]; 10] = [
    [0.05, 0.09, 0.22],
    [0.5, 0.5, 0.48],
    [0.6, 0.58, 0.52],
    [0.22, 0.03, 0.03],
    [0.04, 0.14, 0.06],
    [0.3, 0.18, 0.07],
    [0.02, 0.02, 0.025],
    [0.35, 0.08, 0.18],
    [0.12, 0.25, 0.4],
    [0.55, 0.4, 0.12],
];
/// Trouser and skirt colours.
const LEGS: [[f32; 3]; 6] = [
    [0.03, 0.04, 0.09],
    [0.015, 0.015, 0.018],
    [0.18, 0.15, 0.1],
    [0.1, 0.1, 0.1],
    [0.05, 0.08, 0.16],
    [0.25, 0.06, 0.05],
];

impl Outfit {
    /// An outfit drawn from `seed`; walking when `walks`.
    pub fn draw(seed: u32, walks: bool) -> Self {
        let mut rng = Pcg32::hashed(seed as u64 ^ 0x6f75_7466_6974);
        let mut pick = |n: usize| (rng.next_u32() as usize) % n;
        let figure = if pick(2) == 0 {
            Figure::Man
        } else {
            Figure::Woman
        };
        let shirt = SHIRTS[pick(SHIRTS.len())];
        let legs = LEGS[pick(LEGS.len())];
        let shoes = [[0.02, 0.015, 0.01], [0.25, 0.25, 0.25], [0.12, 0.06, 0.03]][pick(3)];
        let long_sleeves = pick(2) == 0;
        let skirt = figure == Figure::Woman && !walks && pick(2) == 0;
        let phase = pick(1000) as f32 * 0.01;
        Outfit {
            figure,
            shirt,
            legs,
            shoes,
            long_sleeves,
            skirt,
            walks,
            phase,
        }
    }

    /// The skinned parts this person wears: `(mesh index in [`skinned_meshes`], colour)`,
    /// the skin in `skin`.
    pub fn parts(&self, skin: [f32; 3]) -> Vec<(usize, [f32; 4])> {
        let base = self.figure as usize * PARTS.len();
        let c = |rgb: [f32; 3]| [rgb[0], rgb[1], rgb[2], 1.0];
        let mut out = vec![
            (base, c(skin)),
            (base + 1, c(self.shirt)),
            (base + 4, c(self.shoes)),
            (HEAD_MESH, c(skin)),
            (HEAD_MESH + 1, [1.0; 4]),
        ];
        if self.long_sleeves {
            out.push((base + 2, c(self.shirt)));
        }
        out.push(match self.skirt {
            true => (base + 5, c(self.legs)),
            false => (base + 3, c(self.legs)),
        });
        out
    }
}

/// A person's skeleton at time `t`: the figure's clip (walk or idle) sampled at `t + phase`.
/// Returns the skin matrices (bind frame to the figure's frame, which moves in place: the
/// crowd moves the root along its path), the head shape joint's last (the head joint's with
/// the `head_shape` proportions about the cranium centre: [`head_shape_joint`]), and the head
/// joint's alone.
pub fn pose(outfit: &Outfit, t: f32, head_shape: Vec3) -> Result<(Vec<Mat4>, Mat4)> {
    let figure = &figures()?[outfit.figure as usize];
    let clip = figure
        .clip(if outfit.walks { "walk" } else { "idle" })
        .ok_or_else(|| {
            HairError::invalid("hairmeshes/people", "a figure lacks its walk or idle clip")
        })?;
    let s = &figure.skeleton;
    let mut m = s.skin_matrices(&clip.sample(s, t + outfit.phase));
    let head = s
        .find("head")
        .ok_or_else(|| HairError::invalid("hairmeshes/people", "a figure has no head joint"))?;
    let c = super::human::human_head()?.centre;
    let shape =
        Mat4::from_translation(c) * Mat4::from_scale(head_shape) * Mat4::from_translation(-c);
    let h = m[head];
    m.push(h * shape);
    Ok((m, h))
}

/// The figures' walk ground speeds, measured once (walkers ask every frame).
static WALK_SPEEDS: OnceLock<std::result::Result<[f32; 2], String>> = OnceLock::new();

/// Ground speed of a figure's walk (metres per second at scale 1): the speed its planted feet
/// move backward, which the root must move forward at ([`crate::skin::ground_speed`]);
/// measured on the first call, the same thereafter.
pub fn walk_speed(figure: Figure) -> Result<f32> {
    let speeds = WALK_SPEEDS.get_or_init(|| {
        let measure = |c: &Character| {
            let s = &c.skeleton;
            let walk = c.clip("walk").ok_or("no walk clip")?;
            let feet: Vec<usize> = ["ball_l", "ball_r"]
                .iter()
                .filter_map(|n| s.find(n))
                .collect();
            crate::skin::ground_speed(s, walk, &feet, 0.01)
                .ok_or("the walk does not plant its feet")
        };
        let f = figures().map_err(|e| e.to_string())?;
        Ok([measure(&f[0])?, measure(&f[1])?])
    });
    speeds
        .as_ref()
        .map(|s| s[figure as usize])
        .map_err(|e| HairError::invalid("hairmeshes/people", e.clone()))
}

/// Where a person's hair and body go: the hair lives in the person frame (canonical scaled
/// by `height` about the feet), which follows the head joint (`head`, canonical bind to
/// posed): its model is `root S H S^-1`. The body and the skinned head are drawn at `root S`,
/// posed by the skin matrices on the GPU: two data paths that meet at the scalp (what the
/// root-gap measure checks). Returns `(hair model, body model)`.
pub fn head_bound(root: Mat4, height: f32, head: Mat4) -> (Mat4, Mat4) {
    let s = Mat4::from_scale(Vec3::splat(height));
    (root * s * head * s.inverse(), root * s)
}

/// The root of every bundle's first strand in the hair's own frame (the person frame), by the
/// CPU reference generator: where the GPU's root probe must find them, carried by the body.
pub fn expected_roots(
    baked: &crate::bake::BakedHairMesh,
    style: &crate::model::style::HairStyle,
) -> Vec<Vec3> {
    let generator = crate::reference::generate::CpuGenerator::new(baked, *style);
    let (mut pos, mut tan, mut width) = ([Vec3::ZERO; 2], [Vec3::ZERO; 2], [0.0; 2]);
    (0..baked.bundles.len() as u32)
        .map(|b| {
            generator.strand(b, 0, 1, &mut pos, &mut tan, &mut width);
            pos[0]
        })
        .collect()
}

/// The GPU's probed roots (`FrameReport::roots`) of the character in slot `slot`, in bundle
/// order.
pub fn probed_roots(roots: &[[f32; 4]], slot: u32) -> Vec<Vec3> {
    roots
        .iter()
        .filter(|r| r[3] == (slot + 1) as f32)
        .map(|r| Vec3::new(r[0], r[1], r[2]))
        .collect()
}

/// Largest distance, in head radii, between the roots the GPU placed (`probed`, world, the
/// hair's data path: its model and textures) and where the skinned scalp carries them
/// (`expected`, person frame, moved by the body's data path: `body` times the head shape
/// joint's skin matrix `head_joint`, from the canonical head, after `head_to_person`, the
/// person's head placement, is undone). `None` when the counts differ (the probe missed the
/// character).
pub fn root_gap(
    probed: &[Vec3],
    expected: &[Vec3],
    (body, head_joint): (Mat4, Mat4),
    head_to_person: Mat4,
    head_scale: f32,
) -> Option<f32> {
    if probed.len() != expected.len() || probed.is_empty() {
        return None;
    }
    let carry = body * head_joint * head_to_person.inverse();
    let radius = super::person::CANONICAL_RADIUS * head_scale;
    Some(
        probed
            .iter()
            .zip(expected)
            .map(|(g, e)| g.distance(carry.transform_point3(*e)) / radius)
            .fold(0.0, f32::max),
    )
}

/// The bones whose capsules hair collides with: the shoulders (clavicle to upper arm),
/// radii fitted to the shirt.
const COLLIDER_BONES: [(&str, &str); 2] =
    [("clavicle_l", "upperarm_l"), ("clavicle_r", "upperarm_r")];

/// The neck the hair meets: the Sintel bust's (canonical frame; axis ends and radius).
const NECK: (Vec3, Vec3, f32) = (
    Vec3::new(0.0, 1.40, -0.025),
    Vec3::new(0.0, 1.50, -0.015),
    0.048,
);

/// Colliders for the hair dynamics of a person of `figure` shaped `person`, in the person
/// frame (canonical scaled by height): the bust's neck, capsules fitted to the figure's
/// shoulder bones at bind time (each radius the median distance from the bone of the shirt's
/// vertices it moves by a quarter or more), an ellipsoid over the upper chest and back (the
/// shirt's vertices the upper spine moves, their box), then the head itself (last: where the
/// neck and the jaw disagree, the head wins). Not yet: they stay where the bind pose puts
/// them relative to the head, rather than following their bones through the clip.
pub fn colliders(
    figure: Figure,
    person: &super::person::PersonShape,
) -> Result<Vec<crate::dynamics::Collider>> {
    use crate::dynamics::Collider;
    let c = &figures()?[figure as usize];
    let s = &c.skeleton;
    let rest = s.globals(&s.rest_pose());
    let joint = |name: &str| -> Result<usize> {
        s.find(name)
            .ok_or_else(|| HairError::invalid("hairmeshes/people", format!("no joint {name}")))
    };
    let shirt = c
        .meshes
        .iter()
        .find(|m| m.name == "shirt")
        .ok_or_else(|| HairError::invalid("hairmeshes/people", "no shirt"))?;
    // The shirt's vertices joint `j` moves by a quarter or more.
    let moved_by = |j: usize| {
        shirt
            .vertices
            .iter()
            .filter(move |v| (0..4).any(|k| v.joints[k] as usize == j && v.weights[k] >= 0.25))
            .map(|v| v.position)
    };
    let h = person.height;
    let mut out = vec![Collider::Capsule {
        a: NECK.0 * h,
        b: NECK.1 * h,
        radius: NECK.2 * h,
    }];
    for (from, to) in COLLIDER_BONES {
        let (j, k) = (joint(from)?, joint(to)?);
        let (a, b) = (rest[j].w_axis.truncate(), rest[k].w_axis.truncate());
        let mut d: Vec<f32> = moved_by(j).map(|p| segment_distance(p, a, b)).collect();
        if d.is_empty() {
            return Err(HairError::invalid(
                "hairmeshes/people",
                format!("no shirt vertex follows joint {from}"),
            ));
        }
        d.sort_by(f32::total_cmp);
        out.push(Collider::Capsule {
            a: a * h,
            b: b * h,
            radius: d[d.len() / 2] * h,
        });
    }
    let (lo, hi) = moved_by(joint("spine_03")?)
        .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), p| (lo.min(p), hi.max(p)));
    if lo.x > hi.x {
        return Err(HairError::invalid(
            "hairmeshes/people",
            "no shirt vertex follows the chest",
        ));
    }
    out.push(Collider::Ellipsoid {
        centre: (lo + hi) * 0.5 * h,
        radii: (hi - lo) * 0.5 * h,
    });
    out.push(Collider::head(
        &super::human::human_head()?.map,
        person.head_transform()?,
        0.005,
    ));
    Ok(out)
}

/// Distance of `p` from the segment `a..b`.
fn segment_distance(p: Vec3, a: Vec3, b: Vec3) -> f32 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared().max(1e-12)).clamp(0.0, 1.0);
    p.distance(a + ab * t)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both figures load with every part and the same skeleton size, and their colliders are
    /// body-sized: the neck, shoulder capsules of radius 3-12 cm above 1.1 m, a chest
    /// ellipsoid of half-axes 5-30 cm, then the head.
    #[test]
    fn figures_and_their_colliders() {
        use crate::dynamics::Collider;
        let f = figures().unwrap();
        assert_eq!(f[0].skeleton.joints.len(), f[1].skeleton.joints.len());
        let person = super::super::person::PersonShape::default();
        for figure in [Figure::Man, Figure::Woman] {
            let c = colliders(figure, &person).unwrap();
            assert_eq!(c.len(), COLLIDER_BONES.len() + 3, "{figure:?}");
            for k in &c[1..=COLLIDER_BONES.len()] {
                let Collider::Capsule { a, b, radius } = *k else {
                    panic!("{k:?}")
                };
                println!("{figure:?}: {a} .. {b}, radius {radius}");
                assert!(
                    (0.03..0.12).contains(&radius),
                    "{figure:?}: radius {radius}"
                );
                assert!(a.y > 1.1 && b.y > 1.1, "{figure:?}: {a} {b}");
            }
            let Collider::Ellipsoid { centre, radii } = c[COLLIDER_BONES.len() + 1] else {
                panic!("no chest")
            };
            println!("{figure:?}: chest {centre} radii {radii}");
            assert!(
                radii.min_element() > 0.05 && radii.max_element() < 0.3,
                "{radii}"
            );
            assert!(matches!(c.last(), Some(Collider::Head { .. })));
        }
        let meshes = skinned_meshes().unwrap();
        assert_eq!(meshes.len(), (1 + FAR_LEVELS) * FAR_MESHES);
        // Each level never has more triangles than the one before, mesh by mesh; the bodies
        // and clothes (the heads keep one level) have at most two thirds of the level
        // before's, and edge collapse leaves at most a fifth of everything at the first level
        // (vertex clustering left 0.41).
        let triangles = |level: usize, meshes_of: std::ops::Range<usize>| {
            meshes_of
                .map(|k| meshes[level * FAR_MESHES + k].indices.len() / 3)
                .sum::<usize>()
        };
        for level in 1..=FAR_LEVELS {
            for k in 0..FAR_MESHES {
                let near = &meshes[(level - 1) * FAR_MESHES + k];
                let far = &meshes[level * FAR_MESHES + k];
                println!(
                    "{} level {level}: {} triangles",
                    near.name,
                    far.indices.len() / 3
                );
                assert!(far.indices.len() <= near.indices.len(), "{}", near.name);
            }
            let (near_bodies, far_bodies) = (
                triangles(level - 1, 0..HEAD_MESH),
                triangles(level, 0..HEAD_MESH),
            );
            let all = triangles(level, 0..FAR_MESHES);
            println!("level {level}: bodies {far_bodies} of {near_bodies}, all {all}");
            // Measured bodies: 0.12, 0.43, 0.44 and 0.44 of the level before.
            assert!(
                far_bodies * 3 < near_bodies * 2,
                "level {level}: {far_bodies} of {near_bodies}"
            );
        }
        // Measured: 4351 of 36512 (0.12).
        let (near, first) = (triangles(0, 0..FAR_MESHES), triangles(1, 0..FAR_MESHES));
        assert!(
            first * 5 < near,
            "the first far level keeps {first} of {near}"
        );
    }
}
