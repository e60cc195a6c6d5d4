//! Linear hair skinning, the baseline of the paper's comparison (`reference::lhs`): each frame
//! every stored strand vertex is moved by its guides' displacements into the vertex pool,
//! which the static path then draws. Reads: the stored strands, weights and this frame's guide
//! displacements. Writes: the vertex pool.

use std::sync::Arc;

use ash::vk;

use super::{FrameRes, dispatch_2d};
use crate::reference::lhs::LhsModel;
use crate::render::core::graph::FrameGraph;
use crate::render::core::shared::{HairVertex, LhsBinding, LhsWeights};
use crate::render::core::slots::FRAMES_IN_FLIGHT;
use crate::vk::{
    Access, Buffer, BufferDesc, Context, DescriptorSet, DescriptorSetLayout, GpuError, GpuResult,
    Pipeline,
};

use crate::render::core::shared::LHS_GROUP_SIZE as GROUP;

/// The stored strands on the GPU and one guide-displacement buffer per frame slot.
pub struct LhsState {
    model: LhsModel,
    _rest: Buffer,
    _weights: Buffer,
    deltas: Vec<(Buffer, DescriptorSet)>,
    pending: Option<Vec<[f32; 4]>>,
}

impl LhsState {
    /// The model.
    pub fn model(&self) -> &LhsModel {
        &self.model
    }

    /// Set this frame's guide vertices (guide-major, as [`LhsModel::guide_rest`]).
    pub fn set_guides(&mut self, now: &[glam::Vec3]) -> GpuResult<()> {
        let rest = self.model.guide_rest();
        if now.len() != rest.len() || now.iter().any(|p| !p.is_finite()) {
            return Err(GpuError::Unsupported(format!(
                "LHS guides: {} finite positions expected, got {}",
                rest.len(),
                now.len()
            )));
        }
        self.pending = Some(
            now.iter()
                .zip(&rest)
                .map(|(n, r)| (*n - *r).extend(0.0).to_array())
                .collect(),
        );
        Ok(())
    }
}

/// The skinning pipeline.
pub struct LhsSkin {
    ctx: Arc<Context>,
    set_layout: Arc<DescriptorSetLayout>,
    pipeline: Pipeline,
}

impl LhsSkin {
    /// Compile the pass.
    pub fn new(ctx: &Arc<Context>) -> GpuResult<Self> {
        let (set_layout, pipeline) = super::own_set_compute(
            ctx,
            "lhs skin",
            "lhs_skin.comp",
            LhsBinding::ALL.iter().map(|(b, _)| *b as u32),
        )?;
        Ok(LhsSkin {
            ctx: ctx.clone(),
            set_layout,
            pipeline,
        })
    }

    /// Upload `model` with the pool's vertices at rest (`rest`, as captured) skinning into
    /// `pool`.
    pub fn upload(
        &self,
        model: LhsModel,
        rest: &[HairVertex],
        pool: &Buffer,
    ) -> GpuResult<LhsState> {
        if rest.len() != model.rest.len() {
            return Err(GpuError::Unsupported(
                "LHS: rest vertices do not match the model".into(),
            ));
        }
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let rest_buf = Buffer::device_local_with_data(
            &self.ctx,
            "lhs strands",
            usage,
            bytemuck::cast_slice(rest),
        )?;
        let weights: Vec<LhsWeights> = model
            .weights
            .iter()
            .map(|w| LhsWeights {
                guides: [w[0].0, w[1].0, w[2].0, 0],
                weights: [w[0].1, w[1].1, w[2].1, 0.0],
            })
            .collect();
        let weights_buf = Buffer::device_local_with_data(
            &self.ctx,
            "lhs weights",
            usage,
            bytemuck::cast_slice(&weights),
        )?;
        let guide_vertices = (model.guides.len() * model.verts_per_strand) as u64;
        let mut deltas = Vec::with_capacity(FRAMES_IN_FLIGHT);
        for _ in 0..FRAMES_IN_FLIGHT {
            let mut delta = Buffer::new(
                &self.ctx,
                &BufferDesc::new("lhs guide deltas", guide_vertices * 16, usage).host_visible(),
            )?;
            delta.write(0, &vec![0u8; guide_vertices as usize * 16])?;
            let set = DescriptorSet::new(&self.ctx, "lhs skin", &self.set_layout)?;
            set.write_buffer(LhsBinding::Rest as u32, &rest_buf)?;
            set.write_buffer(LhsBinding::Weights as u32, &weights_buf)?;
            set.write_buffer(LhsBinding::GuideDelta as u32, &delta)?;
            set.write_buffer(LhsBinding::Out as u32, pool)?;
            deltas.push((delta, set));
        }
        Ok(LhsState {
            model,
            _rest: rest_buf,
            _weights: weights_buf,
            deltas,
            pending: None,
        })
    }

    /// Add the skinning into the pool for frame slot `slot` (before the strands are drawn);
    /// the guides' deltas set since the last frame are written for that slot first.
    pub fn add<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes,
        state: &'a mut LhsState,
        slot: usize,
    ) -> GpuResult<()> {
        if let Some(d) = state.pending.take() {
            state.deltas[slot].0.write(0, bytemuck::cast_slice(&d))?;
        }
        let state = &*state;
        let m = &state.model;
        let strands = m.weights.len() as u32;
        let verts = m.verts_per_strand as u32;
        let guides = m.guides.len() as u32;
        g.begin_scope("lhs skin");
        g.pass("lhs skin")
            .read(r.constants, Access::ComputeRead)
            .write(r.pool, Access::ComputeReadWrite)
            .record(move |rec, _| {
                rec.bind(&self.pipeline, &[&state.deltas[slot].1]);
                rec.push_constants(&self.pipeline, &[strands, verts, guides, 0u32]);
                let (x, y) = dispatch_2d((strands * verts).div_ceil(GROUP));
                rec.dispatch(x, y, 1);
                Ok(())
            });
        g.end_scope();
        Ok(())
    }
}
