//! `bench crowd --compare-defaults`: the crowd with the look `crowd` shows by default
//! (Marschner, deep opacity shadows, LoD on) drawn with the old default rasterizers (hardware
//! strips for the camera and the light) and with today's (`FrameSettings::with_fastest`:
//! `auto` and the software light passes where the device allows them), back to back in one
//! run: median frame wall time of each and the speed-up.

use std::sync::Arc;

use anyhow::Result;
use glam::Vec3;
use hairmesh::outln;
use hairmesh::render::{
    Camera, FrameOptions, FrameSettings, LightRaster, LodSettings, Renderer, RendererDesc,
    ShadowMode, StrandParams, StrandRaster, View,
};
use hairmesh::vk::Context;

/// One crowd of `count` characters measured both ways.
pub struct DefaultsRun<'a> {
    /// Device.
    pub ctx: &'a Arc<Context>,
    /// Baked meshes and styles, used in turn.
    pub meshes: &'a [(hairmesh::BakedHairMesh, hairmesh::HairStyle)],
    /// Strands per bundle and vertex level.
    pub params: StrandParams,
    /// Image size.
    pub size: (u32, u32),
    /// Timed frames per setting (after one warm-up).
    pub runs: usize,
    /// Camera.
    pub camera: Camera,
}

impl DefaultsRun<'_> {
    /// Print the two rows and the speed-up line for `count` characters.
    pub fn measure(&self, count: usize) -> Result<()> {
        let desc = RendererDesc::default().size(self.size.0, self.size.1);
        let mut r = Renderer::new(self.ctx, &desc)?;
        let side = (count as f32).sqrt().ceil() as usize;
        for i in 0..count {
            let (baked, style) = &self.meshes[i % self.meshes.len()];
            let model = super::crowd_model(i, side, baked);
            r.add_character(baked, style, self.params, model)?;
        }
        let view = View {
            light_dir: Vec3::new(0.4, 1.0, 0.3),
            lod: LodSettings::default(),
            shading: hairmesh::shade::ShadingModel::Marschner,
            shadows: ShadowMode::DeepOpacity,
            ..View::new(self.camera)
        };
        let old = FrameSettings {
            path: r.default_path(),
            raster: StrandRaster::Hardware,
            transparency: view.transparency,
            msaa: r.msaa(),
            light_raster: LightRaster::Hardware,
        };
        let new = old.with_fastest((None, None), &r.caps());
        let mut walls = Vec::new();
        for s in [old, new] {
            let opts = FrameOptions {
                path: Some(s.path),
                raster: s.raster,
                light_raster: s.light_raster,
                ..Default::default()
            };
            let (wall, gpu) = self.time(&mut r, &view, &opts)?;
            outln!(
                "| {count} | {} | draw {}, shadow draw {} | {gpu:.1} | {wall:.1} |",
                s.path,
                s.raster,
                s.light_raster
            )?;
            walls.push(wall);
        }
        outln!(
            "defaults for {count} characters at {}x{}: before (draw hw, shadow draw hw) {:.1} ms, now (draw {}, shadow draw {}) {:.1} ms: {:.1}x",
            self.size.0,
            self.size.1,
            walls[0],
            new.raster,
            new.light_raster,
            walls[1],
            walls[0] / walls[1]
        )?;
        Ok(())
    }

    /// Median frame wall time (submit to completion) and GPU ms over the runs.
    fn time(&self, r: &mut Renderer, view: &View, opts: &FrameOptions) -> Result<(f64, f64)> {
        r.render_one(view, opts)?;
        let (mut walls, mut gpus) = (Vec::new(), Vec::new());
        for _ in 0..self.runs {
            let start = std::time::Instant::now();
            let report = r.render_one(view, opts)?;
            walls.push(start.elapsed().as_secs_f64() * 1e3);
            gpus.push(report.gpu_ms());
        }
        Ok((super::median(walls), super::median(gpus)))
    }
}
