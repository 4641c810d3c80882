// Headless GL tests on Mesa's llvmpipe (surfaceless EGL): golden images of fixed
// ticks of the shipped programs, shader error reporting, context-loss recovery
// and an allocation-free frame.
//
// Golden images live in tests/render/golden/. After an intended change to the
// renderer or the simulation, regenerate them with scripts/update-render-golden.sh
// (it runs this program with MARIONETTE_UPDATE_RENDER_GOLDEN=1) and look at them.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "app/config/character_config.hpp"
#include "app/config/config.hpp"
#include "app/config/program_source.hpp"
#include "app/config/render_config.hpp"
#include "app/eval/replay.hpp"
#include "app/ui/tuning_ui.hpp"
#include "render_es/gl_util.hpp"
#include "render_es/image.hpp"
#include "render_es/view.hpp"
#include "runtime/gait/puppet.hpp"
#include "tests/alloc_counter.hpp"
#include "tests/test_support.hpp"
#include "tests/render/ui_pad_driver.hpp"

using namespace marionette;

namespace {
constexpr std::int32_t kGoldenWidth = 320;
constexpr std::int32_t kGoldenHeight = 200;
constexpr int kChannelTolerance = 24;        // llvmpipe versions round a little differently
constexpr double kMaxDifferingFraction = 0.01;

// The states of the given ticks of a shipped program's recorded log, replayed
// exactly as `marionette render` replays it.
struct Replayed {
    std::vector<PuppetState> states;
    Skeleton skeleton;
    Terrain terrain;  // the configuration's (config/marionette.toml [terrain])
    float ankle_height = 0.0f;
};
Replayed replay_ticks(const std::string& program, std::vector<std::uint64_t> ticks) {
    const SimConfig config = default_config().sim;
    Simulation sim(config);
    InputLogHeader header;
    header.tick_rate_hz = static_cast<std::uint32_t>(config.tick_rate_hz);
    header.clip_data_hash = sim.clip_data_hash();
    header.config_text = serialize_config(config);
    const DecodedInputLog log = decode_input_log(
        encode_input_log(header, render_stick_program(load_program("builtin:" + program), config.tick_rate_hz), 60), program);
    Replayed out;
    ReplayOptions options;
    options.on_tick = [&](const Simulation& s) {
        if (out.skeleton.joint_count() == 0) {
            out.skeleton = s.skeleton();
            out.terrain = s.terrain();
        }
        out.ankle_height = s.config().ankle_height;
        for (std::uint64_t t : ticks)
            if (s.state().tick == t) out.states.push_back(s.state());
        return s.state().tick < ticks.back();
    };
    replay_log(log, program, options);
    REQUIRE(out.states.size() == ticks.size());
    return out;
}

render::PlatformOptions golden_platform() {
    render::PlatformOptions p;
    p.kind = render::PlatformKind::headless;
    p.width = kGoldenWidth;
    p.height = kGoldenHeight;
    p.msaa_samples = 4;
    return p;
}

render::Image snapshot(render::View& view) {
    render::Image image{view.platform().width(), view.platform().height(), {}};
    view.platform().read_pixels(image.rgba);
    return image;
}

void check_golden(const std::string& name, const render::Image& actual) {
    const std::string golden = test::source_path("tests/render/golden/" + name + ".png");
    const char* update = std::getenv("MARIONETTE_UPDATE_RENDER_GOLDEN");
    if (update && std::string(update) == "1") {
        render::write_png(golden, actual);
        WARN("rewrote " << golden);
        return;
    }
    REQUIRE(std::filesystem::exists(golden));
    const render::Image expected = render::read_png(golden);
    const render::ImageDifference d = render::compare_images(expected, actual, kChannelTolerance);
    INFO(name << ": " << d.differing_pixels << " pixels (" << 100.0 * d.differing_fraction
              << " %) differ by more than " << kChannelTolerance << "; largest channel difference " << d.max_channel_difference);
    if (!d.same_size || d.differing_fraction > kMaxDifferingFraction) {
        std::filesystem::create_directories("render_failures");
        render::write_png("render_failures/" + name + ".actual.png", actual);
        if (d.same_size) render::write_png("render_failures/" + name + ".diff.png", d.diff);
        WARN("wrote render_failures/" << name << ".actual.png and .diff.png in " << std::filesystem::current_path());
    }
    REQUIRE(d.same_size);
    CHECK(d.differing_fraction <= kMaxDifferingFraction);
}

Terrain test_steps() {
    // Three 15 cm steps and a ramp beside the puppet's standing spot.
    Terrain t;
    for (int i = 0; i < 3; ++i)
        t.boxes.push_back({0.6f, 0.4f + 0.3f * static_cast<float>(i), 1.6f, 2.2f, 0.15f * static_cast<float>(i + 1)});
    t.slopes.push_back({-1.6f, 0.4f, -0.8f, 2.2f, 0.0f, 0.0f, 0.25f});
    return t;
}
}  // namespace

