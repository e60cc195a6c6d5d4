//! The crowd in a window: winit 0.30 `ApplicationHandler`, a swapchain that survives resize,
//! minimise (zero size), `OUT_OF_DATE` / `SUBOPTIMAL` and close, and an orbit / fly camera.
//!
//! A control panel (egui) sets the character count, strands per bundle, vertex level, LoD and its
//! alphas and lambda, the path, pause and the present mode, and shows the frame's statistics.
//! Mouse: left-drag orbits (outside the panel), wheel zooms. Keys: W/A/S/D/Q/E move the orbit
//! centre, Space pauses the automatic orbit, L toggles LoD, K cycles the shading model, M
//! switches mesh / compute path,
//! V cycles the present mode, `[` and `]` halve / double strands per bundle, - and = lower / raise
//! the vertex level, Escape closes. The title bar repeats the main figures.

use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context as _, Result};
use glam::Vec3;
use hairmesh::characters::preset::{self, StrandDensity};
use hairmesh::outln;
use hairmesh::render::Temporal;
use hairmesh::render::soft::{DEFAULT_SOFT_K, StrandRaster};
use hairmesh::render::transparency::{DEFAULT_OIT_BUDGET, DEFAULT_PEEL_LAYERS, MAX_OIT_BUDGET};
use hairmesh::render::{
    Camera, FrameOptions, FrameReport, FrameTicket, LightRaster, LodSettings, PresentTarget,
    RenderPath, Renderer, ShadowMode, Transparency, View,
};
use hairmesh::shade::ShadingModel;
use hairmesh::vk::{
    Acquired, Context, PresentMode, Semaphore, Swapchain, UiRenderer, WindowHandles,
};
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

use super::{Args, Scene, parse_size};

/// What the control panel edits.
struct Controls {
    visible: usize,
    shading: ShadingModel,
    shadows: ShadowMode,
    light_raster: LightRaster,
    transparency: Transparency,
    temporal: Temporal,
    raster: StrandRaster,
    lod_appearance: bool,
    multiple_scattering: bool,
    volumes: hairmesh::render::VolumeTier,
    moving: bool,
    simulating: bool,
    dynamics: hairmesh::animate::DynamicsPath,
    schedule: bool,
    wind: hairmesh::animate::Wind,
    strands: Strands,
    lod: LodSettings,
    path: RenderPath,
    paused: bool,
    fly: bool,
    present_mode: PresentMode,
    /// Show the frame graph (passes, uses, derived dependencies) of the last frame.
    show_graph: bool,
}

impl Controls {
    fn show(
        &mut self,
        ctx: &egui::Context,
        total: usize,
        (mesh_ok, soft_ok): (bool, bool),
        (stats, graph): (&str, &str),
    ) {
        egui::Window::new("crowd")
            .default_width(260.0)
            .show(ctx, |ui| {
                self.detail_ui(ui, total);
                self.look_ui(ui);
                self.motion_ui(ui);
                self.device_ui(ui, (mesh_ok, soft_ok));
                ui.separator();
                ui.label(stats);
                ui.checkbox(&mut self.show_graph, "frame graph");
                if self.show_graph {
                    egui::ScrollArea::vertical()
                        .max_height(320.0)
                        .show(ui, |ui| ui.monospace(graph));
                }
            });
    }

    /// How many characters, strands and vertices, and the level of detail.
    fn detail_ui(&mut self, ui: &mut egui::Ui, total: usize) {
        ui.add(egui::Slider::new(&mut self.visible, 1..=total.max(1)).text("characters"));
        match &mut self.strands.density {
            StrandDensity::PerCm2(d) => ui.add(
                egui::Slider::new(d, 1.0..=600.0)
                    .logarithmic(true)
                    .text("strands per cm²"),
            ),
            StrandDensity::PerReferenceBundle(n) => ui.add(
                egui::Slider::new(n, 1..=16384)
                    .logarithmic(true)
                    .text("strands per bundle"),
            ),
        };
        ui.add(egui::Slider::new(&mut self.strands.verts_log2, 0..=6).text("vertex level e"));
        ui.checkbox(&mut self.lod.enabled, "level of detail");
        ui.add_enabled(
            self.lod.enabled,
            egui::Slider::new(&mut self.lod.alpha_strands, 0.01..=1.0)
                .logarithmic(true)
                .text("alpha strands"),
        );
        ui.add_enabled(
            self.lod.enabled,
            egui::Slider::new(&mut self.lod.area_below, 0.0..=32.0)
                .text("strands by area below (px)"),
        );
        ui.add_enabled(
            self.lod.enabled,
            egui::Slider::new(&mut self.lod.alpha_verts, 0.01..=1.0)
                .logarithmic(true)
                .text("alpha vertices"),
        );
        ui.add_enabled(
            self.lod.enabled,
            egui::Slider::new(&mut self.lod.lambda, 0.05..=1.0).text("lambda"),
        );
    }

