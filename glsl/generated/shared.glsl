// GENERATED from src/render/core/shared.rs by render::shared::glsl_header(); do not edit.
// Shaders are compiled with this text; this copy is for reading.
#ifndef SHARED_GLSL
#define SHARED_GLSL

#define STRAND_GROUP_SIZE 32
#define VOLUME_GROUP_SIZE 32
#define DYNAMICS_GROUP_SIZE_GPU 128
#define DYNAMICS_GROUP_SIZE_CPU 16
#define MAX_VERTS_LOG2 6u
#define MAX_SEGMENTS 64u
#define MESH_MAX_VERTICES 130
#define MESH_MAX_PRIMITIVES 128
#define MAX_STRANDS_PER_BUNDLE 32768u
#define SLICES_PER_SEGMENT 4u
#define BUNDLE_TRIANGLE 1u
#define TASK_PAYLOAD_BUNDLES 32
#define PAYLOAD_LANE_BITS 5u
#define CULL_GROUP_SIZE 64
#define SCAN_THREADS 256
#define SCAN_BLOCK 1024u
#define DISPATCH_ROW 65535u
#define DEFORM_GROUP_SIZE 64
#define LHS_GROUP_SIZE 64
#define SKIN_GROUP_SIZE 64
#define SKIN_NONE 4294967295u
#define MAX_SIM_COLLIDERS 16
#define COLLIDER_ELLIPSOID 0u
#define COLLIDER_CAPSULE 1u
#define COLLIDER_HEAD 2u
#define BEND_COLOURS 2u
#define COLLISION_ROUNDS 16u
#define MAX_SPLAT_POINTS 64u
#define CHARACTER_VISIBLE 1u
#define CHARACTER_VOLUME_ONLY 2u
#define VOLUME_BUILT 1u
#define VOLUME_OCCLUSION 2u
#define VOLUME_SKIP_EMPTY 4u
#define VOLUME_DIMS_BITS 10u
#define BRICK_CELLS 2u
#define DENSITY_PASS_OCCUPANCY 1u
#define MARSCHNER_LUT_PHI 256u
#define MARSCHNER_LUT_D 64u
#define SCATTER_LUT_THETA 32u
#define SHADING_LUT_WIDTH 256u
#define SHADING_LUT_HEIGHT 128u
#define SET_FRAME 0
#define SET_TEXTURES 1
#define SOFT_TILE 16u
#define SOFT_MAX_K 8u
#define SOFT_BIN_GROUP 256
#define LOD_SOFT 256u
#define LOD_DEMAND_UNIT 64u
#define LOD_LEVEL_MASK 255u
#define MAX_OIT_BUDGET 16u
#define STRAND_RAND_THINNING 3u
#define EMPTY_TEXEL 4294967295u
#define SHADING_PLACEHOLDER 0u
#define SHADING_KAJIYA_KAY 1u
#define SHADING_MARSCHNER 2u
#define SHADOW_OFF 0u
#define SHADOW_DEEP_OPACITY 1u
#define SHADOW_APPROXIMATE 2u
#define RASTER_HARDWARE 0u
#define RASTER_SOFTWARE 1u
#define RASTER_AUTO 2u
#define RASTER_LIGHT 3u
#define TRANSPARENCY_OPAQUE 0u
#define TRANSPARENCY_KBUFFER 1u
#define TRANSPARENCY_PEELING 2u
#define VISIBILITY_EMPTY 4294967295u
#define VISIBILITY_PROP 2147483648u
#define VISIBILITY_SOLID 1073741824u
#define VISIBILITY_INDEX 65535u
#define TEMPORAL_GROUP 16u
#define VISIBILITY_DEPTH_SHIFT 6u
#define STRAND_OPACITY 0.7
#define SOFT_HIDDEN_TRANSMITTANCE 0.001953125
#define OIT_FIXED 1024.0
#define LOD_LEAST_PRESSURE 1e-6
#define SHAPE_TIP_LOSS 0.7
#define BOUND_SLACK 1.001
#define BOUND_PAD 0.0001
#define VISIBILITY_RESIDUAL_STEPS 8.0
#define TEMPORAL_SOLID_MOVING_WEIGHT 0.5
#define TEMPORAL_SOLID_MOTION 0.25
#define MARSCHNER_LUT_TRT_SCALE 5.0
#define ROOT_PHONG_SHAPE 0.5
#define HAIR_ETA 1.55
#define KAJIYA_KAY_EXPONENT 80.0
#define MARSCHNER_ENERGY_SCALE 0.9
#define LIGHT_IRRADIANCE 4.5
#define AMBIENT 0.25
#define PROP_ROUGHNESS 0.55
#define PROP_IRRADIANCE 2.5
#define PROP_AMBIENT 0.3
#define FORWARD_DENSITY 0.7
#define BACKWARD_DENSITY 0.7
#define GAP_DENSITY 0.6
#define SHADOW_OPACITY_FIXED 4096.0
#define VOLUME_FIXED 16384.0
#define SPLAT_SPACING 0.5
#define AO_RADIUS_CELLS 2.0
#define MARCH_STEP_CELLS 2.0
#define MARCH_MIN_TRANSMITTANCE 0.01
#define STRAND_SHADOW_OPACITY 0.5
#define SKY_TINT vec3(0.95, 1.1, 1.5)
#define GROUND_TINT vec3(0.62, 0.56, 0.46)
#define BINDING_FRAME 0
#define BINDING_CHARACTERS 1
#define BINDING_BUNDLES 2
#define BINDING_ROOT_SAMPLES 3
#define BINDING_BUNDLE_LODS 4
#define BINDING_BUNDLE_OFFSETS 5
#define BINDING_SCAN_SCRATCH 6
#define BINDING_ARGS 7
#define BINDING_VERTICES 8
#define BINDING_PROP_VERTICES 9
#define BINDING_PROP_INSTANCES 10
#define BINDING_SHADOW_HAIR_DEPTH 11
#define BINDING_SHADOW_PROP_DEPTH 12
#define BINDING_SHADOW_LAYERS 13
#define BINDING_OIT_NODES 14
#define BINDING_OIT_TAIL 15
#define BINDING_PEEL_DEPTH 16
#define BINDING_PEEL_ACCUM 17
#define BINDING_SHADING_LUT 18
#define BINDING_SOFT_SEGMENTS 19
#define BINDING_SOFT_TILES 20
#define BINDING_SOFT_ENTRIES 21
#define BINDING_SOFT_DEPTH 22
#define BINDING_SOFT_SHADOW_DEPTH 23
#define BINDING_SOFT_SHADOW_LAYERS 24
#define BINDING_VISIBILITY 25
#define BINDING_MOTION 26
#define BINDING_FRAME_COLOR 27
#define BINDING_HISTORY_IN 28
#define BINDING_HISTORY_OUT 29
#define BINDING_VERTEX_MOTION 30
#define BINDING_SEGMENT_MOTION 31
#define BINDING_SKIN_REST 32
#define BINDING_SKIN_MATRICES 34
#define BINDING_SKIN_JOBS 35
#define BINDING_SKINNED_VERTICES 36
#define BINDING_ROOT_PROBE 37
#define BINDING_TEX_POSITION 0
#define BINDING_TEX_UV 1
#define BINDING_TEX_W 2
#define BINDING_TEX_U 3
#define BINDING_TEX_V 4
#define DEFORM_PARAMS 0
#define DEFORM_POSITIONS 1
#define DEFORM_TEXEL_VERTEX 2
#define DEFORM_STYLING_OFFSETS 3
#define DEFORM_STYLING_TERMS 4
#define DEFORM_POSITION_TEXELS 5
#define DEFORM_U_TEXELS 6
#define DEFORM_V_TEXELS 7
#define LHS_REST 0
#define LHS_WEIGHTS 1
#define LHS_GUIDE_DELTA 2
#define LHS_OUT 3
// Depth of the hair mesh texture: SLICES_PER_SEGMENT (L - 1) + 1 slices.
#define POSITION_DEPTH(layers) (SLICES_PER_SEGMENT * ((layers) - 1u) + 1u)

