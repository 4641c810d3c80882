// The input thread on the evdev backend in a umockdev test bed (run under
// umockdev-wrapper): it reads a simulated Xbox pad through libevdev, pushes
// quantised samples into the ring, sees the pad unplugged (its node removed)
// and a pad plugged in on a new node (hot-plug), all without hardware.
#include <catch2/catch.hpp>

#include <umockdev.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>

#include "firmware_sim/sim_pad.hpp"
#include "input/evdev/evdev_pad.hpp"
#include "input/input_thread.hpp"
#include "tests/test_support.hpp"

using namespace marionette;
using namespace marionette::input;
namespace fs = marionette::firmware_sim;

namespace {
template <typename Pred>
bool wait_for(Pred pred, double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
        if (pred()) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return pred();
}
std::string replace_all(std::string s, const std::string& from, const std::string& to) {
    for (std::size_t at = 0; (at = s.find(from, at)) != std::string::npos; at += to.size()) s.replace(at, from.size(), to);
    return s;
}
}  // namespace

TEST_CASE("evdev under umockdev: input thread reads, survives unplug, picks up a new pad", "[input][evdev][umockdev]") {
    // Runs under umockdev-wrapper (tests/CMakeLists.txt), which preloads the library
    // that diverts /dev and /sys into the test bed.
    UMockdevTestbed* bed = umockdev_testbed_new();
    GError* error = nullptr;
    const std::string data = test::source_path("tests/data/umockdev/");
    const std::string description = test::read_text_file(data + "xbox.umockdev");
    REQUIRE(umockdev_testbed_add_from_string(bed, description.c_str(), &error));
    REQUIRE(umockdev_testbed_load_ioctl(bed, "/dev/input/event7", (data + "xbox.ioctl").c_str(), &error));

    // 300 ms at rest (nothing sent), then a stick move, a 1 ms press, a release.
    const StickProgram program = parse_stick_program(
        "hold 300ms\nhold 10ms lx=0.5 ly=-1 rt=1\npress south 1ms\nhold 10ms lx=-1\n", "umockdev.prog");
    fs::SimPadOptions o;
    o.rate_hz = 1000;
    const std::string events = fs::write_evemu_stream(fs::simulate_pad(program, o),
                                                      fs::evdev_pad_description(fs::EvdevPadModel::xbox));
    char events_path[] = "/tmp/marionette-umockdev-XXXXXX";
    const int fd = mkstemp(events_path);
    REQUIRE(fd >= 0);
    std::FILE* f = fdopen(fd, "w");
    std::fputs(events.c_str(), f);
    std::fclose(f);
    REQUIRE(umockdev_testbed_load_evemu_events(bed, "/dev/input/event7", events_path, &error));

    static InputRing ring;
    InputThread thread;
    InputThreadOptions options;
    options.backend = "evdev";
    options.raw = true;
    REQUIRE(thread.start(ring, options).ok());
    CHECK(thread.backend_description() == "evdev: chosen on the command line");
    REQUIRE(wait_for([&] { return thread.device_connected(); }, 2.0));
    // Frames: stick, press, release + stick.
    REQUIRE(wait_for([&] { return ring.size_approx() >= 3; }, 5.0));
    const TimedInput* first = ring.peek();
    REQUIRE(first);
    CHECK(first->input.left_x == quantize_stick(16384.0 / 32767.0));
    CHECK(first->input.left_y == quantize_stick(-1.0));
    CHECK(first->input.right_trigger == 65535);
    CHECK(first->input.buttons == 0);
    // One tick covering all three: latest sticks, and the 1 ms press survives.
    TickInputAssembler assembler;
    InputLatencyHistogram stats;
    const std::int64_t tick_time = monotonic_now_ns() + 1'000'000'000;
    const TickInput tick = assembler.assemble(ring, tick_time, tick_time, stats);
    CHECK(stats.count == 3);
    CHECK(tick.buttons == button_bit(Button::south));
    CHECK(tick.left_x == quantize_stick(-1.0));

    // Unplug: the node goes; the thread notices without blocking or crashing.
    umockdev_testbed_remove_device(bed, "/sys/devices/pci0000:00/0000:00:14.0/usb1/1-1/1-1:1.0/input/input7/event7");
    CHECK(wait_for([&] { return !thread.device_connected(); }, 3.0));
    CHECK(thread.stats().disconnects == 1);
    // ... and tells the simulation through the ring: a disconnect marker.
    REQUIRE(wait_for([&] { return ring.peek() != nullptr; }, 1.0));
    CHECK_FALSE(ring.peek()->connected);
    CHECK(assembler.assemble(ring, monotonic_now_ns(), monotonic_now_ns(), stats) == TickInput{});
    CHECK_FALSE(assembler.connected());

    // Plug in again: the kernel gives the new pad a new node.
    const std::string replugged = replace_all(replace_all(replace_all(description, "event7", "event8"), "input7", "input8"),
                                              "13:71", "13:72");
    REQUIRE(umockdev_testbed_add_from_string(bed, replugged.c_str(), &error));
    REQUIRE(umockdev_testbed_load_ioctl(bed, "/dev/input/event8", (data + "xbox.ioctl").c_str(), &error));
    CHECK(wait_for([&] { return thread.device_connected(); }, 3.0));
    CHECK(thread.stats().connects == 2);
    thread.stop();
    CHECK_FALSE(thread.running());
    std::remove(events_path);
    g_object_unref(bed);
}
