// Camera-facing strip expansion shared by strands.vert (compute path) and strands.mesh.
// Strands thinner than one pixel are widened to one pixel so they do not break into dots.
#ifndef STRIP_GLSL
#define STRIP_GLSL

vec3 strip_offset(vec3 pos, vec3 tangent, float width, float side) {
    vec3 to_eye = frame.camera_pos.xyz - pos;
    float dist = length(to_eye);
    vec3 across = cross(tangent, to_eye / max(dist, 1e-6));
    across = length(across) > 1e-6 ? normalize(across) : normalize(cross(tangent, vec3(0.0, 0.0, 1.0)) + 1e-6);
    float pixel = frame.light_dir.w > 0.0 ? 2.0 * dist / (frame.camera_pos.w * frame.light_dir.w) : 0.0;
    return pos + across * (side * 0.5 * max(width, pixel));
}

#endif