TEST_CASE("golden images: walk_stop mid-stride on the default terrain, circle with skeleton and foot overlays", "[render][golden]") {
    const RenderConfig rc = load_render_config("");
    render::RenderSettings settings = rc.settings;
    settings.show_hud = false;  // text is checked by the CLI frames, not pixel by pixel
    {
        const Replayed r = replay_ticks("walk_stop", {600});
        render::View view(golden_platform(), settings, r.skeleton, r.terrain);
        view.frame(r.states[0], render::DebugOverlay{}, "", 1.0f / 60.0f);
        check_golden("walk_stop_t600", snapshot(view));
    }
    {
        const Replayed r = replay_ticks("circle", {900});
        render::RenderSettings with_overlays = settings;
        with_overlays.show_skeleton = true;
        with_overlays.show_feet = true;
        render::View view(golden_platform(), with_overlays, r.skeleton, Terrain{});
        render::DebugOverlay overlay;
        render::feet_overlay_from_state(r.states[0], Terrain{}, r.ankle_height, overlay);
        view.frame(r.states[0], overlay, "", 1.0f / 60.0f);
        check_golden("circle_t900_overlays", snapshot(view));
    }
}

namespace {
float distance(vec3 a, vec3 b) {
    const vec3 d = a - b;
    return std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
}

// Every tick from `first` to `last` in steps of `stride` (a fixed sample of the run).
std::vector<std::uint64_t> tick_range(std::uint64_t first, std::uint64_t last, std::uint64_t stride) {
    std::vector<std::uint64_t> ticks;
    for (std::uint64_t t = first; t <= last; t += stride) ticks.push_back(t);
    return ticks;
}

// The largest distance between two equally long overlay splines' points.
float largest_move(const render::FootOverlay& a, const render::FootOverlay& b) {
    float moved = 0.0f;
    for (int i = 0; i < std::min(a.spline_points, b.spline_points); ++i)
        moved = std::max(moved, distance(a.spline[static_cast<std::size_t>(i)], b.spline[static_cast<std::size_t>(i)]));
    return moved;
}
}  // namespace

// The fitted step splines the gait overlay draws, over the envelope the gait
// walks in: the shipped walk, circle (turning) and stairs-free run programs,
// ticks sampled across each (every 7th / 11th tick), both feet.
TEST_CASE("the gait overlay's step spline runs from each swinging foot's lift-off to its landing target", "[render][gait_overlay]") {
    const GaitRig rig = make_gait_rig(default_config().sim);
    int swinging = 0, standing = 0;
    for (const auto& [program, ticks] : {std::pair<std::string, std::vector<std::uint64_t>>{"walk_stop", tick_range(120, 900, 7)},
                                         {"circle", tick_range(120, 1200, 11)}}) {
        const Replayed r = replay_ticks(program, ticks);
        for (const PuppetState& s : r.states) {
            render::DebugOverlay overlay, without;
            render::feet_overlay_from_state(s, r.terrain, r.ankle_height, overlay, &rig);
            render::feet_overlay_from_state(s, r.terrain, r.ankle_height, without);
            REQUIRE(overlay.foot_count == 2);
            for (int f = 0; f < 2; ++f) {
                const FootState& foot = s.gait.feet[static_cast<std::size_t>(f)];
                const render::FootOverlay& drawn = overlay.feet[static_cast<std::size_t>(f)];
                INFO(program << " tick " << s.tick << " foot " << f);
                CHECK(without.feet[static_cast<std::size_t>(f)].spline_points == 0);  // no rig, no spline
                if (!foot.swinging) {
                    CHECK(drawn.spline_points == 0);
                    ++standing;
                    continue;
                }
                ++swinging;
                REQUIRE(drawn.spline_points == render::kOverlaySplinePoints);
                CHECK(distance(drawn.spline[0], foot.start) < 1e-4f);
                CHECK(distance(drawn.spline[render::kOverlaySplinePoints - 1], foot.target) < 2e-3f);
                float length = 0.0f;
                for (int i = 0; i + 1 < drawn.spline_points; ++i)
                    length += distance(drawn.spline[static_cast<std::size_t>(i)], drawn.spline[static_cast<std::size_t>(i + 1)]);
                // The path lifts and may swing out, never more than a metre round about.
                CHECK(length >= distance(foot.start, foot.target) - 1e-4f);
                CHECK(length < distance(foot.start, foot.target) + 1.0f);
            }
        }
    }
    CHECK(swinging > 40);
    CHECK(standing > 40);
}

