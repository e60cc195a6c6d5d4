// Thick-strand appearance under strand LoD (seed 000 sec. 4, the aggregated idea): a strip
// that stands for k strands (k = the width factor min(1/L, N_i) of paper 003 sec. 3.6.1)
// should look like the cluster it replaces, not like one fat strand. CPU twin:
// src/shade/lod_appearance.rs. Switched by frame.shading.lod_appearance (off: single-strand behaviour).
//
// - Footprint: seed 000 models a cluster as a cylinder holding n strands of radius r at packing
//   density rho, so its diameter is 2 r sqrt(n / rho). A strand is drawn at most one pixel
//   wide where it is wider (hardware strips are drawn at least that wide), else its own width,
//   so a cluster of k strands is drawn at least sqrt(k) times that (rho = 1), never wider than
//   its bundle. (For strands a pixel wide, one pixel lets the background through: measured
//   +18-24% luminance for opaque hair at mid/far distance; k pixels, strands side by side,
//   over-covers: -22-24%. Real hair, a tenth of a millimetre, is far under a pixel: its k
//   strands' eq. 8 width, k times its own, is more than sqrt(k) times it, and the term leaves
//   it alone.)
// - Opacity: the k strands lie across the strip independently, each covering c / k of it
//   (c = the strip's coverage, so about sqrt(k) strands along a ray, seed 000's n), and light
//   through a point passes (1 - a1 c / k)^k rather than (1 - a1 c): exact at k = 1, the
//   Poisson limit exp(-a1 c) for large k.
// - Multiple scattering (with frame.shading.multiple_scattering): seed 000's aggregated BCSDF (eqs. 7-11) in
//   hair_shading.glsl's dual_scattering, with the strands a ray crosses in the cluster
//   (cluster_crossings).
#ifndef LOD_APPEARANCE_GLSL
#define LOD_APPEARANCE_GLSL

// Least drawn width of a strip of `thickness` strands each `single` wide: one pixel, or with
// the term sqrt(k) times the smaller of a pixel and `single`, at most `cap` (its bundle's
// size), never less than one pixel.
float cluster_min_width(float pixel, float thickness, float cap, float single) {
    if (frame.shading.lod_appearance == 0u) {
        return pixel;
    }
    return max(pixel, min(sqrt(max(thickness, 1.0)) * min(pixel, single), cap));
}

// Strands of a strip's cluster that a ray crosses: sqrt(k) at packing density 1 (seed 000's
// n; 1 for a single strand or with the term off).
float cluster_crossings(float thickness) {
    if (frame.shading.lod_appearance == 0u) {
        return 1.0;
    }
    return sqrt(max(thickness, 1.0));
}

// Opacity of a strip of `thickness` strands whose single-strand opacity over the pixel is
// `alpha` (strand opacity x coverage).
float cluster_opacity(float alpha, float thickness) {
    if (frame.shading.lod_appearance == 0u || thickness <= 1.0) {
        return alpha;
    }
    return 1.0 - pow(max(1.0 - alpha / thickness, 0.0), thickness);
}

#endif
