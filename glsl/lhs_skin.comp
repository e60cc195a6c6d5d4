#version 460
// Linear hair skinning, the baseline of the paper's comparison (src/reference/lhs.rs is the
// CPU twin): every stored strand vertex moves by the weighted displacement of the same vertex
// of its 3 guides, written into the vertex pool the static path draws. One invocation per
// vertex; push constants: x strands, y vertices per strand.
#extension GL_GOOGLE_include_directive : require
#include "shared.glsl"
layout(local_size_x = LHS_GROUP_SIZE) in;

layout(set = 0, binding = LHS_REST, std430) readonly buffer Rest { HairVertex lhs_rest[]; };
layout(set = 0, binding = LHS_WEIGHTS, std430) readonly buffer Weights { LhsWeights lhs_weights[]; };
layout(set = 0, binding = LHS_GUIDE_DELTA, std430) readonly buffer GuideDelta { vec4 guide_delta[]; };
layout(set = 0, binding = LHS_OUT, std430) writeonly buffer Out { HairVertex skinned[]; };
layout(push_constant) uniform Push { uvec4 params; } push;

void main() {
    uint id = gl_GlobalInvocationID.y * DISPATCH_ROW * 64u + gl_GlobalInvocationID.x;
    uint verts = push.params.y;
    if (id >= push.params.x * verts) {
        return;
    }
    uint strand = id / verts;
    uint k = id - strand * verts;
    LhsWeights w = lhs_weights[strand];
    vec3 d = vec3(0.0);
    for (uint i = 0u; i < 3u; i++) {
        d += guide_delta[w.guides[i] * verts + k].xyz * w.weights[i];
    }
    HairVertex v = lhs_rest[id];
    v.pos_width.xyz += d;
    skinned[id] = v;
}
