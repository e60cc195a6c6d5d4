#version 460
// Depth peeling, first pass of a layer: the nearest strand fragment strictly behind the
// previous layer and in front of the opaque depth wins the depth test (depth only).
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
#include "peel.glsl"
#include "volume_shading.glsl"

// The strand's character (strands.vert, strands.mesh): pixels showing its density volume
// drop its strands (peel_color.frag drops the same ones).
layout(location = 4) flat in uint in_character;

void main() {
    uint p = peel_pixel();
    float z = gl_FragCoord.z;
    if (z <= peel_depth[p] || z >= peel_depth[peel_pixels() + p]) {
        discard;
    }
}
