#include "app/eval/replay.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <memory>
#include <stdexcept>

#include "app/config/config.hpp"
#include "app/io/files.hpp"
#include "app/graph/graph_files.hpp"
#include "runtime/formats/bvh.hpp"

namespace marionette {

namespace {
struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

File open_output(const std::string& path) {
    if (path.empty()) return nullptr;
    File f(std::fopen(path.c_str(), "wb"));
    if (!f) throw std::runtime_error(path + ": cannot create output file");
    return f;
}

void write(const File& f, const std::string& text, const std::string& path) {
    if (std::fwrite(text.data(), 1, text.size(), f.get()) != text.size())
        throw std::runtime_error(path + ": write failed");
}
}  // namespace

std::string trace_csv_header() { return "tick,hash,root_x,root_y,root_z\n"; }

std::string trace_csv_row(const PuppetState& s) { return trace_csv_row(s.tick, hash_state(s), s.root_position); }

std::string trace_csv_row(std::uint64_t tick, std::uint64_t state_hash, const vec3& root) {
    // fmt prints the shortest text that reads back to the same float.
    return fmt::format("{},{:016x},{},{},{}\n", tick, state_hash, root.x, root.y, root.z);
}

ReplayResult replay_log(const DecodedInputLog& log, const std::string& log_name, const ReplayOptions& options) {
    const SimConfig config = config_from_text(log.header.config_text, log_name + " (embedded configuration)").sim;
    if (static_cast<std::uint32_t>(config.tick_rate_hz) != log.header.tick_rate_hz)
        throw ImportError(log_name, 0,
                          fmt::format("header tick rate {} Hz disagrees with its configuration's {} Hz",
                                      log.header.tick_rate_hz, config.tick_rate_hz));
    set_simulation_float_mode();
    Simulation sim(config);
    if (options.graph) attach_motion_graph(sim, options.graph);
    if (sim.clip_data_hash() != log.header.clip_data_hash)
        throw ImportError(log_name, 0,
                          fmt::format("recorded with different clip data (hash {:016x}, this build has {:016x})",
                                      log.header.clip_data_hash, sim.clip_data_hash()));

    File trace = open_output(options.trace_csv);
    File joints = open_output(options.joints_csv);
    if (trace) write(trace, trace_csv_header(), options.trace_csv);
    const Skeleton& skeleton = sim.skeleton();
    const size_t joint_count = static_cast<size_t>(skeleton.joint_count());
    if (joints) {
        std::string header = "tick";
        for (const std::string& name : skeleton.joint_names) header += fmt::format(",{0}.x,{0}.y,{0}.z", name);
        write(joints, header + "\n", options.joints_csv);
    }
    Clip performed;
    if (!options.bvh.empty()) {
        performed.name = "performance";
        performed.skeleton = skeleton;
        performed.frame_rate = config.tick_rate_hz;
        performed.animated_translation.assign(joint_count, false);
        performed.animated_translation[0] = true;
        performed.rotations.reserve(log.ticks.size() * joint_count);
        performed.translations.reserve(log.ticks.size() * joint_count);
    }

    ReplayResult result;
    if (options.keep_tick_hashes) result.tick_hashes.reserve(log.ticks.size());
    size_t next_change = 0;
    vec3 previous_root = sim.state().root_position;
    bool keep_going = !options.on_tick || options.on_tick(sim);
    for (size_t k = 0; k < log.ticks.size() && keep_going; ++k) {
        while (next_change < log.config_changes.size() && log.config_changes[next_change].before_tick <= k) {
            const SimConfig next = apply_config_change(sim.config(), log.config_changes[next_change].config_text,
                                                       fmt::format("{} (config change before tick {})", log_name, k));
            if (const Outcome retuned = sim.retune(next); !retuned.ok())
                throw ImportError(log_name, 0, "recorded configuration change alters " + retuned.problem() + ", which cannot change live");
            ++result.config_changes;
            ++next_change;
        }
        sim.step(log.ticks[k]);
        const PuppetState& s = sim.state();
        const vec3 d = s.root_position - previous_root;
        result.distance_m += std::sqrt(static_cast<double>(d.x) * d.x + static_cast<double>(d.z) * d.z);
        previous_root = s.root_position;
        if (options.keep_tick_hashes) result.tick_hashes.push_back(hash_state(s));
        if (options.on_tick) keep_going = options.on_tick(sim);
        if (trace) write(trace, trace_csv_row(s), options.trace_csv);
        if (joints) {
            std::string row = fmt::format("{}", s.tick);
            for (size_t j = 0; j < joint_count; ++j)
                row += fmt::format(",{},{},{}", s.model_positions[j].x, s.model_positions[j].y, s.model_positions[j].z);
            write(joints, row + "\n", options.joints_csv);
        }
        if (!options.bvh.empty()) {
            performed.rotations.insert(performed.rotations.end(), s.local_rotations.begin(),
                                       s.local_rotations.begin() + static_cast<std::ptrdiff_t>(joint_count));
            performed.translations.insert(performed.translations.end(), s.local_translations.begin(),
                                          s.local_translations.begin() + static_cast<std::ptrdiff_t>(joint_count));
        }
    }
    result.ticks = sim.state().tick;  // fewer than the log holds when on_tick stopped early
    result.final_hash = hash_state(sim.state());
    result.duration_s = static_cast<double>(result.ticks) / config.tick_rate_hz;
    result.final_root_position = sim.state().root_position;
    if (!options.bvh.empty()) {
        performed.frame_count = static_cast<int>(log.ticks.size());
        if (performed.frame_count == 0) {
            // A log with no ticks still exports the starting pose.
            const PuppetState& s = sim.state();
            performed.rotations.assign(s.local_rotations.begin(), s.local_rotations.begin() + static_cast<std::ptrdiff_t>(joint_count));
            performed.translations.assign(s.local_translations.begin(), s.local_translations.begin() + static_cast<std::ptrdiff_t>(joint_count));
            performed.frame_count = 1;
        }
        write_text_file(options.bvh, export_bvh(performed));
    }
    return result;
}

}  // namespace marionette
