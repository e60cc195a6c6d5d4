#version 460
// Temporal pass (src/render/temporal.rs), one thread per pixel. With push.params.x, the
// pixel's motion from its nearest surface (visibility word: depth, id, deformation residual;
// the id's clip_to_prev matrix) is written to the motion target. With accumulation (frame.temporal.accumulate) the history
// is reprojected (Catmull-Rom), checked against what the pixel is (visibility id and depth of
// the nearest surface in the 3x3 neighbourhood, both frames), clipped to the neighbourhood's
// colour box (wider on hair) and blended; the result goes to the history and, as sRGB bytes,
// to the second half of the frame's colour buffer, which is copied onto the output image.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
// Only ever built for devices with 64-bit atomics (passes::temporal), whose shaders note
// visibility words.
#ifndef VISIBILITY
#define VISIBILITY 1
#endif
#include "bindings.glsl"
#include "temporal.glsl"
layout(local_size_x = TEMPORAL_GROUP, local_size_y = TEMPORAL_GROUP) in;

layout(set = SET_FRAME, binding = BINDING_MOTION, std430) writeonly buffer MotionOut { uvec4 motion_out[]; };
layout(set = SET_FRAME, binding = BINDING_FRAME_COLOR, std430) buffer FrameColor { uint frame_color[]; };
// History: per pixel, the colour (rg and b halves) at [p], the surface (id, depth bits) at
// [pixels + p]: the filter taps read colours only.
layout(set = SET_FRAME, binding = BINDING_HISTORY_IN, std430) readonly buffer HistoryIn { uvec2 history_in[]; };
layout(set = SET_FRAME, binding = BINDING_HISTORY_OUT, std430) buffer HistoryOut { uvec2 history_out[]; };
layout(set = SET_FRAME, binding = BINDING_PROP_INSTANCES, std430) readonly buffer PropInstances { PropInstance prop_instances[]; };

ivec2 image_size() {
    return ivec2(frame.viewport.xy);
}

uint pixel_count() {
    return uint(image_size().x) * uint(image_size().y);
}

uint index_of(ivec2 p) {
    ivec2 q = clamp(p, ivec2(0), image_size() - 1);
    return uint(q.y) * uint(image_size().x) + uint(q.x);
}

mat4 clip_to_prev_of(uint id) {
    if (id == VISIBILITY_EMPTY) {
        return frame.clip_to_prev;
    }
    uint i = id & VISIBILITY_INDEX;
    if ((id & VISIBILITY_PROP) != 0u) {
        return prop_instances[i].clip_to_prev;
    }
    return characters[i].clip_to_prev;
}

// Previous clip position of the surface at pixel centre `centre` and depth `depth` (CPU twin:
// render::temporal::motion_at).
vec4 previous_clip(uint id, vec2 centre, float depth) {
    vec2 ndc = centre / vec2(image_size()) * 2.0 - 1.0;
    return clip_to_prev_of(id) * vec4(ndc, depth, 1.0);
}

// Rigid motion minus the deformation residual: this position minus the previous one.
vec2 motion_at(uint id, vec2 centre, float depth, vec2 residual) {
    vec4 prev = previous_clip(id, centre, depth);
    if (abs(prev.w) < 1e-12) {
        return vec2(0.0);
    }
    return centre - (prev.xy / prev.w + 1.0) * 0.5 * vec2(image_size()) - residual;
}

bool is_hair(uint id) {
    return id != VISIBILITY_EMPTY && (id & (VISIBILITY_PROP | VISIBILITY_SOLID)) == 0u;
}

// sRGB encoding; above the linear toe, three square roots instead of a power (a fit within
// 0.25 of an 8-bit step: the same byte but for rounding, at a fraction of the cost).
vec3 linear_to_srgb(vec3 l) {
    l = clamp(l, 0.0, 1.0);
    vec3 s1 = sqrt(l);
    vec3 s2 = sqrt(s1);
    vec3 s3 = sqrt(s2);
    vec3 curve = 0.662002687 * s1 + 0.684122060 * s2 - 0.323583601 * s3 - 0.0225411470 * l;
    return mix(l * 12.92, curve, greaterThan(l, vec3(0.0031308)));
}

