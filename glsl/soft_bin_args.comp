#version 460
// Software rasterizer, after generation (one invocation): segments stored (the budget caps
// what generation appended) and the binning passes' indirect dispatch.
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
layout(local_size_x = 1) in;

void main() {
    uint n = min(args.stats.segments_demanded, frame.soft.segment_budget);
    args.stats.segments_written = n;
    uint groups = (n + uint(SOFT_BIN_GROUP) - 1u) / uint(SOFT_BIN_GROUP);
    args.soft_dispatch = uvec4(min(groups, DISPATCH_ROW), (groups + DISPATCH_ROW - 1u) / DISPATCH_ROW, 1u, 0u);
}
