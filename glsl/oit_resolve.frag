#version 460
// Composite the transparent strands over the opaque image: the K-buffer's sorted nodes front
// to back, then its tail as one layer behind them (frame.transparency.mode == 1), or the depth
// peeling accumulation (== 2, PEEL_RESOLVE). Output premultiplied (C, A), blended over:
// dst = C + dst (1 - A), coverage A + a_dst (1 - A) (an opaque image stays opaque; a host
// frame's transparent layer gains the strands' coverage).
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
// Compiled twice: with PEEL_RESOLVE for depth peeling (no 64-bit integers needed), without
// for the K-buffer.
#ifdef PEEL_RESOLVE
#include "peel.glsl"
#else
#include "oit.glsl"
#endif

layout(location = 0) out vec4 out_color;

void main() {
    vec3 c = vec3(0.0);
    float a = 0.0;
#ifdef PEEL_RESOLVE
    vec4 acc = peel_accum[peel_pixel()];
    c = acc.rgb;
    a = acc.a;
#else
    {
        uint p = oit_pixel();
        uint k = frame.transparency.kbuffer_nodes;
        for (uint i = 0u; i < k; i++) {
            uint64_t node = oit_nodes[p * k + i];
            if (node == OIT_EMPTY) {
                break;
            }
            vec4 f = unpack_fragment(uint(node & 0xFFFFFFFFul));
            c += (1.0 - a) * f.a * f.rgb;
            a += (1.0 - a) * f.a;
        }
        uvec4 tail = oit_tail[p];
        if (tail.w > 0u) {
            float tau = float(tail.w) / OIT_FIXED;
            vec3 mean = vec3(tail.xyz) / float(tail.w);
            float ta = 1.0 - exp(-tau);
            c += (1.0 - a) * ta * mean;
            a += (1.0 - a) * ta;
        }
    }
#endif
    out_color = vec4(c, a);
}
