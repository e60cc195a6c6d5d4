// Depth peeling (Transparency::DepthPeeling, the slow reference, seed 004): per pixel the
// previous layer's depth (first half of peel_depth) and the opaque depth (second half), and
// the colour composited front to back so far (premultiplied rgb, opacity).
#ifndef PEEL_GLSL
#define PEEL_GLSL

layout(set = SET_FRAME, binding = BINDING_PEEL_DEPTH, std430) buffer PeelDepth { float peel_depth[]; };
layout(set = SET_FRAME, binding = BINDING_PEEL_ACCUM, std430) buffer PeelAccum { vec4 peel_accum[]; };

uint peel_pixel() {
    return uint(gl_FragCoord.y) * uint(frame.viewport.x) + uint(gl_FragCoord.x);
}

uint peel_pixels() {
    return uint(frame.viewport.x) * uint(frame.viewport.y);
}

#endif
