#version 460
// A host frame's depth in the renderer's terms (render/host.rs, DepthMapping::convert is the
// CPU twin): the host's stored depth d back to view-space z through its projection's depth
// row, d = (a z + b) / (c z + e), then forward through ours. The host's background (no finite
// point in front of the camera) is our far plane. Clears the colour to transparent: the hair
// is drawn premultiplied over nothing and composited over the host's colour afterwards.

layout(set = 0, binding = 0) uniform sampler2D host_depth;

layout(push_constant) uniform DepthRows {
    vec4 host; // a, b, c, e of the host's projection (right-handed view space)
    vec4 ours; // the same of the renderer's
} rows;

layout(location = 0) out vec4 out_color;

void main() {
    float d = texelFetch(host_depth, ivec2(gl_FragCoord.xy), 0).r;
    vec4 h = rows.host;
    float den = d * h.z - h.x;
    float z = (h.y - d * h.w) / den;
    float ours = 1.0;
    if (abs(den) > 1.17549435e-38 && !isinf(z) && !isnan(z) && z < 0.0) {
        vec4 o = rows.ours;
        ours = clamp((o.x * z + o.y) / (o.z * z + o.w), 0.0, 1.0);
    }
    gl_FragDepth = ours;
    out_color = vec4(0.0);
}
