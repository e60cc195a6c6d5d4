//! Crowd presets: `count` characters from a seed, each with its own hairstyle, placed on a grid
//! on the ground with some jitter and a random heading, plus the props (ground, bodies) they
//! stand on.

use glam::{Mat4, Quat, Vec3};

use super::hairstyle::{Hairstyle, StyleFamily, ball_fur, generate, teapot_fur};
use super::head::{HeadShape, ground_mesh};
use super::person::PersonShape;
use crate::animate::walk::{MIN_RING_RADIUS, Rig, WalkPath, Walker};
use crate::error::{HairError, Result};
use crate::render::StrandParams;
use crate::render::core::shared::{PropInstance, PropVertex};
use crate::rng::Pcg32;

/// Most characters a preset makes.
pub const MAX_CROWD: usize = 4096;

/// Which characters a crowd has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Preset {
    /// People with the twelve hairstyle families.
    People,
    /// People and furry balls.
    Mixed,
    /// Furry Utah teapots (the paper's 200-teapot scene).
    Teapots,
}

impl Preset {
    /// Height the cameras look at: heads for people, the middle of a teapot.
    pub fn focus_height(self) -> f32 {
        match self {
            Preset::People | Preset::Mixed => 1.2,
            Preset::Teapots => 0.12,
        }
    }
}

impl std::str::FromStr for Preset {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "people" => Ok(Preset::People),
            "mixed" => Ok(Preset::Mixed),
            "teapots" => Ok(Preset::Teapots),
            _ => Err(format!("unknown preset '{s}' (people, mixed, teapots)")),
        }
    }
}

/// What a character stands on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Body {
    /// A person: the human head and shoulders on a mannequin body.
    Person(PersonShape),
    /// A ball the fur grows on.
    Ball,
    /// A Utah teapot the fur grows on.
    Teapot,
    /// A copy of the user's character ([`super::own::OwnCharacter`]; its walker carries it).
    Own,
}

/// One character of a crowd.
pub struct CrowdCharacter {
    /// Its hairstyle (hair mesh + style), in the character's own frame.
    pub hair: Hairstyle,
    /// Character to world.
    pub model: Mat4,
    /// Its body.
    pub body: Body,
    /// Skin (or ball) colour, linear RGB.
    pub skin: [f32; 3],
    /// A person's skinned, clothed body and its path (people only).
    pub walker: Option<crate::animate::walk::Walker>,
}

/// Indices of [`prop_meshes`]. People's heads, bodies and eyes are skinned meshes
/// ([`super::people::skinned_meshes`]), not props.
pub mod prop_mesh {
    /// The ground.
    pub const GROUND: usize = 0;
    /// A ball.
    pub const BALL: usize = 1;
    /// A teapot.
    pub const TEAPOT: usize = 2;
}

pub use super::people::FAR_CELL_PIXELS;

/// Most vertex level fur uses: 2^3 = 8 segments are plenty for strands a few centimetres long.
pub const FUR_MAX_VERTS_LOG2: u32 = 3;

/// Strands per bundle of fur (balls, teapots) when the crowd asks for a scalp density.
pub const FUR_STRANDS_PER_BUNDLE: u32 = 96;

/// How densely a crowd's heads grow their strands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StrandDensity {
    /// Strands per cm² of scalp (a real head: 150-200,
    /// [`SCALP_STRANDS_PER_CM2`](super::hairstyle::SCALP_STRANDS_PER_CM2)); fur grows
    /// [`FUR_STRANDS_PER_BUNDLE`].
    PerCm2(f32),
    /// Strands per bundle of 24 cm² of scalp (people with coarser hair meshes get
    /// proportionally more per bundle), and per bundle of fur.
    PerReferenceBundle(u32),
}

impl Default for StrandDensity {
    fn default() -> Self {
        StrandDensity::PerCm2(super::hairstyle::SCALP_STRANDS_PER_CM2)
    }
}

impl CrowdCharacter {
    /// The strand settings this character uses when the crowd asks for `crowd`: people get at
    /// least the reference density ([`Hairstyle::strands_per_bundle`](super::hairstyle::Hairstyle::strands_per_bundle)),
    /// fur (balls, teapots) caps the vertex level at [`FUR_MAX_VERTS_LOG2`].
    pub fn strand_params(&self, crowd: StrandParams) -> StrandParams {
        match self.body {
            Body::Person(_) | Body::Own => StrandParams {
                strands_per_bundle: self.hair.strands_per_bundle(crowd.strands_per_bundle),
                ..crowd
            },
            Body::Ball | Body::Teapot => StrandParams {
                verts_log2: crowd.verts_log2.min(FUR_MAX_VERTS_LOG2),
                ..crowd
            },
        }
    }