    /// Shading, shadows, temporal, transparency and the volume tier.
    fn look_ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.label("shading");
            ui.radio_value(&mut self.shading, ShadingModel::Placeholder, "placeholder");
            ui.radio_value(&mut self.shading, ShadingModel::KajiyaKay, "Kajiya-Kay");
            ui.radio_value(&mut self.shading, ShadingModel::Marschner, "Marschner");
        });
        ui.horizontal(|ui| {
            ui.label("shadows");
            for m in ShadowMode::ALL {
                ui.radio_value(&mut self.shadows, m, m.name());
            }
        });
        ui.horizontal(|ui| {
            ui.label("shadow draw");
            ui.radio_value(&mut self.light_raster, LightRaster::Hardware, "hardware");
            ui.radio_value(&mut self.light_raster, LightRaster::Software, "software");
        });
        ui.horizontal(|ui| {
            ui.label("temporal");
            for t in Temporal::ALL {
                ui.radio_value(&mut self.temporal, t, t.name());
            }
        });
        ui.horizontal(|ui| {
            ui.label("transparency");
            let oit = Transparency::KBuffer {
                budget: DEFAULT_OIT_BUDGET,
            };
            let peel = Transparency::DepthPeeling {
                layers: DEFAULT_PEEL_LAYERS,
            };
            let t = &mut self.transparency;
            ui.radio_value(t, Transparency::Opaque, "opaque");
            if ui
                .radio(matches!(t, Transparency::KBuffer { .. }), "OIT")
                .clicked()
            {
                *t = oit;
            }
            if ui
                .radio(matches!(t, Transparency::DepthPeeling { .. }), "peel")
                .clicked()
            {
                *t = peel;
            }
            match t {
                Transparency::KBuffer { budget } => {
                    ui.add(egui::Slider::new(budget, 1..=MAX_OIT_BUDGET).text("K"));
                }
                Transparency::DepthPeeling { layers } => {
                    ui.add(egui::Slider::new(layers, 1..=64).text("layers"));
                }
                Transparency::Opaque => {}
            }
        });
        ui.checkbox(&mut self.lod_appearance, "thick-strand appearance (LoD)");
        ui.checkbox(
            &mut self.multiple_scattering,
            "multiple scattering (Marschner)",
        );
        ui.horizontal(|ui| {
            ui.checkbox(&mut self.volumes.occlusion, "volumetric AO");
            let mut far = self.volumes.far.is_some();
            ui.checkbox(&mut far, "far hair as volumes");
            self.volumes.far = match far {
                true => self.volumes.far.or(hairmesh::render::VolumeTier::on().far),
                false => None,
            };
        });
    }

    /// Motion, hair dynamics and wind.
    fn motion_ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.checkbox(&mut self.moving, "motion");
            ui.checkbox(&mut self.simulating, "hair dynamics");
        });
        ui.horizontal(|ui| {
            use hairmesh::animate::DynamicsPath;
            ui.label("dynamics on");
            ui.radio_value(&mut self.dynamics, DynamicsPath::Gpu, "GPU");
            ui.radio_value(&mut self.dynamics, DynamicsPath::Cpu, "CPU");
            ui.checkbox(&mut self.schedule, "by screen size");
        });
        ui.add(egui::Slider::new(&mut self.wind.strength, 0.0..=60.0).text("wind m/s²"));
        let mut angle = self
            .wind
            .direction
            .z
            .atan2(self.wind.direction.x)
            .to_degrees();
        if ui
            .add(egui::Slider::new(&mut angle, -180.0..=180.0).text("wind direction °"))
            .changed()
        {
            let a = angle.to_radians();
            self.wind.direction = Vec3::new(a.cos(), self.wind.direction.y, a.sin());
        }
    }

    /// The path, the strand draw, presentation and the camera.
    fn device_ui(&mut self, ui: &mut egui::Ui, (mesh_ok, soft_ok): (bool, bool)) {
        ui.horizontal(|ui| {
            ui.label("path");
            ui.add_enabled_ui(mesh_ok, |ui| {
                ui.radio_value(&mut self.path, RenderPath::Mesh, "mesh");
            });
            ui.radio_value(&mut self.path, RenderPath::Compute, "compute");
        });
        ui.horizontal(|ui| {
            ui.label("draw");
            ui.radio_value(&mut self.raster, StrandRaster::Hardware, "hw");
            ui.add_enabled_ui(soft_ok, |ui| {
                let k = DEFAULT_SOFT_K;
                ui.radio_value(&mut self.raster, StrandRaster::Software { k }, "soft");
                ui.radio_value(&mut self.raster, StrandRaster::Auto { k }, "auto");
            });
        });
        ui.horizontal(|ui| {
            ui.label("present");
            ui.radio_value(&mut self.present_mode, PresentMode::Fifo, "FIFO");
            ui.radio_value(&mut self.present_mode, PresentMode::Mailbox, "mailbox");
            ui.radio_value(&mut self.present_mode, PresentMode::Immediate, "immediate");
        });
        ui.horizontal(|ui| {
            ui.checkbox(&mut self.paused, "pause orbit");
            ui.checkbox(&mut self.fly, "fly camera");
        });
    }
}

/// The window's camera: an eye `distance` from `centre` in the direction given by `yaw` and
/// `pitch`. Orbit mode turns the eye around the centre and moves the centre on the ground
/// plane; fly mode turns the view around the eye and moves along the view direction.
struct OrbitCamera {
    centre: Vec3,
    yaw: f32,
    pitch: f32,
    distance: f32,
    fly: bool,
}

