// Inputs of every strand fragment shader (from strands.vert and strands.mesh): the opaque pass
// (strands.frag), k-buffer OIT (oit.frag) and depth peeling (peel_color.frag) shade with
// strand_radiance.glsl, as the software rasterizer does at strand vertices.
#ifndef STRAND_FRAGMENT_GLSL
#define STRAND_FRAGMENT_GLSL
#include "strand_radiance.glsl"
#include "lod_appearance.glsl"

layout(location = 0) in vec3 in_tangent;
layout(location = 1) in float in_s;
layout(location = 2) in vec3 in_pos;
layout(location = 3) flat in vec3 in_color;
layout(location = 4) flat in uint in_character;
// Fraction of the drawn (at least one pixel wide) strip the strand covers (strip.glsl).
layout(location = 5) in float in_coverage;
// Strands this strip stands for under strand LoD (sec. 3.6.1 width factor; 1 at full detail).
layout(location = 6) flat in float in_thickness;
// Deformation residual of the strand here (temporal.glsl), pixels.
layout(location = 7) in vec2 in_residual;

// Radiance toward the eye of this fragment's strand.
vec3 shade_strand() {
    return strand_radiance(in_tangent, in_s, in_pos, in_color, in_character, in_thickness);
}

// Opacity of this fragment over its pixel: one strand's opacity times the fraction of the
// pixel it covers (coverage to alpha, seed 002), aggregated under LoD (lod_appearance.glsl).
float strand_alpha() {
    return cluster_opacity(STRAND_OPACITY * clamp(in_coverage, 0.0, 1.0), in_thickness);
}

#endif
