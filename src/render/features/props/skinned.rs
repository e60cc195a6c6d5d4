//! Skinned props (the crowd's bodies and clothes): skinned meshes on the GPU, the meshes each
//! character wears and its skin matrices for the next frame, and this frame's skinning jobs.
//! The skinning pass (`passes/skin.rs`, `glsl/skin.comp`) poses every drawn instance into the
//! frame's posed vertices, which the prop passes of the camera and the light both draw.

use std::collections::HashMap;
use std::sync::Arc;

use ash::vk;
use glam::{Mat4, Vec3};

use super::draw::PropDraw;
use super::{Projection, PropLod};
use crate::render::core::ids::CharacterId;
use crate::render::core::shared::{PropInstance, SKIN_GROUP_SIZE, SkinJob, SkinRestVertex};
use crate::skin::SkinnedMesh;
use crate::vk::{Buffer, Context, GpuError, GpuResult};

/// One skinned mesh on the GPU.
#[derive(Clone, Copy, Debug, PartialEq)]
struct MeshRange {
    rest_first: u32,
    vertex_count: u32,
    index_first: u32,
    index_count: u32,
    /// Bounding sphere at bind time, padded for poses.
    centre: Vec3,
    radius: f32,
}

/// What a character wears: `(mesh, colour)` and its joint count.
#[derive(Clone, Debug, PartialEq)]
struct Wearer {
    parts: Vec<(usize, [f32; 4])>,
    joints: usize,
    /// The body's placement for the next frame (figure frame to world).
    body: Mat4,
    /// Skin matrices for the next frame (bind frame to figure frame).
    matrices: Vec<Mat4>,
}

/// This frame's skinning: jobs, matrices, posed vertices, and the instances and draws.
#[derive(Default)]
pub(in crate::render) struct SkinWork {
    pub jobs: Vec<SkinJob>,
    pub matrices: Vec<[[f32; 4]; 4]>,
    pub vertices: u32,
    /// The most vertices of any job (the pass's dispatch width).
    pub widest: u32,
}

/// Upper bounds of a frame's skinning ([`SkinnedProps::capacity`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(in crate::render) struct SkinCapacity {
    pub instances: u32,
    pub jobs: u32,
    pub matrices: u32,
    pub vertices: u32,
}

/// Skin mesh `r` into the next `r.vertex_count` posed vertices with the matrices from
/// `matrix_first`: one job per [`SKIN_GROUP_SIZE`] vertices, so the dispatch (a workgroup
/// row per job, as wide as the widest job) has no idle workgroups where near and far
/// meshes, thousands and tens of vertices, share a frame.
fn push_jobs(work: &mut SkinWork, r: &MeshRange, matrix_first: u32) {
    let mut first = 0;
    while first < r.vertex_count {
        let count = (r.vertex_count - first).min(SKIN_GROUP_SIZE);
        work.jobs.push(SkinJob {
            rest_first: r.rest_first + first,
            vertex_count: count,
            matrix_first,
            out_first: work.vertices + first,
        });
        work.widest = work.widest.max(count);
        first += count;
    }
}

/// Skinned meshes and the characters wearing them.
#[derive(Default)]
pub(in crate::render) struct SkinnedProps {
    pub(in crate::render) rest: Option<Buffer>,
    pub(in crate::render) indices: Option<Buffer>,
    meshes: Vec<MeshRange>,
    far: Vec<Option<(usize, f32)>>,
    wearers: HashMap<CharacterId, Wearer>,
}

/// Bounding sphere of a skinned mesh's bind pose, padded by a fifth for poses.
fn bounds(mesh: &SkinnedMesh) -> (Vec3, f32) {
    let (lo, hi) = mesh
        .vertices
        .iter()
        .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), v| {
            (lo.min(v.position), hi.max(v.position))
        });
    let centre = (lo + hi) * 0.5;
    let r = mesh
        .vertices
        .iter()
        .map(|v| v.position.distance(centre))
        .fold(0.0, f32::max);
    (centre, r * 1.2)
}

/// A rest vertex for the GPU: the colour packed as RGBA8 with the roughness in alpha.
fn rest_vertex(v: &crate::skin::SkinVertex) -> SkinRestVertex {
    let c = v.color.clamp(Vec3::ZERO, Vec3::ONE) * 255.0 + 0.5;
    let rough = v.roughness.clamp(0.0, 1.0) * 255.0 + 0.5;
    let j = v.joints.map(u32::from);
    SkinRestVertex {
        position: v.position.to_array(),
        color: c.x as u32 | (c.y as u32) << 8 | (c.z as u32) << 16 | (rough as u32) << 24,
        normal: v.normal.to_array(),
        joints01: j[0] | j[1] << 16,
        weights: v.weights,
        joints23: [j[2] | j[3] << 16, 0, 0, 0],
    }
}

