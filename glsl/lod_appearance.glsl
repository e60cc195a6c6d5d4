// Thick-strand appearance under strand LoD (seed 000 sec. 4): a strip standing for n strands
// (n = the width factor min(1/L, N_i) of paper 003 sec. 3.6.1) is shaded as the cluster it
// replaces, not as one fat strand. CPU twin: src/shade/lod_appearance.rs. Off
// (frame.shading.y == 0) it returns the single-strand values.
#ifndef LOD_APPEARANCE_GLSL
#define LOD_APPEARANCE_GLSL

struct ClusterScattering {
    float single;    // factor on the direct (single-scattering) lobes
    float multiple;  // factor on the multiple-scattering (ambient) term
};

ClusterScattering cluster_scattering(float n, vec3 base) {
    ClusterScattering r = ClusterScattering(1.0, 1.0);
    return r;
}

float cluster_opacity(float alpha, float n) {
    return alpha;
}

#endif
