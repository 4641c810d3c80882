// Frame cost of the renderer on the headless platform, drawing a walking puppet
// over steps with the HUD on, at 800x480 and 1280x800 (4x MSAA, and 1280x800
// without MSAA). Counters:
//   cpu_ms        recording the frame's GL calls (Renderer::draw)
//   finish_ms     present (MSAA resolve) + glFinish: the GPU's share; on llvmpipe
//                 this is where the CPU rasteriser does its work
//   gpu_timer_ms  GL_EXT_disjoint_timer_query around the draw where offered
//                 (-1 when not); on llvmpipe it covers command processing only
// The iteration time is the whole frame.
// Run: build/release/bench/marionette_bench_render
// (LIBGL_ALWAYS_SOFTWARE=1 forces llvmpipe where a GPU is present.)
#include <benchmark/benchmark.h>

#include <EGL/egl.h>
#include <GLES3/gl3.h>
// After gl3.h, which defines the calling-convention macros gl2ext.h uses.
#include <GLES2/gl2ext.h>

#include <chrono>
#include <cstring>

#include "render_es/view.hpp"
#include "runtime/formats/stick_program.hpp"

using namespace marionette;

namespace {

struct TimerQuery {
    PFNGLGENQUERIESEXTPROC gen = nullptr;
    PFNGLBEGINQUERYEXTPROC begin = nullptr;
    PFNGLENDQUERYEXTPROC end = nullptr;
    PFNGLGETQUERYOBJECTUI64VEXTPROC result = nullptr;
    GLuint query = 0;
    bool available = false;

    void init() {
        const char* ext = reinterpret_cast<const char*>(glGetString(GL_EXTENSIONS));
        if (ext == nullptr || std::strstr(ext, "GL_EXT_disjoint_timer_query") == nullptr) return;
        gen = reinterpret_cast<PFNGLGENQUERIESEXTPROC>(eglGetProcAddress("glGenQueriesEXT"));
        begin = reinterpret_cast<PFNGLBEGINQUERYEXTPROC>(eglGetProcAddress("glBeginQueryEXT"));
        end = reinterpret_cast<PFNGLENDQUERYEXTPROC>(eglGetProcAddress("glEndQueryEXT"));
        result = reinterpret_cast<PFNGLGETQUERYOBJECTUI64VEXTPROC>(eglGetProcAddress("glGetQueryObjectui64vEXT"));
        available = gen && begin && end && result;
        if (available) gen(1, &query);
    }
};

std::vector<PuppetState> walking_states(Simulation& sim) {
    const StickProgram program = parse_stick_program("ramp 500ms ly=0.8\nhold 3s\n", "bench");
    std::vector<PuppetState> states;
    for (const TickInput& input : render_stick_program(program, sim.config().tick_rate_hz)) {
        sim.step(input);
        states.push_back(sim.state());
    }
    return states;
}

void BM_Frame(benchmark::State& state) {
    const SimConfig config;
    Terrain terrain;
    for (int i = 0; i < 6; ++i)
        terrain.boxes.push_back({-1.0f, 1.0f + 0.3f * static_cast<float>(i), 1.0f, 3.0f, 0.15f * static_cast<float>(i + 1)});
    Simulation sim(config, terrain);
    const std::vector<PuppetState> states = walking_states(sim);

    render::PlatformOptions options;
    options.width = static_cast<std::int32_t>(state.range(0));
    options.height = static_cast<std::int32_t>(state.range(1));
    options.msaa_samples = static_cast<std::int32_t>(state.range(2));
    render::RenderSettings settings;
    render::View view(options, settings, sim.skeleton(), terrain);
    TimerQuery timer;
    timer.init();
    render::DebugOverlay overlay;
    const std::string hud = "bench  t 1.25 s  tick 300  speed 1.40 m/s  heading 12 deg";

    double cpu_ns = 0.0;
    double finish_ns = 0.0;
    double timer_ns = 0.0;
    std::int64_t timed_frames = 0;
    std::size_t k = 0;
    using Clock = std::chrono::steady_clock;
    for (auto _ : state) {
        const PuppetState& s = states[k++ % states.size()];
        view.platform().begin_frame();
        if (timer.available) timer.begin(GL_TIME_ELAPSED_EXT, timer.query);
        const auto t0 = Clock::now();
        view.renderer().draw(s, overlay, hud, options.width, options.height, 1.0f / 60.0f);
        const auto t1 = Clock::now();
        if (timer.available) timer.end(GL_TIME_ELAPSED_EXT);
        view.platform().present();
        glFinish();
        const auto t2 = Clock::now();
        cpu_ns += std::chrono::duration<double, std::nano>(t1 - t0).count();
        finish_ns += std::chrono::duration<double, std::nano>(t2 - t1).count();
        if (timer.available) {
            GLuint64 elapsed = 0;
            timer.result(timer.query, GL_QUERY_RESULT_EXT, &elapsed);
            GLint disjoint = 0;
            glGetIntegerv(GL_GPU_DISJOINT_EXT, &disjoint);
            // A disjoint period (or llvmpipe's first queries, which report times
            // since context creation) makes the value meaningless: skip it.
            if (!disjoint && elapsed < 1'000'000'000ull) {
                timer_ns += static_cast<double>(elapsed);
                ++timed_frames;
            }
        }
    }
    const double n = static_cast<double>(state.iterations());
    state.counters["cpu_ms"] = cpu_ns / n / 1e6;        // recording the frame's GL calls
    state.counters["finish_ms"] = finish_ns / n / 1e6;  // present + glFinish: the GPU's (rasteriser's) share
    state.counters["gpu_timer_ms"] = timed_frames ? timer_ns / static_cast<double>(timed_frames) / 1e6 : -1.0;
    state.SetLabel(view.platform().description());
}
BENCHMARK(BM_Frame)->ArgNames({"w", "h", "msaa"})->Args({800, 480, 4})->Args({1280, 800, 4})->Args({1280, 800, 0})->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

}  // namespace

BENCHMARK_MAIN();
