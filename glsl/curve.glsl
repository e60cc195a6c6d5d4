// Column curves of the hair mesh (paper 003 sections 2.2 and 3.1): the GLSL twin of
// src/bake/curve.rs. Centripetal Catmull-Rom through the layer vertices -> cubic Bezier ->
// two quadratic Beziers (Truong, Yuksel and Seiler 2020, gamma = 1/2).
#ifndef CURVE_GLSL
#define CURVE_GLSL

#define CATMULL_ROM_ALPHA 0.5

float knot_interval(vec3 a, vec3 b) {
    return max(pow(distance(a, b), CATMULL_ROM_ALPHA), 1e-6);
}

// Cubic Bezier [p1, b0+, b1-, p2] of the Catmull-Rom segment p1 -> p2 (Barry-Goldman form).
void catmull_rom_to_bezier(vec3 p0, vec3 p1, vec3 p2, vec3 p3, out vec3 b[4]) {
    float d0 = knot_interval(p0, p1);
    float d1 = knot_interval(p1, p2);
    float d2 = knot_interval(p2, p3);
    vec3 m1 = (p1 - p0) / d0 - (p2 - p0) / (d0 + d1) + (p2 - p1) / d1;
    vec3 m2 = (p2 - p1) / d1 - (p3 - p1) / (d1 + d2) + (p3 - p2) / d2;
    b[0] = p1;
    b[1] = p1 + m1 * (d1 / 3.0);
    b[2] = p2 - m2 * (d1 / 3.0);
    b[3] = p2;
}

// The first four of the five control points [q0 q1 q2 q3 q4] of the two quadratics.
void cubic_to_quadratics(vec3 b[4], out vec3 q[4]) {
    float gamma = 0.5;
    vec3 q1 = b[0] + (b[1] - b[0]) * (1.5 * gamma);
    vec3 q3 = b[3] + (b[2] - b[3]) * (1.5 * (1.0 - gamma));
    q[0] = b[0];
    q[1] = q1;
    q[2] = q1 * (1.0 - gamma) + q3 * gamma;
    q[3] = q3;
}

#endif
