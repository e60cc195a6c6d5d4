#version 460
// The volume tier's far hair (seed 002, vkhr sec. 4; CPU twin of the march:
// src/shade/volume.rs march): the view ray through the fragment is marched front to back
// through the character's density volume (strands of the frame's opacity, Poisson placed:
// each step absorbs 1 - exp(-sigma ds) of what is left), and the strands are shaded once, at
// the absorption-weighted mean point with the mean flow as tangent, lit through the light's
// maps and, when the character has no strands in them (volume alone), through its own volume.
// Written premultiplied over the target with the mean point's depth, at the volume tier's
// weight (1 for hair drawn as its volume alone; in the switch band, where the strands thin
// out, less).
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
#include "strand_radiance.glsl"
#include "temporal.glsl"
#include "soft_depth.glsl"

layout(location = 0) in vec3 in_world;
layout(location = 1) flat in uint in_character;
layout(location = 0) out vec4 out_color;

// Most march steps of one pixel.
#define MAX_MARCH_STEPS 512u

void main() {
    uint c = in_character;
    float weight = volume_weight(c);
    if (weight <= 0.0) {
        discard;
    }
    vec3 eye = frame.eye;
    vec3 dir = normalize(in_world - eye);
    mat4 to_grid = characters[c].world_to_volume;
    vec3 g0 = (to_grid * vec4(eye, 1.0)).xyz;
    vec3 gd = (to_grid * vec4(dir, 0.0)).xyz;
    vec2 span = volume_span(c, g0, gd);
    float t_enter = span.x;
    float t_exit = span.y;
    // Only the box's far side is rasterized (front faces culled): each pixel it covers once,
    // the eye outside the box or inside it.
    if (t_exit <= max(t_enter, 0.0)) {
        discard;
    }
    // With the software rasterizer the opaque depth (bodies, hardware strands) is at hand
    // (soft_depth.glsl): the march ends at the surface the pixel shows, so hair behind a head
    // is not counted in front of it, and a pixel whose box lies behind that surface is left
    // at once (the depth test would reject whatever it found). The band's depth stays the
    // box's exit (below).
    float t_box_exit = t_exit;
    if (frame.soft.mode != RASTER_HARDWARE) {
        t_exit = min(t_exit, ray_length_to_depth(eye, dir, opaque_depth_at(uvec2(gl_FragCoord.xy))));
        if (t_exit <= max(t_enter, 0.0)) {
            discard;
        }
    }
    float scale = characters[c].model_scale;
    float step = MARCH_STEP_CELLS * characters[c].volume_shading.y * scale;
    // The frame's opacity of one strand: opaque frames draw whole strands.
    float alpha = frame.transparency.mode == TRANSPARENCY_OPAQUE ? 1.0 : STRAND_OPACITY;
    float t0 = max(t_enter, 0.0);
    uint steps = min(uint(ceil((t_exit - t0) / step)), MAX_MARCH_STEPS);
    float transmittance = 1.0;
    vec3 point = vec3(0.0);
    vec3 flow = vec3(0.0);
    // Empty bricks are skipped (shade::volume::march_masked): their samples are exactly 0.
    uvec3 dims = volume_dims(c);
    bool skip = (characters[c].volume.w & VOLUME_SKIP_EMPTY) != 0u;
    uint i = 0u;
    while (i < steps) {
        float ds = min(step, t_exit - t0 - float(i) * step);
        float t = t0 + float(i) * step + 0.5 * ds;
        uvec3 brick = volume_brick(dims, g0 + gd * t);
        if (skip && !brick_occupied(c, dims, brick)) {
            float leave = brick_exit(g0, gd, brick);
            float next = clamp(ceil((leave - t0) / step - 0.5), 0.0, float(steps));
            i = max(i + 1u, uint(next));
            continue;
        }
        i++;
        vec4 s = volume_sample(c, g0 + gd * t);
        if (s.x <= 0.0) {
            continue;
        }
        // s.x is density times width in object units: the world step over the scale.
        float a = transmittance * (1.0 - exp(-alpha * s.x * ds / scale));
        point += (eye + dir * t) * a;
        flow += s.yzw * a;
        transmittance -= a;
        if (transmittance < MARCH_MIN_TRANSMITTANCE) {
            break;
        }
    }
    float absorbed = 1.0 - transmittance;
    if (absorbed < 0.5 / 255.0) {
        discard;
    }
    point /= absorbed;
    vec3 tangent = mat3(characters[c].model) * flow;
    if (dot(tangent, tangent) < 1e-20) {
        tangent = vec3(0.0, -1.0, 0.0);
    }
    vec3 l = normalize(frame.to_light);
    vec3 arrival = light_arrival(point, 0.0);
    if ((characters[c].flags & CHARACTER_VOLUME_ONLY) != 0u) {
        // Through its own hair too: hits add, transmittances multiply.
        float own = volume_light(c, point, l);
        arrival.x *= own;
        arrival.z += -log(max(own, 1e-6));
    }
    HairStyle style = characters[c].style;
    vec3 base = vec3(style.color[0], style.color[1], style.color[2]);
    vec3 radiance = strand_radiance_lit(tangent, 1.0, point, base, c, 1.0, arrival, volume_ambient(c, point));
    // In the band the volume lies under the strands that remain: its depth is where the ray
    // leaves the box, so strands drawn before (hardware) hide it and strands composited after
    // (the software rasterizer's) are not hidden by it.
    vec3 depth_point = weight < 1.0 ? eye + dir * t_box_exit : point;
    vec4 clip = frame.view_proj * vec4(depth_point, 1.0);
    float depth = clamp(clip.z / clip.w, 0.0, 1.0);
    gl_FragDepth = depth;
    note_visible(uvec2(gl_FragCoord.xy), depth, c, vec2(0.0));
    // In the switch band the volume comes in at its weight under the strands thinning out
    // (bundle_lod.glsl), so the two blend with no pattern.
    out_color = vec4(radiance * absorbed, absorbed) * weight;
}
