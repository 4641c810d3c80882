#include "render_es/renderer.hpp"

#include <stb/stb_easy_font.h>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <vector>

#include "render_es/gl_util.hpp"
#include "render_es/shaders.hpp"

namespace marionette::render {

namespace {
// From above, on the default camera's side, so the puppet faces the light and
// each terrain face (top, four walls) gets a different shade.
const vec3 kSun = glm::normalize(vec3(-0.55f, 0.75f, 0.35f));
constexpr GLuint kBonesBinding = 0;

void* offset(std::size_t bytes) { return reinterpret_cast<void*>(bytes); }

// Binds `vao` and fills its vertex and index buffers once, for many draws.
template <typename Vertex, typename Index>
void upload_static_mesh(GLuint vao, GLuint vbo, const std::vector<Vertex>& vertices, GLuint ibo,
                        const std::vector<Index>& indices) {
    glBindVertexArray(vao);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(Vertex)), vertices.data(),
                 GL_STATIC_DRAW);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * sizeof(Index)), indices.data(),
                 GL_STATIC_DRAW);
}

// How the vertex shader reads an attribute: as floats (normalised from integers
// or not) or as integers.
enum class AttributeRead { as_float, normalized, as_integer };

struct VertexAttribute {
    GLint components;
    GLenum type;
    AttributeRead read;
    std::size_t offset;  // bytes into the vertex
};

// Attribute i of the bound VAO reads attributes[i] from vertices `stride` bytes apart.
void set_vertex_attributes(GLsizei stride, std::initializer_list<VertexAttribute> attributes) {
    GLuint index = 0;
    for (const VertexAttribute& a : attributes) {
        glEnableVertexAttribArray(index);
        if (a.read == AttributeRead::as_integer)
            glVertexAttribIPointer(index, a.components, a.type, stride, offset(a.offset));
        else
            glVertexAttribPointer(index, a.components, a.type, a.read == AttributeRead::normalized ? GL_TRUE : GL_FALSE,
                                  stride, offset(a.offset));
        ++index;
    }
}

void set_colours(GLuint program, const char* name, const vec3* colours, int count) {
    glUniform3fv(glGetUniformLocation(program, name), count, glm::value_ptr(colours[0]));
}
}  // namespace

namespace {
SkinnedMesh body_mesh(const Skeleton& skeleton, const SkinnedMesh* body) {
    if (!body) return make_capsule_mesh(skeleton);
    if (body->inverse_bind.size() != static_cast<std::size_t>(skeleton.joint_count()) || body->vertices.empty() ||
        body->vertices.size() > 65535)
        throw std::invalid_argument("the character mesh does not fit the skeleton (" +
                                    std::to_string(body->inverse_bind.size()) + " inverse binds for " +
                                    std::to_string(skeleton.joint_count()) + " joints, " +
                                    std::to_string(body->vertices.size()) + " vertices)");
    for (const SkinnedVertex& v : body->vertices)
        for (std::uint8_t j : v.joints)
            if (j >= body->inverse_bind.size()) throw std::invalid_argument("the character mesh names a joint the skeleton lacks");
    for (std::uint16_t i : body->indices)
        if (i >= body->vertices.size()) throw std::invalid_argument("the character mesh has an index out of range");
    return *body;
}
}  // namespace

Renderer::Renderer(const Skeleton& skeleton, const Terrain& terrain, const RenderSettings& settings,
                   const SkinnedMesh* body)
    : settings_(settings), parents_(skeleton.parents), puppet_(body_mesh(skeleton, body)),
      terrain_(make_terrain_mesh(terrain)) {
    toggles_.skeleton = settings.show_skeleton;
    toggles_.feet = settings.show_feet;
    toggles_.gait = settings.show_gait;
    toggles_.motion_graph = settings.show_motion_graph;
    toggles_.hud = settings.show_hud;
    lines_.reserve(kMaxLineVertices);
    hud_vertices_.resize(kMaxHudQuads * 4);
    create_gl();
}

Renderer::~Renderer() { destroy_gl(); }

