//! Renderer and frame settings.

/// Which generation path draws the strands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RenderPath {
    /// Task + mesh shaders (VK_EXT_mesh_shader).
    Mesh,
    /// Compute generation + vertex pulling.
    Compute,
    /// Static strands, the raster limit: draw the strands the last compute-path frame
    /// generated again (world space, as they were), with no culling, LoD or generation. Valid
    /// until the crowd changes (characters added, removed, moved, restyled or reposed).
    Static,
    /// Linear hair skinning, the paper's baseline: the static strands moved each frame by
    /// their guides (`Renderer::capture_lhs`, `Renderer::set_lhs_guides`), then drawn.
    Lhs,
}

impl RenderPath {
    /// Whether strands are drawn from the vertex pool (compute and static paths).
    pub fn pulls_vertices(self) -> bool {
        matches!(
            self,
            RenderPath::Compute | RenderPath::Static | RenderPath::Lhs
        )
    }
}

/// How to create a [`Renderer`].
#[derive(Clone, Debug)]
pub struct RendererDesc {
    /// Default path; `None` picks mesh where available, else compute.
    pub path: Option<RenderPath>,
    /// Size of the compute path's generated-vertex pool in bytes (<= the device's
    /// `maxStorageBufferRange`). Frames that need more keep whole strands up to it.
    pub vertex_pool_bytes: u64,
    /// Bundles one task workgroup culls (1..=32).
    pub task_bundles: u32,
    /// Most characters at once (five bindless textures each).
    pub max_characters: u32,
    /// Initial target size.
    pub width: u32,
    /// Initial target size.
    pub height: u32,
    /// Samples per pixel (MSAA): 1, or a count the device supports for colour and depth.
    pub msaa: u32,
    /// Side of the square shadow maps in texels (16..=8192).
    pub shadow_resolution: u32,
    /// The software rasterizer's segment and tile-entry budgets (`None`: the most the
    /// device allows, `SoftBudget::for_range`).
    pub soft_budget: Option<super::soft::SoftBudget>,
    /// `StrandRaster::Auto`: bundles whose strands are drawn at most this many pixels wide
    /// go to the software rasterizer (finite, > 0).
    pub auto_split_pixels: f32,
}

impl Default for RendererDesc {
    fn default() -> Self {
        RendererDesc {
            path: None,
            vertex_pool_bytes: 96 << 20,
            task_bundles: super::shared::TASK_PAYLOAD_BUNDLES,
            max_characters: 1024,
            width: 1280,
            height: 720,
            msaa: 1,
            shadow_resolution: super::shadow::DEFAULT_SHADOW_RESOLUTION,
            soft_budget: None,
            auto_split_pixels: super::soft::AUTO_SPLIT_PIXELS,
        }
    }
}

impl RendererDesc {
    /// Set the most characters at once.
    pub fn max_characters(mut self, count: u32) -> Self {
        self.max_characters = count;
        self
    }

    /// Set the initial target size.
    pub fn size(mut self, width: u32, height: u32) -> Self {
        self.width = width;
        self.height = height;
        self
    }

    /// Set the default path.
    pub fn path(mut self, path: Option<RenderPath>) -> Self {
        self.path = path;
        self
    }

    /// Set the MSAA sample count.
    pub fn msaa(mut self, samples: u32) -> Self {
        self.msaa = samples;
        self
    }

    /// Set the shadow map resolution.
    pub fn shadow_resolution(mut self, texels: u32) -> Self {
        self.shadow_resolution = texels;
        self
    }

    /// Set the software rasterizer's budgets.
    pub fn soft_budget(mut self, budget: super::soft::SoftBudget) -> Self {
        self.soft_budget = Some(budget);
        self
    }

    /// Set the vertex pool size in bytes.
    pub fn vertex_pool_bytes(mut self, bytes: u64) -> Self {
        self.vertex_pool_bytes = bytes;
        self
    }
}

/// Per-frame choices.
#[derive(Clone, Copy, Debug)]
pub struct FrameOptions {
    /// Path for this frame (`None`: the renderer's default).
    pub path: Option<RenderPath>,
    /// Clear colour and depth first (else draw over the previous frame's contents).
    pub clear: bool,
    /// Read the colour target back into the report.
    pub read_image: bool,
    /// Hardware strips, the software rasterizer, or a split per bundle (mesh and compute
    /// paths).
    pub raster: super::soft::StrandRaster,
}

impl Default for FrameOptions {
    fn default() -> Self {
        FrameOptions {
            path: None,
            clear: true,
            read_image: false,
            raster: super::soft::StrandRaster::Hardware,
        }
    }
}

/// A submitted frame, to [`Renderer::wait`] for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameTicket(pub u64);
