// Fault injection inside the live pipeline (run_pipeline, real time): a pad
// that floods, a render thread that stalls, the watched configuration file
// deleted / replaced / unreadable / half-written, and where the clock comes
// from (docs/reliability.md, "Fault injection").
#include <catch2/catch.hpp>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "app/config/config.hpp"
#include "app/live/clock.hpp"
#include "app/live/pipeline.hpp"
#include "firmware_sim/sim_hid_device.hpp"
#include "firmware_sim/sim_pad.hpp"
#include "input/hid/hid_pad.hpp"
#include "input/input_thread.hpp"
#include "tests/app/faults/fault_support.hpp"
#include "tests/test_support.hpp"

using namespace marionette;
namespace fs = marionette::firmware_sim;

namespace {

PipelineOptions realtime_run(const std::string& program_text, std::uint64_t ticks) {
    PipelineOptions o;
    o.config = default_config().sim;
    o.script = script_from_program(parse_stick_program(program_text, "fault.prog"), kSimulatedControllerHz);
    o.total_ticks = ticks;
    o.status_lines = false;
    return o;
}

// firmware_sim's in-process HID pad, paced: each report is handed out at its
// time in the stream (8 kHz here), except a backlog window whose reports all
// come at once at its start (a host controller releasing what it held back).
class PacedPad final : public input::HidTransport {
public:
    PacedPad(const fs::SimStream& stream, std::int64_t burst_from_ns, std::int64_t burst_to_ns,
             std::atomic<std::uint64_t>& delivered, std::atomic<std::uint64_t>& valid)
        : delivered_(delivered), valid_(valid), device_(stream, input::HidFormat::dualsense) {
        for (const fs::SimFrame& f : stream.frames)
            if (f.kind == fs::SimFrame::Kind::report)
                due_ns_.push_back(f.t_ns >= burst_from_ns && f.t_ns < burst_to_ns ? burst_from_ns : f.t_ns);
    }
    int read_report(std::span<std::uint8_t> buffer, int timeout_ms) override {
        const std::int64_t now = monotonic_ns();
        if (start_ns_ < 0) start_ns_ = now;
        const std::int64_t limit = now + std::int64_t{timeout_ms} * 1'000'000;
        if (next_ >= due_ns_.size()) {  // the stream is over: a quiet pad
            sleep_until_ns(limit);
            return 0;
        }
        const std::int64_t due = start_ns_ + due_ns_[next_];
        if (due > limit) {
            sleep_until_ns(limit);
            return 0;
        }
        if (due > now) sleep_until_ns(due);
        ++next_;
        const int n = device_.read_report(buffer, 0);
        // What the backend's parser will make of it (garbage is refused).
        input::InputSample sample;
        const bool valid = n > 0 && input::parse_hid_report(input::HidFormat::dualsense,
                                                            buffer.first(static_cast<size_t>(n)), {}, sample) ==
                                        input::ParseStatus::ok;
        delivered_.fetch_add(1, std::memory_order_relaxed);
        if (valid) valid_.fetch_add(1, std::memory_order_relaxed);
        return n;
    }
    int write_report(std::span<const std::uint8_t> r) override { return device_.write_report(r); }
    int send_feature(std::span<const std::uint8_t> r) override { return device_.send_feature(r); }
    int get_feature(std::span<std::uint8_t> b) override { return device_.get_feature(b); }

private:
    // The test's counters: the input thread destroys the pad when it stops.
    std::atomic<std::uint64_t>& delivered_;
    std::atomic<std::uint64_t>& valid_;
    fs::SimHidDevice device_;
    std::vector<std::int64_t> due_ns_;
    size_t next_ = 0;
    std::int64_t start_ns_ = -1;
};

// Runs the pipeline on another thread while `during` acts on it; returns its result.
template <typename Action>
PipelineResult run_while(const PipelineOptions& o, Action during) {
    PipelineResult r;
    std::atomic<bool> done{false};
    std::thread runner([&] {
        r = run_pipeline(o);
        done = true;
    });
    during(done);
    runner.join();
    return r;
}

void sleep_s(double s) { std::this_thread::sleep_for(std::chrono::duration<double>(s)); }

}  // namespace

