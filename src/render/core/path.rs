//! The generation path a frame draws its strands with, which every feature reads.

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

impl std::str::FromStr for RenderPath {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "mesh" => Ok(RenderPath::Mesh),
            "compute" => Ok(RenderPath::Compute),
            "static" => Ok(RenderPath::Static),
            "lhs" => Ok(RenderPath::Lhs),
            _ => Err(format!("path {s:?}: mesh, compute, static or lhs")),
        }
    }
}

impl std::fmt::Display for RenderPath {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str(match self {
            RenderPath::Mesh => "mesh",
            RenderPath::Compute => "compute",
            RenderPath::Static => "static",
            RenderPath::Lhs => "lhs",
        })
    }
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