// A prototype key edited (as the spline editor does, on the working config the
// render thread rebuilds its rig from): every swinging foot's drawn path moves,
// its ends stay at lift-off and landing.
TEST_CASE("the gait overlay's step spline follows an edited swing prototype key", "[render][gait_overlay][spline]") {
    const Replayed r = replay_ticks("walk_stop", tick_range(300, 560, 13));
    const SimConfig base = default_config().sim;
    const GaitRig rig = make_gait_rig(base);
    for (int key = 1; key + 1 < base.walk.swing_foot.count; ++key) {
        for (float PrototypeKey::*component : {&PrototypeKey::x, &PrototypeKey::z}) {
            SimConfig edited = base;
            PrototypeKey& k = edited.walk.swing_foot.keys[static_cast<std::size_t>(key)];
            k.*component += component == &PrototypeKey::x ? 0.04f : -0.08f;
            const GaitRig edited_rig = make_gait_rig(edited);
            int compared = 0;
            for (const PuppetState& s : r.states) {
                render::DebugOverlay before, after;
                render::feet_overlay_from_state(s, r.terrain, r.ankle_height, before, &rig);
                render::feet_overlay_from_state(s, r.terrain, r.ankle_height, after, &edited_rig);
                for (int f = 0; f < 2; ++f) {
                    const render::FootOverlay& a = before.feet[static_cast<std::size_t>(f)];
                    const render::FootOverlay& b = after.feet[static_cast<std::size_t>(f)];
                    if (a.spline_points == 0) continue;
                    INFO("key " << key << " tick " << s.tick << " foot " << f);
                    REQUIRE(b.spline_points == a.spline_points);
                    CHECK(largest_move(a, b) > 2e-3f);
                    CHECK(distance(a.spline[0], b.spline[0]) < 1e-6f);
                    CHECK(distance(a.spline[render::kOverlaySplinePoints - 1], b.spline[render::kOverlaySplinePoints - 1]) < 2e-3f);
                    ++compared;
                }
            }
            CHECK(compared > 5);
        }
    }
}

TEST_CASE("golden image: the gait overlay draws the fitted step spline of the swinging foot", "[render][golden][gait_overlay]") {
    const Replayed r = replay_ticks("walk_stop", {600});
    const PuppetState& s = r.states[0];
    REQUIRE((s.gait.feet[0].swinging || s.gait.feet[1].swinging));
    render::RenderSettings settings = load_render_config("").settings;
    settings.show_hud = false;
    settings.show_gait = settings.show_feet = true;
    render::View view(golden_platform(), settings, r.skeleton, r.terrain);
    const GaitRig rig = make_gait_rig(default_config().sim);
    render::DebugOverlay overlay;
    render::feet_overlay_from_state(s, r.terrain, r.ankle_height, overlay, &rig);
    view.frame(s, overlay, "", 1.0f / 60.0f);
    const render::Image with = snapshot(view);
    check_golden("walk_stop_t600_step_splines", with);
    // The spline is what differs from the same frame without it.
    render::DebugOverlay plain;
    render::feet_overlay_from_state(s, r.terrain, r.ankle_height, plain);
    view.frame(s, plain, "", 1.0f / 60.0f);
    CHECK(render::compare_images(snapshot(view), with, kChannelTolerance).differing_pixels > 20);
}

TEST_CASE("golden image: steps and a ramp are shaded so each face reads", "[render][golden]") {
    const Replayed r = replay_ticks("stand_still", {240});
    render::RenderSettings settings = load_render_config("").settings;
    settings.show_hud = false;
    render::View view(golden_platform(), settings, r.skeleton, test_steps());
    view.frame(r.states[0], render::DebugOverlay{}, "", 1.0f / 60.0f);
    const render::Image image = snapshot(view);
    check_golden("stand_still_t240_steps", image);
}

