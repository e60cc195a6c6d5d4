#version 460
// Compute path, pass 1a: one invocation per bundle. Frustum-cull the bundle's bounding box
// (convex hull of its Bezier control points, grown by the styling amplitudes) and decide its
// strand count (LoD at full detail here). Writes bundle_strands[].
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;
#include "bindings.glsl"
#include "common.glsl"
#include "strand_eval.glsl"

bool box_visible(vec3 lo, vec3 hi) {
    for (int p = 0; p < 6; p++) {
        vec4 pl = frame.planes[p];
        // Corner furthest along the plane normal.
        vec3 c = vec3(pl.x >= 0.0 ? hi.x : lo.x, pl.y >= 0.0 ? hi.y : lo.y, pl.z >= 0.0 ? hi.z : lo.z);
        if (dot(pl.xyz, c) + pl.w < 0.0) {
            return false;
        }
    }
    return true;
}

void main() {
    uint b = gl_GlobalInvocationID.x;
    if (b >= frame.params.z) {
        return;
    }
    BundleDesc desc = bundles[b];
    int depth = int(4u * (mesh.layers - 1u) + 1u);
    vec3 lo = vec3(1e30);
    vec3 hi = vec3(-1e30);
    for (int z = 0; z < depth; z++) {
        for (int c = 0; c < 4; c++) {
            ivec3 t = ivec3(ivec2(desc.origin) + ivec2(c & 1, c >> 1), z);
            vec3 p = (push.model * vec4(decode_position(texelFetch(tex_position, t, 0).xyz), 1.0)).xyz;
            lo = min(lo, p);
            hi = max(hi, p);
        }
    }
    float scale = length(push.model[0].xyz);
    float margin = scale * (style.curl_radius + style.wave_amplitude + style.frizz_amplitude + style.strand_width);
    bool visible = box_visible(lo - margin, hi + margin);
    uint n = frame.params.x;
    uint count = style.density_by_area != 0u ? uint(round(float(n) * desc.density)) : n;
    count = clamp(count, 1u, MAX_STRANDS_PER_BUNDLE);
    bundle_strands[b] = visible ? count : 0u;
}
