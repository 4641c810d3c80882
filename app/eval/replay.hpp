#pragma once
// Replaying an input log: the recorded TickInputs go straight into the
// simulation, with no threads and no clock. Used by `marionette replay` and tests.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "runtime/formats/input_log.hpp"
#include "runtime/sim/simulation.hpp"

namespace marionette {

struct ReplayOptions {
    std::string trace_csv;      // per tick: tick,hash,root_x,root_y,root_z
    std::string joints_csv;     // per tick: every joint's world position
    std::string bvh;            // the performed motion as a BVH animation
    bool keep_tick_hashes = false;
    // Compare the state hash with every checkpoint the log holds (version 2 logs)
    // and throw ReplayDesync (app/eval/log_provenance.hpp) at the first mismatch.
    bool verify_checkpoints = true;
    std::shared_ptr<const MotionGraph> graph;  // --graph: drive the puppet from this graph
    // Called with the simulation at its starting state and after every tick
    // (`marionette render` draws frames from it). Returning false stops the replay.
    std::function<bool(const Simulation&)> on_tick;
};

struct ReplayResult {
    std::uint64_t ticks = 0;
    std::uint64_t final_hash = 0;
    std::vector<std::uint64_t> tick_hashes;  // when keep_tick_hashes
    double duration_s = 0.0;
    double distance_m = 0.0;                 // path length of the root on the ground
    vec3 final_root_position{0.0f};
    int config_changes = 0;
    int checkpoints_verified = 0;
};

// Throws ConfigError/ImportError when the log's configuration or clip data do not
// match this build, ReplayDesync when a checkpoint's state hash differs,
// std::runtime_error when an output cannot be written.
ReplayResult replay_log(const DecodedInputLog& log, const std::string& log_name, const ReplayOptions& options);

// Per-tick CSV rows shared by `run --trace` and `replay --trace`, so the two are
// byte-identical for the same ticks.
std::string trace_csv_header();
std::string trace_csv_row(const PuppetState& state);
// The same row from its parts (the live pipeline hands these to its writer thread).
std::string trace_csv_row(std::uint64_t tick, std::uint64_t state_hash, const vec3& root_position);

}  // namespace marionette
