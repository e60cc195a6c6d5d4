//! Props (bodies, ground): prop meshes on the GPU, the world's instances and the ones that
//! move with a character, and this frame's draw lists.

use std::sync::Arc;

use ash::vk;
use glam::{Mat4, Vec3};

pub mod draw;
pub mod skin;
pub mod skinned;

use crate::render::core::ids::CharacterId;
use crate::render::core::shared::{PropInstance, PropVertex};
use crate::vk::{Buffer, Context, GpuError, GpuResult};
use draw::PropDraw;

/// A far version of a prop mesh: instances whose bounding sphere spans fewer than
/// `below_pixels` pixels of the camera's image are drawn with `far_mesh` instead (in every
/// view of the frame, so their shadows match).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PropLod {
    /// The mesh that has a far version.
    pub mesh: usize,
    /// Its far version.
    pub far_mesh: usize,
    /// Bounding-sphere diameter in pixels below which the far version is drawn.
    pub below_pixels: f32,
}

/// How many pixels a sphere spans in a view: a perspective view's eye, image height and
/// `1 / tan(fov_y / 2)` (from the frame block; 0 for an orthographic view), or an
/// orthographic view's texel size (`texel`; 0 for perspective views). An orthographic view
/// without a texel size picks no far meshes.
#[derive(Clone, Copy, Debug)]
pub(in crate::render) struct Projection {
    pub(in crate::render) eye: Vec3,
    pub(in crate::render) height: f32,
    pub(in crate::render) cot_half_fov: f32,
    /// World size of one texel of an orthographic view (the light's maps); 0: perspective.
    pub(in crate::render) texel: f32,
}

impl Projection {
    /// An orthographic view (a light's map) whose texels are `texel` world units wide.
    pub(in crate::render) fn orthographic(texel: f32) -> Self {
        Projection {
            eye: Vec3::ZERO,
            height: 0.0,
            cot_half_fov: 0.0,
            texel,
        }
    }

    /// Diameter in pixels of a sphere of `radius` at `centre` (infinite at the eye, and in
    /// orthographic views without a texel size).
    pub(in crate::render) fn pixels(&self, centre: Vec3, radius: f32) -> f32 {
        if self.texel > 0.0 {
            return 2.0 * radius / self.texel;
        }
        let d = centre.distance(self.eye);
        if self.cot_half_fov <= 0.0 || d <= radius {
            return f32::INFINITY;
        }
        radius * self.height * self.cot_half_fov / d
    }
}

/// Prop meshes on the GPU and the instances placed for the next frames.
#[derive(Default)]
pub(in crate::render) struct Props {
    pub(in crate::render) vertices: Option<Buffer>,
    pub(in crate::render) meshes: Vec<(u32, u32)>,
    /// Bounding sphere (centre, radius) of each mesh in its own frame.
    bounds: Vec<(Vec3, f32)>,
    /// Far version of each mesh, if any: `(far mesh, below pixels)`.
    far: Vec<Option<(usize, f32)>>,
    pub(in crate::render) instances: Vec<(usize, PropInstance)>,
    /// Props that move with a character: `(character, mesh, instance in its frame)`.
    pub(in crate::render) attached: Vec<(CharacterId, usize, PropInstance)>,
}

impl Props {
    /// The mesh an instance of `mesh` at `model` is drawn with: its far version where the
    /// camera sees it small.
    fn mesh_for(&self, mesh: usize, model: &Mat4, camera: &Projection) -> usize {
        far_choice(mesh, &self.far, self.bounds[mesh], model, camera)
    }

    /// This frame's instance records (sorted by mesh) and one draw per mesh: the world props
    /// (their motion: `world_clip_to_prev`, the camera's) and, placed by `model_of` (model
    /// and clip_to_prev; `None`: not drawn), the characters' own; far versions where `camera`
    /// sees a prop small.
    pub(in crate::render) fn frame_lists(
        &self,
        model_of: &impl Fn(CharacterId) -> Option<(Mat4, Mat4)>,
        world_clip_to_prev: Mat4,
        camera: &Projection,
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
                    skin: inst.skin,
                },
            ))
        }));
        for (mesh, inst) in &mut all {
            *mesh = self.mesh_for(*mesh, &Mat4::from_cols_array_2d(&inst.model), camera);
        }
        sort_nearest_first(&mut all, camera.eye);
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
                    skinned: false,
                }),
            }
        }
        (records, draws)
    }
}

