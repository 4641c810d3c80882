// Platform selection and KMS connector/mode choice, against described
// environments and mode lists (no display or GPU needed).
#include <catch2/catch.hpp>

#include "render_es/platform.hpp"

using namespace marionette::render;

TEST_CASE("auto selects a window under a compositor, KMS on a bare console, else headless", "[render][platform]") {
    DisplayEnvironment env;
    CHECK(select_platform(PlatformRequest::automatic, env) == PlatformKind::headless);
    env.has_drm_device = true;
    CHECK(select_platform(PlatformRequest::automatic, env) == PlatformKind::headless);  // ssh session: no VT
    env.on_virtual_terminal = true;
    CHECK(select_platform(PlatformRequest::automatic, env) == PlatformKind::kms);
    env.has_wayland_display = true;
    CHECK(select_platform(PlatformRequest::automatic, env) == PlatformKind::window);
    env = {};
    env.has_x11_display = true;
    env.on_virtual_terminal = true;  // startx from a VT: X is there, use it
    CHECK(select_platform(PlatformRequest::automatic, env) == PlatformKind::window);
    env.on_virtual_terminal = false;
    env.has_drm_device = false;
    CHECK(select_platform(PlatformRequest::automatic, env) == PlatformKind::window);
}

TEST_CASE("an explicit platform request is honoured whatever the environment", "[render][platform]") {
    DisplayEnvironment env;
    env.has_x11_display = true;
    CHECK(select_platform(PlatformRequest::headless, env) == PlatformKind::headless);
    CHECK(select_platform(PlatformRequest::kms, env) == PlatformKind::kms);
    CHECK(select_platform(PlatformRequest::window, DisplayEnvironment{}) == PlatformKind::window);
}

namespace {
KmsConnector laptop_panel() {
    // eDP panel: preferred native 1920x1200@60, also 144 Hz and lower modes.
    return {42, "eDP-1", true, {{1920, 1200, 60000, true}, {1920, 1200, 144000, false}, {1280, 800, 60000, false}}};
}
KmsConnector hdmi_monitor() {
    return {43, "HDMI-A-1", true,
            {{1920, 1080, 60000, true}, {1920, 1080, 59940, false}, {2560, 1440, 59951, false}, {1280, 720, 120000, false},
             {1920, 1080, 75000, false}}};
}
}  // namespace

TEST_CASE("KMS takes the first connected connector and its preferred mode", "[render][kms]") {
    const std::vector<KmsConnector> connectors = {{40, "DP-1", false, {}}, laptop_panel(), hdmi_monitor()};
    const KmsChoice c = choose_kms_mode(connectors, {});
    REQUIRE(c.chosen.ok());
    CHECK(c.connector_index == 1);
    CHECK(c.mode_index == 0);
}

TEST_CASE("KMS highest_refresh policy takes the fastest mode, ties to the larger", "[render][kms]") {
    const std::vector<KmsConnector> connectors = {laptop_panel()};
    KmsModeRequest r;
    r.policy = KmsModePolicy::highest_refresh;
    const KmsChoice c = choose_kms_mode(connectors, r);
    REQUIRE(c.chosen.ok());
    CHECK(c.mode_index == 1);  // 1920x1200@144

    const std::vector<KmsConnector> tie = {{1, "DP-2", true, {{1280, 720, 120000, false}, {1920, 1080, 120000, false}}}};
    CHECK(choose_kms_mode(tie, r).mode_index == 1);
}

TEST_CASE("KMS without a preferred mode falls back to the largest, then fastest", "[render][kms]") {
    const std::vector<KmsConnector> connectors = {
        {7, "DSI-1", true, {{720, 1280, 60000, false}, {1280, 800, 50000, false}, {1280, 800, 60000, false}}}};
    const KmsChoice c = choose_kms_mode(connectors, {});
    REQUIRE(c.chosen.ok());
    CHECK(c.mode_index == 2);
}

TEST_CASE("KMS forced modes: size with the highest refresh, size and refresh within 1 Hz", "[render][kms]") {
    const std::vector<KmsConnector> connectors = {hdmi_monitor()};
    KmsModeRequest r;
    r.width = 1920;
    r.height = 1080;
    CHECK(choose_kms_mode(connectors, r).mode_index == 4);  // 75 Hz beats 60 and 59.94
    r.refresh_hz = 60;
    CHECK(choose_kms_mode(connectors, r).mode_index == 0);  // 60.000 beats 59.940
    r = {};
    r.width = 2560;
    r.height = 1440;
    r.refresh_hz = 60;  // 59.951 Hz is within 1 Hz
    CHECK(choose_kms_mode(connectors, r).mode_index == 2);
}

TEST_CASE("KMS reports what is missing: no display, unknown or unplugged connector, unavailable mode", "[render][kms]") {
    const std::vector<KmsConnector> none = {{1, "HDMI-A-1", false, {}}, {2, "DP-1", false, {}}};
    KmsChoice c = choose_kms_mode(none, {});
    CHECK(c.connector_index == -1);
    CHECK(c.chosen.problem() == "no connector has a display connected");

    const std::vector<KmsConnector> two = {{1, "HDMI-A-1", false, {}}, laptop_panel()};
    KmsModeRequest r;
    r.connector = "HDMI-A-1";
    CHECK(choose_kms_mode(two, r).chosen.problem() == "connector HDMI-A-1 has no display connected");
    r.connector = "VGA-1";
    CHECK(choose_kms_mode(two, r).chosen.problem() == "no connector named VGA-1");
    r.connector = "eDP-1";
    CHECK(choose_kms_mode(two, r).connector_index == 1);
    r.width = 3840;
    r.height = 2160;
    r.refresh_hz = 60;
    CHECK(choose_kms_mode(two, r).chosen.problem() == "connector eDP-1 offers no mode 3840x2160@60Hz");
}
