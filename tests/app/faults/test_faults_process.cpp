// Fault injection on the whole `marionette run` process: stopped (SIGSTOP) and
// resumed, and the system clock jumping under it (docs/reliability.md).
#include <catch2/catch.hpp>
#include <signal.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>

#include "app/io/files.hpp"
#include "runtime/formats/input_log.hpp"
#include "tests/app/faults/fault_support.hpp"
#include "tests/test_support.hpp"

using namespace marionette;
using test::Child;

namespace {
std::uint64_t ticks_with(const DecodedInputLog& log, Button b) {
    std::uint64_t n = 0;
    for (const TickInput& t : log.ticks)
        if (t.buttons & button_bit(b)) ++n;
    return n;
}
}  // namespace

TEST_CASE("run stopped (SIGSTOP) for 3 s and resumed, the catch-up cap holds, the skip is counted, no sample is lost",
          "[faults][sigstop]") {
    test::TempFolder dir("sigstop");
    // The north button is pressed only while the process is stopped (it is
    // stopped once the 1 s status line is out, and stays stopped 3 s).
    test::write_file(dir.path("gap.prog"), "hold 2s ly=0.6\npress north 200ms\nhold 1.8s ly=0.6\nhold 2s ly=0\n");
    const double program_s = 6.0;
    Child child({"run", "--input", "sim:" + dir.path("gap.prog"), "--record", dir.path("run.mlog"), "--trace",
                 dir.path("run.csv"), "--stats-json", dir.path("stats.json")},
                {}, dir.path("stderr.txt"));
    REQUIRE(child.wait_for_line("[   1.0 s]", 30.0));
    REQUIRE(::kill(child.pid(), SIGSTOP) == 0);
    ::sleep(3);
    REQUIRE(::kill(child.pid(), SIGCONT) == 0);
    const int code = child.finish(60.0);
    INFO(child.output() << test::read_file_or_empty(dir.path("stderr.txt")));
    REQUIRE(code == 0);

    const std::string stats = test::read_file_or_empty(dir.path("stats.json"));
    INFO(stats);
    WARN("SIGSTOP 3 s: ticks " << test::json_number(stats, "ticks") << ", catch_up_drops "
                               << test::json_number(stats, "catch_up_drops") << ", catch_up_skipped_s "
                               << test::json_number(stats, "catch_up_skipped_s") << ", max_ticks_per_wake "
                               << test::json_number(stats, "max_ticks_per_wake") << ", samples "
                               << test::json_number(stats, "samples") << ", dropped_samples "
                               << test::json_number(stats, "dropped_samples") << ", missed_frames "
                               << test::json_number(stats, "missed_frames") << ", wall_s "
                               << test::json_number(stats, "wall_s"));
    // All ticks ran (the log is contiguous); the 3 s gap was skipped in time,
    // counted, and never run as a burst: at most max_catch_up_ticks (8) per wake.
    CHECK(test::json_number(stats, "ticks") == program_s * 240);
    CHECK(test::json_number(stats, "catch_up_drops") >= 1);
    CHECK(test::json_number(stats, "catch_up_skipped_s") > 2.5);
    CHECK(test::json_number(stats, "catch_up_skipped_s") < 3.6);
    CHECK(test::json_number(stats, "max_ticks_per_wake") <= 8);
    CHECK(test::json_number(stats, "max_ticks_per_wake") >= 1);
    CHECK(test::json_number(stats, "wall_s") > program_s + 2.5);
    // Every sample of the program reached the ring. The simulated controller
    // sends a sample only when the pad's state changes (as an evdev pad does):
    // the start (ly 0.6), the press and the release of north (the press falls in
    // the stop) and the stick back to 0 — four, none of them dropped.
    CHECK(test::json_number(stats, "dropped_samples") == 0);
    CHECK(test::json_number(stats, "samples") == 4);

    const DecodedInputLog log = decode_input_log(read_binary_file(dir.path("run.mlog")), dir.path("run.mlog"));
    CHECK(log.complete);
    CHECK(log.ticks.size() == static_cast<size_t>(program_s * 240));
    // The press made during the stop is in the log: folded into the tick(s)
    // that consumed the backlog, not lost.
    CHECK(ticks_with(log, Button::north) >= 1);
    CHECK(ticks_with(log, Button::north) < 48);  // 200 ms would be 48 ticks without the stop

    // And the recording replays to the run's trace.
    Child replay({"replay", dir.path("run.mlog"), "--trace", dir.path("replay.csv")}, {}, dir.path("replay_err.txt"));
    REQUIRE(replay.finish(60.0) == 0);
    CHECK(test::read_file_or_empty(dir.path("replay.csv")) == test::read_file_or_empty(dir.path("run.csv")));

    // The recording played live (--input log:) and stopped the same way still
    // gives the replay's states: tick k consumes recorded sample k whatever the
    // catch-up cap skipped.
    Child live({"run", "--input", "log:" + dir.path("run.mlog"), "--trace", dir.path("live.csv"), "--stats-json",
                dir.path("live.json")},
               {}, dir.path("live_err.txt"));
    REQUIRE(live.wait_for_line("[   1.0 s]", 30.0));
    REQUIRE(::kill(live.pid(), SIGSTOP) == 0);
    ::sleep(3);
    REQUIRE(::kill(live.pid(), SIGCONT) == 0);
    REQUIRE(live.finish(60.0) == 0);
    const std::string live_stats = test::read_file_or_empty(dir.path("live.json"));
    INFO(live_stats);
    CHECK(test::json_number(live_stats, "catch_up_skipped_s") > 2.5);
    CHECK(test::read_file_or_empty(dir.path("live.csv")) == test::read_file_or_empty(dir.path("replay.csv")));
}