impl Props {
    /// World bounding spheres of the props that move with characters, placed by `model_of`
    /// (`None`: not drawn): what the bodies' shadow map is fitted to.
    pub(in crate::render) fn character_spheres(
        &self,
        model_of: &impl Fn(CharacterId) -> Option<Mat4>,
    ) -> Vec<(Vec3, f32)> {
        self.attached
            .iter()
            .filter_map(|(id, mesh, inst)| {
                let model = model_of(*id)? * Mat4::from_cols_array_2d(&inst.model);
                Some(world_sphere(&model, self.bounds[*mesh]))
            })
            .collect()
    }

    /// Replace the prop meshes (triangle lists) and clear the instances; returns the old
    /// vertex buffer (frames in flight may still read it).
    pub(in crate::render) fn set_meshes(
        &mut self,
        ctx: &Arc<Context>,
        meshes: &[Vec<PropVertex>],
    ) -> GpuResult<Option<Buffer>> {
        let mut all = Vec::new();
        let mut ranges = Vec::new();
        let mut bounds = Vec::new();
        for m in meshes {
            if m.len() % 3 != 0 || m.iter().any(|v| !v.position.iter().all(|x| x.is_finite())) {
                return Err(GpuError::Unsupported(
                    "prop meshes are finite triangle lists".into(),
                ));
            }
            ranges.push((all.len() as u32, m.len() as u32));
            bounds.push(bounding_sphere(m));
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
        self.far = vec![None; bounds.len()];
        self.bounds = bounds;
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

    /// Give meshes far versions (replacing earlier ones; chains allowed), checked by
    /// [`far_table`].
    pub(in crate::render) fn set_lods(&mut self, lods: &[PropLod]) -> GpuResult<()> {
        self.far = far_table(lods, self.meshes.len())?;
        Ok(())
    }

    /// Place the world props: `(mesh index, instance)`.
    pub(in crate::render) fn set_instances(
        &mut self,
        instances: &[(usize, PropInstance)],
    ) -> GpuResult<()> {
        self.check(instances)?;
        self.instances = instances.to_vec();
        Ok(())
    }

    /// Replace character `id`'s props (instances in its frame).
    pub(in crate::render) fn set_attached(
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
    pub(in crate::render) fn attached_models(&self, id: CharacterId, model: Mat4) -> Vec<Mat4> {
        self.attached
            .iter()
            .filter(|(c, ..)| *c == id)
            .map(|(_, _, i)| model * Mat4::from_cols_array_2d(&i.model))
            .collect()
    }
}

/// The far version table of `n` meshes from `lods`: refuses unknown meshes, a mesh that is
/// its own far version, a mesh with two far versions, chains of far versions that loop or
/// whose thresholds grow, and thresholds that are not finite and non-negative. A far version
/// may have a far version of its own (a chain of coarser and coarser levels).
pub(in crate::render) fn far_table(
    lods: &[PropLod],
    n: usize,
) -> GpuResult<Vec<Option<(usize, f32)>>> {
    let mut far = vec![None; n];
    for l in lods {
        let bad = if l.mesh >= n || l.far_mesh >= n {
            Some(format!("no prop mesh {}", l.mesh.max(l.far_mesh)))
        } else if l.mesh == l.far_mesh {
            Some(format!(
                "prop mesh {} cannot be its own far version",
                l.mesh
            ))
        } else if far[l.mesh].is_some() {
            Some(format!("prop mesh {} has two far versions", l.mesh))
        } else if !(l.below_pixels.is_finite() && l.below_pixels >= 0.0) {
            Some(format!(
                "far prop threshold {} is not a finite pixel count",
                l.below_pixels
            ))
        } else {
            None
        };
        if let Some(e) = bad {
            return Err(GpuError::Unsupported(e));
        }
        far[l.mesh] = Some((l.far_mesh, l.below_pixels));
    }
    for start in 0..n {
        // A chain longer than n meshes visits one twice.
        let (mut mesh, mut steps) = (start, 0);
        while let Some((next, below)) = far[mesh] {
            let grows = far[next].is_some_and(|(_, b)| b > below);
            if steps > n || grows {
                return Err(GpuError::Unsupported(format!(
                    "the far versions of prop mesh {start} loop or switch later than their \
                     parent ({})",
                    if grows { "threshold grows" } else { "loop" }
                )));
            }
            (mesh, steps) = (next, steps + 1);
        }
    }
    Ok(far)
}

/// The mesh an instance of `mesh` (bounding sphere `(centre, radius)` in its own frame) at
/// `model` is drawn with: down `far`'s chain of far versions while `camera` sees the sphere,
/// scaled by the model's largest axis, smaller than the next version's pixel threshold.
pub(in crate::render) fn far_choice(
    mesh: usize,
    far: &[Option<(usize, f32)>],
    (centre, radius): (Vec3, f32),
    model: &Mat4,
    camera: &Projection,
) -> usize {
    if far[mesh].is_none() {
        return mesh;
    }
    let (centre, radius) = world_sphere(model, (centre, radius));
    let pixels = camera.pixels(centre, radius);
    let mut drawn = mesh;
    // far_table refuses loops, so this ends within far.len() steps.
    while let Some((next, below)) = far[drawn] {
        if pixels >= below {
            break;
        }
        drawn = next;
    }
    drawn
}

/// Order instances by mesh, each mesh's nearest `eye` first, so the depth test spares the
/// shading of what nearer ones hide (`props.frag` tests depth before shading).
pub(in crate::render) fn sort_nearest_first(instances: &mut [(usize, PropInstance)], eye: Vec3) {
    let distance = |i: &PropInstance| eye.distance_squared(Vec3::from_slice(&i.model[3][..3]));
    instances.sort_by(|a, b| {
        a.0.cmp(&b.0)
            .then(distance(&a.1).total_cmp(&distance(&b.1)))
    });
}

/// A bounding sphere (centre, radius) of a mesh placed at `model`, in world space (the
/// radius scaled by the model's largest axis scale).
pub(in crate::render) fn world_sphere(model: &Mat4, (centre, radius): (Vec3, f32)) -> (Vec3, f32) {
    let scale = model
        .x_axis
        .truncate()
        .length()
        .max(model.y_axis.truncate().length())
        .max(model.z_axis.truncate().length());
    (model.transform_point3(centre), radius * scale)
}

/// A bounding sphere of a triangle list: the box's centre and the farthest vertex from it.
pub fn bounding_sphere(vertices: &[PropVertex]) -> (Vec3, f32) {
    let points = || vertices.iter().map(|v| Vec3::from_slice(&v.position[..3]));
    let (lo, hi) = points().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), p| (lo.min(p), hi.max(p)));
    if vertices.is_empty() {
        return (Vec3::ZERO, 0.0);
    }
    let centre = (lo + hi) * 0.5;
    (
        centre,
        points().map(|p| p.distance(centre)).fold(0.0, f32::max),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Instances are grouped by mesh (one draw each), and within a mesh the nearest to the
    /// eye comes first, wherever the eye is.
    #[test]
    fn each_meshs_instances_come_nearest_first() {
        let at = |mesh: usize, x: f32| {
            let model = Mat4::from_translation(Vec3::new(x, 0.0, 0.0)).to_cols_array_2d();
            let inst = PropInstance {
                model,
                color: [0.0; 4],
                clip_to_prev: model,
                skin: [0; 4],
            };
            (mesh, inst)
        };
        let mut v = vec![at(1, 5.0), at(0, 9.0), at(1, 1.0), at(0, 2.0), at(1, 3.0)];
        sort_nearest_first(&mut v, Vec3::ZERO);
        let order: Vec<(usize, f32)> = v.iter().map(|(m, i)| (*m, i.model[3][0])).collect();
        assert_eq!(order, [(0, 2.0), (0, 9.0), (1, 1.0), (1, 3.0), (1, 5.0)]);
        sort_nearest_first(&mut v, Vec3::new(10.0, 0.0, 0.0));
        let order: Vec<(usize, f32)> = v.iter().map(|(m, i)| (*m, i.model[3][0])).collect();
        assert_eq!(order, [(0, 9.0), (0, 2.0), (1, 5.0), (1, 3.0), (1, 1.0)]);
    }

    fn triangle(at: Vec3) -> Vec<PropVertex> {
        [Vec3::ZERO, Vec3::X, Vec3::Y]
            .map(|p| PropVertex {
                position: (p + at).extend(1.0).to_array(),
                normal: [0.0, 0.0, 1.0, 0.0],
            })
            .to_vec()
    }

    /// Three one-triangle props, the first with a far version below 50 pixels; a 60-degree,
    /// 720-pixel camera at the first one's centre; and the distance where it spans 50 pixels.
    fn three_props() -> (Props, Projection, f32) {
        let mut props = Props {
            meshes: vec![(0, 3), (3, 3), (6, 3)],
            bounds: [Vec3::ZERO; 3]
                .map(|v| bounding_sphere(&triangle(v)))
                .to_vec(),
            far: vec![None; 3],
            ..Default::default()
        };
        props.set_lods(&[lod(0, 1, 50.0)]).unwrap();
        // 60 degrees, 720 pixels: the sphere spans r * 720 * cot(30) / d pixels.
        let camera = Projection {
            eye: Vec3::new(0.5, 0.5, 0.0),
            height: 720.0,
            cot_half_fov: 1.0 / 30f32.to_radians().tan(),
            texel: 0.0,
        };
        let d50 = props.bounds[0].1 * 720.0 * camera.cot_half_fov / 50.0;
        (props, camera, d50)
    }

    fn lod(mesh: usize, far_mesh: usize, below_pixels: f32) -> PropLod {
        PropLod {
            mesh,
            far_mesh,
            below_pixels,
        }
    }

    /// `d` in front of the camera.
    fn at(d: f32) -> Mat4 {
        Mat4::from_translation(Vec3::new(0.0, 0.0, -d))
    }

    /// A prop is drawn with its far version exactly when its bounding sphere spans fewer
    /// pixels than the threshold.
    #[test]
    fn far_versions_replace_small_props() {
        let (props, camera, d50) = three_props();
        let (c, r) = props.bounds[0];
        assert!((c - Vec3::new(0.5, 0.5, 0.0)).length() < 1e-6 && (r - 0.5f32.sqrt()).abs() < 1e-6);
        assert_eq!(props.mesh_for(0, &at(d50 * 0.99), &camera), 0);
        assert_eq!(props.mesh_for(0, &at(d50 * 1.01), &camera), 1);
        assert_eq!(props.mesh_for(2, &at(1e4), &camera), 2);
        // Twice the scale, twice the distance.
        let scaled = at(d50 * 1.9) * Mat4::from_scale(Vec3::splat(2.0));
        assert_eq!(props.mesh_for(0, &scaled, &camera), 0);
        let ortho = Projection {
            cot_half_fov: 0.0,
            ..camera
        };
        assert_eq!(props.mesh_for(0, &at(1e4), &ortho), 0);
    }

    /// Bad far versions are refused: a missing mesh, itself, a threshold not a count of
    /// pixels.
    #[test]
    fn bad_far_versions_are_refused() {
        let (mut props, _, _) = three_props();
        for bad in [
            lod(0, 3, 1.0),
            lod(0, 0, 1.0),
            lod(0, 1, f32::NAN),
            lod(0, 1, -1.0),
        ] {
            assert!(props.set_lods(&[bad]).is_err(), "{bad:?}");
        }
    }

    /// A chain of levels switches at each threshold, a level drawn directly follows its own
    /// chain, and chains that do not shrink or that loop are refused.
    #[test]
    fn far_versions_chain() {
        let (mut props, camera, d50) = three_props();
        // 0 -> 1 below 50 pixels, 1 -> 2 below 20.
        props.set_lods(&[lod(0, 1, 50.0), lod(1, 2, 20.0)]).unwrap();
        let d20 = d50 * 2.5;
        assert_eq!(props.mesh_for(0, &at(d50 * 0.99), &camera), 0);
        assert_eq!(props.mesh_for(0, &at(d50 * 1.01), &camera), 1);
        assert_eq!(props.mesh_for(0, &at(d20 * 0.99), &camera), 1);
        assert_eq!(props.mesh_for(0, &at(d20 * 1.01), &camera), 2);
        assert_eq!(props.mesh_for(1, &at(d20 * 1.01), &camera), 2);
        for bad in [
            vec![lod(0, 1, 20.0), lod(1, 2, 50.0)],
            vec![lod(0, 1, 50.0), lod(1, 0, 50.0)],
            vec![lod(0, 1, 50.0), lod(0, 2, 20.0)],
        ] {
            assert!(props.set_lods(&bad).is_err(), "{bad:?}");
        }
    }
}
