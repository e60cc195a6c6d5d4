//! Culling and level of detail for every bundle of the crowd, once per view before its strands
//! are built (both generation paths): `cull.comp` writes each bundle's decision into the bundle
//! LoDs and adds up what the view asks of the frame's buffers; `lod_pressure.comp` then thins
//! every bundle of a kind by the same share when that demand would not fit (the software
//! rasterizer's segment budget; on the compute path the vertex pool), so nothing is appended
//! past a budget and no character loses its hair to the order its strands were built in.
//! CPU twin: `reference::lod::{bundle_lod, lod_pressure, pressed_lod}`.

use std::sync::Arc;

use super::{FrameRes, PassSets, device_shader_options, dispatch_2d};
use crate::render::core::graph::FrameGraph;
use crate::render::core::shared::CULL_GROUP_SIZE;
use crate::vk::shader::compile;
use crate::vk::{Access, Context, GpuResult, Pipeline, PipelineLayout};

/// The bundle LoD pipelines.
pub struct BundleLodPass {
    cull: Pipeline,
    pressure: Pipeline,
}

impl BundleLodPass {
    /// Compile the pipelines.
    pub fn new(ctx: &Arc<Context>, layout: &Arc<PipelineLayout>) -> GpuResult<Self> {
        let opts = device_shader_options(ctx, 1);
        let p =
            |name: &str, file: &str| Pipeline::compute(ctx, name, layout, &compile(file, &opts)?);
        Ok(BundleLodPass {
            cull: p("cull", "cull.comp")?,
            pressure: p("lod pressure", "lod_pressure.comp")?,
        })
    }

    /// Add the decisions of the `bundles` bundles seen from the view of `sets`' frame block,
    /// timed as `scope`; `pool`: the view's hardware bundles go to the vertex pool (the compute
    /// path), whose budget then holds them too. The statistics in `args` must have been cleared
    /// for this view before (the demand accumulates there).
    pub fn add<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        (sets, scope): (PassSets<'a>, &'static str),
        bundles: u32,
        pool: bool,
    ) {
        let rw = Access::ComputeReadWrite;
        let (x, y) = dispatch_2d(bundles.div_ceil(CULL_GROUP_SIZE));
        g.begin_scope(scope);
        g.pass("cull")
            .read_all(&[r.constants, r.textures], Access::ComputeRead)
            .write(r.lods, rw)
            .write(r.args, rw)
            .record(move |rec, _| {
                rec.bind(&self.cull, &sets.both());
                rec.dispatch(x, y, 1);
                Ok(())
            });
        g.pass("lod pressure")
            .read(r.constants, Access::ComputeRead)
            .read(r.args, Access::ComputeRead)
            .write(r.lods, rw)
            .record(move |rec, _| {
                rec.bind(&self.pressure, &sets.both());
                rec.push_constants(&self.pressure, &[pool as u32, 0, 0, 0]);
                rec.dispatch(x, y, 1);
                Ok(())
            });
        g.end_scope();
    }
}
