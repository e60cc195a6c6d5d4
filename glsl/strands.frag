#version 460
// Opaque strands (Transparency::Opaque): strips at least one pixel wide, written with depth;
// MSAA smooths their edges. Coverage to alpha (thin strands keep their true width) needs
// blending in depth order: the transparent modes (oit.frag, peel_color.frag) use it. (A
// dithered sample mask from coverage was tried here: at 4 samples the hair turns to noise.)
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
#include "strand_fragment.glsl"
#include "temporal.glsl"

layout(location = 0) out vec4 out_color;

void main() {
    note_fragment(in_character, in_residual);
    out_color = vec4(shade_strand(), 1.0);
}
