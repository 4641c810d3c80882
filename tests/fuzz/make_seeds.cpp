// Writes the binary seeds of tests/fuzz/corpus (small input logs and a small
// .mgraph) so they come from code, not from a hex editor:
//   cmake --build --preset fuzz --target marionette_fuzz_seeds
//   build/fuzz/tests/fuzz/marionette_fuzz_seeds tests/fuzz/corpus
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "firmware_sim/report_encoders.hpp"
#include "runtime/formats/input_log.hpp"
#include "runtime/formats/stick_program.hpp"
#include "runtime/graph/motion_graph.hpp"
#include "tests/graph_fixture.hpp"

using namespace marionette;

namespace {
void write(const std::string& path, const std::vector<std::uint8_t>& bytes) {
    std::filesystem::create_directories(std::filesystem::path(path).parent_path());
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    if (!out) {
        std::fprintf(stderr, "cannot write %s\n", path.c_str());
        std::exit(1);
    }
}
}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: %s CORPUS_DIR\n", argv[0]);
        return 2;
    }
    const std::string dir = argv[1];
    const StickProgram program = parse_stick_program(
        "ramp 100ms ly=1 lx=-0.5 lt=0.25\nhold 50ms\npress south 20ms\ncircle 100ms stick=right turns=1\n"
        "ramp 30ms ly=0 rt=1\n",
        "seed.prog");
    const std::vector<TickInput> ticks = render_stick_program(program, 240);
    InputLogHeader header;
    header.config_text = "[simulation]\ntick_rate_hz = 240\n";
    header.clip_data_hash = 0x0123456789abcdefull;
    for (const char* d : {"input_log", "input_log_crc"}) {
        const std::string base = dir + "/" + d + "/";
        write(base + "seed_program.mlog", encode_input_log(header, ticks, 20));
        write(base + "seed_one_chunk.mlog", encode_input_log(header, ticks, 0));
        // A configuration change between two chunks, no end marker (an interrupted run).
        std::vector<std::uint8_t> live = InputLogEncoder::encode_header(header);
        InputLogEncoder encoder;
        for (size_t i = 0; i < 10 && i < ticks.size(); ++i) encoder.append_tick(ticks[i]);
        encoder.finish_chunk(live);
        encoder.append_config_change("[gait]\nstep_height = 0.1\n");
        for (size_t i = 10; i < 30 && i < ticks.size(); ++i) encoder.append_tick(ticks[i]);
        encoder.finish_chunk(live);
        write(base + "seed_config_change.mlog", live);
    }
    const std::vector<std::uint8_t> graph = serialize_motion_graph(test::make_locomotion_graph());
    write(dir + "/mgraph/seed_locomotion.mgraph", graph);
    write(dir + "/mgraph_hash/seed_locomotion.mgraph", graph);
    // HID: first byte picks the parser (fuzz_hid.cpp), then one real-format report.
    firmware_sim::PadState pad;
    pad.lx = 0.5, pad.ly = -0.25, pad.rx = -1, pad.ry = 1, pad.lt = 0.75, pad.rt = 0.1, pad.buttons = 0x1235;
    const firmware_sim::ReportClock clock{7, 123456};
    const input::HidFormat formats[] = {input::HidFormat::ds4, input::HidFormat::dualsense, input::HidFormat::switchpro,
                                        input::HidFormat::steamdeck};
    for (int f = 0; f < 4; ++f) {
        for (int bt = 0; bt < 2; ++bt) {
            if (bt == 1 && f >= 2) continue;  // Bluetooth differs only for the Sony pads
            const firmware_sim::Report r = firmware_sim::encode_report(formats[f], pad, clock, bt == 1,
                                                                       firmware_sim::kSimSwitchCalibration);
            std::vector<std::uint8_t> seed{static_cast<std::uint8_t>(f)};
            seed.insert(seed.end(), r.view().begin(), r.view().end());
            write(dir + "/hid/seed_" + std::string(input::hid_format_name(formats[f])) + (bt ? "_bt" : "_usb"), seed);
        }
    }
    {
        const auto cal = input::switchpro::encode_factory_calibration(firmware_sim::kSimSwitchCalibration);
        const firmware_sim::Report r = firmware_sim::encode_report(input::HidFormat::switchpro, pad, clock, false,
                                                                   firmware_sim::kSimSwitchCalibration);
        std::vector<std::uint8_t> seed{4};
        seed.insert(seed.end(), cal.begin(), cal.end());
        seed.insert(seed.end(), r.view().begin(), r.view().end());
        write(dir + "/hid/seed_switchpro_calibrated", seed);
    }
    std::printf("wrote seeds under %s (graph %zu bytes, %zu ticks)\n", dir.c_str(), graph.size(), ticks.size());
    return 0;
}