    /// The strand settings of this character at `density` with full vertex level
    /// `verts_log2` (fur caps it at [`FUR_MAX_VERTS_LOG2`]); people's hair meshes are in
    /// metres. Refused where a bundle would need more strands than a bundle holds.
    pub fn strand_params_at(
        &self,
        density: StrandDensity,
        verts_log2: u32,
    ) -> Result<StrandParams> {
        let strands_per_bundle = match (density, self.body) {
            (StrandDensity::PerCm2(d), Body::Person(_) | Body::Own) => {
                self.hair.strands_per_bundle_at(d, 1.0)?
            }
            (StrandDensity::PerCm2(_), Body::Ball | Body::Teapot) => FUR_STRANDS_PER_BUNDLE,
            (StrandDensity::PerReferenceBundle(n), _) => n,
        };
        let asked = StrandParams {
            strands_per_bundle,
            verts_log2,
        };
        Ok(match (density, self.body) {
            (StrandDensity::PerCm2(_), Body::Person(_) | Body::Own) => asked,
            _ => self.strand_params(asked),
        })
    }

    /// Colliders for this character's hair dynamics in its hair's frame: a person's body and
    /// head (following their figure when skinned), the ball; `None` for a teapot (its fur is
    /// not simulated).
    pub fn colliders(&self) -> Result<Option<Vec<crate::dynamics::Collider>>> {
        let person = match self.body {
            Body::Person(p) => p,
            Body::Own => PersonShape::default(),
            Body::Ball => {
                let h = ball_head();
                return Ok(Some(vec![crate::dynamics::Collider::Ellipsoid {
                    centre: h.centre,
                    radii: h.radii * 0.97,
                }]));
            }
            Body::Teapot => return Ok(None),
        };
        Ok(Some(match &self.walker {
            Some(w) => w.colliders(&person)?,
            None => person.colliders()?,
        }))
    }
}

/// The ball furry characters are.
pub fn ball_head() -> HeadShape {
    HeadShape {
        centre: Vec3::new(0.0, 0.17, 0.0),
        radii: Vec3::splat(0.16),
    }
}

/// Height of a teapot in metres (small enough that neighbours never touch at [`SPACING`]).
pub const TEAPOT_HEIGHT: f32 = 0.27;

/// Grid spacing in metres.
pub const SPACING: f32 = 0.9;

/// The camera of frame `f` of a crowd of `count` characters of `preset`: orbiting the crowd's
/// centre at eye height, far enough to see it (people a little above head height, teapots
/// from further out and above).
pub fn orbit_camera(preset: Preset, count: u32, f: u32) -> crate::render::Camera {
    let side = (count as f32).sqrt().ceil();
    let centre = Vec3::new(0.0, preset.focus_height(), (side - 1.0) * 0.5 * SPACING);
    let (radius, rise) = match preset {
        Preset::Teapots => ((side * SPACING * 1.05).max(1.2), 0.5 + 0.12 * side),
        _ => ((side * SPACING * 0.75).max(1.6), 0.6 + 0.1 * side),
    };
    let angle = std::f32::consts::PI + f as f32 * 0.05;
    let eye = centre + Vec3::new(angle.sin() * radius, rise, angle.cos() * radius);
    crate::render::Camera::look_at(eye, centre, 45.0)
}

/// Build `count` characters of `preset` from `seed`.
pub fn build(preset: Preset, count: usize, seed: u32) -> Result<Vec<CrowdCharacter>> {
    build_families(preset, count, seed, &StyleFamily::PEOPLE)
}