impl SkinnedProps {
    /// Replace the skinned meshes (forgetting what characters wear); returns the old buffers.
    pub(in crate::render) fn set_meshes(
        &mut self,
        ctx: &Arc<Context>,
        meshes: &[SkinnedMesh],
    ) -> GpuResult<Vec<Buffer>> {
        let mut rest = Vec::new();
        let mut indices = Vec::new();
        let mut ranges = Vec::new();
        for (k, m) in meshes.iter().enumerate() {
            let bad = m.indices.len() % 3 != 0
                || m.indices.iter().any(|&i| i as usize >= m.vertices.len())
                || m.vertices
                    .iter()
                    .any(|v| !(v.position.is_finite() && v.normal.is_finite()));
            if bad || m.vertices.is_empty() {
                return Err(GpuError::Unsupported(format!(
                    "skinned mesh {k} '{}' is not a finite, non-empty triangle list",
                    m.name
                )));
            }
            let (centre, radius) = bounds(m);
            ranges.push(MeshRange {
                rest_first: rest.len() as u32,
                vertex_count: m.vertices.len() as u32,
                index_first: indices.len() as u32,
                index_count: m.indices.len() as u32,
                centre,
                radius,
            });
            rest.extend(m.vertices.iter().map(rest_vertex));
            indices.extend_from_slice(&m.indices);
        }
        let upload = |name, bytes: &[u8]| {
            // The indices are the skinned draws' index buffer too.
            let usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::INDEX_BUFFER;
            Buffer::device_local_with_data(ctx, name, usage, bytes)
        };
        let (new_rest, new_indices) = if ranges.is_empty() {
            (None, None)
        } else {
            (
                Some(upload("skin rest vertices", bytemuck::cast_slice(&rest))?),
                Some(upload("skin indices", bytemuck::cast_slice(&indices))?),
            )
        };
        self.meshes = ranges;
        self.far = vec![None; self.meshes.len()];
        self.wearers.clear();
        let old = [
            std::mem::replace(&mut self.rest, new_rest),
            std::mem::replace(&mut self.indices, new_indices),
        ];
        Ok(old.into_iter().flatten().collect())
    }

    /// Give skinned meshes far versions (checked as the static props' are).
    pub(in crate::render) fn set_lods(&mut self, lods: &[PropLod]) -> GpuResult<()> {
        self.far = super::far_table(lods, self.meshes.len())?;
        Ok(())
    }

    /// Character `id` wears `parts` (`(mesh, linear colour)`) over a skeleton of `joints`
    /// (posed at rest until [`Self::set_pose`]); no parts: it wears nothing skinned.
    pub(in crate::render) fn set_wearer(
        &mut self,
        id: CharacterId,
        parts: &[(usize, [f32; 4])],
        joints: usize,
    ) -> GpuResult<()> {
        if let Some((m, _)) = parts.iter().find(|(m, _)| *m >= self.meshes.len()) {
            return Err(GpuError::Unsupported(format!("no skinned mesh {m}")));
        }
        if !parts.iter().all(|(_, c)| c.iter().all(|x| x.is_finite())) || joints == 0 {
            return Err(GpuError::Unsupported(
                "skinned parts need finite colours and a skeleton".into(),
            ));
        }
        if parts.is_empty() {
            self.wearers.remove(&id);
            return Ok(());
        }
        self.wearers.insert(
            id,
            Wearer {
                parts: parts.to_vec(),
                joints,
                body: Mat4::IDENTITY,
                matrices: vec![Mat4::IDENTITY; joints],
            },
        );
        Ok(())
    }

    /// Character `id`'s body placement and skin matrices for the next frame (one per joint,
    /// all finite).
    pub(in crate::render) fn set_pose(
        &mut self,
        id: CharacterId,
        body: Mat4,
        matrices: &[Mat4],
    ) -> GpuResult<()> {
        let w = self
            .wearers
            .get_mut(&id)
            .ok_or_else(|| GpuError::Unsupported("the character wears no skinned mesh".into()))?;
        if matrices.len() != w.joints
            || !matrices.iter().all(|m| m.is_finite())
            || !body.is_finite()
        {
            return Err(GpuError::Unsupported(format!(
                "{} finite skin matrices expected, got {}",
                w.joints,
                matrices.len()
            )));
        }
        w.matrices.copy_from_slice(matrices);
        w.body = body;
        Ok(())
    }

    /// Forget character `id`.
    pub(in crate::render) fn remove(&mut self, id: CharacterId) {
        self.wearers.remove(&id);
    }

    /// Character `id`'s body placement and skin matrices as last set.
    pub(in crate::render) fn pose(&self, id: CharacterId) -> Option<(Mat4, &[Mat4])> {
        self.wearers
            .get(&id)
            .map(|w| (w.body, w.matrices.as_slice()))
    }

