#version 460
// Hair mesh dynamics on the GPU: the twin of src/dynamics/mod.rs (HairDynamics), one workgroup
// per character, every character of the frame in one dispatch. Each character's buffers are
// reached by device address from its SimJob. Per substep, the phases of the CPU solver in its
// order, separated by workgroup barriers:
//   1. predict (velocities, gravity, wind, damping; the scalp placed rigidly; the XPBD pull
//      toward the authored shape, sag-free: the target sits g / k above the authored place);
//   2. spacing, a colour of constraints at a time (Macklin et al. 2016, eq. 18 per constraint);
//   3. bending, a colour at a time;
//   4. follow-the-leader per column with the colliders' push-out (Mueller et al. 2012);
//   5. velocities with the follow-the-leader correction (Mueller et al. 2012, eq. 9), in the
//      same loop as 4 (a thread owns a column; per-vertex results equal the CPU's).
// Then the pose in the character's frame, which glsl/hair_mesh_update.comp reads.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference_uvec2 : require
#include "shared.glsl"
// Invocations per workgroup, chosen per device (shared.rs): CPU_DEVICE is
// defined on CPU devices (lavapipe).
#ifdef CPU_DEVICE
#define GROUP_SIZE DYNAMICS_GROUP_SIZE_CPU
#else
#define GROUP_SIZE DYNAMICS_GROUP_SIZE_GPU
#endif
layout(local_size_x = GROUP_SIZE) in;

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer Jobs { SimJob jobs[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer Vertices { SimVertex vertices[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer Spacing { SimConstraint constraints[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer Colours { uint first[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer Colliders { SimCollider colliders[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) coherent buffer States { SimState states[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) coherent buffer Solve { vec4 p[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) writeonly buffer Poses { vec4 poses[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer HeadMap { float radius[]; };

// The frame's job table and its length.
layout(push_constant) uniform Push {
    uvec2 jobs;
    uint count;
    uint pad;
} push;

const float PI = 3.14159265358979;
const float TAU = 6.28318530717959;

SimJob job;
Vertices verts;
States st;
// The substep's positions being solved.
Solve sol;
// The character's colliders, loaded once per dispatch.
shared SimCollider colliders[MAX_SIM_COLLIDERS];
// The colliders' bounding spheres placed for the substep (xyz centre, w radius squared, padded).
shared vec4 world_bounds[MAX_SIM_COLLIDERS];

// Workgroup barrier that also makes this workgroup's buffer writes visible to it.
void sync() {
    memoryBarrierBuffer();
    barrier();
}

// ---- Placements (src/dynamics/placement.rs) ----

struct Placement {
    vec3 scale;
    vec4 rotation;
    vec3 translation;
};

vec3 rotate(vec4 q, vec3 v) {
    return v + 2.0 * cross(q.xyz, cross(q.xyz, v) + q.w * v);
}

vec4 slerp(vec4 a, vec4 b, float f) {
    float d = dot(a, b);
    if (d < 0.0) {
        d = -d;
        b = -b;
    }
    if (d > 0.9995) {
        return normalize(a * (1.0 - f) + b * f);
    }
    float theta = acos(d);
    float s = sin(theta);
    return a * (sin((1.0 - f) * theta) / s) + b * (sin(f * theta) / s);
}

Placement placement_at(float f) {
    Placement p;
    p.scale = mix(job.from_scale.xyz, job.to_scale.xyz, f);
    p.rotation = slerp(job.from_rotation, job.to_rotation, f);
    p.translation = mix(job.from_translation.xyz, job.to_translation.xyz, f);
    return p;
}

vec3 apply(Placement p, vec3 x) {
    return p.translation + rotate(p.rotation, p.scale * x);
}

vec3 unapply(Placement p, vec3 x) {
    return rotate(vec4(-p.rotation.xyz, p.rotation.w), x - p.translation) / p.scale;
}

// ---- Forces (Wind::acceleration) ----

vec3 wind_acceleration(vec3 p, float t, float along) {
    float strength = job.wind.w;
    if (strength <= 0.0) {
        return vec3(0.0);
    }
    vec3 dir = job.wind.xyz;
    float s = dot(p, dir) * 2.0 - t;
    float gust = 1.0 + job.gravity.w * (0.6 * sin(1.7 * s) + 0.4 * sin(4.3 * s + 1.3));
    float across = 0.15 * sin(3.1 * p.y + 2.3 * t);
    return (dir + vec3(0.0, 1.0, 0.0) * across) * (strength * gust * (0.3 + 0.7 * along));
}

// ---- Colliders (src/dynamics/collider.rs) ----

float map_sample(vec3 d) {
    HeadMap map = HeadMap(job.head_map);
    uint rows = job.colours.y;
    uint cols = job.colours.z;
    float theta = acos(clamp(d.y, -1.0, 1.0));
    float phi = atan(d.z, d.x);
    if (phi < 0.0) {
        phi += TAU;
    }
    float y = theta / PI * float(rows - 1u);
    float x = phi / TAU * float(cols);
    uint r0 = min(uint(floor(y)), rows - 2u);
    float fy = fract(y);
    uint c0 = uint(floor(x)) % cols;
    float fx = fract(x);
    uint c1 = (c0 + 1u) % cols;
    float top = map.radius[r0 * cols + c0] * (1.0 - fx) + map.radius[r0 * cols + c1] * fx;
    float bottom = map.radius[(r0 + 1u) * cols + c0] * (1.0 - fx) + map.radius[(r0 + 1u) * cols + c1] * fx;
    return top * (1.0 - fy) + bottom * fy;
}

// `p` pushed out of collider `i` (reading only the fields its kind uses).
vec3 push_out(uint i, vec3 p) {
    uint kind = colliders[i].shape.x;
    vec4 a = colliders[i].a;
    vec3 b = colliders[i].b.xyz;
    if (kind == COLLIDER_ELLIPSOID) {
        vec3 q = (p - a.xyz) / b;
        float l = length(q);
        return l >= 1e-9 && l < 1.0 ? a.xyz + q / l * b : p;
    }
    if (kind == COLLIDER_CAPSULE) {
        vec3 ab = b - a.xyz;
        float t = clamp(dot(p - a.xyz, ab) / max(dot(ab, ab), 1e-12), 0.0, 1.0);
        vec3 centre = a.xyz + ab * t;
        vec3 d = p - centre;
        float l = length(d);
        return l >= a.w || l < 1e-9 ? p : centre + d / l * a.w;
    }
    // A radial-map head, in its canonical frame (b: the map's centre, a.w: the margin).
    vec3 q = (colliders[i].to_canonical * vec4(p, 1.0)).xyz;
    vec3 r = q - b;
    float l = length(r);
    vec3 d = l < 1e-9 ? vec3(0.0, 1.0, 0.0) : r / l;
    float least = map_sample(d) + a.w;
    if (l >= least) {
        return p;
    }
    return (colliders[i].to_person * vec4(b + d * least, 1.0)).xyz;
}

// dynamics::placed_bounds: thread i < colliders places collider i's bounding sphere for the
// substep, padded against rounding, so a point outside every sphere is outside every collider.
void place_bounds(Placement pl) {
    uint i = gl_LocalInvocationID.x;
    if (i < job.counts.w) {
        vec4 b = colliders[i].bound;
        vec3 s = abs(pl.scale);
        float r = b.w * max(s.x, max(s.y, s.z)) * BOUND_SLACK + BOUND_PAD;
        world_bounds[i] = vec4(apply(pl, b.xyz), r * r);
    }
}

// `p` pushed out of every collider at placement `pl` (bit-for-bit unchanged if outside). A
// point outside every bounding sphere skips the exact test, whose result would be `p` itself.
vec3 collide(vec3 p, Placement pl) {
    bool near = false;
    for (uint i = 0u; i < job.counts.w; i++) {
        vec3 d = p - world_bounds[i].xyz;
        near = near || dot(d, d) <= world_bounds[i].w;
    }
    if (!near) {
        return p;
    }
    vec3 local = unapply(pl, p);
    vec3 moved = local;
    for (uint i = 0u; i < job.counts.w; i++) {
        moved = push_out(i, moved);
    }
    return moved == local ? p : apply(pl, moved);
}

// ---- Phases ----

// A column per thread (no integer division on the way).
void predict(Placement pl, float h, float t) {
    uint n = job.counts.x;
    uint layers = job.counts.y;
    float keep = job.from_scale.w;
    for (uint i = gl_LocalInvocationID.x; i < n; i += GROUP_SIZE) {
        sol.p[i].xyz = apply(pl, verts.vertices[i].rest.xyz);
        for (uint k = 1u; k < layers; k++) {
            uint j = k * n + i;
            float along = float(k) / float(layers - 1u);
            float stiffness = job.stiffness.x * (1.0 - SHAPE_TIP_LOSS * along);
            vec3 x = st.states[j].x.xyz;
            vec3 acc = job.gravity.xyz + wind_acceleration(x, t, along);
            vec3 v = (st.states[j].v.xyz + acc * h) * keep;
            vec3 q = x + v * h;
            if (stiffness > 0.0) {
                float alpha = 1.0 / (stiffness * h * h);
                vec3 target = apply(pl, verts.vertices[j].rest.xyz) - job.gravity.xyz / stiffness;
                q -= (q - target) / (1.0 + alpha);
            }
            sol.p[j].xyz = q;
        }
    }
}

// XPBD distance constraint between vertices a, b (inverse masses wa, wb).
void distance_constraint(uint a, float wa, uint b, float wb, float rest, float alpha) {
    vec3 pa = sol.p[a].xyz;
    vec3 pb = sol.p[b].xyz;
    vec3 d = pa - pb;
    float l = length(d);
    if (l < 1e-9 || wa + wb <= 0.0) {
        return;
    }
    float lambda = -(l - rest) / (wa + wb + alpha);
    vec3 corr = d / l * lambda;
    sol.p[a].xyz = pa + corr * wa;
    sol.p[b].xyz = pb - corr * wb;
}

void spacing(float h) {
    Spacing sp = Spacing(job.spacing);
    Colours colours = Colours(job.spacing_colours);
    float alpha = job.stiffness.y / (h * h);
    for (uint c = 0u; c < job.colours.x; c++) {
        // Read once: the stores through `sol` could alias the colour table for the compiler.
        uint end = colours.first[c + 1u];
        for (uint i = colours.first[c] + gl_LocalInvocationID.x; i < end; i += GROUP_SIZE) {
            SimConstraint con = sp.constraints[i];
            distance_constraint(con.a, 1.0, con.b, 1.0, con.rest, alpha);
        }
        sync();
    }
}

// dynamics::bend_colour: the constraint of layer k (to layer k - 2) has colour (k / 2) % 2. A
// column per thread.
void bending(float h) {
    uint n = job.counts.x;
    uint layers = job.counts.y;
    float alpha = job.stiffness.z / (h * h);
    for (uint colour = 0u; colour < BEND_COLOURS; colour++) {
        for (uint i = gl_LocalInvocationID.x; i < n; i += GROUP_SIZE) {
            for (uint k = 2u; k < layers; k++) {
                if ((k / 2u) % 2u != colour) {
                    continue;
                }
                uint j = k * n + i;
                // The scalp (layer 0) does not move: weight 0.
                float w_below = k == 2u ? 0.0 : 1.0;
                distance_constraint(j, 1.0, j - 2u * n, w_below, verts.vertices[j].lengths.y, alpha);
            }
        }
        sync();
    }
}

vec3 on_edge(vec3 q, vec3 base, float edge) {
    vec3 v = q - base;
    float rcp = 1.0 / length(v);
    // glam's try_normalize: fails for a zero or non-finite length.
    vec3 dir = !isinf(rcp) && !isnan(rcp) && rcp > 0.0 ? v * rcp : vec3(0.0, 1.0, 0.0);
    return base + dir * edge;
}

// Follow-the-leader (phase 4) and the velocities (phase 5) of a column per thread: vertex k's
// velocity needs the correction of vertex k + 1 of the same column, so it is finished one
// vertex behind.
void follow_the_leader(Placement pl, float h) {
    uint n = job.counts.x;
    uint layers = job.counts.y;
    float ftl = job.stiffness.w;
    for (uint i = gl_LocalInvocationID.x; i < n; i += GROUP_SIZE) {
        vec3 base = sol.p[i].xyz;
        st.states[i].x.xyz = base;
        for (uint k = 1u; k < layers; k++) {
            uint j = k * n + i;
            float edge = verts.vertices[j].lengths.x;
            vec3 p = sol.p[j].xyz;
            vec3 q = on_edge(collide(p, pl), base, edge);
            bool settled = false;
            for (uint r = 0u; r < COLLISION_ROUNDS; r++) {
                vec3 out_ = collide(q, pl);
                if (out_ == q) {
                    settled = true;
                    break;
                }
                q = on_edge(out_, base, edge);
            }
            if (!settled) {
                q = collide(q, pl);
            }
            if (k >= 2u) {
                // The vertex below: its velocity less this vertex's correction (eq. 9).
                uint below = j - n;
                vec3 v = (base - st.states[below].x.xyz) / h;
                v -= (q - p) * (ftl / h);
                st.states[below].v.xyz = v;
                st.states[below].x.xyz = base;
            }
            if (k + 1u == layers) {
                st.states[j].v.xyz = (q - st.states[j].x.xyz) / h;
                st.states[j].x.xyz = q;
            }
            base = q;
        }
    }
}

void main() {
    uint index = gl_WorkGroupID.y * DISPATCH_ROW + gl_WorkGroupID.x;
    if (index >= push.count) {
        return;
    }
    job = Jobs(push.jobs).jobs[index];
    verts = Vertices(job.vertices);
    st = States(job.state);
    sol = Solve(job.solve);
    if (gl_LocalInvocationID.x < job.counts.w) {
        colliders[gl_LocalInvocationID.x] = Colliders(job.colliders).colliders[gl_LocalInvocationID.x];
    }
    barrier();
    uint substeps = job.counts.z;
    float h = job.to_translation.w;
    for (uint s = 1u; s <= substeps; s++) {
        Placement pl = placement_at(float(s) / float(substeps));
        place_bounds(pl);
        predict(pl, h, job.from_translation.w + h * float(s));
        sync();
        spacing(h);
        bending(h);
        follow_the_leader(pl, h);
        sync();
    }
    // The pose in the character's frame at the step's end.
    Placement to;
    to.scale = job.to_scale.xyz;
    to.rotation = job.to_rotation;
    to.translation = job.to_translation.xyz;
    Poses poses = Poses(job.pose);
    uint total = job.counts.x * job.counts.y;
    for (uint j = gl_LocalInvocationID.x; j < total; j += GROUP_SIZE) {
        poses.poses[j] = vec4(unapply(to, st.states[j].x.xyz), verts.vertices[j].rest.w);
    }
}