/// [`build`] with people's hairstyles taken in turn from `families` (non-empty).
pub fn build_families(
    preset: Preset,
    count: usize,
    seed: u32,
    families: &[StyleFamily],
) -> Result<Vec<CrowdCharacter>> {
    if families.is_empty() {
        return Err(HairError::invalid("crowd", "no hairstyle families"));
    }
    let side = grid_side(count)?;
    let mut rng = Pcg32::new(seed as u64);
    let mut out = Vec::with_capacity(count);
    for i in 0..count {
        let ball = preset == Preset::Mixed && i % 4 == 3;
        let character_seed = seed.wrapping_mul(0x9E37_79B9).wrapping_add(i as u32);
        let (hair, body) = if preset == Preset::Teapots {
            (teapot_fur(character_seed, TEAPOT_HEIGHT)?, Body::Teapot)
        } else if ball {
            (ball_fur(character_seed, &ball_head())?, Body::Ball)
        } else {
            let f = families[(i + (seed as usize)) % families.len()];
            let person = PersonShape::draw(character_seed);
            (generate(f, character_seed, &person)?, Body::Person(person))
        };
        let model = grid_place(i, side, &mut rng);
        let skin = match body {
            Body::Person(p) => p.skin,
            _ => hair.style.color.map(|c| c * 0.8),
        };
        let walker = match body {
            Body::Person(p) => {
                let walks = count <= 4 || i % 2 == 0;
                let outfit = super::people::Outfit::draw(character_seed, walks);
                let path = walk_path(walks, side, model);
                Some(Walker {
                    rig: Rig::Person(outfit),
                    height: p.height,
                    head: p.head,
                    path,
                })
            }
            _ => None,
        };
        out.push(CrowdCharacter {
            hair,
            model,
            body,
            skin,
            walker,
        });
    }
    Ok(out)
}

/// Columns of the square grid of a crowd of `count` (1..=[`MAX_CROWD`]).
fn grid_side(count: usize) -> Result<usize> {
    if count == 0 || count > MAX_CROWD {
        return Err(HairError::invalid(
            "crowd",
            format!("count {count} outside 1..={MAX_CROWD}"),
        ));
    }
    Ok((count as f32).sqrt().ceil() as usize)
}

/// Place `i` of a grid of `side` columns: a little jitter and a random heading, roughly
/// toward -Z (the cameras' side).
fn grid_place(i: usize, side: usize, rng: &mut Pcg32) -> Mat4 {
    let x = (i % side) as f32 - (side as f32 - 1.0) * 0.5;
    let z = (i / side) as f32;
    let jitter = Vec3::new(rng.next_f32() - 0.5, 0.0, rng.next_f32() - 0.5) * 0.3;
    let yaw = (rng.next_f32() - 0.5) * 2.4 + std::f32::consts::PI;
    Mat4::from_rotation_translation(
        Quat::from_rotation_y(yaw),
        Vec3::new(x, 0.0, z) * SPACING + jitter,
    )
}

/// The path of a person of a crowd on a grid of `side` columns placed at `model`: walkers
/// all go the same way round one centre beside the crowd, each on the ring through their own
/// place, so they move along parallel arcs at the same speed and never meet each other,
/// turning gently enough (rings of at least [`MIN_RING_RADIUS`]) that their planted feet stay
/// put. Not yet: walkers pass through people who stand in their way.
fn walk_path(walks: bool, side: usize, model: Mat4) -> WalkPath {
    let half = (side as f32 - 1.0) * 0.5 * SPACING;
    let centre = Vec3::new(-(half + MIN_RING_RADIUS), 0.0, half);
    let at = model.w_axis.truncate() - centre;
    match walks {
        true => WalkPath::Ring {
            centre,
            radius: Vec3::new(at.x, 0.0, at.z).length().max(MIN_RING_RADIUS),
            angle: at.z.atan2(at.x),
            clockwise: false,
        },
        false => WalkPath::Stand(model),
    }
}

/// A crowd of `count` copies of the user's character `own`, each with its own hairstyle
/// (families from `families` in turn, grown on its head from the copy's seed) and clip phase;
/// half walk (all of four or fewer) where its clip walks, the others play it in place.
pub fn build_own(
    own: &std::sync::Arc<super::own::OwnCharacter>,
    count: usize,
    seed: u32,
    families: &[StyleFamily],
) -> Result<Vec<CrowdCharacter>> {
    if families.is_empty() || families.contains(&StyleFamily::Fur) {
        return Err(HairError::invalid(
            &own.name,
            "no hairstyle families for heads",
        ));
    }
    let side = grid_side(count)?;
    let mut rng = Pcg32::new(seed as u64);
    (0..count)
        .map(|i| {
            let character_seed = seed.wrapping_mul(0x9E37_79B9).wrapping_add(i as u32);
            let family = families[(i + seed as usize) % families.len()];
            let hair = own.grow(family, character_seed)?;
            let model = grid_place(i, side, &mut rng);
            let walks = own.walk_speed().is_some() && (count <= 4 || i % 2 == 0);
            let phase = (Pcg32::hashed(character_seed as u64).next_u32() % 1000) as f32 * 0.01;
            let walker = Walker {
                rig: Rig::Own {
                    character: own.clone(),
                    walks,
                    phase,
                },
                height: 1.0,
                head: Vec3::ONE,
                path: walk_path(walks, side, model),
            };
            Ok(CrowdCharacter {
                hair,
                model,
                body: Body::Own,
                skin: [1.0; 3],
                walker: Some(walker),
            })
        })
        .collect()
}

