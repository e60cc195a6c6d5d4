#version 460
// Deep opacity maps, second light pass (Yuksel and Keyser 2008): each strand fragment adds its
// opacity (one strand's opacity times the fraction of the texel it covers, strip.glsl) to the
// layer its depth falls in, counted from the hair depth of the first light pass in steps of
// frame.shadow.layer_thickness. Additive blending sums the layers; the last one keeps everything
// further back. Lookups: shadow_lookup.glsl.
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
#include "lod_appearance.glsl"

// Only the hair depth: the layers are this pass's attachment.
layout(set = SET_FRAME, binding = BINDING_SHADOW_HAIR_DEPTH) uniform sampler2D shadow_hair_depth;

layout(location = 5) in float in_coverage;
layout(location = 6) flat in float in_thickness;
layout(location = 0) out vec4 out_layers;

void main() {
    float d0 = texelFetch(shadow_hair_depth, ivec2(gl_FragCoord.xy), 0).r;
    float dz = max(gl_FragCoord.z - d0, 0.0) * frame.shadow.depth_range;
    int layer = min(int(dz / frame.shadow.layer_thickness), 3);
    vec4 add = vec4(0.0);
    add[layer] = cluster_opacity(frame.shadow.strand_opacity * in_coverage, in_thickness);
    out_layers = add;
}