void Renderer::recreate() {
    // The names belonged to the lost context; start from zero.
    skinned_program_ = terrain_program_ = line_program_ = hud_program_ = 0;
    puppet_vao_ = puppet_vbo_ = puppet_ibo_ = bones_ubo_ = 0;
    terrain_vao_ = terrain_vbo_ = terrain_ibo_ = 0;
    line_vao_ = line_vbo_ = 0;
    hud_vao_ = hud_vbo_ = hud_ibo_ = 0;
    create_gl();
}

void Renderer::set_terrain(const Terrain& terrain) {
    terrain_ = make_terrain_mesh(terrain);
    upload_terrain();
}

void Renderer::create_gl() {
    skinned_program_ = build_program("skinned_puppet", shaders::kSkinnedVertex, shaders::kSkinnedFragment);
    terrain_program_ = build_program("terrain", shaders::kTerrainVertex, shaders::kTerrainFragment);
    line_program_ = build_program("debug_lines", shaders::kLineVertex, shaders::kLineFragment);
    hud_program_ = build_program("hud_text", shaders::kHudVertex, shaders::kHudFragment);
    glUniformBlockBinding(skinned_program_, glGetUniformBlockIndex(skinned_program_, "Bones"), kBonesBinding);

    // Puppet mesh, skinned in the vertex shader.
    glGenVertexArrays(1, &puppet_vao_);
    glGenBuffers(1, &puppet_vbo_);
    glGenBuffers(1, &puppet_ibo_);
    upload_static_mesh(puppet_vao_, puppet_vbo_, puppet_.vertices, puppet_ibo_, puppet_.indices);
    set_vertex_attributes(sizeof(SkinnedVertex),
                          {{3, GL_FLOAT, AttributeRead::as_float, offsetof(SkinnedVertex, position)},
                           {3, GL_FLOAT, AttributeRead::as_float, offsetof(SkinnedVertex, normal)},
                           {4, GL_UNSIGNED_BYTE, AttributeRead::as_integer, offsetof(SkinnedVertex, joints)},
                           {4, GL_FLOAT, AttributeRead::as_float, offsetof(SkinnedVertex, weights)},
                           {1, GL_UNSIGNED_BYTE, AttributeRead::as_float, offsetof(SkinnedVertex, part)}});

    glGenBuffers(1, &bones_ubo_);
    glBindBuffer(GL_UNIFORM_BUFFER, bones_ubo_);
    glBufferData(GL_UNIFORM_BUFFER, sizeof(bones_), nullptr, GL_DYNAMIC_DRAW);
    glBindBufferBase(GL_UNIFORM_BUFFER, kBonesBinding, bones_ubo_);

    glGenVertexArrays(1, &terrain_vao_);
    glGenBuffers(1, &terrain_vbo_);
    glGenBuffers(1, &terrain_ibo_);
    upload_terrain();

    // Debug lines: one stream buffer of fixed capacity.
    glGenVertexArrays(1, &line_vao_);
    glGenBuffers(1, &line_vbo_);
    glBindVertexArray(line_vao_);
    glBindBuffer(GL_ARRAY_BUFFER, line_vbo_);
    glBufferData(GL_ARRAY_BUFFER, kMaxLineVertices * sizeof(LineVertex), nullptr, GL_STREAM_DRAW);
    set_vertex_attributes(sizeof(LineVertex), {{3, GL_FLOAT, AttributeRead::as_float, offsetof(LineVertex, position)},
                                               {3, GL_FLOAT, AttributeRead::as_float, offsetof(LineVertex, colour)}});

    // HUD quads → triangles through a fixed index buffer.
    glGenVertexArrays(1, &hud_vao_);
    glGenBuffers(1, &hud_vbo_);
    glGenBuffers(1, &hud_ibo_);
    glBindVertexArray(hud_vao_);
    glBindBuffer(GL_ARRAY_BUFFER, hud_vbo_);
    glBufferData(GL_ARRAY_BUFFER, kMaxHudQuads * 4 * sizeof(HudVertex), nullptr, GL_STREAM_DRAW);
    std::vector<std::uint16_t> quad_indices;
    quad_indices.reserve(kMaxHudQuads * 6);
    for (std::size_t q = 0; q < kMaxHudQuads && q * 4 + 3 < 65536; ++q) {
        const auto b = static_cast<std::uint16_t>(q * 4);
        quad_indices.insert(quad_indices.end(), {b, static_cast<std::uint16_t>(b + 1), static_cast<std::uint16_t>(b + 2), b,
                                                 static_cast<std::uint16_t>(b + 2), static_cast<std::uint16_t>(b + 3)});
    }
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, hud_ibo_);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(quad_indices.size() * sizeof(std::uint16_t)),
                 quad_indices.data(), GL_STATIC_DRAW);
    set_vertex_attributes(sizeof(HudVertex), {{2, GL_FLOAT, AttributeRead::as_float, offsetof(HudVertex, x)},
                                              {4, GL_UNSIGNED_BYTE, AttributeRead::normalized, offsetof(HudVertex, colour)}});
    glBindVertexArray(0);
}

