#pragma once
// GLSL ES 3.00 sources of the renderer's four programs.

namespace marionette::render::shaders {

// Puppet: capsules skinned on the GPU, up to 4 weights, bones in a uniform block.
inline constexpr const char* kSkinnedVertex = R"(#version 300 es
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in uvec4 a_joints;
layout(location = 3) in vec4 a_weights;
layout(location = 4) in float a_part;
layout(std140) uniform Bones { mat4 u_bones[64]; };
uniform mat4 u_view_projection;
uniform vec3 u_part_colours[3];
out vec3 v_normal;
out vec3 v_colour;
void main() {
    mat4 skin = a_weights.x * u_bones[a_joints.x] + a_weights.y * u_bones[a_joints.y] +
                a_weights.z * u_bones[a_joints.z] + a_weights.w * u_bones[a_joints.w];
    vec4 world = skin * vec4(a_position, 1.0);
    v_normal = mat3(skin) * a_normal;
    v_colour = u_part_colours[int(a_part + 0.5)];
    gl_Position = u_view_projection * world;
}
)";

inline constexpr const char* kSkinnedFragment = R"(#version 300 es
precision mediump float;
in vec3 v_normal;
in vec3 v_colour;
uniform vec3 u_sun;
out vec4 o_colour;
void main() {
    vec3 n = normalize(v_normal);
    float diffuse = max(dot(n, u_sun), 0.0);
    float sky = 0.5 + 0.5 * n.y;
    o_colour = vec4(v_colour * (0.22 + 0.25 * sky + 0.65 * diffuse), 1.0);
}
)";

// Terrain: colour by part, a 0.5 m checker and 1 m grid lines on the ground so
// motion and step edges read, a blob shadow under the puppet.
inline constexpr const char* kTerrainVertex = R"(#version 300 es
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in float a_part;
uniform mat4 u_view_projection;
out vec3 v_world;
out vec3 v_normal;
flat out int v_part;
void main() {
    v_world = a_position;
    v_normal = a_normal;
    v_part = int(a_part + 0.5);
    gl_Position = u_view_projection * vec4(a_position, 1.0);
}
)";

inline constexpr const char* kTerrainFragment = R"(#version 300 es
precision highp float;
in vec3 v_world;
in vec3 v_normal;
flat in int v_part;
uniform vec3 u_part_colours[3];
uniform vec3 u_sun;
uniform vec3 u_shadow_centre;
uniform vec3 u_sky;
uniform vec3 u_eye;
out vec4 o_colour;
void main() {
    vec3 n = normalize(v_normal);
    vec3 base = u_part_colours[v_part];
    vec2 cell = floor(v_world.xz / 0.5);
    float checker = mod(cell.x + cell.y, 2.0) < 0.5 ? 1.0 : 0.88;
    vec2 grid = abs(fract(v_world.xz + 0.5) - 0.5) / max(fwidth(v_world.xz), vec2(1e-4));
    float line = 1.0 - 0.25 * (1.0 - clamp(min(grid.x, grid.y), 0.0, 1.0));
    float flat_face = step(0.5, n.y);
    // Checker and grid on the ground and on slope tops (a wide hillside is
    // otherwise one flat colour and motion across it does not read); boxes stay
    // plain so their faces (lit differently by the sun) make each step's edge read.
    float textured = v_part == 1 ? 0.0 : 1.0;
    base *= mix(1.0, checker * line, flat_face * textured);
    float diffuse = max(dot(n, u_sun), 0.0);
    float sky = 0.5 + 0.5 * n.y;
    vec3 lit = base * (0.25 + 0.25 * sky + 0.6 * diffuse);
    float d = length(v_world.xz - u_shadow_centre.xz);
    float above = step(abs(v_world.y - u_shadow_centre.y), 0.6);
    lit *= mix(1.0, mix(0.55, 1.0, smoothstep(0.12, 0.42, d)), flat_face * above);
    float fog = clamp((length(v_world - u_eye) - 25.0) / 40.0, 0.0, 1.0);
    o_colour = vec4(mix(lit, u_sky, fog), 1.0);
}
)";

// Debug lines and markers, world space, per-vertex colour.
inline constexpr const char* kLineVertex = R"(#version 300 es
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_colour;
uniform mat4 u_view_projection;
out vec3 v_colour;
void main() {
    v_colour = a_colour;
    gl_Position = u_view_projection * vec4(a_position, 1.0);
}
)";

inline constexpr const char* kLineFragment = R"(#version 300 es
precision mediump float;
in vec3 v_colour;
out vec4 o_colour;
void main() { o_colour = vec4(v_colour, 1.0); }
)";

// Text HUD: stb_easy_font quads in pixels (top-left origin), translucent panel.
inline constexpr const char* kHudVertex = R"(#version 300 es
layout(location = 0) in vec2 a_pixel;
layout(location = 1) in vec4 a_colour;
uniform vec2 u_screen;
uniform float u_scale;
out vec4 v_colour;
void main() {
    v_colour = a_colour;
    vec2 p = a_pixel * u_scale;
    gl_Position = vec4(p.x / u_screen.x * 2.0 - 1.0, 1.0 - p.y / u_screen.y * 2.0, 0.0, 1.0);
}
)";

inline constexpr const char* kHudFragment = R"(#version 300 es
precision mediump float;
in vec4 v_colour;
out vec4 o_colour;
void main() { o_colour = v_colour; }
)";

}  // namespace marionette::render::shaders