struct MeshInfo {
    vec4 pos_origin;
    vec4 pos_extent;
    vec4 uv_origin_extent;
    uvec2 root_size;
    uint layers;
    uint bundle_count;
};

struct HairStyle {
    uint seed;
    float strand_width;
    float tip_width_ratio;
    float taper_power;
    float length_variation;
    float root_ramp;
    float clump_strength;
    float clump_power;
    float curl_radius;
    float curl_frequency;
    float curl_phase_jitter;
    float wave_amplitude;
    float wave_frequency;
    float wave_angle;
    float wave_phase_jitter;
    float frizz_amplitude;
    float frizz_frequency;
    float frizz_power;
    uint density_by_area;
    float color[3];
    float roughness;
    float cuticle_tilt_degrees;
};

struct BundleDesc {
    uvec2 origin;
    uint flags;
    float rest_size;
    float density;
    uint _pad[3];
};

struct LodFields {
    float alpha_strands;
    float alpha_verts;
    float lambda;
    float tan_fov;
    float ortho_height;
    float area_below;
    float strands_per_pixel;
    float _pad;
};

struct CountFields {
    uint bundles;
    uint slots;
    uint lod_on;
    uint vertex_budget;
};

struct ShadingFields {
    uint model;
    uint lod_appearance;
    uint multiple_scattering;
    uint _pad;
};

struct ShadowFields {
    uint mode;
    uint resolution;
    uvec2 _pad;
    float layer_thickness;
    float depth_range;
    float strand_opacity;
    float bias;
};

struct TransparencyFields {
    uint mode;
    uint kbuffer_nodes;
    uint samples;
    uint _pad;
};

