// Descriptor set 0 of every hair pass (src/render/hair_resources.rs creates it).
// Binding numbers are shared by the compute path, the mesh path and the draw.
#ifndef BINDINGS_GLSL
#define BINDINGS_GLSL
#include "hair_types.glsl"

// src/render/frame.rs: FrameParams
layout(set = 0, binding = 0, std140) uniform Frame {
    mat4 view_proj;
    vec4 camera_pos;      // xyz, w: vertical resolution in pixels
    vec4 light_dir;       // xyz towards the light, w: 1 / tan(fov_y / 2) (0: orthographic)
    vec4 viewport;        // width, height, 1/width, 1/height
    uvec4 params;         // x: strands per bundle N, y: full vertex level e (2^e segments), z: bundle count, w: LoD on
    vec4 planes[6];       // frustum planes (xyz normal, w offset), inside when dot >= 0
    vec4 lod;             // x: alpha strands, y: alpha vertices, z: lambda, w: tan(fov_y) (0: orthographic, see lod_ortho)
    vec4 lod_ortho;       // x: view height for orthographic views (eq. 7 orthographic form), yzw unused
} frame;

layout(set = 0, binding = 1, std430) readonly buffer MeshBuf {
    MeshInfo mesh;
    HairStyle style;
};
layout(set = 0, binding = 2, std430) readonly buffer Bundles { BundleDesc bundles[]; };
layout(set = 0, binding = 3) uniform sampler3D tex_position;
layout(set = 0, binding = 4) uniform sampler2D tex_uv;
layout(set = 0, binding = 5) uniform sampler3D tex_w;
layout(set = 0, binding = 6) uniform sampler3D tex_u;
layout(set = 0, binding = 7) uniform sampler3D tex_v;
// Root samples: [0, 4096) quad set, [4096, 8192) triangle set.
layout(set = 0, binding = 8, std430) readonly buffer RootSamples { vec2 root_samples[]; };

// Per-bundle LoD decision (x: strands, y: vertex level e, z: gamma bits, w: thickness bits) and
// exclusive prefix sums (x: first strand, y: first vertex slot, z: first draw vertex,
// w: first compute workgroup).
layout(set = 0, binding = 9, std430) buffer Counts { uvec4 bundle_lods[]; };
layout(set = 0, binding = 10, std430) buffer Offsets { uvec4 bundle_offsets[]; };
// Indirect arguments: VkDispatchIndirectCommand then VkDrawIndirectCommand.
layout(set = 0, binding = 11, std430) buffer Indirect {
    uint dispatch_x;
    uint dispatch_y;
    uint dispatch_z;
    uint total_strands;
    uint draw_vertex_count;
    uint draw_instance_count;
    uint draw_first_vertex;
    uint draw_first_instance;
    uint total_triangles;   // strand triangles generated (both paths)
    uint total_vertex_slots;
    uint total_groups;      // compute path: strand-building workgroups
    uint pad1;
} indirect;

// Generated strand vertices (compute path): position + width, tangent + s.
struct HairVertex {
    vec4 pos_width;
    vec4 tangent_s;
};
layout(set = 0, binding = 12, std430) buffer Vertices { HairVertex hair_vertices[]; };

// Object-to-world transform of the character being drawn.
layout(push_constant) uniform Push {
    mat4 model;
} push;

// Largest dispatch size per dimension we rely on (Vulkan guarantees 65535).
#define DISPATCH_ROW 65535u

#endif
