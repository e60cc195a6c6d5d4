// Shading from a character's strand density volume (seed 002, vkhr; CPU twins in
// src/shade/volume.rs): its ambient occlusion of strands, the light's transmittance through
// it, and the volume tier's screen-door blend with the strands. The volume is read by device
// address (CharacterRecord::volume); passes that include this declare the frame's density
// volumes as read (FrameRes::shading_uses). Requires bindings.glsl.
#ifndef VOLUME_SHADING_GLSL
#define VOLUME_SHADING_GLSL
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference_uvec2 : require

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer VolumeCells { VolumeCell cells[]; };

bool volume_built(uint c) {
    return (characters[c].volume.w & VOLUME_BUILT) != 0u;
}

uvec3 volume_dims(uint c) {
    uint packed = characters[c].volume.z;
    uint mask = (1u << VOLUME_DIMS_BITS) - 1u;
    return uvec3(packed & mask, (packed >> VOLUME_DIMS_BITS) & mask, packed >> (2u * VOLUME_DIMS_BITS));
}

// Grid coordinates (cell i spans [i, i + 1)) of world point p in character c's volume.
vec3 volume_grid(uint c, vec3 p) {
    return (characters[c].world_to_volume * vec4(p, 1.0)).xyz;
}

// Character c's cells at grid point g, trilinear between cell centres, 0 outside the grid:
// x density times strand width (object units: the optical depth of opaque strands per unit
// length), yzw the flow in the same units (reference::volume::DensityVolume::sample).
vec4 volume_sample(uint c, vec3 g) {
    uvec3 dims = volume_dims(c);
    VolumeCells v = VolumeCells(characters[c].volume.xy);
    vec3 q = g - vec3(0.5);
    vec3 base = floor(q);
    vec3 f = q - base;
    vec4 sum = vec4(0.0);
    for (uint corner = 0u; corner < 8u; corner++) {
        uvec3 o = uvec3(corner & 1u, (corner >> 1u) & 1u, corner >> 2u);
        vec3 cc = base + vec3(o);
        if (any(lessThan(cc, vec3(0.0))) || any(greaterThanEqual(cc, vec3(dims)))) {
            continue;
        }
        vec3 w = mix(vec3(1.0) - f, f, vec3(o));
        uvec3 u = uvec3(cc);
        VolumeCell cell = v.cells[(u.z * dims.y + u.y) * dims.x + u.x];
        ivec3 flow = ivec3(int(cell.flow[0]), int(cell.flow[1]), int(cell.flow[2]));
        sum += (w.x * w.y * w.z) * vec4(float(cell.len), vec3(flow));
    }
    return sum * characters[c].volume_shading.x;
}

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer VolumeWords { uint words[]; };

// Whether brick b of character c's occupancy mask is set (reference::volume::brick_set): the
// density build writes the mask, a bit per brick of BRICK_CELLS^3 cells (x fastest), after the
// grid's cells and the one after them.
bool brick_occupied(uint c, uvec3 dims, uvec3 b) {
    uvec3 n = (dims + uvec3(BRICK_CELLS - 1u)) / BRICK_CELLS;
    // Clamped, so a ray that went NaN never reads past the mask.
    uint bit = min((b.z * n.y + b.y) * n.x + b.x, n.x * n.y * n.z - 1u);
    uint first = (dims.x * dims.y * dims.z + 1u) * 4u;
    uint word = VolumeWords(characters[c].volume.xy).words[first + (bit >> 5u)];
    return (word & (1u << (bit & 31u))) != 0u;
}

// The brick holding grid point g, clamped to the grid's (reference::volume::brick_of).
uvec3 volume_brick(uvec3 dims, vec3 g) {
    vec3 last = vec3((dims + uvec3(BRICK_CELLS - 1u)) / BRICK_CELLS - uvec3(1u));
    return uvec3(clamp(floor(g / float(BRICK_CELLS)), vec3(0.0), last));
}

// Where the ray g0 + t gd (grid coordinates) leaves brick b (reference::volume::brick_exit).
float brick_exit(vec3 g0, vec3 gd, uvec3 b) {
    vec3 face = (vec3(b) + step(vec3(0.0), gd)) * float(BRICK_CELLS);
    vec3 t = mix((face - g0) / gd, vec3(1e30), equal(gd, vec3(0.0)));
    return min(t.x, min(t.y, t.z));
}

// Ambient light reaching world point p of character c through its hair
// (shade::volume::ambient_visibility): 1 without a volume or with occlusion off.
float volume_ambient(uint c, vec3 p) {
    if ((characters[c].volume.w & (VOLUME_BUILT | VOLUME_OCCLUSION)) != (VOLUME_BUILT | VOLUME_OCCLUSION)) {
        return 1.0;
    }
    float radius = AO_RADIUS_CELLS * characters[c].volume_shading.y;
    return exp(-STRAND_SHADOW_OPACITY * volume_sample(c, volume_grid(c, p)).x * radius);
}

// How far along the ray eye + t dir (unit dir, world units) the frame's view puts `depth`
// (0..1): where the march meets the opaque surface a pixel shows. Infinite at the cleared
// depth. CPU twin: shade::volume::ray_length_to_depth.
float ray_length_to_depth(vec3 eye, vec3 dir, float depth) {
    vec4 a = frame.view_proj * vec4(eye, 1.0);
    vec4 b = frame.view_proj * vec4(dir, 0.0);
    float t = (depth * a.w - a.z) / (b.z - depth * b.w);
    return depth < 1.0 && !isinf(t) && !isnan(t) && t >= 0.0 ? t : 1e30;
}

// The volume tier's share of character c (0: strands only).
float volume_weight(uint c) {
    return volume_built(c) ? characters[c].volume_shading.z : 0.0;
}

// Where the ray g0 + t gd (grid coordinates; t in the units of gd's length) enters and
// leaves character c's grid box [0, dims]: (t_enter, t_exit), no crossing when
// t_exit <= t_enter.
vec2 volume_span(uint c, vec3 g0, vec3 gd) {
    vec3 inv = sign(gd + 1e-20) / max(abs(gd), vec3(1e-20));
    vec3 ta = -g0 * inv;
    vec3 tb = (vec3(volume_dims(c)) - g0) * inv;
    vec3 lo = min(ta, tb);
    vec3 hi = max(ta, tb);
    return vec2(max(lo.x, max(lo.y, lo.z)), min(hi.x, min(hi.y, hi.z)));
}

// Transmittance of the light from world point p through character c's own volume, toward
// the unit direction l (shade::volume::light_transmittance), strands STRAND_SHADOW_OPACITY
// opaque: the self-shadow of hair drawn as a volume alone (its strands are in no light map).
float volume_light(uint c, vec3 p, vec3 l) {
    vec3 g = volume_grid(c, p);
    vec3 gd = (characters[c].world_to_volume * vec4(l, 0.0)).xyz;
    // Up to where the ray leaves the grid.
    float world_length = max(volume_span(c, g, gd).y, 0.0);
    float scale = characters[c].model_scale;
    float step = MARCH_STEP_CELLS * characters[c].volume_shading.y * scale;
    uint steps = min(uint(ceil(world_length / step)), 256u);
    float depth = 0.0;
    for (uint i = 0u; i < steps; i++) {
        float t = (float(i) + 0.5) * step;
        depth += volume_sample(c, g + gd * t).x;
    }
    // Object-unit optical depth: the world step over the model's scale.
    return exp(-STRAND_SHADOW_OPACITY * depth * step / scale);
}

#endif