void Renderer::upload_terrain() {
    upload_static_mesh(terrain_vao_, terrain_vbo_, terrain_.vertices, terrain_ibo_, terrain_.indices);
    set_vertex_attributes(sizeof(TerrainVertex), {{3, GL_FLOAT, AttributeRead::as_float, offsetof(TerrainVertex, position)},
                                                  {3, GL_FLOAT, AttributeRead::as_float, offsetof(TerrainVertex, normal)},
                                                  {1, GL_FLOAT, AttributeRead::as_float, offsetof(TerrainVertex, part)}});
    glBindVertexArray(0);
}

void Renderer::destroy_gl() {
    for (GLuint program : {skinned_program_, terrain_program_, line_program_, hud_program_})
        if (program) glDeleteProgram(program);
    const GLuint buffers[] = {puppet_vbo_, puppet_ibo_, bones_ubo_, terrain_vbo_, terrain_ibo_, line_vbo_, hud_vbo_, hud_ibo_};
    glDeleteBuffers(static_cast<GLsizei>(std::size(buffers)), buffers);
    const GLuint arrays[] = {puppet_vao_, terrain_vao_, line_vao_, hud_vao_};
    glDeleteVertexArrays(static_cast<GLsizei>(std::size(arrays)), arrays);
}

void Renderer::add_line(vec3 a, vec3 b, vec3 colour) {
    if (lines_.size() + 2 > kMaxLineVertices) return;  // full: drop, never grow in a frame
    lines_.push_back({{a.x, a.y, a.z}, {colour.x, colour.y, colour.z}});
    lines_.push_back({{b.x, b.y, b.z}, {colour.x, colour.y, colour.z}});
}

void Renderer::add_cross(vec3 p, float s, vec3 colour) {
    add_line(p - vec3(s, 0, 0), p + vec3(s, 0, 0), colour);
    add_line(p - vec3(0, s, 0), p + vec3(0, s, 0), colour);
    add_line(p - vec3(0, 0, s), p + vec3(0, 0, s), colour);
}

void Renderer::add_ring(vec3 c, float r, vec3 colour) {
    // Octagon on the ground plane; cos/sin of multiples of 45° written out.
    constexpr float h = 0.70710678f;
    const vec2 dirs[8] = {{1, 0}, {h, h}, {0, 1}, {-h, h}, {-1, 0}, {-h, -h}, {0, -1}, {h, -h}};
    for (int i = 0; i < 8; ++i) {
        const vec2 a = dirs[i] * r;
        const vec2 b = dirs[(i + 1) % 8] * r;
        add_line(c + vec3(a.x, 0, a.y), c + vec3(b.x, 0, b.y), colour);
    }
}

