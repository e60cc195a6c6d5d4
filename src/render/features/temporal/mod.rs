//! Temporal stability: motion vectors, temporal accumulation made for strands, sub-pixel
//! jitter, and the CPU side of the flicker measure (`bench temporal`).
//!
//! **Motion.** Every camera pass that draws a surface (strand fragments in every
//! transparency mode, the software rasterizer's fragments, scalps, props) notes the nearest
//! surface of each pixel in a visibility word ([`VisibilityWord`]: depth, visibility id,
//! deformation residual), by 64-bit `atomicMin` (`temporal.glsl`). The id names a character
//! (hair, or its scalp with [`VISIBILITY_SOLID`]) or a prop instance, and each of those
//! carries the matrix from this frame's unjittered clip space to the previous frame's
//! (`clip_to_prev`: the previous view-projection, the surface's own rigid motion, the
//! inverse of this one), so a pixel's rigid motion follows from its depth alone, exactly for
//! camera motion and characters that move as a whole (walk, turn, sway). Hair generated from
//! the same textures and seed lands on the same strands both frames. Where a hair mesh also
//! changed pose relative to its head this frame (dynamics, wind), the generators evaluate
//! every strand vertex a second time from the previous pose's textures (an animated
//! character keeps two texture sets and alternates between them) and carry the difference,
//! projected into the previous frame's pixels, as the residual: rigid motion minus residual
//! is the strand's exact motion.
//!
//! **Accumulation** (`temporal.comp`): the history is reprojected with a Catmull-Rom filter
//! (sharp: a single strand stays a strand), and trusted by what the pixel *is*, not only by
//! its colour: a history pixel whose visibility id differs, or whose depth disagrees with the
//! reprojected depth, is a disocclusion and is dropped; on hair the colour clamp is wider
//! ([`TemporalTuning::hair_clamp`] standard deviations of the 3x3 neighbourhood in YCoCg),
//! because a sub-pixel strand's neighbourhood rarely brackets its own history, and a tight
//! clamp erases strands. A pixel moves with the nearest hair of its 3x3 neighbourhood (a
//! strand thinner than a pixel drags its history along) but never with a neighbouring solid
//! (its silhouette would smear). Moving solid surfaces keep a shorter history
//! ([`TEMPORAL_SOLID_MOVING_WEIGHT`](crate::render::core::shared::TEMPORAL_SOLID_MOVING_WEIGHT)) against blur and lag on their edges. The
//! jitter (Halton 2, 3 over 8 frames) moves the raster by under a pixel each frame, so the
//! history integrates 8 sample positions per pixel.

use std::sync::Arc;

use ash::vk;
use glam::{Mat4, Vec2, Vec3, Vec4};

mod pass;

pub use pass::{TemporalInputs, TemporalPass, TemporalRes};

use crate::render::core::graph::{FrameGraph, Res, TransientBuffer};
use crate::render::core::shared::{
    FrameBinding, FrameBlock, VISIBILITY_DEPTH_SHIFT, VISIBILITY_EMPTY, VISIBILITY_INDEX,
    VISIBILITY_PROP, VISIBILITY_RESIDUAL_STEPS, VISIBILITY_SOLID,
};
pub use crate::render::core::slots::PixelMotion;
use crate::vk::{Buffer, BufferDesc, Context, GpuError, GpuResult, PipelineLayout};

/// Temporal accumulation of a frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Temporal {
    /// Every frame on its own (no jitter, no history).
    #[default]
    Off,
    /// Temporal anti-aliasing made for strands: jitter, motion vectors, history.
    Taa,
}

impl Temporal {
    /// Every mode, in menu order.
    pub const ALL: [Temporal; 2] = [Temporal::Off, Temporal::Taa];

    /// Name used by flags and scene files.
    pub fn name(self) -> &'static str {
        match self {
            Temporal::Off => "off",
            Temporal::Taa => "taa",
        }
    }
}

impl std::str::FromStr for Temporal {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Temporal::ALL
            .into_iter()
            .find(|t| t.name() == s)
            .ok_or_else(|| format!("temporal {s:?}: off or taa"))
    }
}

impl std::fmt::Display for Temporal {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The accumulation's constants (`TemporalFields::history_weight`, `TemporalFields::hair_clamp`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TemporalTuning {
    /// Weight of the current frame in a pixel whose history is trusted (the rest is history):
    /// about the last `1 / current_weight` frames contribute.
    pub current_weight: f32,
    /// Width of the colour clamp on hair, in standard deviations of the neighbourhood (1 on
    /// solid surfaces).
    pub hair_clamp: f32,
}

impl Default for TemporalTuning {
    fn default() -> Self {
        TemporalTuning {
            current_weight: 0.125,
            hair_clamp: 2.0,
        }
    }
}

/// Sub-pixel jitter of frame `index`, in pixels in `[-0.5, 0.5)`: the Halton (2, 3) sequence
/// over 8 frames (`index` 0 is the sequence's first point).
pub fn jitter(index: u64) -> Vec2 {
    let i = (index % 8) as u32 + 1;
    Vec2::new(radical_inverse(i, 2), radical_inverse(i, 3)) - 0.5
}