struct SoftFields {
    uint mode;
    uint k;
    uint segment_budget;
    uint tile_entry_budget;
    float auto_split_pixels;
    float strand_opacity;
    uvec2 _pad;
    uint tiles_x;
    uint tiles_y;
    uvec2 _pad2;
};

struct TemporalFields {
    uint motion;
    uint accumulate;
    uint history_valid;
    uint residuals;
    vec2 jitter;
    float history_weight;
    float hair_clamp;
};

struct BodyShadowFields {
    float resolution;
    float depth_range;
    float bias;
    float texel;
};

struct FrameBlock {
    mat4 view_proj;
    vec3 eye;
    float pixels_high;
    vec3 to_light;
    float cot_half_fov;
    vec4 viewport;
    vec4 planes[6];
    LodFields lod;
    CountFields counts;
    ShadingFields shading;
    mat4 light_view_proj;
    ShadowFields shadow;
    TransparencyFields transparency;
    SoftFields soft;
    TemporalFields temporal;
    mat4 clip_to_prev;
    mat4 unjittered_view_proj;
    mat4 body_view_proj;
    BodyShadowFields body_shadow;
};

struct CharacterRecord {
    mat4 model;
    MeshInfo mesh;
    HairStyle style;
    uint texture_slot;
    uint first_bundle;
    uint bundle_count;
    uint strands_per_bundle;
    uint verts_log2;
    uint flags;
    float model_scale;
    uint prev_texture_slot;
    mat4 clip_to_prev;
    mat4 world_to_volume;
    uvec4 volume;
    vec4 volume_shading;
};

struct GpuBundle {
    uvec2 origin;
    uint flags;
    float rest_size;
    float density;
    uint character;
    uint local_index;
    uint _pad;
};

struct FrameStats {
    uint bundles_visible;
    uint strands_demanded;
    uint strands_drawn;
    uint triangles_demanded;
    uint triangles_drawn;
    uint vertex_slots_demanded;
    uint vertex_slots_written;
    uint groups;
    uint segments_demanded;
    uint segments_written;
    uint tile_entries_demanded;
    uint tile_entries_written;
    uint soft_demand;
    uint soft_slack;
    uint pool_demand;
    uint pool_slack;
};

struct GenerateArgs {
    uvec4 dispatch;
    uvec4 draw;
    uvec4 soft_dispatch;
    FrameStats stats;
    FrameStats light_stats;
};

struct HairVertex {
    vec4 pos_width;
    vec4 tangent_s;
};

struct SoftSegment {
    vec2 a;
    float za;
    uint dz_id;
    uvec4 b;
};

struct PropVertex {
    vec4 position;
    vec4 normal;
};

struct PropInstance {
    mat4 model;
    vec4 color;
    mat4 clip_to_prev;
    uvec4 skin;
};

struct SkinRestVertex {
    vec3 position;
    uint color;
    vec3 normal;
    uint joints01;
    vec4 weights;
    uvec4 joints23;
};

struct SkinnedVertex {
    vec3 position;
    uint color;
    vec3 normal;
    uint pad;
};

struct SkinJob {
    uint rest_first;
    uint vertex_count;
    uint matrix_first;
    uint out_first;
};

struct TaskPayload {
    uvec4 lods[32];
    uint bundle[32];
    uint place[33];
    uint count;
    uint _pad[2];
};

struct DeformParams {
    vec4 origin;
    vec4 extent;
    uvec4 counts;
};

struct LhsWeights {
    uvec4 guides;
    vec4 weights;
};

struct StylingTerm {
    uint i1;
    uint i2;
    vec2 u;
    vec2 v;
};

struct SimVertex {
    vec4 rest;
    vec4 lengths;
};

struct SimConstraint {
    uint a;
    uint b;
    float rest;
    uint _pad;
};

struct SimCollider {
    uvec4 shape;
    vec4 a;
    vec4 b;
    mat4 to_canonical;
    mat4 to_person;
    vec4 bound;
};

struct SimState {
    vec4 x;
    vec4 v;
};

struct SimJob {
    uvec2 vertices;
    uvec2 spacing;
    uvec2 spacing_colours;
    uvec2 colliders;
    uvec2 state;
    uvec2 pose;
    uvec2 head_map;
    uvec2 solve;
    uvec4 counts;
    uvec4 colours;
    vec4 from_rotation;
    vec4 to_rotation;
    vec4 from_translation;
    vec4 to_translation;
    vec4 from_scale;
    vec4 to_scale;
    vec4 gravity;
    vec4 wind;
    vec4 stiffness;
};

struct DensityJob {
    uvec2 cells;
    uvec2 _pad;
    vec4 origin;
    vec4 cell;
    uvec4 dims;
    uvec4 bundles;
};

struct VolumeCell {
    uint len;
    uint flow[3];
};

#endif