void Renderer::draw(const PuppetState& state, const DebugOverlay& overlay, std::string_view hud_text,
                    std::int32_t width, std::int32_t height, float dt_s) {
    follow(camera_, state.root_position, dt_s, settings_.camera);
    const float aspect = height > 0 ? static_cast<float>(width) / static_cast<float>(height) : 1.0f;
    const glm::mat4 view_projection = camera_view_projection(camera_, settings_.camera, aspect);
    const vec3 eye = camera_eye(camera_, settings_.camera);

    glViewport(0, 0, width, height);
    glClearColor(settings_.sky_colour.x, settings_.sky_colour.y, settings_.sky_colour.z, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);

    // Terrain.
    const vec3 terrain_colours[3] = {settings_.ground_colour, settings_.box_colour, settings_.slope_colour};
    glUseProgram(terrain_program_);
    glUniformMatrix4fv(glGetUniformLocation(terrain_program_, "u_view_projection"), 1, GL_FALSE, glm::value_ptr(view_projection));
    set_colours(terrain_program_, "u_part_colours", terrain_colours, 3);
    glUniform3fv(glGetUniformLocation(terrain_program_, "u_sun"), 1, glm::value_ptr(kSun));
    glUniform3fv(glGetUniformLocation(terrain_program_, "u_shadow_centre"), 1, glm::value_ptr(state.root_position));
    glUniform3fv(glGetUniformLocation(terrain_program_, "u_sky"), 1, glm::value_ptr(settings_.sky_colour));
    glUniform3fv(glGetUniformLocation(terrain_program_, "u_eye"), 1, glm::value_ptr(eye));
    glBindVertexArray(terrain_vao_);
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(terrain_.indices.size()), GL_UNSIGNED_INT, nullptr);

    // Puppet: bone matrix = current model transform × inverse bind.
    const int joints = std::min<int>(state.joint_count, static_cast<int>(puppet_.inverse_bind.size()));
    for (int j = 0; j < joints; ++j) {
        const auto i = static_cast<std::size_t>(j);
        glm::mat4 model = glm::mat4_cast(state.model_rotations[i]);
        model[3] = glm::vec4(state.model_positions[i], 1.0f);
        bones_[i] = model * glm::make_mat4(puppet_.inverse_bind[i].data());
    }
    glBindBuffer(GL_UNIFORM_BUFFER, bones_ubo_);
    glBufferSubData(GL_UNIFORM_BUFFER, 0, sizeof(bones_), bones_.data());
    glBindBufferBase(GL_UNIFORM_BUFFER, kBonesBinding, bones_ubo_);
    const vec3 part_colours[3] = {settings_.body_colour, settings_.left_colour, settings_.right_colour};
    glUseProgram(skinned_program_);
    glUniformMatrix4fv(glGetUniformLocation(skinned_program_, "u_view_projection"), 1, GL_FALSE, glm::value_ptr(view_projection));
    set_colours(skinned_program_, "u_part_colours", part_colours, 3);
    glUniform3fv(glGetUniformLocation(skinned_program_, "u_sun"), 1, glm::value_ptr(kSun));
    glBindVertexArray(puppet_vao_);
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(puppet_.indices.size()), GL_UNSIGNED_SHORT, nullptr);

    draw_overlays(state, overlay, view_projection);
    // The motion-graph state is a line of text under the HUD's own, written into
    // fixed scratch space (no allocation).
    std::size_t text_length = 0;
    if (toggles_.hud) {
        text_length = std::min(hud_text.size(), hud_text_.size() - 1);
        std::memcpy(hud_text_.data(), hud_text.data(), text_length);
    }
    if (toggles_.motion_graph && overlay.motion_graph.valid) {
        const MotionGraphOverlay& m = overlay.motion_graph;
        const auto name = [](const std::array<char, kOverlayNameLength>& n) {
            return std::string_view(n.data(), strnlen(n.data(), n.size()));
        };
        const std::string_view clip = name(m.current_clip);
        const std::string_view next = name(m.next_transition);
        const int written = std::snprintf(hud_text_.data() + text_length, hud_text_.size() - text_length,
                                          "%sclip %.*s%s%.*s (%d%%)", text_length ? "\n" : "", static_cast<int>(clip.size()),
                                          clip.data(), next.empty() ? "" : " -> ", static_cast<int>(next.size()), next.data(),
                                          static_cast<int>(std::clamp(m.transition_progress, 0.0f, 1.0f) * 100.0f + 0.5f));
        if (written > 0) text_length = std::min(hud_text_.size() - 1, text_length + static_cast<std::size_t>(written));
    }
    hud_text_[text_length] = '\0';
    if (text_length > 0) draw_hud(width, height);
    glBindVertexArray(0);
}

