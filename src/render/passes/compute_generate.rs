//! Compute path generation for the whole crowd, after the bundle LoD pass: a
//! multi-level exclusive scan over all bundles, finalize (totals, vertex-pool budget, indirect
//! arguments), generate (strand workgroups into the vertex pool).
//! What each step reads and writes is declared where it is added to the frame graph.

use std::sync::Arc;

use super::{FrameRes, PassSets, TemporalRes, device_shader_options, dispatch_2d};
use crate::render::core::graph::FrameGraph;
use crate::render::core::shared::{GenerateArgs, SCAN_BLOCK, SCAN_THREADS};
use crate::vk::shader::compile;
use crate::vk::{Access, Context, GpuResult, Pipeline, PipelineLayout};

pub use crate::render::core::workspace::{ScanLevel, scan_plan};

/// Which view a generation serves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GenerateView {
    /// The camera: software bundles append their segments (`soft_segments.glsl`).
    Camera,
    /// The light's hardware shadow passes: strips in the vertex pool.
    Light,
    /// The light's software shadow passes: every bundle's segments, unshaded.
    LightSoftware,
}

impl GenerateView {
    /// Profiler scope names of the scan and generate timings.
    pub fn scopes(self) -> [&'static str; 2] {
        match self {
            GenerateView::Camera => ["scan", "generate"],
            GenerateView::Light | GenerateView::LightSoftware => ["shadow scan", "shadow generate"],
        }
    }
}

/// The compute pipelines of the generation pass.
pub struct ComputeGenerate {
    scan: Pipeline,
    scan_add: Pipeline,
    finalize: Pipeline,
    /// Strand workgroups for the light (no software rasterizer).
    generate_light: Pipeline,
    /// Strand workgroups for the camera and the light's software passes (`SOFT_RASTER`).
    generate_camera: Pipeline,
}

impl ComputeGenerate {
    /// Compile the pipelines.
    pub fn new(ctx: &Arc<Context>, layout: &Arc<PipelineLayout>) -> GpuResult<Self> {
        let opts = device_shader_options(ctx, 1);
        let p =
            |name: &str, file: &str| Pipeline::compute(ctx, name, layout, &compile(file, &opts)?);
        Ok(ComputeGenerate {
            scan: p("scan", "scan.comp")?,
            scan_add: p("scan add", "scan_add.comp")?,
            finalize: p("finalize", "finalize.comp")?,
            generate_light: p("generate", "generate.comp")?,
            generate_camera: Pipeline::compute(
                ctx,
                "generate (camera)",
                layout,
                &compile("generate.comp", &opts.clone().define("SOFT_RASTER", 1))?,
            )?,
        })
    }

    /// Add generation of every visible strand of the `bundles` bundles, seen from the view
    /// of `sets`' frame block, into the vertex pool: the scan levels, finalize and the
    /// strand workgroups, each a pass, after the view's bundle LoD pass
    /// (`bundle_lod::BundleLodPass`) decided each bundle's strands.
    pub fn add<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        sets: PassSets<'a>,
        bundles: u32,
        view: GenerateView,
    ) {
        let scopes = view.scopes();
        let rw = Access::ComputeReadWrite;
        let inputs = [r.constants, r.textures];
        g.begin_scope(scopes[0]);
        self.add_scan(g, r, sets, bundles);
        g.end_scope();
        g.begin_scope(scopes[1]);
        let generate = match view {
            GenerateView::Camera | GenerateView::LightSoftware => &self.generate_camera,
            GenerateView::Light => &self.generate_light,
        };
        let args = r.args_buffer;
        let mut p = g
            .pass("generate")
            .read_all(&inputs, Access::ComputeRead)
            .read_all(&[r.lods, r.offsets], Access::ComputeRead)
            .read(r.args, Access::IndirectRead)
            .write(r.args, rw)
            .discard(r.pool, rw);
        if view != GenerateView::Light {
            // Software bundles are shaded here (shadow lookups included; the light's view
            // shades nothing, but the pipeline binds the maps).
            p = r.shading_uses(p.write(r.soft_segments, rw), Access::ComputeRead);
        }
        if view == GenerateView::Camera {
            // Frames with motion vectors: the vertices' and segments' deformation residuals.
            p = p
                .write_some(TemporalRes::vertex_motion(r.temporal), rw)
                .write_some(TemporalRes::segment_motion(r.temporal), rw);
        }
        p.record(move |rec, _| {
            rec.bind(generate, &sets.both());
            rec.dispatch_indirect(args, GenerateArgs::DISPATCH_OFFSET);
            Ok(())
        });
        g.end_scope();
    }

    /// The multi-level exclusive scan of the bundles' strand and vertex counts, then
    /// finalize (totals, vertex-pool budget, indirect arguments).
    fn add_scan<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        sets: PassSets<'a>,
        bundles: u32,
    ) {
        let rw = Access::ComputeReadWrite;
        let (levels, _) = scan_plan(bundles);
        for (i, l) in levels.iter().copied().enumerate() {
            g.pass("scan")
                .read(r.lods, Access::ComputeRead)
                .write(r.offsets, rw)
                .write(r.scan, rw)
                .record(move |rec, _| {
                    rec.bind(&self.scan, &sets.both());
                    rec.push_constants(&self.scan, &[l.count, l.input, l.sums, (i > 0) as u32]);
                    let (x, y) = dispatch_2d(l.count.div_ceil(SCAN_BLOCK));
                    rec.dispatch(x, y, 1);
                    Ok(())
                });
        }
        for (i, l) in levels.iter().copied().enumerate().rev() {
            if l.count <= SCAN_BLOCK {
                continue; // one block: its scanned block sum is 0
            }
            g.pass("scan add")
                .write(r.offsets, rw)
                .write(r.scan, rw)
                .record(move |rec, _| {
                    rec.bind(&self.scan_add, &sets.both());
                    rec.push_constants(&self.scan_add, &[l.count, l.input, l.sums, (i > 0) as u32]);
                    let (x, y) = dispatch_2d(l.count.div_ceil(SCAN_THREADS));
                    rec.dispatch(x, y, 1);
                    Ok(())
                });
        }
        let total = levels.last().map_or(0, |l| l.sums);
        g.pass("finalize")
            .read(r.constants, Access::ComputeRead)
            .read(r.offsets, Access::ComputeRead)
            .read(r.scan, Access::ComputeRead)
            .write(r.args, rw)
            .record(move |rec, _| {
                rec.bind(&self.finalize, &sets.both());
                rec.push_constants(&self.finalize, &[total, 0u32, 0, 0]);
                rec.dispatch(1, 1, 1);
                Ok(())
            });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scan_plan_reaches_one_block() {
        let (l, scratch) = scan_plan(100);
        assert_eq!(l.len(), 1);
        assert_eq!(scratch, 1);
        let (l, scratch) = scan_plan(50_400);
        assert_eq!(l.len(), 2);
        assert_eq!(
            (l[0].count, l[0].sums, l[1].count, l[1].input, l[1].sums),
            (50_400, 0, 50, 0, 50)
        );
        assert_eq!(scratch, 51);
        let (l, _) = scan_plan(3 * 1024 * 1024 + 1);
        assert_eq!(l.len(), 3);
        assert_eq!(l.last().unwrap().count.div_ceil(SCAN_BLOCK), 1);
    }
}