fn radical_inverse(mut i: u32, base: u32) -> f32 {
    let (mut inv, mut f) = (0.0f32, 1.0f32 / base as f32);
    while i > 0 {
        inv += (i % base) as f32 * f;
        i /= base;
        f /= base as f32;
    }
    inv
}

/// `view_proj` moved by `pixels` on a `size` target (clip-space translation scaled by w, so
/// every point moves by the same sub-pixel offset).
pub fn jittered(view_proj: Mat4, pixels: Vec2, size: (u32, u32)) -> Mat4 {
    let ndc = Vec2::new(
        2.0 * pixels.x / size.0 as f32,
        2.0 * pixels.y / size.1 as f32,
    );
    Mat4::from_translation(ndc.extend(0.0)) * view_proj
}

/// This frame's unjittered clip space to the previous frame's, for a surface that moved by
/// `prev_from_now` in world space (its previous model times the inverse of its current one):
/// `prev_view_proj * prev_from_now * view_proj^-1`.
pub fn clip_to_prev(prev_view_proj: Mat4, prev_from_now: Mat4, view_proj: Mat4) -> Mat4 {
    prev_view_proj * prev_from_now * view_proj.inverse()
}

/// Screen motion (pixels, this frame's position minus the previous frame's) of the surface at
/// pixel centre `centre` (pixels, y down) and depth `depth` (0..1) on a `size` target; the
/// CPU twin of `motion_at` in `temporal.comp`.
pub fn motion_at(clip_to_prev: Mat4, centre: Vec2, depth: f32, size: Vec2) -> Vec2 {
    let ndc = centre / size * 2.0 - 1.0;
    let prev = clip_to_prev * Vec4::new(ndc.x, ndc.y, depth, 1.0);
    if prev.w.abs() < 1e-12 {
        return Vec2::ZERO;
    }
    let prev_px = (Vec2::new(prev.x, prev.y) / prev.w + 1.0) * 0.5 * size;
    centre - prev_px
}

/// A pixel's visibility word, the CPU twin of `temporal.glsl`: from the top, 24 bits of the
/// depth's float bits (nearest wins the `atomicMin`), the visibility id in 18 bits (16 of
/// index, then [`VISIBILITY_SOLID`] and [`VISIBILITY_PROP`]), and the deformation residual
/// in two signed 11-bit fields of [`VISIBILITY_RESIDUAL_STEPS`] per pixel. An empty word
/// (all ones) decodes as [`VISIBILITY_EMPTY`] at depth 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VisibilityWord {
    /// Depth, 0..1 (quantised to the word's 24 bits).
    pub depth: f32,
    /// Visibility id.
    pub id: u32,
    /// Previous-frame position of the strand minus its rigidly moved position, pixels.
    pub residual: Vec2,
}

const RESIDUAL_BIAS: i32 = 1 << 10;
const ID_EMPTY: u64 = (1 << 18) - 1;

impl VisibilityWord {
    /// Pack into the GPU's word.
    pub fn pack(&self) -> u64 {
        let depth = (self.depth.clamp(0.0, 1.0).to_bits() >> VISIBILITY_DEPTH_SHIFT) as u64;
        let id = if self.id == VISIBILITY_EMPTY {
            ID_EMPTY
        } else {
            let solid = (self.id & VISIBILITY_SOLID != 0) as u64;
            let prop = (self.id & VISIBILITY_PROP != 0) as u64;
            let kind = solid | (prop << 1);
            (self.id & VISIBILITY_INDEX) as u64 | kind << 16
        };
        let field = |r: f32| {
            let steps = (r * VISIBILITY_RESIDUAL_STEPS + 0.5).floor() as i32;
            (steps.clamp(-RESIDUAL_BIAS, RESIDUAL_BIAS - 1) + RESIDUAL_BIAS) as u64
        };
        depth << 40 | id << 22 | field(self.residual.x) << 11 | field(self.residual.y)
    }

    /// Decode the GPU's word.
    pub fn unpack(word: u64) -> Self {
        let id18 = (word >> 22) & ID_EMPTY;
        if id18 == ID_EMPTY {
            return VisibilityWord {
                depth: 1.0,
                id: VISIBILITY_EMPTY,
                residual: Vec2::ZERO,
            };
        }
        let kind = id18 >> 16;
        let id = (id18 & VISIBILITY_INDEX as u64) as u32
            | if kind & 1 != 0 { VISIBILITY_SOLID } else { 0 }
            | if kind & 2 != 0 { VISIBILITY_PROP } else { 0 };
        let field =
            |f: u64| ((f & 0x7FF) as i32 - RESIDUAL_BIAS) as f32 / VISIBILITY_RESIDUAL_STEPS;
        VisibilityWord {
            depth: f32::from_bits(((word >> 40) as u32) << VISIBILITY_DEPTH_SHIFT),
            id,
            residual: Vec2::new(field(word >> 11), field(word)),
        }
    }
}

