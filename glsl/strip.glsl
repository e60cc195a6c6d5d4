// Camera-facing strip expansion shared by strands.vert (compute path) and strands.mesh, for
// perspective views (the camera) and orthographic ones (the light: frame.cot_half_fov == 0,
// facing frame.to_light). A strand thinner than one pixel is drawn one pixel wide so it does
// not break into dots; strip_coverage says which fraction of the drawn strip the strand really
// covers (coverage to alpha, seed 002), for passes that accumulate opacity.
#ifndef STRIP_GLSL
#define STRIP_GLSL
#include "lod_appearance.glsl"

// World size of one pixel at `pos`.
float pixel_size(vec3 pos) {
    if (frame.cot_half_fov > 0.0) {
        return 2.0 * length(frame.eye - pos) / (frame.pixels_high * frame.cot_half_fov);
    }
    return frame.lod.ortho_height / frame.pixels_high;
}

// Width the strip is drawn with: the strand's (LoD-thickened) width, at least one pixel; with
// the thick-strand term, at least the pixels of the `thickness` one-pixel strips it stands for
// (sqrt(k) pixels), capped by the bundle's size `cap` (lod_appearance.glsl).
float drawn_width(vec3 pos, float width, float thickness, float cap) {
    // A strip's single strand is drawn at least a pixel wide at full detail, so its cluster's
    // footprint counts pixels.
    float pixel = pixel_size(pos);
    float single = max(width / max(thickness, 1.0), pixel);
    return max(width, cluster_min_width(pixel, thickness, cap, single));
}

vec3 strip_offset(vec3 pos, vec3 tangent, float drawn, float side) {
    vec3 to_eye = frame.cot_half_fov > 0.0 ? normalize(frame.eye - pos) : frame.to_light;
    vec3 across = cross(tangent, to_eye);
    across = length(across) > 1e-6 ? normalize(across) : normalize(cross(tangent, vec3(0.0, 0.0, 1.0)) + 1e-6);
    return pos + across * (side * 0.5 * drawn);
}

// Fraction of the drawn strip the strand covers: 1 when wider than a pixel.
float strip_coverage(float width, float drawn) {
    return clamp(width / max(drawn, 1e-12), 0.0, 1.0);
}

#endif