void Renderer::draw_overlays(const PuppetState& state, const DebugOverlay& overlay, const glm::mat4& view_projection) {
    lines_.clear();
    const vec3 c = settings_.overlay_colour;
    if (toggles_.skeleton) {
        const int joints = std::min<int>(state.joint_count, static_cast<int>(parents_.size()));
        for (int j = 0; j < joints; ++j) {
            const int p = parents_[static_cast<std::size_t>(j)];
            const vec3 q = state.model_positions[static_cast<std::size_t>(j)];
            if (p >= 0) add_line(state.model_positions[static_cast<std::size_t>(p)], q, c);
            add_cross(q, 0.02f, c);
        }
    }
    const int feet = std::clamp(overlay.foot_count, 0, kOverlayMaxFeet);
    for (int f = 0; f < feet; ++f) {
        const FootOverlay& foot = overlay.feet[static_cast<std::size_t>(f)];
        if (toggles_.feet) {
            add_cross(foot.target, 0.06f, vec3(0.2f, 0.9f, 1.0f));
            const vec3 ground(foot.position.x, foot.target.y + 0.005f, foot.position.z);
            add_ring(ground, 0.08f, foot.in_contact ? vec3(0.1f, 0.95f, 0.2f) : vec3(0.95f, 0.2f, 0.1f));
        }
        if (toggles_.gait) {
            const int n = std::clamp(foot.spline_points, 0, kOverlaySplinePoints);
            for (int i = 0; i + 1 < n; ++i)
                add_line(foot.spline[static_cast<std::size_t>(i)], foot.spline[static_cast<std::size_t>(i + 1)], vec3(1.0f, 0.5f, 0.9f));
        }
    }
    if (lines_.empty()) return;
    glDisable(GL_DEPTH_TEST);  // overlays show through the body
    glUseProgram(line_program_);
    glUniformMatrix4fv(glGetUniformLocation(line_program_, "u_view_projection"), 1, GL_FALSE, glm::value_ptr(view_projection));
    glBindVertexArray(line_vao_);
    glBindBuffer(GL_ARRAY_BUFFER, line_vbo_);
    glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(lines_.size() * sizeof(LineVertex)), lines_.data());
    glDrawArrays(GL_LINES, 0, static_cast<GLsizei>(lines_.size()));
    glEnable(GL_DEPTH_TEST);
}

void Renderer::draw_hud(std::int32_t width, std::int32_t height) {
    const float scale = std::max(1.0f, static_cast<float>(height) / 400.0f);
    const auto byte = [](float v) { return static_cast<std::uint8_t>(std::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f); };

    // Panel behind the text, then the glyph quads stb_easy_font writes.
    const float w = static_cast<float>(stb_easy_font_width(hud_text_.data())) + 8.0f;
    const float h = static_cast<float>(stb_easy_font_height(hud_text_.data())) + 6.0f;
    const std::array<std::uint8_t, 4> panel{0, 0, 0, 140};
    hud_vertices_[0] = {2, 2, 0, panel};
    hud_vertices_[1] = {2 + w, 2, 0, panel};
    hud_vertices_[2] = {2 + w, 2 + h, 0, panel};
    hud_vertices_[3] = {2, 2 + h, 0, panel};
    unsigned char colour[4] = {byte(settings_.hud_colour.x), byte(settings_.hud_colour.y), byte(settings_.hud_colour.z), 255};
    const int quads = stb_easy_font_print(6.0f, 5.0f, hud_text_.data(), colour, hud_vertices_.data() + 4,
                                          static_cast<int>((hud_vertices_.size() - 4) * sizeof(HudVertex)));

    glDisable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glUseProgram(hud_program_);
    glUniform2f(glGetUniformLocation(hud_program_, "u_screen"), static_cast<float>(width), static_cast<float>(height));
    glUniform1f(glGetUniformLocation(hud_program_, "u_scale"), scale);
    glBindVertexArray(hud_vao_);
    glBindBuffer(GL_ARRAY_BUFFER, hud_vbo_);
    glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>((static_cast<std::size_t>(quads) + 1) * 4 * sizeof(HudVertex)),
                    hud_vertices_.data());
    glDrawElements(GL_TRIANGLES, (quads + 1) * 6, GL_UNSIGNED_SHORT, nullptr);
    glDisable(GL_BLEND);
    glEnable(GL_DEPTH_TEST);
}

}  // namespace marionette::render
