#version 460
// Opaque strands (Transparency::Opaque). With MSAA, alpha is the strand's pixel coverage and
// the pipeline turns it into a sample mask (alpha to coverage; colour alpha is not written),
// so strands thinner than a pixel keep their width.
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
#include "strand_fragment.glsl"

layout(location = 0) out vec4 out_color;

void main() {
    out_color = vec4(shade_strand(), clamp(in_coverage, 0.0, 1.0));
}