impl OrbitCamera {
    /// Unit vector from the centre to the eye.
    fn to_eye(&self) -> Vec3 {
        Vec3::new(
            self.pitch.cos() * self.yaw.sin(),
            self.pitch.sin(),
            self.pitch.cos() * self.yaw.cos(),
        )
    }

    fn eye(&self) -> Vec3 {
        self.centre + self.to_eye() * self.distance
    }

    fn camera(&self) -> Camera {
        Camera::look_at(self.eye(), self.centre, 45.0)
    }

    /// A mouse drag of `(dx, dy)` pixels.
    fn drag(&mut self, dx: f32, dy: f32) {
        if self.fly {
            // Turn the view around the eye: the eye stays, the centre moves.
            let eye = self.eye();
            self.yaw -= dx * 0.003;
            self.pitch = (self.pitch - dy * 0.003).clamp(-1.4, 1.4);
            self.centre = eye - self.to_eye() * self.distance;
        } else {
            self.yaw -= dx * 0.005;
            self.pitch = (self.pitch + dy * 0.005).clamp(-0.2, 1.4);
        }
    }

    /// One step of a movement key: `forward`, `right` and `up` in -1..=1.
    fn step(&mut self, forward: f32, right: f32, up: f32) {
        let step = self.distance * 0.05;
        let ahead = if self.fly {
            -self.to_eye()
        } else {
            Vec3::new(-self.yaw.sin(), 0.0, -self.yaw.cos())
        };
        let side = ahead.cross(Vec3::Y).normalize_or(Vec3::X);
        self.centre += (ahead * forward + side * right + Vec3::Y * up) * step;
    }
}

/// The control panel's state: what it edits and egui's own state.
struct Panel {
    ui: UiRenderer,
    egui_ctx: egui::Context,
    egui_state: egui_winit::State,
    /// Textures egui freed in a frame, released once that frame completed.
    pending_free: Vec<(FrameTicket, Vec<egui::TextureId>)>,
    visible: usize,
    lod: LodSettings,
}

/// Everything that exists while the window does. Field order is drop order: Vulkan objects
/// first, the window last (the surface must not outlive it).
/// How densely the crowd grows its strands, and their full vertex level.
#[derive(Clone, Copy, PartialEq)]
struct Strands {
    density: StrandDensity,
    verts_log2: u32,
}

impl Strands {
    /// The density scaled by `factor` (the `[` and `]` keys).
    fn scaled(self, factor: f32) -> Self {
        let density = match self.density {
            StrandDensity::PerCm2(d) => StrandDensity::PerCm2((d * factor).clamp(1.0, 2000.0)),
            StrandDensity::PerReferenceBundle(n) => StrandDensity::PerReferenceBundle(
                ((n as f32 * factor).round() as u32).clamp(1, 16384),
            ),
        };
        Strands { density, ..self }
    }
}

struct Running {
    panel: Panel,
    swapchain: Option<Swapchain>,
    acquire: Vec<Semaphore>,
    renderer: Renderer,
    ctx: Arc<Context>,
    frame: u64,
    size: (u32, u32),
    recreate: bool,
    present_mode: PresentMode,
    camera: OrbitCamera,
    strands: Strands,
    /// The crowd (each character's strand settings follow from `strands` and its hair).
    scene: Arc<Scene>,
    path: RenderPath,
    shading: ShadingModel,
    shadows: ShadowMode,
    /// How the light's passes draw (hardware where the settings refuse software).
    light_raster: LightRaster,
    transparency: Transparency,
    temporal: Temporal,
    raster: StrandRaster,
    /// The software rasterizer can draw this window's frames (device support, no MSAA).
    soft_ok: bool,
    lod_appearance: bool,
    multiple_scattering: bool,
    volumes: hairmesh::render::VolumeTier,
    animation: hairmesh::animate::CrowdAnimation,
    last_draw: Instant,
    paused: bool,
    dragging: Option<(f64, f64)>,
    cursor: (f64, f64),
    last_ticket: Option<FrameTicket>,
    last_report: Option<FrameReport>,
    /// The panel shows the frame graph (frames then keep its description).
    show_graph: bool,
    fps_window: (Instant, u64),
    fps: f64,
    /// Swapchain (re)creations and frames skipped for a zero-size window.
    recreations: u32,
    zero_skips: u32,
    /// `--test-resize`: redraws left with a simulated zero-size window.
    hold_zero: u32,
    window: Arc<Window>,
}

struct App {
    args: Args,
    scene: Arc<Scene>,
    running: Option<Running>,
    error: Option<anyhow::Error>,
    presented: u64,
    simulated_zero: u32,
    resize_requested: bool,
    summary: String,
}

/// Open the window and run until it is closed (or `--exit-after-frames`).
pub fn run(args: Args, scene: Scene) -> Result<()> {
    parse_size(&args.size)?;
    let event_loop =
        EventLoop::new().context("cannot open a window (no display?); use --headless")?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = App {
        args,
        scene: Arc::new(scene),
        running: None,
        error: None,
        presented: 0,
        simulated_zero: 0,
        resize_requested: false,
        summary: String::new(),
    };
    event_loop.run_app(&mut app)?;
    if let Some(e) = app.error {
        return Err(e);
    }
    outln!("presented {} frames{}", app.presented, app.summary)?;
    Ok(())
}