vec3 to_ycocg(vec3 c) {
    return vec3(0.25 * c.r + 0.5 * c.g + 0.25 * c.b, 0.5 * c.r - 0.5 * c.b, -0.25 * c.r + 0.5 * c.g - 0.25 * c.b);
}

vec3 from_ycocg(vec3 c) {
    return vec3(c.x + c.y - c.z, c.x + c.z, c.x - c.y - c.z);
}

// The frame's colour at p, linear: sRGB decoded by a cubic (error under 0.0015 of full
// scale; the history's colour clamp and blend need no more).
vec3 current_color(ivec2 p) {
    vec3 c = unpackUnorm4x8(frame_color[index_of(p)]).rgb;
    return c * (c * (c * 0.305306011 + 0.682171111) + 0.012522878);
}

vec3 history_color(ivec2 p) {
    uvec2 h = history_in[index_of(p)];
    return vec3(unpackHalf2x16(h.x), unpackHalf2x16(h.y).x);
}

// Catmull-Rom weights of the four taps around a sample at fraction f.
vec4 catmull_rom(float f) {
    return vec4(f * (-0.5 + f * (1.0 - 0.5 * f)), 1.0 + f * f * (-2.5 + 1.5 * f),
                f * (0.5 + f * (2.0 - 1.5 * f)), f * f * (-0.5 + 0.5 * f));
}

// The history at position q (pixels) through a Catmull-Rom filter: sharp, so single strands
// survive many frames of reprojection (a bilinear history blurs a little each frame). The
// four corner taps, whose weights are the products of two outer lobes (at most 0.0049), are
// left out and the rest renormalised: 12 taps.
vec3 history_at(vec2 q) {
    vec2 t = q - 0.5;
    vec2 f = fract(t);
    ivec2 base = ivec2(floor(t)) - 1;
    vec4 wx = catmull_rom(f.x);
    vec4 wy = catmull_rom(f.y);
    vec3 sum = vec3(0.0);
    float total = 0.0;
    for (int j = 0; j < 4; j++) {
        for (int i = 0; i < 4; i++) {
            bool corner = (i == 0 || i == 3) && (j == 0 || j == 3);
            if (!corner) {
                float w = wx[i] * wy[j];
                sum += w * history_color(base + ivec2(i, j));
                total += w;
            }
        }
    }
    return max(sum / total, vec3(0.0));
}

// Offset of neighbour k (0..8) in the 3x3 around a pixel, row by row.
ivec2 neighbour(int k) {
    return ivec2(k % 3 - 1, k / 3 - 1);
}

// Whether the history near q saw the surface `id` at the depth it should have had then
// (`expected`, NDC): some pixel of the 3x3 around q holds the same id at a depth within 10%
// in distance ((1 - z) is close to proportional to 1 / distance). Hair is thin: its pixel
// may have held the strand or what is behind it, so the neighbourhood is searched.
bool history_saw(vec2 q, uint id, float expected) {
    ivec2 c = ivec2(floor(q));
    // The centre first: where the history holds the surface, it is usually there.
    for (int k = 0; k < 9; k++) {
        ivec2 d = neighbour((k + 4) % 9);
        {
            uvec2 h = history_in[pixel_count() + index_of(c + d)];
            if (h.x != id) {
                continue;
            }
            if (id == VISIBILITY_EMPTY) {
                return true;
            }
            float ratio = (1.0 - uintBitsToFloat(h.y)) / max(1.0 - expected, 1e-9);
            if (ratio > 0.9 && ratio < 1.1) {
                return true;
            }
        }
    }
    return false;
}