/// Bytes per pixel of the history (`uvec2` colour: rg and b halves; `uvec2` surface:
/// visibility id, depth bits).
const HISTORY_TEXEL: u64 = 16;

/// What the renderer keeps between frames for temporal work: the previous frame's matrices
/// (motion vectors) and the accumulated history (two buffers, read one, write the other).
#[derive(Default)]
pub struct TemporalState {
    /// The previous frame's unjittered view-projection and each character slot's model.
    prev: Option<PreviousFrame>,
    /// History buffers for the target size they were made for.
    history: Option<([Buffer; 2], (u32, u32))>,
    /// Which history buffer this frame writes.
    parity: usize,
    /// Whether the history read this frame holds an earlier accumulated frame.
    valid: bool,
    /// Frames accumulated since the history was reset (jitter phase).
    index: u64,
}

/// Temporal stability as one feature of the renderer: its state between frames (the previous
/// frame's matrices, the accumulated history) and its pipeline, what it writes into the
/// camera's frame block, and the passes it adds to a frame.
pub struct TemporalFeature {
    state: TemporalState,
    /// The motion and accumulation pipeline, on devices with 64-bit buffer atomics.
    pass: Option<TemporalPass>,
    /// The device's name, for the refusal where it has no such atomics.
    device: String,
}

impl TemporalFeature {
    /// The feature for `ctx`'s device (without its pipeline where the device lacks 64-bit
    /// buffer atomics: frames that ask for motion are then refused).
    pub fn new(ctx: &Arc<Context>, layout: &Arc<PipelineLayout>) -> GpuResult<Self> {
        let pass = match ctx.info.int64_atomics {
            true => Some(TemporalPass::new(ctx, layout)?),
            false => None,
        };
        Ok(TemporalFeature {
            state: TemporalState::default(),
            pass,
            device: ctx.info.name.clone(),
        })
    }

    /// Forget the previous frame and the history (a camera cut).
    pub fn reset(&mut self) {
        self.state.reset();
    }

    /// This frame's work for `mode` (`None`: no motion vectors), or why this device cannot do
    /// it; `vertex_slots` are the compute path's vertices that carry deformation residuals.
    pub fn work(
        &self,
        mode: Temporal,
        read_motion: bool,
        vertex_slots: u64,
    ) -> GpuResult<Option<TemporalWork>> {
        let accumulate = mode == Temporal::Taa;
        if !accumulate && !read_motion {
            return Ok(None);
        }
        if self.pass.is_none() {
            return Err(GpuError::Unsupported(format!(
                "{}: motion vectors and temporal accumulation need shaderInt64 and 64-bit buffer atomics",
                self.device
            )));
        }
        Ok(Some(TemporalWork {
            accumulate,
            vertex_slots,
        }))
    }

    /// Make the history buffers for `size` when `work` accumulates; returns the old ones to
    /// retire with the frame.
    pub fn prepare(
        &mut self,
        ctx: &Arc<Context>,
        work: Option<TemporalWork>,
        size: (u32, u32),
    ) -> GpuResult<Option<[Buffer; 2]>> {
        match work.is_some_and(|t| t.accumulate) {
            true => self.state.ensure_history(ctx, size),
            false => Ok(None),
        }
    }

    /// The camera block's temporal fields for `work` (the view-projection jittered when
    /// accumulating), and the frame's motion matrices.
    pub fn write_block(
        &self,
        block: &mut FrameBlock,
        work: Option<TemporalWork>,
        size: (u32, u32),
    ) -> FrameMotion {
        let view_proj = Mat4::from_cols_array_2d(&block.unjittered_view_proj);
        let motion = FrameMotion::new(view_proj, self.state.previous(size));
        let Some(work) = work else {
            return motion;
        };
        let jitter = match work.accumulate {
            true => self.state.jitter(),
            false => Vec2::ZERO,
        };
        let valid = work.accumulate && self.state.history_valid(size);
        let tuning = TemporalTuning::default();
        block.view_proj = jittered(view_proj, jitter, size).to_cols_array_2d();
        let residuals = work.vertex_slots > 0;
        block.temporal = crate::render::core::shared::TemporalFields {
            motion: 1,
            accumulate: work.accumulate as u32,
            history_valid: valid as u32,
            residuals: residuals as u32,
            jitter: jitter.to_array(),
            history_weight: tuning.current_weight,
            hair_clamp: tuning.hair_clamp,
        };
        block.clip_to_prev = motion.camera().to_cols_array_2d();
        motion
    }

    /// The history buffers as `(read, write)` this frame, once made.
    pub fn history(&self) -> Option<(&Buffer, &Buffer)> {
        self.state.history()
    }

    /// After a frame is submitted: its matrices become the next frame's previous ones, and
    /// with accumulation its history the next frame's to read.
    pub fn remember(&mut self, previous: PreviousFrame, work: Option<TemporalWork>) {
        self.state
            .advance(previous, work.is_some_and(|t| t.accumulate));
    }

