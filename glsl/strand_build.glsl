// Build one strand in shared memory with a workgroup of S threads (paper 003 sec. 3.2):
// n = max(segments / S, 1) vertices per thread (segments <= 2 S = MAX_SEGMENTS), tangents by eq. 5-6 (sec. 3.5) and the
// vertex-LoD geomorph (eq. 11 and the tangent morph of sec. 3.6.2).
// Used unchanged by generate.comp (compute path) and strands.mesh (mesh path).
// The including shader defines S and MAX_SEGMENTS.
#ifndef STRAND_BUILD_GLSL
#define STRAND_BUILD_GLSL

// Vertices each thread owns in the tangent / morph phases: ceil((MAX_SEGMENTS + 1) / S).
#define PER_THREAD ((MAX_SEGMENTS + S) / S)

shared vec3 sp[MAX_SEGMENTS + 1u];   // positions
shared vec3 st[MAX_SEGMENTS + 1u];   // tangents

vec3 end_tangent(uint k, uint segments, bool coarse) {
    // Eq. 5 (tip) / eq. 6 (root), on the full or even-only (coarse) polyline.
    uint step = coarse ? 2u : 1u;
    if (segments == step) {
        return safe_normalize(sp[segments] - sp[0], vec3(0.0, 1.0, 0.0));
    }
    uint inner = k == 0u ? step : segments - step;
    vec3 ti = safe_normalize(sp[inner + step] - sp[inner - step], vec3(0.0, 1.0, 0.0));
    vec3 q = k == 0u ? safe_normalize(sp[step] - sp[0], ti) : safe_normalize(sp[segments] - sp[segments - step], ti);
    return safe_normalize(2.0 * q * dot(ti, q) - ti, q);
}

vec3 tangent_at(uint k, uint segments) {
    if (k > 0u && k < segments) {
        return safe_normalize(sp[k + 1u] - sp[k - 1u], vec3(0.0, 1.0, 0.0));
    }
    return end_tangent(k, segments, false);
}

vec3 coarse_tangent_at_even(uint k, uint segments) {
    if (k > 0u && k < segments) {
        return safe_normalize(sp[k + 2u] - sp[k - 2u], vec3(0.0, 1.0, 0.0));
    }
    return end_tangent(k, segments, true);
}

// Tangent of the coarse (even-only) level: even k as usual on the even polyline, odd k the
// average of its even neighbours.
vec3 coarse_tangent_at(uint k, uint segments) {
    if ((k & 1u) == 1u) {
        return 0.5 * (coarse_tangent_at_even(k - 1u, segments) + coarse_tangent_at_even(k + 1u, segments));
    }
    return coarse_tangent_at_even(k, segments);
}

// Must be called by all S threads (contains barriers). World-space results in sp/st.
void build_strand(StrandInfo si, uint segments, float gamma, uint t) {
    uint n = max(segments / S, 1u);
    for (uint i = 0u; i < n; i++) {
        uint k = t * n + i + 1u;
        if (k <= segments) {
            sp[k] = (push.model * vec4(strand_vertex(si, k, segments), 1.0)).xyz;
        }
    }
    if (t == 0u) {
        sp[0] = (push.model * vec4(strand_vertex(si, 0u, segments), 1.0)).xyz;
    }
    barrier();
    // Tangents from the unmorphed positions, blended toward the coarse tangents by gamma.
    vec3 tl[PER_THREAD];
    uint cnt = 0u;
    for (uint k = t; k <= segments && cnt < PER_THREAD; k += S) {
        vec3 tk = tangent_at(k, segments);
        if (gamma > 0.0 && segments >= 2u) {
            tk = safe_normalize(mix(tk, coarse_tangent_at(k, segments), gamma), tk);
        }
        tl[cnt++] = tk;
    }
    barrier();
    cnt = 0u;
    for (uint k = t; k <= segments && cnt < PER_THREAD; k += S) {
        st[k] = tl[cnt++];
    }
    // Eq. 11: odd vertices move toward the midpoint of their even neighbours.
    vec3 morphed[PER_THREAD];
    cnt = 0u;
    for (uint k = t; k <= segments && cnt < PER_THREAD; k += S) {
        vec3 pk = sp[k];
        if (gamma > 0.0 && (k & 1u) == 1u && k < segments) {
            pk = mix(pk, 0.5 * (sp[k - 1u] + sp[k + 1u]), gamma);
        }
        morphed[cnt++] = pk;
    }
    barrier();
    cnt = 0u;
    for (uint k = t; k <= segments && cnt < PER_THREAD; k += S) {
        sp[k] = morphed[cnt++];
    }
    barrier();
}

#endif