fn present_mode(name: &str) -> PresentMode {
    match name {
        "mailbox" => PresentMode::Mailbox,
        "immediate" => PresentMode::Immediate,
        _ => PresentMode::Fifo,
    }
}

impl App {
    fn start(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let (w, h) = parse_size(&self.args.size)?;
        let window = Arc::new(
            event_loop.create_window(
                Window::default_attributes()
                    .with_title("hairmesh crowd")
                    .with_inner_size(PhysicalSize::new(w, h)),
            )?,
        );
        let ctx = self.window_context(&window)?;
        let size = window.inner_size();
        let mut renderer =
            self.scene
                .renderer(&ctx, &self.args, size.width.max(1), size.height.max(1))?;
        let animation = self.scene.animation(&mut renderer, &self.args)?;
        let path = renderer.default_path();
        let panel = self.panel(&ctx, &window)?;
        let acquire = (0..hairmesh::render::FRAMES_IN_FLIGHT)
            .map(|_| Semaphore::new(&ctx))
            .collect::<Result<_, _>>()?;
        let soft_ok = renderer.has_software_raster() && self.args.msaa() == 1;
        let chosen = hairmesh::render::FrameSettings {
            path,
            raster: self.args.look.draw.unwrap_or_default(),
            transparency: self.args.transparency(),
            msaa: renderer.msaa(),
            light_raster: self.args.look.shadow_draw.unwrap_or_default(),
        }
        .with_fastest(
            (self.args.look.draw, self.args.look.shadow_draw),
            &renderer.caps(),
        );
        self.running = Some(Running {
            soft_ok,
            panel,
            swapchain: None,
            acquire,
            renderer,
            ctx,
            frame: 0,
            size: (size.width, size.height),
            recreate: true,
            present_mode: present_mode(&self.args.present_mode),
            camera: self.start_camera(),
            strands: Strands {
                density: self.args.density(),
                verts_log2: self.args.verts_log2,
            },
            scene: Arc::clone(&self.scene),
            path,
            shading: self.args.shading(),
            shadows: self.args.shadows(),
            light_raster: chosen.light_raster,
            transparency: self.args.transparency(),
            temporal: self.args.temporal(),
            raster: chosen.raster,
            lod_appearance: self.args.lod_appearance(),
            multiple_scattering: self.args.multiple_scattering(),
            volumes: self.args.volume_tier()?,
            animation,
            last_draw: Instant::now(),
            paused: false,
            dragging: None,
            cursor: (0.0, 0.0),
            last_ticket: None,
            last_report: None,
            show_graph: false,
            fps_window: (Instant::now(), 0),
            fps: 0.0,
            recreations: 0,
            zero_skips: 0,
            hold_zero: 0,
            window,
        });
        Ok(())
    }

    /// The first camera: the whole crowd in view, from behind its first row.
    fn start_camera(&self) -> OrbitCamera {
        let side = (self.scene.character_count() as f32).sqrt().ceil();
        OrbitCamera {
            centre: Vec3::new(
                0.0,
                self.args.preset.focus_height(),
                (side - 1.0) * 0.5 * preset::SPACING,
            ),
            yaw: std::f32::consts::PI,
            pitch: 0.35,
            distance: (side * 0.9 * 0.8).max(1.8),
            fly: false,
        }
    }

    /// The device, made for `window`'s surface.
    fn window_context(&self, window: &Window) -> Result<Arc<Context>> {
        let handles = WindowHandles {
            display: window.display_handle()?.as_raw(),
            window: window.window_handle()?.as_raw(),
        };
        Ok(Arc::new(Context::new(
            &self.args.gpu.context_desc().window(handles),
        )?))
    }

    /// The control panel: egui's state for `window` and its renderer.
    fn panel(&self, ctx: &Arc<Context>, window: &Window) -> Result<Panel> {
        let egui_ctx = egui::Context::default();
        let egui_state = egui_winit::State::new(
            egui_ctx.clone(),
            egui::ViewportId::ROOT,
            window,
            Some(window.scale_factor() as f32),
            None,
            Some(4096),
        );
        Ok(Panel {
            ui: UiRenderer::new(
                ctx,
                hairmesh::render::targets::COLOR_FORMAT,
                hairmesh::render::FRAMES_IN_FLIGHT,
            )?,
            egui_ctx,
            egui_state,
            pending_free: Vec::new(),
            visible: self.scene.character_count(),
            lod: self.args.lod_settings()?,
        })
    }

