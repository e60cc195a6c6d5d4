#version 460
// Strand density volumes (seed 002, vkhr): the twin of src/reference/volume.rs. One workgroup
// per (bundle, job): each invocation generates a strand of the bundle's first `sampled` ones
// with the generator's own evaluation (strand_eval.glsl) and splats every segment's length,
// weighted by the strands it stands for, trilinearly into the job's cells at points no more
// than SPLAT_SPACING of a cell apart. Cells (VolumeCell) hold fixed-point strand length and
// flow (VOLUME_FIXED per object unit; the flow's components as two's complement); the one
// after the grid gathers the length that fell outside. A second dispatch
// (DENSITY_PASS_OCCUPANCY, a workgroup per job) writes each job's occupancy mask after that
// cell, a bit per brick (the twin of reference::volume::occupancy_of): volume_hair.frag skips
// the bricks it leaves clear.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference_uvec2 : require
#include "bindings.glsl"
layout(local_size_x = VOLUME_GROUP_SIZE) in;
#include "common.glsl"
#include "strand_eval.glsl"

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer DensityJobs { DensityJob jobs[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer Cells { VolumeCell cells[]; };

DensityJob job;
Cells cells;

// volume::DensityVolume::splat, in fixed point.
void splat(vec3 p, float length, vec3 along) {
    uvec3 dims = job.dims.xyz;
    vec3 g = (p - job.origin.xyz) / job.cell.xyz - vec3(0.5);
    vec3 base = floor(g);
    vec3 f = g - base;
    for (uint corner = 0u; corner < 8u; corner++) {
        uvec3 o = uvec3(corner & 1u, (corner >> 1u) & 1u, corner >> 2u);
        vec3 w = mix(vec3(1.0) - f, f, vec3(o));
        float weight = w.x * w.y * w.z;
        uint add = uint(round(length * weight * VOLUME_FIXED));
        vec3 c = base + vec3(o);
        if (all(greaterThanEqual(c, vec3(0.0))) && all(lessThan(c, vec3(dims)))) {
            uvec3 u = uvec3(c);
            uint index = (u.z * dims.y + u.y) * dims.x + u.x;
            uvec3 flow = uvec3(ivec3(round(along * (weight * VOLUME_FIXED))));
            if (add != 0u) {
                atomicAdd(cells.cells[index].len, add);
            }
            if (flow.x != 0u) {
                atomicAdd(cells.cells[index].flow[0], flow.x);
            }
            if (flow.y != 0u) {
                atomicAdd(cells.cells[index].flow[1], flow.y);
            }
            if (flow.z != 0u) {
                atomicAdd(cells.cells[index].flow[2], flow.z);
            }
        } else if (add != 0u) {
            atomicAdd(cells.cells[dims.x * dims.y * dims.z].len, add);
        }
    }
}

// volume::DensityVolume::splat_segment.
void splat_segment(vec3 a, vec3 b, float weight) {
    float length = distance(a, b);
    float step = SPLAT_SPACING * min(job.cell.x, min(job.cell.y, job.cell.z));
    uint n = clamp(uint(ceil(length / step)), 1u, MAX_SPLAT_POINTS);
    float share = weight / float(n);
    for (uint i = 0u; i < n; i++) {
        float t = (float(i) + 0.5) / float(n);
        splat(a + (b - a) * t, length * share, (b - a) * share);
    }
}

layout(buffer_reference, std430, buffer_reference_align = 16) buffer Words { uint words[]; };

// reference::volume::occupancy_of, a brick per invocation: set where a cell from
// k * BRICK_CELLS - 1 to (k + 1) * BRICK_CELLS (per axis) holds strand length. The words
// follow the cells and the one after them, cleared with them.
void write_occupancy() {
    uvec3 dims = job.dims.xyz;
    uvec3 bricks = (dims + uvec3(BRICK_CELLS - 1u)) / BRICK_CELLS;
    uint cells_after = dims.x * dims.y * dims.z + 1u;
    Words words = Words(job.cells);
    uint total = bricks.x * bricks.y * bricks.z;
    for (uint b = gl_LocalInvocationID.x; b < total; b += VOLUME_GROUP_SIZE) {
        uvec3 k = uvec3(b % bricks.x, (b / bricks.x) % bricks.y, b / (bricks.x * bricks.y));
        ivec3 lo = max(ivec3(k * BRICK_CELLS) - 1, ivec3(0));
        ivec3 hi = min(ivec3((k + 1u) * BRICK_CELLS), ivec3(dims) - 1);
        bool filled = false;
        for (int z = lo.z; z <= hi.z && !filled; z++) {
            for (int y = lo.y; y <= hi.y && !filled; y++) {
                for (int x = lo.x; x <= hi.x && !filled; x++) {
                    filled = cells.cells[(uint(z) * dims.y + uint(y)) * dims.x + uint(x)].len != 0u;
                }
            }
        }
        if (filled) {
            atomicOr(words.words[cells_after * 4u + (b >> 5u)], 1u << (b & 31u));
        }
    }
}

void main() {
    job = DensityJobs(push.params.xy).jobs[gl_WorkGroupID.y];
    if (push.params.w == DENSITY_PASS_OCCUPANCY) {
        cells = Cells(job.cells);
        write_occupancy();
        return;
    }
    uint local = gl_WorkGroupID.x;
    if (local >= job.bundles.y) {
        return;
    }
    uint g = job.bundles.x + local;
    bind_character(job.dims.w);
    cells = Cells(job.cells);
    // generate::strands_in_bundle (as bundle_lod.glsl), for the character's own N.
    uint n = ch_strands;
    uint strands = style.density_by_area != 0u ? uint(round(float(n) * bundles[g].density)) : n;
    strands = clamp(strands, 1u, MAX_STRANDS_PER_BUNDLE);
    uint sampled = min(strands, max(job.bundles.z, 1u));
    float weight = float(strands) / float(sampled);
    uint segments = 1u << job.bundles.w;
    for (uint strand = gl_LocalInvocationID.x; strand < sampled; strand += VOLUME_GROUP_SIZE) {
        StrandInfo si = strand_info(g, strand);
        vec3 a = strand_vertex(si, 0u, segments);
        for (uint k = 1u; k <= segments; k++) {
            vec3 b = strand_vertex(si, k, segments);
            splat_segment(a, b, weight);
            a = b;
        }
    }
}
