#version 460
// Linear blend skinning of this frame's skinned prop instances (src/skin/mod.rs `skin_vertex`
// is the CPU twin): v' = sum_i w_i M_i v with M_i = G_i B_i^-1, the joint's global transform
// times its inverse bind matrix (glTF 2.0 section 3.7.3); the normal by the blended matrix's
// upper 3x3, renormalized. One invocation per posed vertex: workgroup row y is a job, x runs
// over its vertices; push constant x is the first job of this dispatch.
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
layout(local_size_x = SKIN_GROUP_SIZE) in;

layout(set = SET_FRAME, binding = BINDING_SKIN_REST, std430) readonly buffer Rest { SkinRestVertex skin_rest[]; };
layout(set = SET_FRAME, binding = BINDING_SKIN_MATRICES, std430) readonly buffer Matrices { mat4 skin_matrices[]; };
layout(set = SET_FRAME, binding = BINDING_SKIN_JOBS, std430) readonly buffer Jobs { SkinJob skin_jobs[]; };
layout(set = SET_FRAME, binding = BINDING_SKINNED_VERTICES, std430) writeonly buffer Posed { SkinnedVertex skinned[]; };

void main() {
    SkinJob job = skin_jobs[push.params.x + gl_WorkGroupID.y];
    uint k = gl_GlobalInvocationID.x;
    if (k >= job.vertex_count) {
        return;
    }
    SkinRestVertex v = skin_rest[job.rest_first + k];
    uint joints[4] = uint[4](v.joints01 & 0xffffu, v.joints01 >> 16, v.joints23.x & 0xffffu, v.joints23.x >> 16);
    mat4 m = mat4(0.0);
    for (int i = 0; i < 4; i++) {
        if (v.weights[i] != 0.0) {
            m += skin_matrices[job.matrix_first + joints[i]] * v.weights[i];
        }
    }
    vec3 n = (m * vec4(v.normal, 0.0)).xyz;
    float len = length(n);
    SkinnedVertex o;
    o.position = (m * vec4(v.position, 1.0)).xyz;
    o.color = v.color;
    o.normal = len > 0.0 ? n / len : v.normal;
    o.pad = 0u;
    skinned[job.out_first + k] = o;
}