    /// Test script of `--test-resize`, run once per redraw: a new size after 3 frames, a
    /// zero-size (minimised) window for 3 redraws after 6 frames.
    fn scripted_resize(&mut self) {
        let Some(r) = &mut self.running else { return };
        if !self.args.test_resize {
            return;
        }
        if self.presented >= 3 && !self.resize_requested {
            self.resize_requested = true;
            let _ = r
                .window
                .request_inner_size(PhysicalSize::new(r.size.0 / 2 + 17, r.size.1 / 2 + 9));
        }
        // A zero-size window for the next 3 redraws (Resized events are held meanwhile).
        if self.presented == 6 && self.simulated_zero == 0 {
            self.simulated_zero = 1;
            r.hold_zero = 3;
            r.size_changed(0, 0);
        } else if r.hold_zero > 0 {
            r.hold_zero -= 1;
            if r.hold_zero == 0 {
                let s = r.window.inner_size();
                r.size_changed(s.width, s.height);
            }
        }
    }
}

impl Running {
    /// The cursor moved to `(x, y)`: a drag with the left button turns the camera.
    fn cursor_moved(&mut self, x: f64, y: f64) {
        if let Some((x0, y0)) = self.dragging {
            self.camera.drag((x - x0) as f32, (y - y0) as f32);
            self.dragging = Some((x, y));
        }
        self.cursor = (x, y);
    }

    /// The wheel moved by `delta`: the camera comes closer or goes back (0.3 to 200 m).
    fn zoom(&mut self, delta: MouseScrollDelta) {
        let d = match delta {
            MouseScrollDelta::LineDelta(_, y) => y,
            MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
        };
        self.camera.distance = (self.camera.distance * (1.0 - 0.1 * d)).clamp(0.3, 200.0);
    }

    fn size_changed(&mut self, width: u32, height: u32) {
        self.size = (width, height);
        self.recreate = true;
    }

    /// Draw and present one frame; returns whether an image was presented.
    fn draw(&mut self, scene_len: usize) -> Result<bool> {
        let (w, h) = self.size;
        if w == 0 || h == 0 {
            self.zero_skips += 1;
            return Ok(false); // minimised: nothing to present to
        }
        if (self.recreate || self.swapchain.is_none()) && !self.recreate_swapchain(w, h)? {
            return Ok(false);
        }
        if !self.paused {
            self.camera.yaw += 0.004;
        }
        self.renderer.wait_for_free_slot()?;
        let chain = self.swapchain.as_ref().expect("created above");
        let semaphore = &self.acquire[(self.frame % self.acquire.len() as u64) as usize];
        let (image, suboptimal) = match chain.acquire(semaphore)? {
            Acquired::Image(image, suboptimal) => (image, suboptimal),
            Acquired::OutOfDate => {
                self.recreate = true;
                return Ok(false);
            }
        };
        let dt = self.last_draw.elapsed().as_secs_f32();
        self.last_draw = Instant::now();
        let camera = self.camera.camera();
        self.animation.advance(&mut self.renderer, dt, &camera, h)?;
        let view = View {
            light_dir: hairmesh::render::camera::CROWD_LIGHT_DIR,
            lod: self.panel.lod,
            shading: self.shading,
            shadows: self.shadows,
            transparency: self.transparency,
            temporal: self.temporal,
            lod_appearance: self.lod_appearance,
            multiple_scattering: self.multiple_scattering,
            volumes: self.volumes,
            ..View::new(camera)
        };
        let (primitives, ppp, freed) = self.panel_frame(scene_len)?;
        let (raster, light_raster) = self.frame_raster();
        let chain = self.swapchain.as_ref().expect("created above");
        let semaphore = &self.acquire[(self.frame % self.acquire.len() as u64) as usize];
        let ui = &mut self.panel.ui;
        let mut overlay = |rec: &mut hairmesh::vk::CommandRecorder,
                           target: &hairmesh::vk::Image| {
            ui.draw(rec, target, ppp, &primitives)
        };
        let ticket = self.renderer.render_frame_to(
            &view,
            &FrameOptions {
                path: Some(self.path),
                raster,
                light_raster,
                describe_frame: self.show_graph,
                ..Default::default()
            },
            Some(PresentTarget {
                image: &image,
                wait: semaphore,
                signal: chain.render_finished(image.index),
                overlay: Some(&mut overlay),
            }),
        )?;
        self.panel.pending_free.push((ticket, freed));
        let stale = chain.present(image.index)?;
        self.recreate |= stale || suboptimal;
        self.frame += 1;
        // The previous frame has (nearly always) completed: its report costs no stall.
        if let Some(t) = self.last_ticket.replace(ticket) {
            self.collect_report(t)?;
        }
        self.update_title(scene_len);
        Ok(true)
    }

    /// A new swapchain of `w`x`h` (replacing the old one) and the renderer resized to it;
    /// false when the surface has no area to present to.
    fn recreate_swapchain(&mut self, w: u32, h: u32) -> Result<bool> {
        let old = self.swapchain.take();
        let chain = Swapchain::new(&self.ctx, w, h, self.present_mode, old)?;
        let [cw, ch] = chain.extent();
        if cw == 0 || ch == 0 {
            return Ok(false);
        }
        self.renderer.resize(cw, ch)?;
        self.swapchain = Some(chain);
        self.recreate = false;
        self.recreations += 1;
        Ok(true)
    }

