#version 460
// Rebuild the animated textures of one character from its layer vertex positions (paper 003
// sections 3.4 and 4): the GPU twin of src/bake/deform.rs (DeformBasis::rebuild). One
// invocation per (root-slice texel, layer k) writes the column's quadratic control points of
// segment k (slices 4k .. 4k + 3; the last layer writes the tip slice) and the styling
// directions u, v of layer k (eq. 1-3 with the uv map fixed), packed as the textures' 16-bit
// texels; the pass then copies them into the textures.
#extension GL_GOOGLE_include_directive : require
#include "shared.glsl"
#include "curve.glsl"
layout(local_size_x = DEFORM_GROUP_SIZE) in;

layout(set = 0, binding = DEFORM_PARAMS, std430) readonly buffer Params { DeformParams params; };
layout(set = 0, binding = DEFORM_POSITIONS, std430) readonly buffer Positions { vec4 positions[]; };
layout(set = 0, binding = DEFORM_TEXEL_VERTEX, std430) readonly buffer TexelVertex { uint texel_vertex[]; };
layout(set = 0, binding = DEFORM_STYLING_OFFSETS, std430) readonly buffer StylingOffsets { uint styling_offsets[]; };
layout(set = 0, binding = DEFORM_STYLING_TERMS, std430) readonly buffer StylingTerms { StylingTerm styling_terms[]; };
layout(set = 0, binding = DEFORM_POSITION_TEXELS, std430) writeonly buffer PositionTexels { uvec2 position_texels[]; };
layout(set = 0, binding = DEFORM_U_TEXELS, std430) writeonly buffer UTexels { uvec2 u_texels[]; };
layout(set = 0, binding = DEFORM_V_TEXELS, std430) writeonly buffer VTexels { uvec2 v_texels[]; };

vec3 vertex(uint layer, uint v) {
    return positions[layer * params.counts.z + v].xyz;
}

// Column point i of vertex v with the phantom ends 2 p0 - p1 and 2 p_last - p_(last-1).
vec3 column_point(uint v, int i) {
    int last = int(params.counts.y) - 1;
    if (i < 0) {
        return 2.0 * vertex(0u, v) - vertex(1u, v);
    }
    if (i > last) {
        return 2.0 * vertex(uint(last), v) - vertex(uint(last - 1), v);
    }
    return vertex(uint(i), v);
}

// src/bake/mod.rs to_unorm16 / to_snorm16, packed two per word.
uint unorm16(float x) {
    return uint(floor(clamp(x, 0.0, 1.0) * 65535.0 + 0.5));
}

uint snorm16(float x) {
    float s = clamp(x, -1.0, 1.0) * 32767.0;
    return uint(int(sign(s) * floor(abs(s) + 0.5))) & 0xFFFFu;
}

uvec2 pack_position(vec3 p) {
    vec3 q = (p - params.origin.xyz) / params.extent.xyz;
    return uvec2(unorm16(q.x) | (unorm16(q.y) << 16), unorm16(q.z));
}

uvec2 pack_direction(vec3 d) {
    return uvec2(snorm16(d.x) | (snorm16(d.y) << 16), snorm16(d.z));
}

void main() {
    uint slice = params.counts.x;
    uint layers = params.counts.y;
    uint id = gl_GlobalInvocationID.y * DISPATCH_ROW * 64u + gl_GlobalInvocationID.x;
    if (id >= slice * layers) {
        return;
    }
    uint t = id % slice;
    uint k = id / slice;
    uint v = texel_vertex[t];
    if (v == EMPTY_TEXEL) {
        // As the bake: empty texels are zero.
        if (k + 1u < layers) {
            for (uint j = 0u; j < 4u; j++) {
                position_texels[(4u * k + j) * slice + t] = uvec2(0u);
            }
        } else {
            position_texels[4u * k * slice + t] = uvec2(0u);
        }
        u_texels[k * slice + t] = uvec2(0u);
        v_texels[k * slice + t] = uvec2(0u);
        return;
    }
    if (k + 1u < layers) {
        int j = int(k);
        vec3 b[4];
        catmull_rom_to_bezier(column_point(v, j - 1), column_point(v, j), column_point(v, j + 1), column_point(v, j + 2), b);
        vec3 q[4];
        cubic_to_quadratics(b, q);
        for (uint i = 0u; i < 4u; i++) {
            uvec2 texel = pack_position(q[i]);
            if (k == 0u && i == 0u) {
                // The root slice's alpha: the root thinning, carried in the root layer's w
                // (as the bake's encode_columns).
                texel.y |= unorm16(positions[v].w) << 16;
            }
            position_texels[(4u * k + i) * slice + t] = texel;
        }
    } else {
        position_texels[4u * k * slice + t] = pack_position(vertex(k, v));
    }
    // Eq. 1-3: area-weighted sum of the corner triangles' maps of the uv axes, normalised.
    vec3 p0 = vertex(k, v);
    vec3 su = vec3(0.0);
    vec3 sv = vec3(0.0);
    for (uint i = styling_offsets[v]; i < styling_offsets[v + 1u]; i++) {
        StylingTerm st = styling_terms[i];
        vec3 e1 = vertex(k, st.i1) - p0;
        vec3 e2 = vertex(k, st.i2) - p0;
        su += e1 * st.u.x + e2 * st.u.y;
        sv += e1 * st.v.x + e2 * st.v.y;
    }
    // glam's try_normalize: fails for a zero or non-finite length.
    float lu = length(su);
    float lv = length(sv);
    vec3 u = lu > 0.0 && !isinf(1.0 / lu) ? su / lu : vec3(1.0, 0.0, 0.0);
    vec3 w = lv > 0.0 && !isinf(1.0 / lv) ? sv / lv : vec3(0.0, 1.0, 0.0);
    u_texels[k * slice + t] = pack_direction(u);
    v_texels[k * slice + t] = pack_direction(w);
}