TEST_CASE("the HUD draws text into the top-left corner", "[render][hud]") {
    const Replayed r = replay_ticks("stand_still", {10});
    render::RenderSettings settings;
    render::View view(golden_platform(), settings, r.skeleton, Terrain{});
    view.frame(r.states[0], render::DebugOverlay{}, "", 0.0f);
    const render::Image without = snapshot(view);
    view.frame(r.states[0], render::DebugOverlay{}, "HUD 123", 0.0f);
    const render::Image with = snapshot(view);
    const render::ImageDifference d = render::compare_images(without, with, 8);
    CHECK(d.differing_pixels > 50);
    // Every differing pixel is inside the HUD panel (top-left).
    for (std::int32_t y = 0; y < with.height; ++y)
        for (std::int32_t x = 0; x < with.width; ++x) {
            const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(with.width) + static_cast<std::size_t>(x)) * 4;
            if (d.diff.rgba[i] == 255 && d.diff.rgba[i + 1] == 0) REQUIRE((x < 80 && y < 24));
        }
}

TEST_CASE("the motion-graph overlay writes the current clip and next transition when toggled on", "[render][hud]") {
    const Replayed r = replay_ticks("stand_still", {10});
    render::View view(golden_platform(), render::RenderSettings{}, r.skeleton, Terrain{});
    render::DebugOverlay overlay;
    overlay.motion_graph.valid = true;
    std::snprintf(overlay.motion_graph.current_clip.data(), overlay.motion_graph.current_clip.size(), "walk");
    std::snprintf(overlay.motion_graph.next_transition.data(), overlay.motion_graph.next_transition.size(), "run");
    overlay.motion_graph.transition_progress = 0.4f;
    view.frame(r.states[0], overlay, "", 0.0f);
    const render::Image off = snapshot(view);
    view.renderer().toggles().motion_graph = true;
    view.frame(r.states[0], overlay, "", 0.0f);
    const render::Image on = snapshot(view);
    const render::ImageDifference d = render::compare_images(off, on, 8);
    CHECK(d.differing_pixels > 50);
    view.renderer().toggles().hud = false;  // the HUD toggle does not hide the motion-graph line
    view.frame(r.states[0], overlay, "ignored", 0.0f);
    CHECK(render::compare_images(on, snapshot(view), 0).differing_pixels == 0);
}

TEST_CASE("shader compile and link errors name the shader and carry its log", "[render][shader]") {
    render::View view(golden_platform(), render::RenderSettings{}, make_puppet_skeleton(SimConfig{}), Terrain{});
    const char* vs = "#version 300 es\nvoid main() { gl_Position = vec4(0.0); }\n";
    const char* bad_fs = "#version 300 es\nprecision mediump float;\nout vec4 c;\nvoid main() { c = undefined_thing; }\n";
    try {
        render::build_program("broken_example", vs, bad_fs);
        FAIL("a broken shader compiled");
    } catch (const render::ShaderError& e) {
        const std::string what = e.what();
        CHECK(what.find("shader broken_example (fragment) failed to compile") != std::string::npos);
        CHECK(what.find("undefined_thing") != std::string::npos);  // the compiler's log
    }
    // Links fail when stages disagree: the fragment shader reads a varying nobody writes.
    const char* needs_varying = "#version 300 es\nprecision mediump float;\nin vec3 v_missing;\nout vec4 c;\nvoid main() { c = vec4(v_missing, 1.0); }\n";
    CHECK_THROWS_WITH(render::build_program("mismatched_example", vs, needs_varying),
                      Catch::Contains("shader mismatched_example (program) failed to link"));
}

TEST_CASE("after a lost context the view rebuilds everything and draws the same frame", "[render][recovery]") {
    const Replayed r = replay_ticks("walk_stop", {700});
    render::RenderSettings settings;
    settings.camera.smoothing_s = 0.0f;
    render::View view(golden_platform(), settings, r.skeleton, test_steps());
    view.frame(r.states[0], render::DebugOverlay{}, "recovery", 0.0f);
    const render::Image before = snapshot(view);
    // What View::frame does when present() reports a lost context.
    REQUIRE(view.platform().recover());
    view.platform().begin_frame();
    view.renderer().recreate();
    view.frame(r.states[0], render::DebugOverlay{}, "recovery", 0.0f);
    const render::Image after = snapshot(view);
    const render::ImageDifference d = render::compare_images(before, after, 0);
    CHECK(d.differing_pixels == 0);
}