    /// Frame `t`'s report (warned about on stderr when it dropped work) and the panel
    /// textures it no longer uses, freed.
    fn collect_report(&mut self, t: FrameTicket) -> Result<()> {
        let report = self.renderer.wait(t)?;
        let dropped = report.dropped();
        // Nothing dropped goes unsaid: on stderr too, at most once a second of frames.
        if dropped.any() && self.frame % 60 == 1 {
            eprintln!("crowd: warning: frame {}: {dropped} (buffers full)", t.0);
        }
        self.last_report = Some(report);
        let done: Vec<_> = self
            .panel
            .pending_free
            .iter()
            .filter(|(f, _)| f.0 <= t.0)
            .flat_map(|(_, ids)| ids.clone())
            .collect();
        self.panel.pending_free.retain(|(f, _)| f.0 > t.0);
        self.panel.ui.free_textures(&done)?;
        Ok(())
    }

    /// Run the control panel for this frame: returns its meshes, pixels per point and the
    /// textures egui freed; applies what the user changed.
    fn panel_frame(
        &mut self,
        scene_len: usize,
    ) -> Result<(Vec<egui::ClippedPrimitive>, f32, Vec<egui::TextureId>)> {
        let input = self.panel.egui_state.take_egui_input(&self.window);
        let egui_ctx = self.panel.egui_ctx.clone();
        let mut c = Controls {
            visible: self.panel.visible,
            shading: self.shading,
            shadows: self.shadows,
            light_raster: self.light_raster,
            transparency: self.transparency,
            temporal: self.temporal,
            raster: self.raster,
            lod_appearance: self.lod_appearance,
            multiple_scattering: self.multiple_scattering,
            volumes: self.volumes,
            moving: self.animation.moving,
            simulating: self.animation.simulating,
            dynamics: self.animation.path,
            schedule: self.animation.schedule,
            wind: self.animation.wind,
            strands: self.strands,
            lod: self.panel.lod,
            path: self.path,
            paused: self.paused,
            fly: self.camera.fly,
            present_mode: self.present_mode,
            show_graph: self.show_graph,
        };
        let stats = self.stats_text(scene_len);
        let ok = (self.renderer.has_mesh_path(), self.soft_ok());
        let graph = self
            .last_report
            .as_ref()
            .and_then(|r| r.frame_graph.as_deref())
            .unwrap_or("(shown from the next frame)");
        let text = (stats.as_str(), graph);
        let output = egui_ctx.run_ui(input, |ui| c.show(ui.ctx(), scene_len, ok, text));
        self.panel
            .egui_state
            .handle_platform_output(&self.window, output.platform_output);
        self.panel.ui.set_textures(&output.textures_delta)?;
        self.apply(c)?;
        let ppp = output.pixels_per_point;
        let primitives = egui_ctx.tessellate(output.shapes, ppp);
        Ok((
            primitives,
            ppp,
            output.textures_delta.free.iter().copied().collect(),
        ))
    }

    /// Whether the software rasterizer can draw this window's frames at all (device support
    /// and single-sample targets), for the panel.
    fn soft_ok(&self) -> bool {
        self.soft_ok
    }

    /// The camera's and the light's raster of the next frame: the chosen ones where the
    /// settings allow them (`FrameSettings::validate` holds the rules), else hardware.
    fn frame_raster(&self) -> (StrandRaster, LightRaster) {
        let settings = |raster, light_raster| hairmesh::render::FrameSettings {
            path: self.path,
            raster,
            transparency: self.transparency,
            msaa: self.renderer.msaa(),
            light_raster,
        };
        let caps = self.renderer.caps();
        let ok = |r, l| settings(r, l).validate(&caps).is_ok();
        let raster = match ok(self.raster, LightRaster::Hardware) {
            true => self.raster,
            false => StrandRaster::Hardware,
        };
        let light = match ok(raster, self.light_raster) {
            true => self.light_raster,
            false => LightRaster::Hardware,
        };
        (raster, light)
    }

    fn apply(&mut self, c: Controls) -> Result<()> {
        if c.visible != self.panel.visible {
            for (k, id) in self.renderer.crowd().ids().into_iter().enumerate() {
                self.renderer.set_visible(id, k < c.visible)?;
            }
            self.panel.visible = c.visible;
        }
        if c.strands != self.strands {
            self.set_strands(c.strands)?;
        }
        if c.present_mode != self.present_mode {
            self.present_mode = c.present_mode;
            self.recreate = true;
        }
        self.panel.lod = c.lod;
        self.shading = c.shading;
        self.shadows = c.shadows;
        self.light_raster = c.light_raster;
        self.transparency = c.transparency;
        self.temporal = c.temporal;
        self.raster = c.raster;
        self.lod_appearance = c.lod_appearance;
        self.multiple_scattering = c.multiple_scattering;
        self.volumes = c.volumes;
        self.animation.moving = c.moving;
        self.animation.simulating = c.simulating;
        self.animation.path = c.dynamics;
        self.animation.schedule = c.schedule;
        self.animation.wind = c.wind;
        self.path = c.path;
        self.paused = c.paused || (c.fly && !self.camera.fly);
        self.camera.fly = c.fly;
        self.show_graph = c.show_graph;
        Ok(())
    }

