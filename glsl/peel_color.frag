#version 460
// Depth peeling, second pass of a layer: the fragment at the layer's depth (depth test EQUAL)
// is composited under the layers in front of it: C += (1 - A) c a, A += (1 - A) a.
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
#include "strand_fragment.glsl"
#include "peel.glsl"
#include "temporal.glsl"

layout(early_fragment_tests) in;

void main() {
    note_fragment(in_character, in_residual);
    uint p = peel_pixel();
    float a = strand_alpha();
    vec4 acc = peel_accum[p];
    acc.rgb += (1.0 - acc.a) * a * shade_strand();
    acc.a += (1.0 - acc.a) * a;
    peel_accum[p] = acc;
}