    /// Add the pass that empties the visibility words (before any camera pass notes them).
    pub fn add_clear(g: &mut FrameGraph<'_>, visibility: Option<Res>) {
        TemporalPass::add_clear(g, visibility);
    }

    /// Add the motion pass and, with accumulation, the accumulation around it (after every
    /// camera pass).
    pub fn add<'a>(&'a self, g: &mut FrameGraph<'a>, inputs: Option<TemporalInputs<'a>>) {
        if let (Some(pass), Some(inputs)) = (&self.pass, inputs) {
            pass.add(g, inputs);
        }
    }
}

/// What a frame leaves for the next one's motion.
#[derive(Clone, Debug)]
pub struct PreviousFrame {
    /// Unjittered world to clip.
    pub view_proj: Mat4,
    /// Model of each character slot (`None`: empty or hidden).
    pub models: Vec<Option<Mat4>>,
    /// Target size.
    pub size: (u32, u32),
}

impl TemporalState {
    /// Forget the history and the previous frame (a cut: the next frame starts afresh).
    pub fn reset(&mut self) {
        self.prev = None;
        self.valid = false;
        self.index = 0;
    }

    /// The previous frame, when there is one of the same target size.
    pub fn previous(&self, size: (u32, u32)) -> Option<&PreviousFrame> {
        self.prev.as_ref().filter(|p| p.size == size)
    }

    /// This frame's jitter (pixels) with accumulation on.
    pub fn jitter(&self) -> Vec2 {
        jitter(self.index)
    }

    /// Whether the history holds an accumulated frame of `size` to blend with.
    pub fn history_valid(&self, size: (u32, u32)) -> bool {
        self.valid && self.history.as_ref().is_some_and(|h| h.1 == size)
    }

    /// Make the history buffers for `size` (new ones start invalid); returns the replaced
    /// ones, which frames in flight may still use.
    pub fn ensure_history(
        &mut self,
        ctx: &Arc<Context>,
        size: (u32, u32),
    ) -> GpuResult<Option<[Buffer; 2]>> {
        if self.history.as_ref().is_some_and(|h| h.1 == size) {
            return Ok(None);
        }
        let bytes = size.0 as u64 * size.1 as u64 * HISTORY_TEXEL;
        let make = |name| {
            Buffer::new(
                ctx,
                &BufferDesc::new(name, bytes, vk::BufferUsageFlags::STORAGE_BUFFER),
            )
        };
        let fresh = [make("temporal history a")?, make("temporal history b")?];
        self.valid = false;
        self.index = 0;
        Ok(self.history.replace((fresh, size)).map(|h| h.0))
    }

    /// The history buffers as `(read, write)` this frame, once made.
    pub fn history(&self) -> Option<(&Buffer, &Buffer)> {
        self.history
            .as_ref()
            .map(|(h, _)| (&h[1 - self.parity], &h[self.parity]))
    }

    /// After a frame is recorded: remember its matrices; with accumulation, the history it
    /// wrote becomes the next frame's to read.
    pub fn advance(&mut self, prev: PreviousFrame, accumulated: bool) {
        self.prev = Some(prev);
        if accumulated {
            self.parity = 1 - self.parity;
            self.valid = true;
            self.index += 1;
        } else {
            self.valid = false;
            self.index = 0;
        }
    }
}

/// The motion matrices of a frame: the camera's `clip_to_prev`, and what a character's adds.
#[derive(Clone, Debug)]
pub struct FrameMotion {
    /// This frame's unjittered view-projection.
    pub view_proj: Mat4,
    /// Its inverse (computed once: every character's `clip_to_prev` ends with it).
    view_proj_inverse: Mat4,
    /// The previous frame's (this frame's where there is none: no motion).
    pub prev_view_proj: Mat4,
    /// The previous frame's model of each character slot.
    pub prev_models: Vec<Option<Mat4>>,
}

impl FrameMotion {
    /// The motion of this frame seen from `view_proj` (unjittered), after `prev`.
    pub fn new(view_proj: Mat4, prev: Option<&PreviousFrame>) -> Self {
        FrameMotion {
            view_proj,
            view_proj_inverse: view_proj.inverse(),
            prev_view_proj: prev.map_or(view_proj, |p| p.view_proj),
            prev_models: prev.map_or_else(Vec::new, |p| p.models.clone()),
        }
    }

    /// `clip_to_prev` of what did not move (the background, world props).
    pub fn camera(&self) -> Mat4 {
        self.prev_view_proj * self.view_proj_inverse
    }

    /// `clip_to_prev` of character slot `slot` at `model` now (the camera's where the slot
    /// had no model last frame): [`clip_to_prev`] with the inverse computed once.
    pub fn character(&self, slot: usize, model: Mat4) -> Mat4 {
        match self.prev_models.get(slot).copied().flatten() {
            Some(before) if model.determinant().abs() > 1e-20 => {
                self.prev_view_proj * before * model.inverse() * self.view_proj_inverse
            }
            _ => self.camera(),
        }
    }
}

