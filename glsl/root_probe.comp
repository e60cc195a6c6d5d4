#version 460
// Root probe: the root of every bundle's first strand, placed in the world as the mesh and
// compute paths place it (strand_eval.glsl `strand_info`, `strand_vertex` with k = 0, the
// character record's model: the same functions, this frame's textures and records), written
// for the host, w = character slot + 1. One workgroup of one invocation per crowd bundle, so
// the texture index is uniform in the workgroup (bindings.glsl reads the w, u and v textures
// with a uniform index; a workgroup spanning characters read another character's); push
// constant x is the bundle count. The root-gap measure compares these with the scalp as the skinning pass
// draws it.
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
layout(local_size_x = 1) in;
#include "common.glsl"
#include "strand_eval.glsl"

layout(set = SET_FRAME, binding = BINDING_ROOT_PROBE, std430) writeonly buffer RootProbe { vec4 root_probe[]; };

void main() {
    uint bundle = gl_WorkGroupID.y * DISPATCH_ROW + gl_WorkGroupID.x;
    if (bundle >= push.params.x) {
        return;
    }
    uint character = bundles[bundle].character;
    bind_character(character);
    StrandInfo si = strand_info(bundle, 0u);
    vec3 root = (model * vec4(strand_vertex(si, 0u, 1u), 1.0)).xyz;
    root_probe[bundle] = vec4(root, float(character + 1u));
}
