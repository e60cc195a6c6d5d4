#version 460
// K-buffer insert (Transparency::KBuffer): each strand fragment in front of the opaque depth
// (tested before this shader runs) walks the pixel's K nodes with atomicMin, carrying the
// larger value on; whatever falls off the end (the farthest so far) is merged into the tail.
// Concurrent inserts leave the K nearest fragments sorted, whatever their order. No colour
// output: the resolve (oit_resolve.frag) composites.
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
#include "strand_fragment.glsl"
#include "oit.glsl"
#include "temporal.glsl"

layout(early_fragment_tests) in;

void main() {
    // With MSAA a fragment runs for a pixel when the strip covers any of its samples: weigh
    // it by the samples it covers, so a strip adds the same opacity whatever the sample count.
    float a = strand_alpha() * float(bitCount(gl_SampleMaskIn[0])) / float(frame.transparency.samples);
    if (a < 0.5 / 255.0) {
        return;
    }
    note_fragment(in_character, in_residual);
    uint pixel = oit_pixel();
    uint k = frame.transparency.kbuffer_nodes;
    uint64_t v = (uint64_t(floatBitsToUint(gl_FragCoord.z)) << 32) | uint64_t(pack_fragment(shade_strand(), a));
    for (uint i = 0u; i < k; i++) {
        uint64_t old = atomicMin(oit_nodes[pixel * k + i], v);
        if (old == OIT_EMPTY) {
            return;
        }
        v = max(old, v);
    }
    vec4 f = unpack_fragment(uint(v & 0xFFFFFFFFul));
    float tau = optical_depth(f.a);
    uvec4 add = uvec4(round(vec4(f.rgb * tau, tau) * OIT_FIXED));
    atomicAdd(oit_tail[pixel].x, add.x);
    atomicAdd(oit_tail[pixel].y, add.y);
    atomicAdd(oit_tail[pixel].z, add.z);
    atomicAdd(oit_tail[pixel].w, add.w);
}