    fn stats_text(&self, scene_len: usize) -> String {
        let Some(r) = &self.last_report else {
            return "waiting for the first frame".into();
        };
        let passes: Vec<String> = r
            .pass_ms
            .iter()
            .map(|(n, ms)| format!("{n} {ms:.1} ms"))
            .collect();
        let mut text = format!(
            "{:.1} fps\nGPU: {}\nCPU record: {:.2} ms\nstrands {} / triangles {}\ncharacters {} of {scene_len}, textures {:.1} MiB",
            self.fps,
            passes.join(", "),
            r.record_ms,
            r.stats.strands_drawn,
            r.stats.triangles_drawn,
            self.panel.visible,
            self.renderer.crowd().texture_bytes() as f64 / (1 << 20) as f64,
        );
        let a = &self.animation.stats;
        text.push_str(&format!(
            "\nhair dynamics on the {}: {:.1} ms CPU, {} characters, {} vertices",
            a.path, a.simulate_ms, a.simulated, a.vertices
        ));
        // What the buffers could not hold, every frame: the LoD pressure that kept the frame
        // inside them, and anything dropped all the same.
        let dropped = r.dropped();
        text.push_str(&format!(
            "\nLoD pressure {:.3}; {}{dropped}",
            r.lod_pressure(),
            if dropped.any() { "WARNING: " } else { "" }
        ));
        if r.path == RenderPath::Compute {
            text.push_str(&format!(
                "\nvertex pool {} of {} slots{}",
                r.stats.vertex_slots_written,
                self.renderer.vertex_budget(),
                if r.stats.strands_drawn < r.stats.strands_demanded {
                    format!(
                        ", OVERFLOW: {} of {} strands",
                        r.stats.strands_drawn, r.stats.strands_demanded
                    )
                } else {
                    String::new()
                }
            ));
        }
        text
    }

    fn update_title(&mut self, scene_len: usize) {
        let (since, frames) = self.fps_window;
        let elapsed = since.elapsed().as_secs_f64();
        if elapsed < 0.5 {
            return;
        }
        self.fps = (self.frame - frames) as f64 / elapsed;
        self.fps_window = (Instant::now(), self.frame);
        let Some(r) = &self.last_report else { return };
        let passes: Vec<String> = r
            .pass_ms
            .iter()
            .map(|(n, ms)| format!("{n} {ms:.1}"))
            .collect();
        let pool = if self.path == RenderPath::Compute {
            format!(
                ", pool {:.0}%{}",
                100.0 * r.stats.vertex_slots_written as f64
                    / self.renderer.vertex_budget().max(1) as f64,
                if r.stats.strands_drawn < r.stats.strands_demanded {
                    " OVERFLOW"
                } else {
                    ""
                }
            )
        } else {
            String::new()
        };
        self.window.set_title(&format!(
            "hairmesh crowd - {scene_len} characters, {:.1} fps, GPU {} ms, CPU {:.2} ms, {} strands, {} tris, tex {:.1} MiB{pool}, {:?}, LoD {}, {:?}, {} e {}",
            self.fps,
            passes.join(" / "),
            r.record_ms,
            r.stats.strands_drawn,
            r.stats.triangles_drawn,
            self.renderer.crowd().texture_bytes() as f64 / (1 << 20) as f64,
            self.path,
            if self.panel.lod.enabled { "on" } else { "off" },
            self.swapchain.as_ref().map_or(self.present_mode, |s| s.present_mode),
            match self.strands.density {
                StrandDensity::PerCm2(d) => format!("{d:.0} strands per cm²"),
                StrandDensity::PerReferenceBundle(n) => format!("N {n}"),
            },
            self.strands.verts_log2,
        ));
    }

    /// Grow every character at `strands` (each its own strands per bundle, fur its own vertex
    /// cap); a density a character cannot hold, or settings the renderer refuses, leave the
    /// crowd as it was.
    fn set_strands(&mut self, strands: Strands) -> Result<()> {
        // Characters were added in order into slots 0.. and never removed: ids() is in that
        // order.
        let ids: Vec<_> = self.renderer.crowd().ids();
        let mut params = Vec::with_capacity(ids.len());
        for i in 0..ids.len() {
            match self
                .scene
                .strand_params(i, strands.density, strands.verts_log2)
            {
                Ok(p) if p.validate().is_ok() => params.push(p),
                _ => return Ok(()),
            }
        }
        self.strands = strands;
        for (id, p) in ids.into_iter().zip(params) {
            self.renderer.set_params(id, p)?;
        }
        Ok(())
    }