    /// Upper bounds of a frame's instances, skinning jobs, matrices and posed vertices.
    pub(in crate::render) fn capacity(&self) -> SkinCapacity {
        let mut out = SkinCapacity::default();
        for w in self.wearers.values() {
            // Each part twice: the camera's instance and the light's.
            out.instances += 2 * w.parts.len() as u32;
            out.matrices += w.joints as u32;
            for (m, _) in &w.parts {
                // Far versions have no more vertices than their mesh, and the light's own
                // version, when it has one, is at least the first far one.
                let light = self.far[*m].map_or(0, |(far, _)| self.meshes[far].vertex_count);
                for vertices in [self.meshes[*m].vertex_count, light] {
                    out.jobs += vertices.div_ceil(SKIN_GROUP_SIZE);
                    out.vertices += vertices;
                }
            }
        }
        out
    }

    /// This frame's skinning work, instances (appended to `records`, with their motion) and
    /// draws, for the characters `model_of` draws (`None`: hidden; the second matrix is the
    /// character's clip-space motion, which the body shares), each at its body placement:
    /// the camera's (`draws`; far versions where `camera` sees a mesh small) and the light's
    /// (`light_draws`; coarser far versions where `light`'s map sees a body smaller than the
    /// camera does, posed alongside). Characters are taken in slot order, so frames are
    /// repeatable.
    pub(in crate::render) fn frame_lists(
        &self,
        model_of: impl Fn(CharacterId) -> Option<(Mat4, Mat4)>,
        (camera, light): (&Projection, Option<&Projection>),
        records: &mut Vec<PropInstance>,
        (draws, light_draws): (&mut Vec<PropDraw>, &mut Vec<PropDraw>),
    ) -> SkinWork {
        let mut work = SkinWork::default();
        let mut ids: Vec<&CharacterId> = self.wearers.keys().collect();
        ids.sort_by_key(|id| id.slot());
        let mut placed: Vec<(usize, PropInstance)> = Vec::new();
        let mut cast: Vec<(usize, PropInstance)> = Vec::new();
        for id in ids {
            let w = &self.wearers[id];
            let Some((_, clip_to_prev)) = model_of(*id) else {
                continue;
            };
            let model = w.body;
            let matrix_first = work.matrices.len() as u32;
            work.matrices
                .extend(w.matrices.iter().map(|m| m.to_cols_array_2d()));
            let mut pose = |mesh: usize, color| {
                let r = self.meshes[mesh];
                push_jobs(&mut work, &r, matrix_first);
                let inst = PropInstance {
                    model: model.to_cols_array_2d(),
                    color,
                    clip_to_prev: clip_to_prev.to_cols_array_2d(),
                    skin: [work.vertices, 0, 0, 0],
                };
                work.vertices += r.vertex_count;
                (mesh, inst)
            };
            for &(mesh, color) in &w.parts {
                let seen = pose(self.mesh_for(mesh, &model, camera), color);
                placed.push(seen);
                // The light's map draws the camera's version, or a coarser one of its own.
                let lit = light.map_or(seen.0, |l| self.coarser_for(mesh, seen.0, &model, l));
                cast.push(if lit == seen.0 {
                    seen
                } else {
                    pose(lit, color)
                });
            }
        }
        super::sort_nearest_first(&mut placed, camera.eye);
        self.push_draws(&placed, records, draws);
        if light.is_some() {
            cast.sort_by_key(|(mesh, _)| *mesh);
            self.push_draws(&cast, records, light_draws);
        } else {
            light_draws.extend(draws.iter().filter(|d| d.skinned).copied());
        }
        work
    }

    /// World bounding spheres of the drawn characters' (`model_of`: `None` hidden) skinned
    /// meshes, each part at its body placement (bind-pose spheres, widened by a fifth for the
    /// pose).
    pub(in crate::render) fn character_spheres(
        &self,
        model_of: &impl Fn(CharacterId) -> Option<Mat4>,
    ) -> Vec<(Vec3, f32)> {
        let mut out = Vec::new();
        for (id, w) in &self.wearers {
            if model_of(*id).is_none() {
                continue;
            }
            for &(mesh, _) in &w.parts {
                let r = &self.meshes[mesh];
                out.push(super::world_sphere(&w.body, (r.centre, r.radius)));
            }
        }
        out
    }

    /// Append `placed` (mesh, instance) to `records` and one draw per run of the same mesh to
    /// `draws`.
    fn push_draws(
        &self,
        placed: &[(usize, PropInstance)],
        records: &mut Vec<PropInstance>,
        draws: &mut Vec<PropDraw>,
    ) {
        for &(mesh, inst) in placed {
            let r = self.meshes[mesh];
            let k = records.len() as u32;
            records.push(inst);
            match draws.last_mut() {
                Some(d) if d.first_vertex == r.index_first && d.skinned => d.instance_count += 1,
                _ => draws.push(PropDraw {
                    first_vertex: r.index_first,
                    vertex_count: r.index_count,
                    first_instance: k,
                    instance_count: 1,
                    skinned: true,
                }),
            }
        }
    }

