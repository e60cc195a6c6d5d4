// Strand evaluation from the five textures: the GPU twin of src/reference/generate.rs (CPU oracle).
// Included unchanged by the compute path (generate.comp) and the mesh path.
// Requires bindings.glsl and common.glsl.
#ifndef STRAND_EVAL_GLSL
#define STRAND_EVAL_GLSL

// Root sample of a strand (paper 003 sec. 3.3); quads shift the toroidal set per bundle.
// bundle_index is the bundle's index within its mesh (as in the CPU oracle).
vec2 root_sample(GpuBundle b, uint bundle_index, uint strand) {
    uint s = strand % MAX_STRANDS_PER_BUNDLE;
    if ((b.flags & BUNDLE_TRIANGLE) != 0u) {
        return root_samples[MAX_STRANDS_PER_BUNDLE + s];
    }
    uint h = hash_u32(bundle_index ^ 0x51ed270bu);
    return fract(root_samples[s] + vec2(hash_f32(h), hash_f32(h + 1u)));
}

vec3 decode_position(vec3 t) {
    return mesh.pos_origin.xyz + mesh.pos_extent.xyz * t;
}

// Local cell coordinate of root sample xi; triangles map xi -> (xi.x / (1 - xi.y), xi.y)
// (src/reference/root_surface.rs: local_coord).
vec2 root_local(GpuBundle b, vec2 xi) {
    vec2 local = xi;
    if ((b.flags & BUNDLE_TRIANGLE) != 0u) {
        local = vec2(xi.x / max(1.0 - xi.y, 1e-6), xi.y);
    }
    return clamp(local, vec2(0.0), vec2(1.0));
}

// Normalised root-slice coordinate of local cell coordinate `local`.
vec2 root_coord_local(GpuBundle b, vec2 local) {
    return (vec2(b.origin) + 0.5 + local) / vec2(mesh.root_size);
}

vec2 root_coord(GpuBundle b, vec2 xi) {
    return root_coord_local(b, root_local(b, xi));
}

// A bundle's root cell: corners and root-layer normals (u x v, eq. 1-3), texel order
// (0,0) (1,0) (0,1) (1,1) (src/reference/root_surface.rs: RootCell::from_baked).
struct RootCell {
    vec3 p[4];
    vec3 n[4];
};

RootCell root_cell(uvec2 origin) {
    RootCell c;
    for (int i = 0; i < 4; i++) {
        ivec3 t = ivec3(ivec2(origin) + ivec2(i & 1, i >> 1), 0);
        c.p[i] = decode_position(texelFetch(TEX_POSITION, t, 0).xyz);
        vec3 n = cross(texelFetch(TEX_U, t, 0).xyz, texelFetch(TEX_V, t, 0).xyz);
        float l = length(n);
        c.n[i] = l > 0.0 ? n / l : vec3(0.0);
    }
    return c;
}

// Phong offset of the root at `local` (Boubekeur and Alexa 2008, eq. 4):
// -alpha sum_i w_i ((q - p_i) . n_i) n_i with q the bilinear root (RootCell::bulge).
vec3 root_bulge(RootCell c, vec2 local) {
    float w[4] = float[4]((1.0 - local.x) * (1.0 - local.y), local.x * (1.0 - local.y),
                          (1.0 - local.x) * local.y, local.x * local.y);
    vec3 q = c.p[0] * w[0] + c.p[1] * w[1] + c.p[2] * w[2] + c.p[3] * w[3];
    vec3 sum = vec3(0.0);
    for (int i = 0; i < 4; i++) {
        sum += c.n[i] * (w[i] * dot(q - c.p[i], c.n[i]));
    }
    return -ROOT_PHONG_SHAPE * sum;
}

// Largest root offset in the cell (RootCell::bulge_bound).
float root_bulge_bound(RootCell c) {
    float most = 0.0;
    for (int i = 0; i < 4; i++) {
        for (int j = 0; j < 4; j++) {
            most = max(most, abs(dot(c.p[j] - c.p[i], c.n[i])));
        }
    }
    return ROOT_PHONG_SHAPE * most;
}

// Share of the root offset left at curve parameter r: (1 - r)^2 over the first segment.
float root_bulge_fade(float r) {
    float x = max(1.0 - r, 0.0);
    return x * x;
}

// Curve point at parameter r in [0, L-1]: two trilinear fetches + one lerp (sec. 3.1).
vec3 curve_point(vec2 coord, float r) {
    uint layers = mesh.layers;
    r = clamp(r, 0.0, float(layers - 1u));
    uint j = min(uint(floor(r)), layers - 2u);
    float tau = r - float(j);
    uint slice = 4u * j;
    float t = tau * 2.0;
    if (tau >= 0.5) {
        slice += 2u;
        t = tau * 2.0 - 1.0;
    }
    float depth = float(POSITION_DEPTH(layers));
    vec3 a = texture(TEX_POSITION, vec3(coord, (float(slice) + 0.5 + t) / depth)).xyz;
    vec3 b = texture(TEX_POSITION, vec3(coord, (float(slice) + 1.5 + t) / depth)).xyz;
    return decode_position(mix(a, b, t));
}

vec3 root_point(vec2 coord) {
    float depth = float(POSITION_DEPTH(mesh.layers));
    return decode_position(texture(TEX_POSITION, vec3(coord, 0.5 / depth)).xyz);
}

// Root thinning at coord: the cube of the root slice's alpha (src/reference/generate.rs:
// root_thinning).
float root_thinning(vec2 coord) {
    float depth = float(POSITION_DEPTH(mesh.layers));
    float a = texture(TEX_POSITION, vec3(coord, 0.5 / depth)).a;
    return a * a * a;
}