TEST_CASE("run ignores the system clock, CLOCK_REALTIME jumping by hours changes nothing", "[faults][clock]") {
    test::TempFolder dir("clock");
    const std::string shim = MARIONETTE_CLOCK_JUMP_SHIM;
    REQUIRE(std::filesystem::exists(shim));
    // ASan insists on being first in the preload list; the shim is not instrumented.
    const std::vector<std::string> env = {"LD_PRELOAD=" + shim, "MARIONETTE_CLOCK_JUMP_REPORT=" + dir.path("shim.txt"),
                                          "ASAN_OPTIONS=verify_asan_link_order=0:detect_leaks=0"};
    {
        // Positive control: a program that reads the realtime clock sees it jump.
        Child date("/bin/date", {"+%s"}, env, dir.path("date_err.txt"));
        REQUIRE(date.finish(10.0) == 0);
        const double shown = std::strtod(date.output().c_str(), nullptr);
        const double actual = static_cast<double>(std::time(nullptr));
        INFO("date under the shim printed " << date.output());
        CHECK(std::fabs(shown - actual) > 3 * 3600);
    }
    Child child({"run", "--input", "sim:builtin:walk_stop", "--duration", "3", "--stats-json", dir.path("stats.json"),
                 "--record", dir.path("run.mlog")},
                env, dir.path("stderr.txt"));
    const int code = child.finish(60.0);
    INFO(child.output() << test::read_file_or_empty(dir.path("stderr.txt")));
    REQUIRE(code == 0);
    const std::string stats = test::read_file_or_empty(dir.path("stats.json"));
    const std::string shim_report = test::read_file_or_empty(dir.path("shim.txt"));
    INFO(stats << "\nshim: " << shim_report);
    REQUIRE(shim_report.find("realtime_reads") != std::string::npos);  // the shim was loaded
    WARN("clock jump: the run under the shim made " << shim_report.substr(0, shim_report.find('\n'))
                                                << " (each one shifted by hours)");
    CHECK(test::json_number(stats, "ticks") == 3 * 240);
    CHECK(test::json_number(stats, "catch_up_skipped_s") < 0.25);
    CHECK(test::json_number(stats, "wall_s") > 2.9);
    CHECK(test::json_number(stats, "wall_s") < 4.5);
}
