// Build strands in shared memory with a workgroup of S threads (paper 003 sec. 3.2 and 3.6.2).
// Long strands (segments >= S): one strand per workgroup, n = segments / S vertices per thread.
// Short strands (segments < S, i.e. n would drop below 1): P = S / segments strands per
// workgroup, one vertex per thread, so no thread idles (the "reduce s" option of sec. 3.6.2).
// Then tangents by eq. 5-6 (sec. 3.5) and the vertex-LoD geomorph (eq. 11 + tangent morph).
// Used unchanged by generate.comp (compute path) and strands.mesh (mesh path), both with
// local_size_x = STRAND_GROUP_SIZE (MAX_SEGMENTS <= 2 S, from shared.glsl).
#ifndef STRAND_BUILD_GLSL
#define STRAND_BUILD_GLSL

#define S uint(STRAND_GROUP_SIZE)

// Shared entries: P strands x (segments + 1) vertices <= S + P <= MAX_SEGMENTS + 1.
#define MAX_ENTRIES (MAX_SEGMENTS + 1u)
// Entries each thread owns in the tangent / morph phases.
#define PER_THREAD ((MAX_ENTRIES + S - 1u) / S)

shared vec3 sp[MAX_ENTRIES];   // positions, strand j at j * (segments + 1)
shared vec3 st[MAX_ENTRIES];   // tangents

// Strands one workgroup builds for strands of `segments` segments.
uint strands_per_group(uint segments) {
    return max(S / segments, 1u);
}

vec3 end_tangent(uint base, uint k, uint segments, bool coarse) {
    // Eq. 5 (tip) / eq. 6 (root), on the full or even-only (coarse) polyline.
    uint step = coarse ? 2u : 1u;
    if (segments == step) {
        return safe_normalize(sp[base + segments] - sp[base], vec3(0.0, 1.0, 0.0));
    }
    uint inner = k == 0u ? step : segments - step;
    vec3 ti = safe_normalize(sp[base + inner + step] - sp[base + inner - step], vec3(0.0, 1.0, 0.0));
    vec3 q = k == 0u ? safe_normalize(sp[base + step] - sp[base], ti)
                     : safe_normalize(sp[base + segments] - sp[base + segments - step], ti);
    return safe_normalize(2.0 * q * dot(ti, q) - ti, q);
}

vec3 tangent_at(uint base, uint k, uint segments) {
    if (k > 0u && k < segments) {
        return safe_normalize(sp[base + k + 1u] - sp[base + k - 1u], vec3(0.0, 1.0, 0.0));
    }
    return end_tangent(base, k, segments, false);
}

vec3 coarse_tangent_at_even(uint base, uint k, uint segments) {
    if (k > 0u && k < segments) {
        return safe_normalize(sp[base + k + 2u] - sp[base + k - 2u], vec3(0.0, 1.0, 0.0));
    }
    return end_tangent(base, k, segments, true);
}

// Tangent of the coarse (even-only) level: odd k average their even neighbours.
vec3 coarse_tangent_at(uint base, uint k, uint segments) {
    if ((k & 1u) == 1u) {
        return 0.5 * (coarse_tangent_at_even(base, k - 1u, segments) + coarse_tangent_at_even(base, k + 1u, segments));
    }
    return coarse_tangent_at_even(base, k, segments);
}

// Build strands first .. first + strands_per_group(segments) - 1 of crowd bundle `bundle` (extra strands
// past the bundle's count are computed and ignored by the caller). Must be called by all S
// threads (contains barriers). World-space results in sp / st.
void build_strands(uint bundle, uint first, uint segments, float gamma, uint t) {
    uint per = strands_per_group(segments);
    uint stride = segments + 1u;
    if (per == 1u) {
        StrandInfo si = strand_info(bundle, first);
        uint n = segments / S;
        for (uint i = 0u; i < n; i++) {
            uint k = t * n + i + 1u;
            sp[k] = (model * vec4(strand_vertex(si, k, segments), 1.0)).xyz;
        }
        if (t == 0u) {
            sp[0] = (model * vec4(strand_vertex(si, 0u, segments), 1.0)).xyz;
        }
    } else {
        uint j = t / segments;
        uint k = t % segments + 1u;
        sp[j * stride + k] = (model * vec4(strand_vertex(strand_info(bundle, first + j), k, segments), 1.0)).xyz;
        if (t < per) {
            sp[t * stride] = (model * vec4(strand_vertex(strand_info(bundle, first + t), 0u, segments), 1.0)).xyz;
        }
    }
    barrier();
    uint entries = per * stride;
    // Tangents from the unmorphed positions, blended toward the coarse tangents by gamma, and
    // eq. 11: odd vertices move toward the midpoint of their even neighbours. Both read the
    // unmorphed positions, so results are written back after a barrier.
    vec3 tl[PER_THREAD];
    vec3 morphed[PER_THREAD];
    for (uint i = 0u; i < PER_THREAD; i++) {
        uint idx = t + i * S;
        if (idx < entries) {
            uint base = (idx / stride) * stride;
            uint k = idx - base;
            vec3 tk = tangent_at(base, k, segments);
            vec3 pk = sp[idx];
            if (gamma > 0.0 && segments >= 2u) {
                tk = safe_normalize(mix(tk, coarse_tangent_at(base, k, segments), gamma), tk);
                if ((k & 1u) == 1u && k < segments) {
                    pk = mix(pk, 0.5 * (sp[idx - 1u] + sp[idx + 1u]), gamma);
                }
            }
            tl[i] = tk;
            morphed[i] = pk;
        }
    }
    barrier();
    for (uint i = 0u; i < PER_THREAD; i++) {
        uint idx = t + i * S;
        if (idx < entries) {
            st[idx] = tl[i];
            sp[idx] = morphed[i];
        }
    }
    barrier();
}

#endif