/// What a frame's temporal passes do.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TemporalWork {
    /// Blend the reprojected history into the frame (else motion vectors only).
    pub accumulate: bool,
    /// Vertex pool slots whose deformation residuals the compute path writes (0 on the other
    /// paths: the mesh path hands them to its fragments, the stored strands have none).
    pub vertex_slots: u64,
}

/// The temporal passes' transient buffers of a `width x height` frame: visibility, motion,
/// the frame's colour, and the deformation residuals of the compute path's vertices and the
/// software rasterizer's `segments` (0 bytes where unused: no motion, no accumulation).
pub fn transient_buffers(
    work: Option<TemporalWork>,
    segments: u32,
    (w, h): (u32, u32),
) -> [TransientBuffer; 5] {
    let pixels = w as u64 * h as u64;
    let motion = work.is_some();
    let accumulate = work.is_some_and(|t| t.accumulate);
    let on = |bytes: u64, used: bool| if used { bytes * pixels } else { 0 };
    let residuals = |count: u64| if motion { 4 * count } else { 0 };
    const HISTORY: (&str, &str) = (
        "temporal accumulation's history",
        "lower --size, or use --temporal off",
    );
    [
        TransientBuffer::storage("visibility", on(8, motion), FrameBinding::Visibility as u32)
            .for_user(HISTORY.0, HISTORY.1),
        TransientBuffer::storage("motion", on(16, motion), FrameBinding::Motion as u32)
            .for_user(HISTORY.0, HISTORY.1),
        // The frame's colour, then the accumulated one.
        TransientBuffer::storage(
            "frame colour",
            on(8, accumulate),
            FrameBinding::FrameColor as u32,
        )
        .for_user(HISTORY.0, HISTORY.1),
        TransientBuffer::storage(
            "vertex motion",
            residuals(work.map_or(0, |t| t.vertex_slots)),
            FrameBinding::VertexMotion as u32,
        )
        .for_user(HISTORY.0, HISTORY.1),
        TransientBuffer::storage(
            "segment motion",
            residuals(segments as u64),
            FrameBinding::SegmentMotion as u32,
        )
        .for_user(HISTORY.0, HISTORY.1),
    ]
}

impl PixelMotion {
    /// Decode the GPU's `uvec4` (motion x, y bits, id, depth bits).
    pub fn from_words(w: [u32; 4]) -> Self {
        PixelMotion {
            motion: Vec2::new(f32::from_bits(w[0]), f32::from_bits(w[1])),
            id: w[2],
            depth: f32::from_bits(w[3]),
        }
    }

    /// Whether the nearest surface is a character's hair.
    pub fn is_hair(&self) -> bool {
        self.id != VISIBILITY_EMPTY && self.id & (VISIBILITY_PROP | VISIBILITY_SOLID) == 0
    }
}