TEST_CASE("a terrain edit redraws the ground: the same frame as a view opened on the edited terrain", "[render][terrain]") {
    // What the render thread does when the simulation applied a terrain edit
    // (app/live/pipeline.cpp, take_applied_terrain).
    const Replayed r = replay_ticks("walk_stop", {700});
    render::RenderSettings settings;
    settings.camera.smoothing_s = 0.0f;
    render::View view(golden_platform(), settings, r.skeleton, Terrain{});
    view.frame(r.states[0], render::DebugOverlay{}, "", 0.0f);
    const render::Image flat = snapshot(view);
    const std::size_t flat_triangles = view.renderer().terrain_triangle_count();
    view.renderer().set_terrain(test_steps());
    view.frame(r.states[0], render::DebugOverlay{}, "", 0.0f);
    const render::Image edited = snapshot(view);
    CHECK(view.renderer().terrain_triangle_count() > flat_triangles);
    CHECK(render::compare_images(flat, edited, kChannelTolerance).differing_pixels > 0);
    view.renderer().set_terrain(Terrain{});
    view.frame(r.states[0], render::DebugOverlay{}, "", 0.0f);
    CHECK(render::compare_images(flat, snapshot(view), 0).differing_pixels == 0);
    // Last: opening a second view makes its context current.
    render::View fresh(golden_platform(), settings, r.skeleton, test_steps());
    fresh.frame(r.states[0], render::DebugOverlay{}, "", 0.0f);
    CHECK(render::compare_images(snapshot(fresh), edited, 0).differing_pixels == 0);
}

TEST_CASE("a frame allocates nothing once the view is open", "[render][alloc]") {
    const Replayed r = replay_ticks("circle", {400, 401, 402, 403});
    render::RenderSettings settings;
    settings.show_skeleton = settings.show_feet = settings.show_gait = true;
    render::View view(golden_platform(), settings, r.skeleton, test_steps());
    render::DebugOverlay overlay;
    overlay.foot_count = 1;
    overlay.feet[0].spline_points = 8;
    for (const PuppetState& s : r.states) view.frame(s, overlay, "warm-up", 1.0f / 60.0f);  // shaders JIT-compile here
    const std::uint64_t before = test::allocation_count();
    for (int i = 0; i < 8; ++i)
        for (const PuppetState& s : r.states) view.frame(s, overlay, "tick 123  speed 1.00 m/s", 1.0f / 60.0f);
    CHECK(test::allocation_count() - before == 0);
}

// The shipped glTF character (config/characters/blocky.gltf, made by
// scripts/generate-character.py) drawn GPU-skinned in place of the capsules, in
// the walk_stop golden's pose: a golden of its own, visibly not the capsules, and
// still no allocation per frame.
TEST_CASE("golden image: the shipped glTF character walks in place of the capsules", "[render][golden][character]") {
    RenderConfig rc = load_render_config("");
    rc.character = test::source_path("config/characters/blocky.gltf");
    render::RenderSettings settings = rc.settings;
    settings.show_hud = false;
    const Replayed r = replay_ticks("walk_stop", {600, 601, 602});
    const std::shared_ptr<const render::SkinnedMesh> body = load_render_character(rc, r.skeleton);
    REQUIRE(body);
    render::View view(golden_platform(), settings, r.skeleton, r.terrain, body.get());
    CHECK(view.renderer().puppet_triangle_count() == 20 * 12);
    view.frame(r.states[0], render::DebugOverlay{}, "", 1.0f / 60.0f);
    const render::Image image = snapshot(view);
    check_golden("character_walk_stop_t600", image);
    render::View capsules(golden_platform(), settings, r.skeleton, r.terrain);
    capsules.frame(r.states[0], render::DebugOverlay{}, "", 1.0f / 60.0f);
    CHECK(render::compare_images(snapshot(capsules), image, kChannelTolerance).differing_pixels > 300);

    for (const PuppetState& s : r.states) view.frame(s, render::DebugOverlay{}, "warm-up", 1.0f / 60.0f);
    const std::uint64_t before = test::allocation_count();
    for (int i = 0; i < 4; ++i)
        for (const PuppetState& s : r.states) view.frame(s, render::DebugOverlay{}, "tick 600", 1.0f / 60.0f);
    CHECK(test::allocation_count() - before == 0);
}