    /// The mesh an instance of `mesh` at `model` is drawn with.
    fn mesh_for(&self, mesh: usize, model: &Mat4, camera: &Projection) -> usize {
        self.coarser_for(mesh, mesh, model, camera)
    }

    /// The version of `mesh` at `model` that `view` needs, starting from `drawn` (`mesh` or
    /// one of its far versions): `drawn` or a coarser one down its chain.
    fn coarser_for(&self, mesh: usize, drawn: usize, model: &Mat4, view: &Projection) -> usize {
        let r = self.meshes[mesh];
        super::far_choice(drawn, &self.far, (r.centre, r.radius), model, view)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A mesh of `vertices` vertices and as many triangles, its indices from `index_first`.
    fn range(rest_first: u32, vertices: u32, index_first: u32) -> MeshRange {
        MeshRange {
            rest_first,
            vertex_count: vertices,
            index_first,
            index_count: 3 * vertices,
            centre: Vec3::ZERO,
            radius: 1.0,
        }
    }

    /// One character wearing mesh 0 (200 vertices), whose far levels 1 (40) and 2 (8) take
    /// over below 50 and 20 pixels: the camera sees it at 100 pixels (near), the light's map
    /// at `light_pixels`.
    fn frame(light_pixels: Option<f32>) -> (SkinWork, Vec<PropInstance>, [Vec<PropDraw>; 2]) {
        let mut props = SkinnedProps {
            meshes: vec![range(0, 200, 0), range(200, 40, 600), range(240, 8, 720)],
            far: vec![Some((1, 50.0)), Some((2, 20.0)), None],
            ..Default::default()
        };
        let id = CharacterId::test_id(0);
        props.set_wearer(id, &[(0, [1.0; 4])], 2).unwrap();
        let cot = 1.0;
        let camera = Projection {
            eye: Vec3::new(0.0, 0.0, 720.0 * cot / 100.0),
            height: 720.0,
            cot_half_fov: cot,
            texel: 0.0,
        };
        let light = light_pixels.map(|p| Projection::orthographic(2.0 / p));
        let (mut records, mut draws, mut light_draws) = (Vec::new(), Vec::new(), Vec::new());
        let work = props.frame_lists(
            |_| Some((Mat4::IDENTITY, Mat4::IDENTITY)),
            (&camera, light.as_ref()),
            &mut records,
            (&mut draws, &mut light_draws),
        );
        let capacity = props.capacity();
        assert!(work.jobs.len() as u32 <= capacity.jobs && work.vertices <= capacity.vertices);
        assert!(records.len() as u32 <= capacity.instances);
        (work, records, [draws, light_draws])
    }

    /// The light's map draws the level its texels need, posed into vertices of its own, or
    /// the camera's posed mesh when that is as coarse; jobs are at most a workgroup wide and
    /// cover every posed vertex once.
    #[test]
    fn the_light_draws_its_own_far_level_and_jobs_fit_a_workgroup() {
        let (work, records, [camera, light]) = frame(Some(10.0));
        assert_eq!((camera.len(), light.len()), (1, 1));
        assert_eq!(camera[0].first_vertex, 0, "the camera sees the near mesh");
        assert_eq!(light[0].first_vertex, 720, "the light's 10 texels: level 2");
        assert_eq!(work.vertices, 208);
        let light_record = records[light[0].first_instance as usize];
        assert_eq!(light_record.skin[0], 200, "posed after the camera's");
        let mut covered = vec![0u32; work.vertices as usize];
        for j in &work.jobs {
            assert!(j.vertex_count <= SKIN_GROUP_SIZE && j.vertex_count > 0);
            for k in 0..j.vertex_count {
                covered[(j.out_first + k) as usize] += 1;
            }
        }
        assert!(covered.iter().all(|&n| n == 1), "{covered:?}");
        assert!(work.widest <= SKIN_GROUP_SIZE);
        // A light map that sees it as large as the camera does: the camera's posed mesh.
        let (work, records, [camera, light]) = frame(Some(200.0));
        assert_eq!(light[0].first_vertex, camera[0].first_vertex);
        assert_eq!(work.vertices, 200);
        let (cam, lit) = (camera[0].first_instance, light[0].first_instance);
        assert_eq!(records[cam as usize].skin, records[lit as usize].skin);
        // No light view: the light draws what the camera does.
        let (_, _, [camera, light]) = frame(None);
        assert_eq!(camera, light);
    }
}
