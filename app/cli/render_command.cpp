// `marionette render LOG --out DIR`: replays an input log headless and writes PNG
// frames at a fixed frame rate (interpolating between ticks as the live renderer
// does), optionally piping them to ffmpeg for a video.
#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>
#include <sys/wait.h>

#include "app/cli/cli.hpp"
#include "app/io/log.hpp"
#include "app/config/config.hpp"
#include "app/io/files.hpp"
#include "app/config/character_config.hpp"
#include "app/config/render_config.hpp"
#include "app/eval/log_provenance.hpp"
#include "app/eval/replay.hpp"
#include "render_es/image.hpp"
#include "render_es/interpolate.hpp"
#include "render_es/view.hpp"
#include "runtime/errors/import_error.hpp"

namespace marionette {

namespace {
struct RenderCommandOptions {
    std::string log_file;
    std::string out_dir;
    std::string size;
    double fps = 60.0;
    double from_s = 0.0;
    double to_s = -1.0;
    std::string video;
    std::string render_config;
    std::string overlays;
    bool no_hud = false;
    std::string graph_file;  // --graph; default: the graph the log names
};

bool parse_size(const std::string& text, std::int32_t& w, std::int32_t& h) {
    render::KmsModeRequest r;
    if (!parse_mode_text(text, r) || r.refresh_hz != 0) return false;
    w = r.width;
    h = r.height;
    return true;
}

// The executable `program` on $PATH, if there is one.
std::optional<std::string> find_on_path(const std::string& program) {
    const char* path = std::getenv("PATH");
    std::stringstream dirs(path ? path : "");
    std::string dir;
    while (std::getline(dirs, dir, ':')) {
        const std::filesystem::path candidate = std::filesystem::path(dir.empty() ? "." : dir) / program;
        std::error_code ec;
        if (std::filesystem::is_regular_file(candidate, ec) && access(candidate.c_str(), X_OK) == 0) return candidate.string();
    }
    return std::nullopt;
}

void apply_overlay_list(const std::string& list, render::RenderSettings& s) {
    std::stringstream items(list);
    std::string item;
    while (std::getline(items, item, ',')) {
        if (item == "skeleton") s.show_skeleton = true;
        else if (item == "feet") s.show_feet = true;
        else if (item == "gait") s.show_gait = true;
        else if (item == "motion_graph") s.show_motion_graph = true;
        else if (item == "hud") s.show_hud = true;
        else if (!item.empty())
            throw ImportError("--overlays", 0, "unknown overlay '" + item + "' (expected skeleton, feet, gait, motion_graph or hud)");
    }
}

// Pipes raw RGBA frames into ffmpeg, which encodes them as H.264.
class VideoPipe {
public:
    VideoPipe(const std::string& ffmpeg, const std::string& file, std::int32_t w, std::int32_t h, double fps) : file_(file) {
        const std::string command = fmt::format(
            "'{}' -loglevel error -y -f rawvideo -pix_fmt rgba -s {}x{} -r {} -i - -c:v libx264 -pix_fmt yuv420p '{}'",
            ffmpeg, w, h, fps, file);
        pipe_ = popen(command.c_str(), "w");
        if (pipe_ == nullptr) throw std::runtime_error(file + ": cannot start ffmpeg");
    }
    ~VideoPipe() {
        if (pipe_) pclose(pipe_);
    }
    void write(const std::vector<std::uint8_t>& rgba) {
        if (std::fwrite(rgba.data(), 1, rgba.size(), pipe_) != rgba.size())
            throw std::runtime_error(file_ + ": ffmpeg stopped accepting frames");
    }
    void finish() {
        const int status = pclose(pipe_);
        pipe_ = nullptr;
        if (status != 0) throw std::runtime_error(file_ + ": ffmpeg failed (status " + std::to_string(status) + ")");
    }

private:
    std::string file_;
    std::FILE* pipe_ = nullptr;
};

int render_command(const RenderCommandOptions& o) {
    if (o.out_dir.empty() && o.video.empty())
        throw ImportError("render", 0, "nothing to write: give --out DIR (PNG frames) and/or --video FILE.mp4");
    RenderConfig rc = load_render_config(o.render_config);
    if (!o.size.empty() && !parse_size(o.size, rc.settings.width, rc.settings.height))
        throw ImportError("--size", 0, "expected WIDTHxHEIGHT (e.g. 1280x800), got '" + o.size + "'");
    apply_overlay_list(o.overlays, rc.settings);
    if (o.no_hud) rc.settings.show_hud = false;
    if (o.to_s >= 0.0 && o.to_s < o.from_s)
        throw ImportError("--to", 0, fmt::format("--to {} is before --from {}", o.to_s, o.from_s));
    std::string ffmpeg;
    if (!o.video.empty()) {
        const std::optional<std::string> found = find_on_path("ffmpeg");
        if (!found)
            throw std::runtime_error("--video " + o.video + " needs ffmpeg, which is not installed (apt-get install ffmpeg); "
                                     "PNG frames (--out DIR) need nothing");
        ffmpeg = *found;
    }
    const DecodedInputLog log = decode_input_log(read_input_log_bytes(o.log_file), o.log_file);
    if (!log.warning.empty()) log_message(LogLevel::warning, fmt::format("warning: {}", log.warning));
    if (!o.out_dir.empty()) {
        std::error_code ec;
        std::filesystem::create_directories(o.out_dir, ec);
        if (ec) throw std::runtime_error(o.out_dir + ": cannot create the output folder (" + ec.message() + ")");
    }

    render::PlatformOptions platform;
    platform.kind = render::PlatformKind::headless;
    platform.width = rc.settings.width;
    platform.height = rc.settings.height;
    platform.msaa_samples = rc.settings.msaa_samples;
    const Terrain* terrain = nullptr;  // the replayed simulation's

    std::shared_ptr<const render::SkinnedMesh> body;  // [render] character, loaded with the first tick
    std::unique_ptr<render::View> view;
    std::unique_ptr<VideoPipe> video;
    PuppetState previous;
    PuppetState drawn;
    render::DebugOverlay overlay;
    std::vector<std::uint8_t> pixels;
    std::uint64_t frame = 0;
    double tick_rate = 0.0;
    double ankle_height = 0.08;
    const auto started = std::chrono::steady_clock::now();

    auto draw_frame = [&](const PuppetState& state, double seconds) {
        render::feet_overlay_from_state(state, *terrain, static_cast<float>(ankle_height), overlay);
        const float speed = std::sqrt(state.velocity.x * state.velocity.x + state.velocity.y * state.velocity.y);
        const std::string hud = fmt::format("{}  t {:.2f} s  tick {}  speed {:.2f} m/s  heading {:.0f} deg",
                                            std::filesystem::path(o.log_file).filename().string(), seconds, state.tick,
                                            speed, state.heading * det::kRadToDeg);
        view->frame(state, overlay, hud, static_cast<float>(1.0 / o.fps));
        view->platform().read_pixels(pixels);
        if (!o.out_dir.empty()) {
            render::Image image{view->platform().width(), view->platform().height(), pixels};
            render::write_png(fmt::format("{}/frame_{:05d}.png", o.out_dir, frame), image);
        }
        if (video) video->write(pixels);
        ++frame;
    };

    ReplayOptions options;
    options.graph = graph_for_log(log.header, o.log_file, o.graph_file,
                                  config_from_text(log.header.config_text, o.log_file + " (embedded configuration)"));
    options.on_tick = [&](const Simulation& sim) {
        const PuppetState& s = sim.state();
        if (!view) {
            tick_rate = sim.config().tick_rate_hz;
            ankle_height = sim.config().ankle_height;
            terrain = &sim.terrain();
            body = load_render_character(rc, sim.skeleton());
            view = std::make_unique<render::View>(platform, rc.settings, sim.skeleton(), *terrain, body.get());
            if (!ffmpeg.empty()) video = std::make_unique<VideoPipe>(ffmpeg, o.video, platform.width, platform.height, o.fps);
        }
        // Every frame whose time falls in (previous tick, this tick] is drawn now.
        while (true) {
            const double seconds = o.from_s + static_cast<double>(frame) / o.fps;
            if (o.to_s >= 0.0 && seconds > o.to_s + 1e-9) return false;
            const double at_tick = seconds * tick_rate;
            if (at_tick > static_cast<double>(s.tick) + 1e-9) break;
            if (s.tick == 0 || at_tick <= static_cast<double>(s.tick - 1)) {
                drawn = s;
            } else {
                render::interpolate_state(previous, s, static_cast<float>(at_tick - static_cast<double>(s.tick - 1)), drawn);
            }
            draw_frame(drawn, seconds);
        }
        previous = s;
        return true;
    };
    const ReplayResult r = replay_log(log, o.log_file, options);
    if (video) video->finish();
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    fmt::print("rendered {} frames ({}x{}, {} fps) of {} ({} ticks) in {:.1f} s ({:.1f} ms per frame){}{}\n", frame,
               platform.width, platform.height, o.fps, o.log_file, r.ticks, elapsed,
               frame ? 1000.0 * elapsed / static_cast<double>(frame) : 0.0,
               o.out_dir.empty() ? "" : "; PNGs in " + o.out_dir, o.video.empty() ? "" : "; video " + o.video);
    if (view) fmt::print("renderer: {}\n", view->platform().description());
    return 0;
}
}  // namespace

void register_render_command(CLI::App& app, int& exit_code) {
    auto o = std::make_shared<RenderCommandOptions>();
    CLI::App* cmd = app.add_subcommand("render", "Replay an input log headless and write PNG frames (or a video)");
    cmd->add_option("log", o->log_file, "input log")->required();
    cmd->add_option("--out", o->out_dir, "folder for frame_NNNNN.png");
    cmd->add_option("--size", o->size, "WIDTHxHEIGHT (default from the render settings, 1280x800)");
    cmd->add_option("--fps", o->fps, "frames per second of log time")->check(CLI::Range(1.0, 1000.0));
    cmd->add_option("--from", o->from_s, "first frame's time in the log (s)")->check(CLI::Range(0.0, 1e7));
    cmd->add_option("--to", o->to_s, "last frame's time in the log (s); default: the log's end")->check(CLI::Range(0.0, 1e7));
    cmd->add_option("--video", o->video, "also encode the frames with ffmpeg into this file (H.264)");
    cmd->add_option("--render-config", o->render_config, "render settings TOML overriding config/render.toml")
        ->check(CLI::ExistingFile);
    cmd->add_option("--overlays", o->overlays, "comma-separated: skeleton,feet,gait,motion_graph,hud");
    cmd->add_flag("--no-hud", o->no_hud, "no text HUD");
    cmd->add_option("--graph", o->graph_file,
                    "the motion graph (.mgraph, or default) the log was recorded with (default: the one the log names)");
    on_parsed(cmd, exit_code, [o] { return render_command(*o); });
}

}  // namespace marionette
