#version 460
// Compute path, pass 2: one workgroup of S threads per strand, each thread computing
// n = segments / S vertices (paper 003 sec. 3.2), then tangents by eq. 5-6 (sec. 3.5).
#extension GL_GOOGLE_include_directive : require
#define S 32u
#define MAX_SEGMENTS 256u
layout(local_size_x = 32) in;
#include "bindings.glsl"
#include "common.glsl"
#include "strand_eval.glsl"

shared vec3 p[MAX_SEGMENTS + 1u];

// Bundle owning global strand `g`: last bundle whose offset is <= g (offsets ascending).
uint find_bundle(uint g) {
    uint lo = 0u;
    uint hi = frame.params.z - 1u;
    while (lo < hi) {
        uint mid = (lo + hi + 1u) / 2u;
        if (bundle_offsets[mid] <= g) {
            lo = mid;
        } else {
            hi = mid - 1u;
        }
    }
    // The last bundle starting at or before g is never an empty (culled) one for g < total.
    return lo;
}

void main() {
    uint g = gl_WorkGroupID.y * DISPATCH_ROW + gl_WorkGroupID.x;
    if (g >= indirect.total_strands) {
        return;
    }
    uint segments = 1u << frame.params.y;
    uint bundle = find_bundle(g);
    uint strand = g - bundle_offsets[bundle];
    StrandInfo si = strand_info(bundle, strand);
    uint t = gl_LocalInvocationID.x;
    uint n = max(segments / S, 1u);
    for (uint i = 0u; i < n; i++) {
        uint k = t * n + i + 1u;
        if (k <= segments) {
            p[k] = (push.model * vec4(strand_vertex(si, k, segments), 1.0)).xyz;
        }
    }
    if (t == 0u) {
        p[0] = (push.model * vec4(strand_vertex(si, 0u, segments), 1.0)).xyz;
    }
    barrier();
    float scale = length(push.model[0].xyz);
    uint base = g * (segments + 1u);
    for (uint k = t; k <= segments; k += S) {
        vec3 tangent;
        if (k > 0u && k < segments) {
            tangent = safe_normalize(p[k + 1u] - p[k - 1u], vec3(0.0, 1.0, 0.0));
        } else if (segments == 1u) {
            tangent = safe_normalize(p[1] - p[0], vec3(0.0, 1.0, 0.0));
        } else {
            // Eq. 5 (tip) and eq. 6 (root): mirror the neighbour tangent about the end segment.
            uint inner = k == 0u ? 1u : segments - 1u;
            vec3 ti = safe_normalize(p[inner + 1u] - p[inner - 1u], vec3(0.0, 1.0, 0.0));
            vec3 q = k == 0u ? safe_normalize(p[1] - p[0], ti) : safe_normalize(p[segments] - p[segments - 1u], ti);
            tangent = safe_normalize(2.0 * q * dot(ti, q) - ti, q);
        }
        float s = float(k) / float(segments);
        hair_vertices[base + k].pos_width = vec4(p[k], scale * strand_width_at(s));
        hair_vertices[base + k].tangent_s = vec4(tangent, s);
    }
}
