//! Props (bodies, ground): prop meshes on the GPU, the world's instances and the ones that
//! move with a character, and this frame's draw lists.

use glam::Mat4;

use super::crowd::CharacterId;
use super::frame::Retired;
use super::passes::props::PropDraw;
use super::renderer::Renderer;
use super::shared::{PropInstance, PropVertex};
use crate::vk::{Buffer, GpuError, GpuResult};
use ash::vk;

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
    /// and, placed by `model_of` (`None`: not drawn), the characters' own.
    pub(super) fn frame_lists(
        &self,
        model_of: impl Fn(CharacterId) -> Option<Mat4>,
    ) -> (Vec<PropInstance>, Vec<PropDraw>) {
        let mut all = self.instances.clone();
        all.extend(self.attached.iter().filter_map(|(id, mesh, inst)| {
            let model = model_of(*id)? * Mat4::from_cols_array_2d(&inst.model);
            Some((
                *mesh,
                PropInstance {
                    model: model.to_cols_array_2d(),
                    color: inst.color,
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

impl Renderer {
    /// Upload the prop meshes (triangle lists); instances refer to them by index. Replaces
    /// earlier meshes and clears the instances.
    pub fn set_prop_meshes(&mut self, meshes: &[Vec<PropVertex>]) -> GpuResult<()> {
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
                &self.ctx,
                "prop vertices",
                vk::BufferUsageFlags::STORAGE_BUFFER,
                bytemuck::cast_slice(&all),
            )?)
        };
        if let Some(old) = std::mem::replace(&mut self.props.vertices, vertices) {
            self.retire(Retired::Resource(Box::new(old)));
        }
        self.props.meshes = ranges;
        self.props.instances.clear();
        self.props.attached.clear();
        Ok(())
    }
    /// Refuse instances of meshes that do not exist or with non-finite values.
    fn check_prop_instances(&self, instances: &[(usize, PropInstance)]) -> GpuResult<()> {
        if let Some((m, _)) = instances
            .iter()
            .find(|(m, _)| *m >= self.props.meshes.len())
        {
            return Err(GpuError::Unsupported(format!("no prop mesh {m}")));
        }
        if instances.iter().any(|(_, i)| {
            !i.model
                .iter()
                .flatten()
                .chain(&i.color)
                .all(|x| x.is_finite())
        }) {
            return Err(GpuError::Unsupported("prop transform is not finite".into()));
        }
        Ok(())
    }
    /// Place world props for the next frames: `(mesh index, instance)`.
    pub fn set_prop_instances(&mut self, instances: &[(usize, PropInstance)]) -> GpuResult<()> {
        self.check_prop_instances(instances)?;
        self.props.instances = instances.to_vec();
        Ok(())
    }
    /// Give character `id` props that move with it (its head and body): `(mesh index,
    /// instance in the character's frame)`, drawn every frame at the character's current
    /// model, and not at all while it is hidden or after it is removed. Replaces its earlier
    /// props.
    pub fn set_character_props(
        &mut self,
        id: CharacterId,
        instances: &[(usize, PropInstance)],
    ) -> GpuResult<()> {
        if !self.crowd.contains(id) {
            return Err(GpuError::Unsupported(format!("no character {id:?}")));
        }
        self.check_prop_instances(instances)?;
        self.props.attached.retain(|(c, ..)| *c != id);
        self.props
            .attached
            .extend(instances.iter().map(|(m, i)| (id, *m, *i)));
        Ok(())
    }
    /// Where character `id`'s props are drawn this frame (world transforms, in the order
    /// given to [`Self::set_character_props`]); empty while it is hidden.
    pub fn character_prop_models(&self, id: CharacterId) -> Vec<Mat4> {
        let Some(model) = self.crowd.drawn_model(id) else {
            return Vec::new();
        };
        self.props
            .attached
            .iter()
            .filter(|(c, ..)| *c == id)
            .map(|(_, _, i)| model * Mat4::from_cols_array_2d(&i.model))
            .collect()
    }
}