/// Give character `id` of `renderer` what it wears: its props (a person's head and eyes, a
/// ball, a teapot) and a person's skinned, clothed body, posed and placed at time 0 (the
/// animation moves both on).
pub fn dress(
    renderer: &mut crate::render::Renderer,
    id: crate::render::CharacterId,
    c: &CrowdCharacter,
) -> Result<()> {
    let gpu = |e: crate::vk::GpuError| HairError::invalid("crowd", e.to_string());
    renderer
        .set_character_props(id, &character_props(c)?)
        .map_err(gpu)?;
    if let Some(w) = &c.walker {
        let (parts, joints) = w.parts(c.skin)?;
        renderer
            .set_character_skin(id, &parts, joints)
            .map_err(gpu)?;
        let f = w.frame(0.0)?;
        renderer
            .set_character_pose(id, f.body, &f.skin)
            .map_err(gpu)?;
        renderer.set_model(id, f.hair).map_err(gpu)?;
    }
    Ok(())
}

/// A portrait of the head of a person whose hair is placed by `model`: from the front, side or
/// back (`view`), at eye height, 0.8 m away (`crowd --view front|side|back`).
pub fn portrait_camera(model: Mat4, view: &str) -> crate::render::Camera {
    let eye_local = match view {
        "side" => Vec3::new(0.8, 1.6, 0.0),
        "back" => Vec3::new(0.0, 1.62, -0.8),
        _ => Vec3::new(0.0, 1.6, 0.8),
    };
    let at = model.transform_point3(Vec3::new(0.0, 1.52, 0.0));
    crate::render::Camera::look_at(model.transform_point3(eye_local), at, 35.0)
}

/// Prop meshes of crowds, indexed by [`prop_mesh`].
pub fn prop_meshes() -> Result<Vec<Vec<PropVertex>>> {
    let ball = ball_head();
    Ok(vec![
        ground_mesh(60.0),
        super::head::sphere_mesh(ball.centre, ball.radii * 0.985),
        super::teapot::teapot_mesh(TEAPOT_HEIGHT),
    ])
}

/// The world props: the ground.
pub fn world_props() -> Vec<(usize, PropInstance)> {
    vec![(
        prop_mesh::GROUND,
        PropInstance {
            model: Mat4::IDENTITY.to_cols_array_2d(),
            color: [0.32, 0.34, 0.3, 1.0],
            clip_to_prev: Mat4::IDENTITY.to_cols_array_2d(),
            skin: [crate::render::core::shared::SKIN_NONE, 0, 0, 0],
        },
    )]
}

/// The props that move with character `c`, in its own frame: a person's head and body, a
/// ball or a teapot.
pub fn character_props(c: &CrowdCharacter) -> Result<Vec<(usize, PropInstance)>> {
    let color = [c.skin[0], c.skin[1], c.skin[2], 1.0];
    let at = |mesh: usize, model: Mat4| {
        (
            mesh,
            PropInstance {
                model: model.to_cols_array_2d(),
                color,
                clip_to_prev: Mat4::IDENTITY.to_cols_array_2d(),
                skin: [crate::render::core::shared::SKIN_NONE, 0, 0, 0],
            },
        )
    };
    Ok(match c.body {
        // Head, eyes, body and clothes are skinned meshes ([`dress`]).
        Body::Person(_) | Body::Own => Vec::new(),
        Body::Ball => vec![at(prop_mesh::BALL, Mat4::IDENTITY)],
        Body::Teapot => vec![at(prop_mesh::TEAPOT, Mat4::IDENTITY)],
    })
}
