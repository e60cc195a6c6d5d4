//! Props (bodies, ground): prop meshes on the GPU, the world's instances and the ones that
//! move with a character, and this frame's draw lists.

use std::sync::Arc;

use ash::vk;
use glam::Mat4;

use super::crowd::CharacterId;
use super::passes::props::PropDraw;
use super::shared::{PropInstance, PropVertex};
use crate::vk::{Buffer, Context, GpuError, GpuResult};

/// Prop meshes on the GPU and the instances placed for the next frames.
#[derive(Default)]
pub(super) struct Props {
    pub(super) vertices: Option<Buffer>,
    pub(super) meshes: Vec<(u32, u32)>,
    pub(super) instances: Vec<(usize, PropInstance)>,
    /// Props that move with a character: `(character, mesh, instance in its frame)`.
    pub(super) attached: Vec<(CharacterId, usize, PropInstance)>,
}

impl Props {
    /// This frame's instance records (sorted by mesh) and one draw per mesh: the world props
    /// (their motion: `world_clip_to_prev`, the camera's) and, placed by `model_of` (model
    /// and clip_to_prev; `None`: not drawn), the characters' own.
    pub(super) fn frame_lists(
        &self,
        model_of: impl Fn(CharacterId) -> Option<(Mat4, Mat4)>,
        world_clip_to_prev: Mat4,
    ) -> (Vec<PropInstance>, Vec<PropDraw>) {
        let mut all = self.instances.clone();
        for (_, inst) in &mut all {
            inst.clip_to_prev = world_clip_to_prev.to_cols_array_2d();
        }
        all.extend(self.attached.iter().filter_map(|(id, mesh, inst)| {
            let (character, clip_to_prev) = model_of(*id)?;
            let model = character * Mat4::from_cols_array_2d(&inst.model);
            Some((
                *mesh,
                PropInstance {
                    model: model.to_cols_array_2d(),
                    color: inst.color,
                    clip_to_prev: clip_to_prev.to_cols_array_2d(),
                },
            ))
        }));
        all.sort_by_key(|(m, _)| *m);
        let records = all.iter().map(|(_, i)| *i).collect();
        let mut draws: Vec<PropDraw> = Vec::new();
        for (k, (mesh, _)) in all.iter().enumerate() {
            let (first_vertex, vertex_count) = self.meshes[*mesh];
            match draws.last_mut() {
                Some(d) if d.first_vertex == first_vertex => d.instance_count += 1,
                _ => draws.push(PropDraw {
                    first_vertex,
                    vertex_count,
                    first_instance: k as u32,
                    instance_count: 1,
                }),
            }
        }
        (records, draws)
    }
}

impl Props {
    /// Replace the prop meshes (triangle lists) and clear the instances; returns the old
    /// vertex buffer (frames in flight may still read it).
    pub(super) fn set_meshes(
        &mut self,
        ctx: &Arc<Context>,
        meshes: &[Vec<PropVertex>],
    ) -> GpuResult<Option<Buffer>> {
        let mut all = Vec::new();
        let mut ranges = Vec::new();
        for m in meshes {
            if m.len() % 3 != 0 || m.iter().any(|v| !v.position.iter().all(|x| x.is_finite())) {
                return Err(GpuError::Unsupported(
                    "prop meshes are finite triangle lists".into(),
                ));
            }
            ranges.push((all.len() as u32, m.len() as u32));
            all.extend_from_slice(m);
        }
        let vertices = if all.is_empty() {
            None
        } else {
            Some(Buffer::device_local_with_data(
                ctx,
                "prop vertices",
                vk::BufferUsageFlags::STORAGE_BUFFER,
                bytemuck::cast_slice(&all),
            )?)
        };
        self.meshes = ranges;
        self.instances.clear();
        self.attached.clear();
        Ok(std::mem::replace(&mut self.vertices, vertices))
    }

    /// Refuse instances of meshes that do not exist or with non-finite values.
    fn check(&self, instances: &[(usize, PropInstance)]) -> GpuResult<()> {
        if let Some((m, _)) = instances.iter().find(|(m, _)| *m >= self.meshes.len()) {
            return Err(GpuError::Unsupported(format!("no prop mesh {m}")));
        }
        let finite = |i: &PropInstance| {
            i.model
                .iter()
                .flatten()
                .chain(&i.color)
                .all(|x| x.is_finite())
        };
        if !instances.iter().all(|(_, i)| finite(i)) {
            return Err(GpuError::Unsupported("prop transform is not finite".into()));
        }
        Ok(())
    }

    /// Place the world props: `(mesh index, instance)`.
    pub(super) fn set_instances(&mut self, instances: &[(usize, PropInstance)]) -> GpuResult<()> {
        self.check(instances)?;
        self.instances = instances.to_vec();
        Ok(())
    }

    /// Replace character `id`'s props (instances in its frame).
    pub(super) fn set_attached(
        &mut self,
        id: CharacterId,
        instances: &[(usize, PropInstance)],
    ) -> GpuResult<()> {
        self.check(instances)?;
        self.attached.retain(|(c, ..)| *c != id);
        self.attached
            .extend(instances.iter().map(|(m, i)| (id, *m, *i)));
        Ok(())
    }

    /// Character `id`'s props placed at `model` (world transforms, in the order given).
    pub(super) fn attached_models(&self, id: CharacterId, model: Mat4) -> Vec<Mat4> {
        self.attached
            .iter()
            .filter(|(c, ..)| *c == id)
            .map(|(_, _, i)| model * Mat4::from_cols_array_2d(&i.model))
            .collect()
    }
}
