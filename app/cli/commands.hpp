#pragma once
// One function per `marionette` subcommand; main.cpp only parses the command line.
// Each returns the process exit code: 0 success, 1 failure, 2 bad input.
#include <string>
#include <vector>

namespace marionette {

struct RunOptions {
    std::string config_file;
    std::string input = "auto";              // auto|evdev|hidapi|sdl|sim:PROGRAM|log:FILE
    std::string display = "auto";
    std::string render_config_file;          // render settings (config/render.toml overrides)
    std::string record_file;
    std::string trace_file;
    std::string stats_json;
    double duration_s = -1.0;                // < 0: until the input ends
    std::vector<double> unplug;              // pairs: at, for (seconds), simulated controller only
    bool fast = false;                       // no real-time pacing: virtual time
    std::string graph_file;                  // --graph: drive the puppet from this .mgraph (or default)
};
int run_command(const RunOptions& options);

struct RecordOptions {
    std::string program_file;
    std::string output_file;
    std::string config_file;
    unsigned chunk_ticks = 60;               // 250 ms at 240 Hz, as a live run flushes
    bool json = false;
    std::string graph_file;                  // --graph: drive the puppet from this .mgraph
};
int record_command(const RecordOptions& options);

struct ReplayCommandOptions {
    std::string log_file;
    bool print_hash = false;
    bool json = false;
    std::string trace_csv;
    std::string joints_csv;
    std::string bvh;
    std::string graph_file;                  // --graph: the .mgraph the log was recorded with
    bool no_verify = false;                  // --no-verify: replay on past a checkpoint mismatch
};
int replay_command(const ReplayCommandOptions& options);

struct ClipOptions {
    std::string file;
    std::string asf_file;
    int frame = 0;
    bool json = false;
    std::string map_file;     // retarget: [retarget] table
    std::string config_file;  // retarget: the puppet's proportions
    std::string output_file;  // retarget: BVH out
};
int clip_info_command(const ClipOptions& options);
int clip_retarget_command(const ClipOptions& options);
int clip_fk_command(const ClipOptions& options);

}  // namespace marionette