// Hidden from test discovery ([.window]): CTest runs it under xvfb-run (see
// tests/CMakeLists.txt), where the SDL window platform must draw exactly what the
// headless one draws.
TEST_CASE("the SDL window platform draws the golden frame under Xvfb", "[.window]") {
    REQUIRE(std::getenv("DISPLAY") != nullptr);
    const Replayed r = replay_ticks("walk_stop", {600});
    render::RenderSettings settings = load_render_config("").settings;
    settings.show_hud = false;
    render::PlatformOptions options = golden_platform();
    options.kind = render::PlatformKind::window;
    render::View view(options, settings, r.skeleton, r.terrain);
    INFO(view.platform().description());
    REQUIRE(view.platform().width() == kGoldenWidth);
    REQUIRE(view.platform().height() == kGoldenHeight);
    const render::FrameResult result = view.frame(r.states[0], render::DebugOverlay{}, "", 1.0f / 60.0f);
    CHECK(result.present == render::PresentResult::ok);
    CHECK_FALSE(result.events.close_requested);
    check_golden("walk_stop_t600", snapshot(view));
}

// ---- the tuning UI (app/ui/, docs/ui.md) -------------------------------------

namespace {
render::PlatformOptions ui_platform() {
    render::PlatformOptions p = golden_platform();
    p.width = 640;  // the panel needs more room than the puppet goldens
    p.height = 400;
    return p;
}

std::string file_text(const std::string& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}
}  // namespace

TEST_CASE("golden image: the tuning UI open over the puppet", "[render][golden][ui]") {
    const Replayed r = replay_ticks("walk_stop", {600});
    render::RenderSettings settings;
    render::View view(ui_platform(), settings, r.skeleton, r.terrain);
    ui::TuningUiOptions options{default_config(), "", "", stderr};
    ui::TuningUi tuning(view.platform(), options);
    view.set_layer(&tuning);
    tuning.feed_pad(TickInput{}, 0, 0, ui::PadPress{}, true);
    tuning.set_open(true);
    render::DebugOverlay overlay{};
    render::feet_overlay_from_state(r.states[0], r.terrain, r.ankle_height, overlay);
    // ImGui lays a new window out over its first frames; the third is settled.
    for (int i = 0; i < 3; ++i) view.frame(r.states[0], overlay, "", 1.0f / 60.0f);
    check_golden("tuning_ui_open_walk_stop_t600", snapshot(view));
}

TEST_CASE("golden images: the terrain editor, then the spline editor open over the walking puppet", "[render][golden][ui][spline][terrain]") {
    const Replayed r = replay_ticks("walk_stop", {600});
    render::View view(ui_platform(), render::RenderSettings{}, r.skeleton, r.terrain);
    ui::TuningUi tuning(view.platform(), ui::TuningUiOptions{default_config(), "", "", stderr});
    view.set_layer(&tuning);
    render::DebugOverlay overlay{};
    render::feet_overlay_from_state(r.states[0], r.terrain, r.ankle_height, overlay);
    test::UiPadDriver pad_driver(tuning, view, r.states[0], overlay);
    auto frame_with = [&](std::uint32_t buttons) { pad_driver.frame(buttons); };
    frame_with(0);
    frame_with(ui::kUiChord);
    for (int i = 0; i < 4; ++i) frame_with(0);
    // West once: the terrain editor opens with the pad on its first button, "add box".
    frame_with(button_bit(Button::west));
    for (int i = 0; i < 4; ++i) frame_with(0);
    AppConfig edit;
    CHECK_FALSE(tuning.take_edit(edit));  // opening the section edits nothing
    check_golden("tuning_ui_terrain_editor_walk_stop_t600", snapshot(view));
    // West again: the spline editor's curve; south: d-pad mode, up: one step.
    for (Button b : {Button::west, Button::south, Button::dpad_up}) {
        frame_with(button_bit(b));
        for (int i = 0; i < 4; ++i) frame_with(0);
    }
    REQUIRE(tuning.spline_pad_mode());
    CHECK(tuning.working().sim.walk.swing_foot.keys[1].y == 0.055f);
    check_golden("tuning_ui_spline_editor_walk_stop_t600", snapshot(view));
}