TEST_CASE("a pad flooding at 8 kHz with duplicates and garbage for 10 s, drops counted, no stall, flat memory",
          "[faults][flood]") {
    const double seconds = 10.0;
    fs::SimPadOptions pad;
    pad.hid_format = input::HidFormat::dualsense;
    pad.rate_hz = 8000;
    pad.faults = fs::parse_faults("dup=0.25,corrupt=0.25,noise=0.02,seed=18");
    const StickProgram program = parse_stick_program("circle 10s radius=1 turns=5\n", "flood.prog");
    const fs::SimStream stream = fs::simulate_pad(program, pad);
    REQUIRE(stream.stats.duplicated > 10'000);
    REQUIRE(stream.stats.corrupted > 10'000);
    // From 5 s to 7 s the pad's reports (~20 000) arrive all at once.
    std::atomic<std::uint64_t> delivered{0}, valid{0};
    int opens = 0;
    input::InputThreadOptions device;
    device.backend = "hidraw";
    device.open_hid = [&](const std::string&, input::OpenedHidPad& opened) {
        if (++opens > 1) return Outcome::failure("the flooding pad is plugged in only once");
        // Slow on purpose: it copies the 100 000-frame stream, which the run's
        // start-up must absorb before its clock starts (no catch-up drop).
        opened.transport = std::make_unique<PacedPad>(stream, 5'000'000'000, 7'000'000'000, delivered, valid);
        opened.format = input::HidFormat::dualsense;
        opened.path = "firmware_sim:dualsense@8kHz";
        return Outcome::success();
    };
    PipelineOptions o;
    o.config = default_config().sim;
    o.device = &device;
    o.total_ticks = static_cast<std::uint64_t>(seconds * 240);
    o.status_lines = false;
    std::int64_t rss_after_1s = 0, rss_max = 0;
    const PipelineResult r = run_while(o, [&](const std::atomic<bool>& done) {
        const auto start = std::chrono::steady_clock::now();
        while (!done) {
            sleep_s(0.05);
            const std::int64_t rss = test::resident_bytes();
            if (std::chrono::steady_clock::now() - start < std::chrono::seconds(1)) rss_after_1s = rss;
            else rss_max = std::max(rss_max, rss);
        }
    });
    INFO("delivered " << delivered << " reports, " << valid << " valid; samples " << r.samples_pushed << ", dropped " << r.samples_dropped
                      << "; wall " << r.wall_s << " s; catch-up drops " << r.catch_up_drops << " skipping "
                      << r.catch_up_skipped_s << " s, longest tick " << r.tick_time.max_ns / 1e3
                      << " us, input latency max " << r.input_latency.max_ns / 1e6 << " ms; RSS after 1 s "
                      << rss_after_1s << ", max later " << rss_max);
    WARN("flood: delivered " << delivered << " reports (" << valid << " valid), " << r.samples_pushed << " samples into the ring, "
                             << r.samples_dropped << " dropped (counted); RSS growth " << (rss_max - rss_after_1s)
                             << " bytes; wall " << r.wall_s << " s for " << seconds << " s");
    // The stream was read (but for the last reports when the run ends first),
    // and every valid report is accounted for: a sample in the ring, or one
    // dropped because the ring was full. The backlog overflowed it.
    CHECK(delivered.load() > stream.stats.reports * 95 / 100);
    CHECK(valid.load() < delivered.load());  // garbage was sent, and refused
    CHECK(r.samples_pushed + r.samples_dropped == valid.load());
#if defined(__SANITIZE_ADDRESS__)
    // Under ASan the input thread reads the backlog slower than the simulation
    // drains the ring, so it may not overflow: the accounting above still holds.
    if (r.samples_dropped == 0) WARN("ASan build: the backlog did not overflow the ring (nothing dropped)");
#else
    CHECK(r.samples_dropped > 0);
#endif
    // The simulation kept its rate: every tick ran, none skipped, on time.
    CHECK(r.ticks == o.total_ticks);
    // A simulation held up by the flood would skip seconds; on a shared 2-core
    // machine a descheduled thread may still skip a tick or thirty, so the
    // bound is a quarter of a second, not zero.
    CHECK(r.catch_up_skipped_s < 0.25);
    CHECK(r.wall_s < seconds + 0.5);
    // Memory is flat once running (the threads allocate nothing in steady state).
#if defined(__SANITIZE_ADDRESS__)
    // ASan's quarantine keeps freed blocks resident (2.5 MB measured here).
    CHECK(rss_max - rss_after_1s <= 4 * 1024 * 1024);
#else
    CHECK(rss_max - rss_after_1s <= 1024 * 1024);
#endif
}

TEST_CASE("the render thread stalled for 500 ms, the simulation keeps its rate, frames are dropped not queued",
          "[faults][render_stall]") {
    const double seconds = 3.0;
    PipelineOptions o = realtime_run("hold 3s ly=0.8\n", static_cast<std::uint64_t>(seconds * 240));
    o.frame_rate_hz = 60;
    o.test_render_stall_after_frames = 60;  // about 1 s in
    o.test_render_stall_ns = 500'000'000;
    const PipelineResult r = run_pipeline(o);
    INFO("frames " << r.frames << ", missed " << r.missed_frames << ", wall " << r.wall_s << " s, frame max "
                   << r.frame_time.max_ns / 1e6 << " ms, catch-up drops " << r.catch_up_drops);
    WARN("render stall: " << r.frames << " frames built, " << r.missed_frames << " missed, longest frame "
                          << r.frame_time.max_ns / 1e6 << " ms; " << r.ticks << " ticks in " << r.wall_s << " s");
    CHECK(r.frame_time.max_ns >= 500'000'000);  // the hook did stall a frame
    // The simulation did not wait for the renderer.
    CHECK(r.ticks == o.total_ticks);
    // (Waiting for the renderer would skip ~0.5 s; a loaded machine may skip a few ticks.)
    CHECK(r.catch_up_skipped_s < 0.25);
    CHECK(r.wall_s < seconds + 0.4);
    // The ~30 frame deadlines passed during the stall are counted as missed and
    // skipped; the thread does not build them afterwards to catch up.
    CHECK(r.missed_frames >= 29);
    const auto deadlines = static_cast<std::uint64_t>(r.wall_s * 60);
    CHECK(r.frames + r.missed_frames <= deadlines + 4);
    CHECK(r.frames <= deadlines - 30 + 4);
}

namespace {

// The configuration-file faults, acted out on a run watching FOLDER/live.toml.
// Plain code, no Catch macros: it may run in a child process (below). Writes
// the run's stdout and stderr to FOLDER/out.txt and FOLDER/err.txt and
// "TICKS CONFIG_CHANGES UNREADABLE_BLOCKED" to FOLDER/result.txt.
void act_out_config_faults(const std::string& folder) {
    const std::string file = folder + "/live.toml";
    // Not the default (3.0): a fault read as "no settings" would show as a change.
    const std::string good = "[locomotion]\nmax_speed = 2.0\n";
    std::ofstream(file) << good;
    PipelineOptions o = realtime_run("hold 9s ly=1\n", 9 * 240);
    o.config = load_config(file).sim;
    o.watch_config_file = file;
    o.out = std::fopen((folder + "/out.txt").c_str(), "w");
    o.err = std::fopen((folder + "/err.txt").c_str(), "w");
    if (!o.out || !o.err) return;
    bool unreadable_blocks_reads = false;
    const double settle = 0.6;  // > the watcher's 100 ms quiet time, with room for a loaded machine
    const PipelineResult r = run_while(o, [&](const std::atomic<bool>&) {
        sleep_s(0.5);
        std::filesystem::remove(file);  // 1. deleted
        sleep_s(settle);
        std::filesystem::create_directory(file);  // 2. a folder in its place
        sleep_s(settle);
        std::filesystem::remove(file);
        std::ofstream(file) << good;  // back (the same values: no change to apply)
        sleep_s(settle);
        ::chmod(file.c_str(), 0);  // 3. unreadable
        unreadable_blocks_reads = !std::ifstream(file).is_open();
        sleep_s(settle);
        ::chmod(file.c_str(), 0644);
        sleep_s(settle);
        {  // 4. rewritten half-way: the writer stops in the middle of a line
            std::ofstream half(file, std::ios::trunc);
            half << "[locomotion]\nmax_speed = 1.";
            half.flush();
            sleep_s(settle);
            half << "5\n";  // ... and finishes: now a valid edit, applied
        }
        sleep_s(settle);
    });
    std::fclose(o.out);
    std::fclose(o.err);
    std::ofstream(folder + "/result.txt") << r.ticks << " " << r.config_changes << " " << unreadable_blocks_reads << "\n";
}

}  // namespace

TEST_CASE("the watched config file deleted, made a folder, unreadable or cut short, the old config stays, one message each",
          "[faults][config_file]") {
    test::TempFolder dir("config");
    if (::geteuid() == 0) {
        // Root reads a file whatever its mode, so chmod 000 would test nothing:
        // act it out in a child that has dropped to nobody (65534).
        REQUIRE(::chown(dir.folder().c_str(), 65534, 65534) == 0);
        const pid_t child = ::fork();
        REQUIRE(child >= 0);
        if (child == 0) {
            if (::setgid(65534) != 0 || ::setuid(65534) != 0) ::_exit(3);
            act_out_config_faults(dir.folder());
            ::_exit(0);
        }
        int status = 0;
        REQUIRE(::waitpid(child, &status, 0) == child);
        REQUIRE(WIFEXITED(status));
        REQUIRE(WEXITSTATUS(status) == 0);
    } else {
        act_out_config_faults(dir.folder());
    }
    const std::string printed = test::read_file_or_empty(dir.path("out.txt"));
    const std::string errors = test::read_file_or_empty(dir.path("err.txt"));
    std::istringstream result(test::read_file_or_empty(dir.path("result.txt")));
    std::uint64_t ticks = 0, config_changes = 0;
    bool unreadable_blocks_reads = false;
    result >> ticks >> config_changes >> unreadable_blocks_reads;
    INFO("stdout:\n" << printed << "\nstderr:\n" << errors);
    REQUIRE(unreadable_blocks_reads);  // the chmod 000 case was really exercised
    CHECK(ticks == 9 * 240);           // no crash, no stop: the run went on
    CHECK(test::count_lines_with(errors, "live.toml: cannot open the configuration file: No such file or directory; "
                                         "keeping the previous configuration") == 1);
    CHECK(test::count_lines_with(errors, "live.toml: is a directory, not a configuration file; keeping the previous "
                                         "configuration") == 1);
    CHECK(test::count_lines_with(errors, "live.toml: cannot open the configuration file: Permission denied; keeping "
                                         "the previous configuration") == 1);
    // The half-written file names its line and is not applied; the finished one is.
    CHECK(test::count_lines_with(errors, "live.toml:2") == 1);
    CHECK(test::count_lines_with(errors, "config:") == 4);  // one line per fault, nothing else
    CHECK(config_changes == 1);
    CHECK(test::count_lines_with(printed, "config: applied before tick") == 1);
    CHECK_THAT(printed, Catch::Contains("locomotion.max_speed 2.0 → 1.5"));
    WARN("config file faults, stderr:\n" << errors);
}

TEST_CASE("nothing in the live pipeline reads the realtime clock, only CLOCK_MONOTONIC paces it", "[faults][clock]") {
    // The run's timing code: the live pipeline, the command, the input thread and
    // backends, the runtime's handoffs and fixed-step driver.
    const char* forbidden[] = {"CLOCK_REALTIME", "system_clock", "high_resolution_clock", "gettimeofday",
                               "time(nullptr)", "time(NULL)", "std::time(", "CLOCK_TAI"};
    int files = 0;
    for (const char* folder : {"app/live", "app/cli", "input", "runtime/handoff", "runtime/sim", "render_es"}) {
        for (const auto& entry : std::filesystem::recursive_directory_iterator(test::source_path(folder))) {
            const std::string ext = entry.path().extension().string();
            if (ext != ".cpp" && ext != ".hpp") continue;
            ++files;
            const std::string text = test::read_text_file(entry.path().string());
            for (const char* f : forbidden) {
                INFO(entry.path().string() << " uses " << f);
                CHECK(text.find(f) == std::string::npos);
            }
        }
    }
    CHECK(files > 40);
    // And the clock it does use is the monotonic one.
    CHECK_THAT(test::read_text_file(test::source_path("app/live/clock.hpp")), Catch::Contains("clock_gettime(CLOCK_MONOTONIC"));
}