// Styling frame (eq. 4) and w at parameter r.
void styling_frame(vec2 coord, float r, out vec3 fu, out vec3 fv, out vec3 fw, out float w) {
    float z = (r + 0.5) / float(mesh.layers);
    vec3 u = texture(TEX_U, vec3(coord, z)).xyz;
    vec3 v = texture(TEX_V, vec3(coord, z)).xyz;
    fu = length(u) > 0.0 ? normalize(u) : vec3(1.0, 0.0, 0.0);
    fv = length(v) > 0.0 ? normalize(v) : vec3(0.0, 1.0, 0.0);
    vec3 c = cross(fu, fv);
    fw = length(c) > 0.0 ? normalize(c) : vec3(0.0, 0.0, 1.0);
    w = mesh.pos_origin.w * texture(TEX_W, vec3(coord, z)).x;
}

float smoothstep_safe(float e0, float e1, float x) {
    if (e1 <= e0) {
        return x >= e1 ? 1.0 : 0.0;
    }
    return smoothstep(e0, e1, x);
}

// Styling offset in the u v w frame (sec. 3.4; src/reference/generate.rs: styling_offset).
vec3 styling_offset(uint key, float s, float w) {
    const float TAU = 6.28318530718;
    float ramp = smoothstep_safe(0.0, style.root_ramp, w);
    vec3 off = vec3(0.0);
    float cp = TAU * (style.curl_frequency * w + style.curl_phase_jitter * strand_rand(key, 1u));
    off += vec3(cos(cp), sin(cp), 0.0) * (style.curl_radius * ramp);
    float wp = TAU * (style.wave_frequency * w + style.wave_phase_jitter * strand_rand(key, 2u));
    off += vec3(cos(style.wave_angle), sin(style.wave_angle), 0.0) * (style.wave_amplitude * ramp * sin(wp));
    float frizz = style.frizz_amplitude * pow(s, style.frizz_power);
    float x = w * style.frizz_frequency;
    uint fk = hash_u32(key ^ 0x7f4a7c15u);
    off += vec3(value_noise(fk, x), value_noise(fk + 0x68bc21ebu, x), value_noise(fk + 0x02e5be93u, x)) * frizz;
    return off;
}

float strand_width_at(float s) {
    return style.strand_width * (1.0 + (style.tip_width_ratio - 1.0) * pow(s, style.taper_power));
}

// Everything constant along one strand.
struct StrandInfo {
    vec2 coord;         // root-slice coordinate of the root sample
    vec2 centre_coord;  // bundle centre (clumping target)
    uvec2 origin;       // the bundle's root cell
    vec2 local;         // local cell coordinate of the root
    uint key;           // per-strand random key
    float span;         // curve parameter at the tip
    bool kept;          // false: thinned out at a hairline, every vertex at the root
};

// Strand `strand` of crowd bundle `g` (its character bound with bind_character).
StrandInfo strand_info(uint g, uint strand) {
    GpuBundle b = bundles[g];
    StrandInfo si;
    si.key = strand_key(style.seed, b.local_index, strand);
    si.local = root_local(b, root_sample(b, b.local_index, strand));
    si.coord = root_coord_local(b, si.local);
    si.origin = b.origin;
    vec2 centre = (b.flags & BUNDLE_TRIANGLE) != 0u ? vec2(1.0 / 3.0) : vec2(0.5);
    si.centre_coord = root_coord(b, centre);
    float length_factor = 1.0 - style.length_variation * strand_rand(si.key, 0u);
    si.span = float(mesh.layers - 1u) * length_factor;
    si.kept = strand_rand(si.key, STRAND_RAND_THINNING) >= root_thinning(si.coord);
    return si;
}

// strand_vertex with the strand's root offset `root_offset` (root_bulge of its cell and local
// coordinate) given: the strand builders compute it once per strand, not per vertex.
vec3 strand_vertex_offset(StrandInfo si, vec3 root_offset, uint k, uint segments) {
    if (k == 0u || !si.kept) {
        return root_point(si.coord) + root_offset;
    }
    float s = float(k) / float(segments);
    float r = s * si.span;
    // Curved roots over the first segment only (src/reference/root_surface.rs).
    float fade = root_bulge_fade(r);
    vec3 bulge = fade > 0.0 ? root_offset * fade : vec3(0.0);
    vec3 p = curve_point(si.coord, r);
    if (style.clump_strength > 0.0) {
        vec3 c = curve_point(si.centre_coord, r);
        p += (c - p) * (style.clump_strength * pow(s, style.clump_power));
    }
    vec3 fu, fv, fw;
    float w;
    styling_frame(si.coord, r, fu, fv, fw, w);
    vec3 off = styling_offset(si.key, s, w);
    return p + fu * off.x + fv * off.y + fw * off.z + bulge;
}

// Position of vertex k of `segments` (k = 0 is the root: one lookup, no styling).
vec3 strand_vertex(StrandInfo si, uint k, uint segments) {
    return strand_vertex_offset(si, root_bulge(root_cell(si.origin), si.local), k, segments);
}

// Tangents from positions (sec. 3.5): central differences, eq. 5 / eq. 6 at the ends.
// `prev`/`next` are the neighbours (ignored where they do not exist).
vec3 safe_normalize(vec3 v, vec3 fallback) {
    float l = length(v);
    return l > 0.0 ? v / l : fallback;
}

#endif
