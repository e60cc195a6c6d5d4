// The camera's opaque depth as the software rasterizer keeps it: one float (0..1) per pixel,
// row by row, copied from the depth target (passes::soft_raster::add_depth_copy) after the
// opaque pass, for the far hair's march, and again before the software raster. Bound when the
// camera's strands go through the software rasterizer (frame.soft.mode != RASTER_HARDWARE).
// Requires bindings.glsl.
#ifndef SOFT_DEPTH_GLSL
#define SOFT_DEPTH_GLSL

layout(set = SET_FRAME, binding = BINDING_SOFT_DEPTH, std430) readonly buffer SoftDepth { float soft_depth[]; };

// Opaque depth at `pixel` of the camera's target.
float opaque_depth_at(uvec2 pixel) {
    return soft_depth[pixel.y * uint(frame.viewport.x) + pixel.x];
}

#endif
