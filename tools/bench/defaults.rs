//! `bench crowd --compare-defaults`: the crowd with the look `crowd` shows by default
//! (Marschner, deep opacity shadows, LoD on) drawn with the old default rasterizers (hardware
//! strips for the camera and the light) and with today's (`FrameSettings::with_fastest`:
//! `auto` and the software light passes where the device allows them), back to back in one
//! run: median frame wall time of each and the speed-up.

use anyhow::Result;
use hairmesh::outln;
use hairmesh::render::{FrameOptions, FrameSettings, LightRaster, StrandRaster, View};

/// Print the two rows and the speed-up line for `count` characters of `run`'s crowd (its
/// meshes, size, camera and timed frames).
pub fn compare(run: &super::CrowdRun, count: usize) -> Result<()> {
    let mut r = run.renderer(hairmesh::render::shared::TASK_PAYLOAD_BUNDLES)?;
    run.add_crowd(&mut r, count)?;
    let view = View::crowd_look(run.camera);
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
        r.render_one(&view, &opts)?;
        let (reports, wall) = super::timed_frames(&mut r, &view, &opts, run.runs)?;
        let gpu = super::median(reports.iter().map(|r| r.gpu_ms()).collect());
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
        run.size.0,
        run.size.1,
        walls[0],
        new.raster,
        new.light_raster,
        walls[1],
        walls[0] / walls[1]
    )?;
    Ok(())
}