TEST_CASE("the pad chord opens and closes the tuning UI, the d-pad and south move a slider", "[render][ui]") {
    const Replayed r = replay_ticks("stand_still", {10});
    render::View view(ui_platform(), render::RenderSettings{}, r.skeleton, r.terrain);
    ui::TuningUi tuning(view.platform(), ui::TuningUiOptions{default_config(), "", "", stderr});
    view.set_layer(&tuning);
    const render::DebugOverlay no_overlay{};
    // One frame per tick of pad input, as the render thread would see them.
    test::UiPadDriver pad_driver(tuning, view, r.states[0], no_overlay);
    auto frame_with = [&](std::uint32_t buttons) { pad_driver.frame(buttons); };
    auto press = [&](Button b) { pad_driver.press(b); };
    frame_with(0);
    CHECK_FALSE(tuning.is_open());
    frame_with(button_bit(Button::back));  // back alone is not the chord
    frame_with(0);
    CHECK_FALSE(tuning.is_open());
    frame_with(ui::kUiChord);
    CHECK(tuning.is_open());
    frame_with(0);
    frame_with(0);
    // The first slider (gait.pelvis_height) has the focus; down to step_length_multiplier, A, right ×2, A.
    const float before = tuning.working().sim.step_length_multiplier;
    press(Button::dpad_down);
    press(Button::south);
    press(Button::dpad_right);
    press(Button::dpad_right);
    press(Button::south);
    const float after = tuning.working().sim.step_length_multiplier;
    INFO("message: " << tuning.message());
    CHECK(after > before);
    CHECK(after == Approx(before + 2 * 0.0195f).margin(0.002f));
    AppConfig handed{};
    CHECK(tuning.take_edit(handed));
    CHECK(handed.sim.step_length_multiplier == after);
    CHECK_FALSE(tuning.take_edit(handed));  // once per edit
    frame_with(ui::kUiChord);
    CHECK_FALSE(tuning.is_open());
}

TEST_CASE("the tuning UI takes each pad press as one step, with 0 ms and 500 ms frames", "[render][ui]") {
    const Replayed r = replay_ticks("stand_still", {10});
    render::View view(ui_platform(), render::RenderSettings{}, r.skeleton, r.terrain);
    ui::TuningUi tuning(view.platform(), ui::TuningUiOptions{default_config(), "", "", stderr});
    view.set_layer(&tuning);
    constexpr std::int64_t tick_ns = 8'333'333;  // 120 Hz
    std::uint64_t tick = 0;
    std::uint32_t held = 0;
    std::vector<ui::PadPress> queue;  // as app/live/pipeline.cpp's ring: presses in tick order
    int frame_count = 0;
    // A frame after `ticks` new ticks of `buttons`, alternately 0 ms and 500 ms
    // long in ImGui's time (a stalled llvmpipe frame, then an immediate one).
    auto frame = [&](std::uint32_t buttons, int ticks) {
        for (int i = 0; i < ticks; ++i) {
            ++tick;
            if (const std::uint32_t e = ui::press_event(held, buttons); e != 0) queue.push_back({e, tick});
            held = buttons;
        }
        ui::PadPress press{};
        if (!tuning.releasing() && !queue.empty()) {
            press = queue.front();
            queue.erase(queue.begin());
        }
        TickInput pad;
        pad.buttons = held;
        tuning.feed_pad(pad, tick, tick_ns, press, queue.empty());
        view.frame(r.states[0], render::DebugOverlay{}, "", (frame_count++ % 2 == 0) ? 0.0f : 0.5f);
    };
    // A 150 ms tap (18 ticks) seen held over six frames that ImGui is told last 1.5 s in all.
    auto tap = [&](Button b) {
        frame(button_bit(b), 3);
        for (int i = 0; i < 5; ++i) frame(button_bit(b), 3);
        for (int i = 0; i < 2; ++i) frame(0, 10);
    };
    frame(0, 1);
    frame(ui::kUiChord, 1);
    REQUIRE(tuning.is_open());
    // The first tap comes at once: it waits in the queue while the panel puts the
    // focus on its first slider (a step taken then would be undone).
    const AppConfig start = tuning.working();
    tap(Button::dpad_down);   // pelvis_height -> step_length_multiplier
    tap(Button::south);       // adjust
    tap(Button::dpad_right);  // +1 %
    tap(Button::dpad_right);  // +1 %
    tap(Button::south);       // done
    tap(Button::dpad_down);   // the next row: nothing changes
    const AppConfig& end = tuning.working();
    INFO("message: " << tuning.message());
    CHECK(end.sim.pelvis_height == start.sim.pelvis_height);
    const double steps = (end.sim.step_length_multiplier - start.sim.step_length_multiplier) / 0.0195;
    // A step is 1 % of the range (0.0195), shown and kept to the slider's 3 decimals.
    CHECK(steps == Approx(2.0).margin(0.1));  // exactly two steps, not three
    // Held 1.175 s (141 ticks after the press edge's, 3 a frame) on an active
    // slider: the press and the repeats due at 0.5, 0.6 … 1.1 s.
    tap(Button::dpad_up);
    tap(Button::south);
    const float before_hold = tuning.working().sim.step_length_multiplier;
    frame(button_bit(Button::dpad_right), 1);
    for (int i = 0; i < 47; ++i) frame(button_bit(Button::dpad_right), 3);
    for (int i = 0; i < 4; ++i) frame(0, 1);
    const double held_steps = (tuning.working().sim.step_length_multiplier - before_hold) / 0.0195;
    CHECK(held_steps == Approx(1.0 + 7.0).margin(0.1));
}

