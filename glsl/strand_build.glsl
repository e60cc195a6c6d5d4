// Build strands in shared memory with a workgroup of S threads (paper 003 sec. 3.2 and 3.6.2).
// Long strands (segments >= S): one strand per workgroup, n = segments / S vertices per thread.
// Short strands (segments < S, i.e. n would drop below 1): P = S / segments strands per
// workgroup, one vertex per thread, so no thread idles (the "reduce s" option of sec. 3.6.2).
// Then tangents by eq. 5-6 (sec. 3.5) and the vertex-LoD geomorph (eq. 11 + tangent morph).
// Used unchanged by generate.comp (compute path) and strands.mesh (mesh path), both with
// local_size_x = STRAND_GROUP_SIZE (MAX_SEGMENTS <= 2 S, from shared.glsl).
#ifndef STRAND_BUILD_GLSL
#define STRAND_BUILD_GLSL

#include "temporal.glsl"

#define S uint(STRAND_GROUP_SIZE)

// Shared entries: P strands x (segments + 1) vertices <= S + P <= MAX_SEGMENTS + 1.
#define MAX_ENTRIES (MAX_SEGMENTS + 1u)
// Entries each thread owns in the tangent / morph phases.
#define PER_THREAD ((MAX_ENTRIES + S - 1u) / S)

shared vec3 sp[MAX_ENTRIES];   // positions, strand j at j * (segments + 1)
shared vec3 st[MAX_ENTRIES];   // tangents
#ifdef VISIBILITY
// With deform_motion() (temporal.glsl): the previous pose's position minus this one's.
shared vec3 sd[MAX_ENTRIES];
#endif

// Per strand of the workgroup, what is constant along it (strand_info) and its root offset
// (root_bulge: twelve texel fetches), made once per strand instead of once per vertex.
shared StrandInfo s_info[S];
shared vec3 s_root_offset[S];
// Per strand (lane) of the workgroup: its bundle and index there, and eq. 12's geomorph
// factor. The software passes of the mesh path pack strands of several bundles (one
// character, one vertex level) into a workgroup (strands.task); the others fill every lane
// from one bundle (build_strands).
shared uvec2 s_lane[S];
shared float s_lane_gamma[S];

// Before build_lane_strands, by the thread of lane j: strand `strand` of crowd bundle `bundle`.
void set_strand_lane(uint j, uint bundle, uint strand, float gamma) {
    s_lane[j] = uvec2(bundle, strand);
    s_lane_gamma[j] = gamma;
}

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

// Shared entry idx: vertex k of strand j of the workgroup (s_info / s_root_offset), world space;
// with `moving`, also its displacement to the previous pose (the same strand from the previous
// texture set: same seed and root; its root offset from those textures).
void place_vertex(uint idx, uint j, uint k, uint segments, bool moving) {
    StrandInfo si = s_info[j];
    vec3 now = (model * vec4(strand_vertex_offset(si, s_root_offset[j], k, segments), 1.0)).xyz;
    sp[idx] = now;
#ifdef VISIBILITY
    if (moving) {
        uint current = tex_slot;
        tex_slot = ch_prev_slot;
        sd[idx] = (model * vec4(strand_vertex(si, k, segments), 1.0)).xyz - now;
        tex_slot = current;
    }
#endif
}

// Deformation residual (temporal.glsl) of shared entry idx of `character`, the bound one:
// zero unless deform_motion().
vec2 entry_residual(uint idx, uint character) {
#ifdef VISIBILITY
    if (deform_motion()) {
        return deformation_residual(character, sp[idx], sd[idx]);
    }
#endif
    return vec2(0.0);
}

// Build the strands of the workgroup's lanes (set_strand_lane by threads 0 .. per - 1, of the
// bound character), all of `segments` segments (lanes past the caller's count are computed
// and ignored). Must be called by all S threads (contains barriers). World-space results in
// sp / st (and sd with deform_motion()).
void build_lane_strands(uint segments, uint t) {
    uint per = strands_per_group(segments);
    uint stride = segments + 1u;
#ifdef VISIBILITY
    bool moving = deform_motion();
#else
    bool moving = false;
#endif
    if (t < per) {
        StrandInfo si = strand_info(s_lane[t].x, s_lane[t].y);
        s_info[t] = si;
        s_root_offset[t] = root_bulge(root_cell(si.origin), si.local);
    }
    barrier();
    if (per == 1u) {
        uint n = segments / S;
        for (uint i = 0u; i < n; i++) {
            uint k = t * n + i + 1u;
            place_vertex(k, 0u, k, segments, moving);
        }
        if (t == 0u) {
            place_vertex(0u, 0u, 0u, segments, moving);
        }
    } else {
        uint j = t / segments;
        uint k = t % segments + 1u;
        place_vertex(j * stride + k, j, k, segments, moving);
        if (t < per) {
            place_vertex(t * stride, t, 0u, segments, moving);
        }
    }
    barrier();
    uint entries = per * stride;
    // Tangents from the unmorphed positions, blended toward the coarse tangents by gamma, and
    // eq. 11: odd vertices move toward the midpoint of their even neighbours. Both read the
    // unmorphed positions, so results are written back after a barrier.
    vec3 tl[PER_THREAD];
    vec3 morphed[PER_THREAD];
#ifdef VISIBILITY
    // Eq. 11 is linear in the positions: the displacements morph alike.
    vec3 morphed_d[PER_THREAD];
#endif
    for (uint i = 0u; i < PER_THREAD; i++) {
        uint idx = t + i * S;
        if (idx < entries) {
            uint base = (idx / stride) * stride;
            uint k = idx - base;
            float gamma = s_lane_gamma[idx / stride];
            vec3 tk = tangent_at(base, k, segments);
            vec3 pk = sp[idx];
            bool morph_odd = gamma > 0.0 && segments >= 2u && (k & 1u) == 1u && k < segments;
            if (gamma > 0.0 && segments >= 2u) {
                tk = safe_normalize(mix(tk, coarse_tangent_at(base, k, segments), gamma), tk);
                if (morph_odd) {
                    pk = mix(pk, 0.5 * (sp[idx - 1u] + sp[idx + 1u]), gamma);
                }
            }
            tl[i] = tk;
            morphed[i] = pk;
#ifdef VISIBILITY
            if (moving) {
                vec3 dk = sd[idx];
                morphed_d[i] = morph_odd ? mix(dk, 0.5 * (sd[idx - 1u] + sd[idx + 1u]), gamma) : dk;
            }
#endif
        }
    }
    barrier();
    for (uint i = 0u; i < PER_THREAD; i++) {
        uint idx = t + i * S;
        if (idx < entries) {
            st[idx] = tl[i];
            sp[idx] = morphed[i];
#ifdef VISIBILITY
            if (moving) {
                sd[idx] = morphed_d[i];
            }
#endif
        }
    }
    barrier();
}

// Build strands first .. first + strands_per_group(segments) - 1 of crowd bundle `bundle` (extra strands
// past the bundle's count are computed and ignored by the caller): build_lane_strands with
// every lane from one bundle.
void build_strands(uint bundle, uint first, uint segments, float gamma, uint t) {
    if (t < strands_per_group(segments)) {
        set_strand_lane(t, bundle, first + t, gamma);
    }
    build_lane_strands(segments, t);
}

#endif