    fn key(&mut self, code: KeyCode, event_loop: &ActiveEventLoop) -> Result<()> {
        match code {
            KeyCode::Escape => event_loop.exit(),
            KeyCode::KeyW => self.camera.step(1.0, 0.0, 0.0),
            KeyCode::KeyS => self.camera.step(-1.0, 0.0, 0.0),
            KeyCode::KeyD => self.camera.step(0.0, 1.0, 0.0),
            KeyCode::KeyA => self.camera.step(0.0, -1.0, 0.0),
            KeyCode::KeyE => self.camera.step(0.0, 0.0, 1.0),
            KeyCode::KeyQ => self.camera.step(0.0, 0.0, -1.0),
            KeyCode::KeyF => {
                self.camera.fly = !self.camera.fly;
                self.paused |= self.camera.fly;
            }
            KeyCode::Space => self.paused = !self.paused,
            KeyCode::KeyL => self.panel.lod.enabled = !self.panel.lod.enabled,
            KeyCode::KeyK => {
                self.shading = match self.shading {
                    ShadingModel::Placeholder => ShadingModel::KajiyaKay,
                    ShadingModel::KajiyaKay => ShadingModel::Marschner,
                    ShadingModel::Marschner => ShadingModel::Placeholder,
                }
            }
            KeyCode::KeyR if self.soft_ok() => {
                let k = DEFAULT_SOFT_K;
                self.raster = match self.raster {
                    StrandRaster::Hardware => StrandRaster::Software { k },
                    StrandRaster::Software { .. } => StrandRaster::Auto { k },
                    StrandRaster::Auto { .. } => StrandRaster::Hardware,
                }
            }
            KeyCode::KeyT => {
                self.transparency = match self.transparency {
                    Transparency::Opaque => Transparency::KBuffer {
                        budget: DEFAULT_OIT_BUDGET,
                    },
                    _ => Transparency::Opaque,
                }
            }
            KeyCode::KeyH => {
                let k = ShadowMode::ALL.iter().position(|m| *m == self.shadows);
                self.shadows = ShadowMode::ALL[(k.unwrap_or(0) + 1) % ShadowMode::ALL.len()];
            }
            KeyCode::KeyM => {
                self.path = match self.path {
                    RenderPath::Mesh => RenderPath::Compute,
                    RenderPath::Compute if self.renderer.has_mesh_path() => RenderPath::Mesh,
                    // The window never picks the static path (the crowd moves).
                    _ => RenderPath::Compute,
                }
            }
            KeyCode::KeyV => {
                self.present_mode = match self.present_mode {
                    PresentMode::Fifo => PresentMode::Mailbox,
                    PresentMode::Mailbox => PresentMode::Immediate,
                    PresentMode::Immediate => PresentMode::Fifo,
                };
                self.recreate = true;
            }
            KeyCode::BracketLeft => self.set_strands(self.strands.scaled(0.5))?,
            KeyCode::BracketRight => self.set_strands(self.strands.scaled(2.0))?,
            KeyCode::Minus => self.set_strands(Strands {
                verts_log2: self.strands.verts_log2.saturating_sub(1),
                ..self.strands
            })?,
            KeyCode::Equal => self.set_strands(Strands {
                verts_log2: (self.strands.verts_log2 + 1).min(6),
                ..self.strands
            })?,
            _ => {}
        }
        Ok(())
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.running.is_none()
            && let Err(e) = self.start(event_loop)
        {
            self.error = Some(e);
            event_loop.exit();
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let scene_len = self.scene.character_count();
        let Some(r) = &mut self.running else { return };
        let consumed = r
            .panel
            .egui_state
            .on_window_event(&r.window, &event)
            .consumed;
        let redraw = matches!(event, WindowEvent::RedrawRequested);
        let result = match event {
            WindowEvent::KeyboardInput { .. }
            | WindowEvent::MouseInput { .. }
            | WindowEvent::MouseWheel { .. }
                if consumed =>
            {
                Ok(())
            }
            WindowEvent::CloseRequested => {
                event_loop.exit();
                Ok(())
            }
            WindowEvent::Resized(size) => {
                if r.hold_zero == 0 {
                    r.size_changed(size.width, size.height);
                }
                Ok(())
            }
            WindowEvent::KeyboardInput { event, .. } => match (event.state, event.physical_key) {
                (ElementState::Pressed, PhysicalKey::Code(code)) => r.key(code, event_loop),
                _ => Ok(()),
            },
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                r.dragging = (state == ElementState::Pressed).then_some(r.cursor);
                Ok(())
            }
            WindowEvent::CursorMoved { position, .. } => {
                r.cursor_moved(position.x, position.y);
                Ok(())
            }
            WindowEvent::MouseWheel { delta, .. } => {
                r.zoom(delta);
                Ok(())
            }
            WindowEvent::RedrawRequested => match r.draw(scene_len) {
                Ok(true) => {
                    self.presented += 1;
                    if self
                        .args
                        .exit_after_frames
                        .is_some_and(|n| self.presented >= n)
                    {
                        event_loop.exit();
                    }
                    Ok(())
                }
                Ok(false) => Ok(()),
                Err(e) => Err(e),
            },
            _ => Ok(()),
        };
        if let Err(e) = result {
            self.error = Some(e);
            event_loop.exit();
        }
        if redraw {
            self.scripted_resize();
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(r) = &self.running {
            r.window.request_redraw();
        }
    }

    fn exiting(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(r) = &mut self.running {
            let _ = r.renderer.finish();
            let s = r.window.inner_size();
            self.summary = format!(
                "; swapchain created {} times; {} frames skipped at zero size; final size {}x{}",
                r.recreations, r.zero_skips, s.width, s.height
            );
            if r.ctx.validation_errors() > 0 && self.error.is_none() {
                self.error = Some(anyhow::anyhow!(
                    "{} Vulkan validation error(s)",
                    r.ctx.validation_errors()
                ));
            }
        }
        self.running = None;
    }
}
