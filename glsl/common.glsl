// Hashes and noise shared by every shader; bit-exact twins of src/rng.rs and src/reference/generate.rs.
#ifndef COMMON_GLSL
#define COMMON_GLSL

// PCG output permutation (src/rng.rs: hash_u32).
uint hash_u32(uint x) {
    uint state = x * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// [0, 1) with 24 bits (src/rng.rs: hash_f32).
float hash_f32(uint x) {
    return float(hash_u32(x) >> 8u) * (1.0 / 16777216.0);
}

// src/reference/generate.rs: strand_key / strand_rand / value_noise.
uint strand_key(uint seed, uint bundle, uint strand) {
    return hash_u32(hash_u32(bundle ^ hash_u32(seed)) + strand);
}

float strand_rand(uint key, uint slot) {
    return hash_f32(key + slot * 0x9E3779B9u);
}

float value_noise(uint key, float x) {
    float i = floor(x);
    float f = x - i;
    uint ii = uint(i);
    float a = hash_f32(key + hash_u32(ii));
    float b = hash_f32(key + hash_u32(ii + 1u));
    float s = f * f * (3.0 - 2.0 * f);
    return (a + (b - a) * s) * 2.0 - 1.0;
}

#endif