// Clip `h` toward the centre of the box `mean` +- `extent` (YCoCg).
vec3 clip_to_box(vec3 h, vec3 mean, vec3 extent) {
    vec3 d = h - mean;
    vec3 ratio = abs(d) / max(extent, vec3(1e-6));
    float most = max(ratio.x, max(ratio.y, ratio.z));
    return most > 1.0 ? mean + d / most : h;
}

// The accumulated colour of pixel p, whose own visibility word is `own`.
vec3 accumulate(ivec2 p, uint64_t own) {
    vec3 current = current_color(p);
    if (frame.temporal.history_valid == 0u) {
        return current;
    }
    // The nearest surface of the 3x3 neighbourhood moves the pixel: a strand crossing it
    // drags its history along rather than the background behind. The depth leads the word,
    // so the smallest word is the nearest surface.
    uint64_t nearest = own;
    for (int k = 0; k < 9; k++) {
        if (k != 4) {
            nearest = min(nearest, visibility[index_of(p + neighbour(k))]);
        }
    }
    // Nothing drawn around: the clear colour, which needs no history.
    if (visibility_empty(nearest)) {
        return current;
    }
    vec3 m1 = vec3(0.0);
    vec3 m2 = vec3(0.0);
    for (int k = 0; k < 9; k++) {
        vec3 c = to_ycocg(k == 4 ? current : current_color(p + neighbour(k)));
        m1 += c;
        m2 += c * c;
    }
    // Only thin surfaces (hair) lend their motion to their neighbours: a solid's edge pixel
    // that shows what is behind it moves with that, or the solid's silhouette smears out.
    uvec2 near = visibility_surface(nearest);
    if (!is_hair(near.x)) {
        nearest = own;
        near = visibility_surface(nearest);
    }
    vec2 residual = visibility_residual(nearest);
    vec2 centre = vec2(p) + 0.5;
    float depth = uintBitsToFloat(near.y);
    vec4 prev = previous_clip(near.x, centre, depth);
    vec2 q = (prev.xy / prev.w + 1.0) * 0.5 * vec2(image_size()) + residual;
    bool inside = prev.w > 0.0 && all(greaterThanEqual(q, vec2(0.0))) && all(lessThan(q, vec2(image_size())));
    if (!inside || !history_saw(q, near.x, prev.z / prev.w)) {
        return current;
    }
    vec3 mean = m1 / 9.0;
    vec3 sigma = sqrt(max(m2 / 9.0 - mean * mean, vec3(0.0)));
    // Hair keeps a wide clamp (a tight one erases single strands).
    float gamma = is_hair(near.x) ? frame.temporal.hair_clamp : 1.0;
    vec3 h = clip_to_box(to_ycocg(history_at(q)), mean, gamma * sigma + 1e-4);
    // Moving solid surfaces keep a shorter history (less blur and lag on their edges).
    float weight = frame.temporal.history_weight;
    if (!is_hair(near.x)) {
        float moving = clamp(distance(q, centre) / TEMPORAL_SOLID_MOTION, 0.0, 1.0);
        weight = mix(weight, max(weight, TEMPORAL_SOLID_MOVING_WEIGHT), moving);
    }
    return mix(from_ycocg(h), current, weight);
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, image_size()))) {
        return;
    }
    uint i = index_of(p);
    uint64_t word = visibility[i];
    uvec2 own = visibility_surface(word);
    if (push.params.x != 0u) {
        vec2 m = motion_at(own.x, vec2(p) + 0.5, uintBitsToFloat(own.y), visibility_residual(word));
        motion_out[i] = uvec4(floatBitsToUint(m), own);
    }
    if (frame.temporal.accumulate != 0u) {
        vec3 c = accumulate(p, word);
        history_out[i] = uvec2(packHalf2x16(c.rg), packHalf2x16(vec2(c.b, 1.0)));
        history_out[pixel_count() + i] = own;
        frame_color[pixel_count() + i] = packUnorm4x8(vec4(linear_to_srgb(c), 1.0));
    }
}
