#version 460
// A host frame's hair over the host's colour: the renderer's image holds the hair (and any
// props) premultiplied by coverage over transparent black; blended `ONE, ONE_MINUS_SRC_ALPHA`
// (render/passes/host_targets.rs).

layout(set = 0, binding = 1) uniform sampler2D hair;

layout(location = 0) out vec4 out_color;

void main() {
    out_color = texelFetch(hair, ivec2(gl_FragCoord.xy), 0);
}