/// Rec. 709 luminance of an sRGB-encoded RGBA8 pixel, linear.
pub fn luminance(rgba: &[u8]) -> f32 {
    let lin = |c: u8| {
        let c = c as f32 / 255.0;
        match c <= 0.04045 {
            true => c / 12.92,
            false => ((c + 0.055) / 1.055).powf(2.4),
        }
    };
    Vec3::new(lin(rgba[0]), lin(rgba[1]), lin(rgba[2])).dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// Luminance of `image` (RGBA8 sRGB, `width` wide) sampled bilinearly at `p` (pixels; centres
/// at half-integers), or `None` outside the image.
fn sample_luminance(image: &[u8], (width, height): (u32, u32), p: Vec2) -> Option<f32> {
    let q = p - 0.5;
    let (x0, y0) = (q.x.floor(), q.y.floor());
    if x0 < 0.0 || y0 < 0.0 || x0 + 1.0 >= width as f32 || y0 + 1.0 >= height as f32 {
        return None;
    }
    let (fx, fy) = (q.x - x0, q.y - y0);
    let at = |x: f32, y: f32| {
        let i = (y as usize * width as usize + x as usize) * 4;
        luminance(&image[i..i + 4])
    };
    let top = at(x0, y0) * (1.0 - fx) + at(x0 + 1.0, y0) * fx;
    let bottom = at(x0, y0 + 1.0) * (1.0 - fx) + at(x0 + 1.0, y0 + 1.0) * fx;
    Some(top * (1.0 - fy) + bottom * fy)
}

/// The flicker measure of one pair of frames: the mean absolute change of luminance over the
/// pixels `mask` selects (hair), after moving the previous frame's image along the current
/// frame's `motion` (bilinear), over pixels whose previous position is inside the image.
/// Returns `(mean change, pixels measured)`.
pub fn reprojected_change(
    previous: &[u8],
    current: &[u8],
    motion: &[PixelMotion],
    mask: &[bool],
    size: (u32, u32),
) -> (f64, usize) {
    let (mut sum, mut n) = (0.0f64, 0usize);
    for (i, m) in motion.iter().enumerate() {
        if !mask[i] {
            continue;
        }
        let centre = Vec2::new((i as u32 % size.0) as f32, (i as u32 / size.0) as f32) + 0.5;
        let Some(before) = sample_luminance(previous, size, centre - m.motion) else {
            continue;
        };
        sum += (luminance(&current[i * 4..i * 4 + 4]) - before).abs() as f64;
        n += 1;
    }
    (if n > 0 { sum / n as f64 } else { 0.0 }, n)
}

/// Box-filter an RGBA8 sRGB image of `size` down by `factor` per side (in linear light), the
/// supersampled reference's resolve.
pub fn downsample(rgba: &[u8], size: (u32, u32), factor: u32) -> Vec<u8> {
    let (w, h) = (size.0 / factor, size.1 / factor);
    let decode = |c: u8| {
        let c = c as f32 / 255.0;
        match c <= 0.04045 {
            true => c / 12.92,
            false => ((c + 0.055) / 1.055).powf(2.4),
        }
    };
    let encode = |l: f32| {
        let c = match l <= 0.0031308 {
            true => l * 12.92,
            false => 1.055 * l.powf(1.0 / 2.4) - 0.055,
        };
        (c.clamp(0.0, 1.0) * 255.0).round() as u8
    };
    let mut out = vec![0u8; (w * h * 4) as usize];
    let n = (factor * factor) as f32;
    for y in 0..h {
        for x in 0..w {
            let mut acc = [0.0f32; 4];
            for sy in 0..factor {
                for sx in 0..factor {
                    let i = (((y * factor + sy) * size.0 + x * factor + sx) * 4) as usize;
                    for c in 0..3 {
                        acc[c] += decode(rgba[i + c]);
                    }
                    acc[3] += rgba[i + 3] as f32 / 255.0;
                }
            }
            let o = ((y * w + x) * 4) as usize;
            for c in 0..3 {
                out[o + c] = encode(acc[c] / n);
            }
            out[o + 3] = (acc[3] / n * 255.0).round() as u8;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bilinear sampling weighs the four pixels around the point by their distances, pixel
    /// centres at half-integers, and gives `None` where a neighbour is outside the image.
    #[test]
    fn luminance_is_sampled_bilinearly_between_pixel_centres() {
        let (w, h) = (4u32, 3u32);
        let grey = |x: u32, y: u32| (40 * x + 10 * y) as u8;
        let image: Vec<u8> = (0..h)
            .flat_map(|y| (0..w).flat_map(move |x| [grey(x, y), grey(x, y), grey(x, y), 255]))
            .collect();
        let lum = |x: u32, y: u32| luminance(&[grey(x, y), grey(x, y), grey(x, y), 255]);
        let (fx, fy) = (0.25, 0.5);
        let want = (lum(1, 1) * (1.0 - fx) + lum(2, 1) * fx) * (1.0 - fy)
            + (lum(1, 2) * (1.0 - fx) + lum(2, 2) * fx) * fy;
        let got = sample_luminance(&image, (w, h), Vec2::new(1.5 + fx, 1.5 + fy)).unwrap();
        assert!((got - want).abs() < 1e-6, "{got} vs {want}");
        assert!(sample_luminance(&image, (w, h), Vec2::new(0.2, 1.5)).is_none());
        assert!(sample_luminance(&image, (w, h), Vec2::new(3.7, 1.5)).is_none());
    }

    #[test]
    fn visibility_words_order_by_depth_and_round_trip() {
        let word = |depth: f32, id: u32, r: Vec2| VisibilityWord {
            depth,
            id,
            residual: r,
        };
        let cases = [
            word(0.25, 7, Vec2::new(3.5, -1.25)),
            word(0.999, VISIBILITY_SOLID | 65535, Vec2::ZERO),
            word(1.0, VISIBILITY_PROP | 3, Vec2::new(-128.0, 127.875)),
        ];
        for w in cases {
            let back = VisibilityWord::unpack(w.pack());
            assert_eq!(back.id, w.id);
            assert_eq!(back.residual, w.residual);
            assert!(
                (back.depth - w.depth).abs() <= w.depth * 2f32.powi(-16),
                "{back:?}"
            );
        }
        // Nearer wins whatever the id and residual; residuals past the range clamp.
        let far = word(0.5001, 0, Vec2::splat(-200.0));
        let near = word(0.5, VISIBILITY_PROP | 65535, Vec2::splat(200.0));
        assert!(near.pack() < far.pack());
        assert_eq!(
            VisibilityWord::unpack(far.pack()).residual,
            Vec2::splat(-128.0)
        );
        let empty = VisibilityWord::unpack(u64::MAX);
        assert_eq!((empty.id, empty.depth), (VISIBILITY_EMPTY, 1.0));
        assert!(word(1.0, VISIBILITY_PROP | 65535, Vec2::splat(127.0)).pack() < u64::MAX);
    }

    #[test]
    fn jitter_covers_the_pixel_in_eight_frames() {
        let points: Vec<Vec2> = (0..8).map(jitter).collect();
        assert!(points.iter().all(|p| p.abs().max_element() < 0.5));
        let mean = points.iter().sum::<Vec2>() / 8.0;
        assert!(mean.length() < 0.1, "mean {mean}");
        assert_eq!(jitter(3), jitter(11));
        for (i, a) in points.iter().enumerate() {
            for b in &points[i + 1..] {
                assert!(a.distance(*b) > 0.1);
            }
        }
    }

    /// A perspective camera at `eye` looking at the origin (45 degrees, Vulkan depth 0..1, y
    /// down, as the renderer's): the maths below holds for any projection.
    fn perspective_at(eye: Vec3, aspect: f32) -> Mat4 {
        let f = (-eye).normalize();
        let s = f.cross(Vec3::Y).normalize();
        let u = s.cross(f);
        let view = Mat4::from_cols(
            Vec4::new(s.x, u.x, -f.x, 0.0),
            Vec4::new(s.y, u.y, -f.y, 0.0),
            Vec4::new(s.z, u.z, -f.z, 0.0),
            Vec4::new(-s.dot(eye), -u.dot(eye), f.dot(eye), 1.0),
        );
        let (g, n, far) = (1.0 / 22.5f32.to_radians().tan(), 0.05, 100.0);
        let proj = Mat4::from_cols(
            Vec4::new(g / aspect, 0.0, 0.0, 0.0),
            Vec4::new(0.0, -g, 0.0, 0.0),
            Vec4::new(0.0, 0.0, far / (n - far), -1.0),
            Vec4::new(0.0, 0.0, n * far / (n - far), 0.0),
        );
        proj * view
    }

    #[test]
    fn motion_of_a_camera_move_is_the_projected_difference() {
        let size = Vec2::new(320.0, 180.0);
        let view = |eye: Vec3| perspective_at(eye, size.x / size.y);
        let (before, now) = (
            view(Vec3::new(0.1, 0.0, 3.0)),
            view(Vec3::new(0.0, 0.0, 3.0)),
        );
        let point = Vec3::new(0.3, -0.2, 0.1);
        let project = |vp: Mat4| {
            let c = vp * point.extend(1.0);
            let ndc = c / c.w;
            ((Vec2::new(ndc.x, ndc.y) + 1.0) * 0.5 * size, ndc.z)
        };
        let ((p_now, depth), (p_before, _)) = (project(now), project(before));
        let m = motion_at(
            clip_to_prev(before, Mat4::IDENTITY, now),
            p_now,
            depth,
            size,
        );
        assert!(
            (m - (p_now - p_before)).length() < 1e-3,
            "{m} vs {}",
            p_now - p_before
        );
        // A character that moved with the camera (fixed in its clip space: its previous model
        // times the inverse of its current one is `before^-1 now`) stays put on screen,
        // through `clip_to_prev` and through `FrameMotion::character` alike.
        let with_camera = before.inverse() * now;
        let m = motion_at(clip_to_prev(before, with_camera, now), p_now, depth, size);
        assert!(m.length() < 1e-3, "{m}");
        let frame = FrameMotion {
            view_proj: now,
            view_proj_inverse: now.inverse(),
            prev_view_proj: before,
            prev_models: vec![Some(with_camera)],
        };
        let m = motion_at(frame.character(0, Mat4::IDENTITY), p_now, depth, size);
        assert!(m.length() < 1e-3, "{m}");
        // One that stood still moves by the camera's motion (0.2 px here, 200 times the bound
        // above).
        let m = motion_at(frame.camera(), p_now, depth, size);
        assert!(
            (m - (p_now - p_before)).length() < 1e-3 && m.length() > 0.1,
            "{m}"
        );
    }

    #[test]
    fn jittered_projection_moves_every_point_by_the_jitter() {
        let size = (200u32, 100u32);
        let vp = perspective_at(Vec3::new(0.0, 0.0, 3.0), 2.0);
        let j = jittered(vp, Vec2::new(0.25, -0.5), size);
        for p in [Vec3::new(0.0, 0.0, -1.0), Vec3::new(0.5, 0.3, -4.0)] {
            let a = vp * p.extend(1.0);
            let b = j * p.extend(1.0);
            let d = (Vec2::new(b.x, b.y) / b.w - Vec2::new(a.x, a.y) / a.w) * 0.5;
            let px = d * Vec2::new(size.0 as f32, size.1 as f32);
            assert!((px - Vec2::new(0.25, -0.5)).length() < 1e-4, "{px}");
        }
    }

    #[test]
    fn reprojected_change_is_zero_for_a_moved_image_and_not_without_motion() {
        let size = (16u32, 8u32);
        let image = |shift: u32| {
            let mut v = vec![0u8; 16 * 8 * 4];
            for y in 0..8 {
                for x in 0..16u32 {
                    let i = ((y * 16 + x) * 4) as usize;
                    let g = (((x + 16 - shift) % 16) * 16) as u8;
                    v[i..i + 4].copy_from_slice(&[g, g, g, 255]);
                }
            }
            v
        };
        let (before, now) = (image(0), image(2));
        let mask = vec![true; 128];
        let moved = PixelMotion {
            motion: Vec2::new(2.0, 0.0),
            ..Default::default()
        };
        let (c, n) = reprojected_change(&before, &now, &[moved; 128], &mask, size);
        assert!(n > 0 && c < 1e-6, "{c}");
        let still = PixelMotion::default();
        let (c0, _) = reprojected_change(&before, &now, &[still; 128], &mask, size);
        assert!(c0 > 0.01, "{c0}");
    }

    /// Luminance is Rec. 709's weighting of the linear channels, through the sRGB toe below
    /// 0.04045 and the power curve above it.
    #[test]
    fn luminance_weighs_linear_channels() {
        let lum = |rgb: [u8; 3]| luminance(&[rgb[0], rgb[1], rgb[2], 255]);
        assert!((lum([255, 0, 0]) - 0.2126).abs() < 1e-6);
        assert!((lum([0, 255, 0]) - 0.7152).abs() < 1e-6);
        assert!((lum([0, 0, 255]) - 0.0722).abs() < 1e-6);
        assert!((lum([10, 10, 10]) - 10.0 / 255.0 / 12.92).abs() < 1e-6);
        assert!((lum([128, 128, 128]) - 0.215861).abs() < 1e-5);
    }

    /// The flicker measure is the mean change over the masked pixels whose previous position
    /// has its four neighbours in the image (without motion: all but the last column and row),
    /// and 0 over no pixels; a point above or below the image samples nothing.
    #[test]
    fn reprojected_change_is_the_mean_over_measured_pixels() {
        let size = (5u32, 4u32);
        let grey = |g: u8| [g, g, g, 255].repeat(20);
        let (before, now) = (grey(100), grey(150));
        let mut mask = vec![false; 20];
        // Pixel 4 ends the first row, 19 is the last: not measured.
        for i in [0, 1, 4, 6, 19] {
            mask[i] = true;
        }
        let still = [PixelMotion::default(); 20];
        let (c, n) = reprojected_change(&before, &now, &still, &mask, size);
        let want = luminance(&[150, 150, 150, 255]) - luminance(&[100, 100, 100, 255]);
        assert_eq!(n, 3);
        assert!((c - want as f64).abs() < 1e-6, "{c} vs {want}");
        let none = reprojected_change(&before, &now, &still, &[false; 20], size);
        assert_eq!(none, (0.0, 0));
        assert!(sample_luminance(&now, size, Vec2::new(2.5, 0.2)).is_none());
        assert!(sample_luminance(&now, size, Vec2::new(2.5, 3.7)).is_none());
        assert!(sample_luminance(&now, size, Vec2::new(2.5, 3.4)).is_some());
    }

    /// Only a character's hair counts as hair: not a prop's or a solid's pixel, nor an empty
    /// one (a survivor of the fourth mutation sample joined the two tests with `||`, which
    /// took every prop for hair).
    #[test]
    fn hair_pixels_are_characters_not_props_or_solids() {
        let with = |id: u32| PixelMotion {
            id,
            ..Default::default()
        };
        assert!(with(5).is_hair());
        assert!(!with(VISIBILITY_PROP | 3).is_hair());
        assert!(!with(VISIBILITY_SOLID | 1).is_hair());
        assert!(!with(VISIBILITY_EMPTY).is_hair());
    }

    #[test]
    fn downsample_averages_in_linear_light() {
        let px = [
            255u8, 255, 255, 255, 0, 0, 0, 255, 255, 255, 255, 255, 0, 0, 0, 255,
        ];
        let out = downsample(&px, (2, 2), 2);
        // Half white in linear light is sRGB 188.
        assert_eq!(out[0], 188);
        assert_eq!(out[3], 255);
        // Two blocks side by side (4x2 -> 2x1): the left half white, the right black with one
        // of its four pixels clear (alpha 0.75). Each output pixel reads its own block, and alpha is averaged (the
        // column offset divided and the mean multiplied survived the 2026-12-06 sample).
        let (white, black, clear) = ([255u8, 255, 255, 255], [0u8, 0, 0, 255], [0u8, 0, 0, 0]);
        let row = |right: [u8; 4]| [white, black, black, right].concat();
        let px = [row(clear), row(black)].concat();
        let out = downsample(&px, (4, 2), 2);
        assert_eq!(out, vec![188, 188, 188, 255, 0, 0, 0, 191]);
        // Two blocks stacked (2x4 -> 1x2): each output row reads its own block's rows (the row
        // offset divided survived the third sample).
        let px = [white, white, white, white, black, black, black, black].concat();
        let out = downsample(&px, (2, 4), 2);
        assert_eq!(out, vec![255, 255, 255, 255, 0, 0, 0, 255]);
    }
}