TEST_CASE("tuning UI edits pass the schema's checks, save keeps the file's comments and order", "[render][ui]") {
    const Replayed r = replay_ticks("stand_still", {10});
    render::View view(ui_platform(), render::RenderSettings{}, r.skeleton, r.terrain);
    const std::string path = "ui_save_test.toml";
    const std::string original = "# my walk\n[gait]   # tuned by hand\nwalk_duty = 0.6   # planted longer\n\n[locomotion]\nmax_speed = 3.0\n";
    std::ofstream(path) << original;
    ui::TuningUi tuning(view.platform(), ui::TuningUiOptions{load_config(path), path, "", stderr});

    CHECK(tuning.edit("gait", "step_length_multiplier", "0.62"));
    CHECK(tuning.edit("gait", "walk_duty", "0.7"));
    CHECK(tuning.edit("locomotion", "stick_deadzone", "0.2"));
    // Out of range, and a relation between keys: refused, the working copy unchanged, the message names the key.
    CHECK_FALSE(tuning.edit("gait", "walk_duty", "0.95"));
    CHECK_THAT(tuning.message(), Catch::Contains("gait.walk_duty") && Catch::Contains("[0.5, 0.9]"));
    CHECK_FALSE(tuning.edit("gait", "min_step_duration", "2.0"));
    CHECK(tuning.working().sim.walk_duty == 0.7f);
    // Every documented key of the panel's tables, with the schema's range; graph build keys locked.
    for (const ConfigKeyInfo& k : config_schema()) {
        if (k.table != "gait" && k.table != "motion" && k.table != "motion_graph") continue;
        bool found = false;
        for (const ui::PanelKey& p : ui::panel_keys())
            if (p.table == k.table && p.key == k.key) {
                found = true;
                CHECK(p.min == k.min);
                CHECK(p.max == k.max);
                CHECK(p.locked == (!k.live || k.type == "string"));
            }
        INFO(k.table << "." << k.key);
        CHECK(found);
    }
    REQUIRE(tuning.save(path));
    const std::string saved = file_text(path);
    CHECK(saved == "# my walk\n[gait]   # tuned by hand\nwalk_duty = 0.7   # planted longer\nstep_length_multiplier = 0.62\n\n"
                   "[locomotion]\nmax_speed = 3.0\nstick_deadzone = 0.2\n");
    const AppConfig reloaded = load_config(path);
    CHECK(reloaded.sim.step_length_multiplier == 0.62f);
    CHECK(reloaded.sim.walk_duty == 0.7f);
    CHECK(reloaded.sim.stick_deadzone == 0.2f);
    // Reset to the default and save again: the default value is written.
    for (const ui::PanelKey& p : ui::panel_keys())
        if (p.key == "walk_duty") CHECK(tuning.reset(p));
    REQUIRE(tuning.save(path));
    CHECK(load_config(path).sim.walk_duty == default_config().sim.walk_duty);
    CHECK(file_text(path).find("# planted longer") != std::string::npos);
    // A new file holds just the edited keys.
    std::filesystem::remove("ui_new.toml");
    REQUIRE(tuning.save("ui_new.toml"));
    CHECK(load_config("ui_new.toml").sim.step_length_multiplier == 0.62f);
    std::filesystem::remove(path);
    std::filesystem::remove("ui_new.toml");
}
