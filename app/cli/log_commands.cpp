// `marionette record` and `marionette replay`.
#include <fmt/format.h>

#include "app/cli/cli.hpp"
#include "app/io/log.hpp"
#include "app/cli/commands.hpp"
#include "app/config/config.hpp"
#include "app/io/files.hpp"
#include "app/graph/graph_files.hpp"
#include "app/graph/graph_rebuild.hpp"
#include "app/io/json.hpp"
#include "app/config/program_source.hpp"
#include "app/eval/log_provenance.hpp"
#include "app/eval/replay.hpp"

namespace marionette {

int record_command(const RecordOptions& o) {
    const AppConfig app = load_config(o.config_file);
    const SimConfig& config = app.sim;
    const StickProgram program = load_program(o.program_file);
    const std::vector<TickInput> ticks = render_stick_program(program, config.tick_rate_hz);

    set_simulation_float_mode();
    Simulation sim(config);
    InputLogHeader header;
    if (auto graph = load_graph_argument_rebuilding_stale(o.graph_file, config, app.graph_build)) {
        header.motion_data = motion_data_reference(o.graph_file, graph.get());
        attach_motion_graph(sim, std::move(graph), o.graph_file.empty() ? "the default motion graph" : "graph " + o.graph_file);
    }
    header.tick_rate_hz = static_cast<std::uint32_t>(config.tick_rate_hz);
    header.clip_data_hash = sim.clip_data_hash();
    header.config_text = serialize_config(config);
    header.provenance = build_provenance();
    InputLogFile log(o.output_file, header);
    std::uint64_t hash = hash_state(sim.state());
    for (std::size_t k = 0; k < ticks.size(); ++k) {
        sim.step(ticks[k]);
        log.append_tick(ticks[k]);
        hash = hash_state(sim.state());
        // A checkpoint every kCheckpointIntervalTicks and after the last tick.
        if ((k + 1) % kCheckpointIntervalTicks == 0 || k + 1 == ticks.size()) log.append_checkpoint(hash);
        if (log.pending_ticks() >= o.chunk_ticks) log.flush();
    }
    log.close();
    if (o.json) {
        fmt::print("{{\"log\":{},\"program\":{},\"ticks\":{},\"duration_s\":{},\"final_hash\":\"{:016x}\"}}\n",
                   json::quote(o.output_file), json::quote(o.program_file), ticks.size(),
                   json::number(static_cast<double>(ticks.size()) / config.tick_rate_hz), hash);
    } else {
        fmt::print("recorded {} ticks ({:.2f} s at {} Hz) from {} to {}; final state hash {:016x}\n", ticks.size(),
                   static_cast<double>(ticks.size()) / config.tick_rate_hz, config.tick_rate_hz, o.program_file,
                   o.output_file, hash);
    }
    return 0;
}

int replay_command(const ReplayCommandOptions& o) {
    const DecodedInputLog log = decode_input_log(read_input_log_bytes(o.log_file), o.log_file);
    if (!log.warning.empty()) log_message(LogLevel::warning, fmt::format("warning: {}", log.warning));
    ReplayOptions options;
    options.trace_csv = o.trace_csv;
    options.joints_csv = o.joints_csv;
    options.bvh = o.bvh;
    // Never rebuilds a stale graph (unlike run/record): a rebuilt graph has other
    // bytes than the one recorded, so the log's clip hash would refuse it.
    // The graph the log names (embedded default, or its file by recorded path and
    // content hash) unless --graph says otherwise.
    const AppConfig recorded = config_from_text(log.header.config_text, o.log_file + " (embedded configuration)");
    options.graph = graph_for_log(log.header, o.log_file, o.graph_file, recorded);
    options.verify_checkpoints = !o.no_verify;
    const ReplayResult r = replay_log(log, o.log_file, options);
    if (o.json) {
        fmt::print("{{\"log\":{},\"ticks\":{},\"tick_rate_hz\":{},\"duration_s\":{},\"final_hash\":\"{:016x}\","
                   "\"complete\":{},\"warning\":{},\"config_changes\":{},\"distance_m\":{},\"final_root_position\":[{},{},{}],"
                   "\"checkpoints\":{},\"checkpoints_verified\":{},\"recorded_by\":{}}}\n",
                   json::quote(o.log_file), r.ticks, log.header.tick_rate_hz, json::number(r.duration_s), r.final_hash,
                   log.complete ? "true" : "false", log.warning.empty() ? "null" : json::quote(log.warning),
                   r.config_changes, json::number(r.distance_m), json::number(r.final_root_position.x),
                   json::number(r.final_root_position.y), json::number(r.final_root_position.z), log.checkpoints.size(),
                   r.checkpoints_verified, log.header.provenance.empty() ? "null" : json::quote(log.header.provenance));
    } else if (o.print_hash) {
        fmt::print("{:016x}\n", r.final_hash);
    } else {
        fmt::print("replayed {} ticks ({:.2f} s); root travelled {:.2f} m; final state hash {:016x}\n", r.ticks,
                   r.duration_s, r.distance_m, r.final_hash);
    }
    return 0;
}

void register_log_commands(CLI::App& app, int& exit_code) {
    auto rec = std::make_shared<RecordOptions>();
    CLI::App* record = app.add_subcommand("record", "Make an input log from a scripted stick program");
    record->add_option("--program", rec->program_file, "stick program file (or builtin:NAME)")->required();
    record->add_option("-o,--output", rec->output_file, "input log to write")->required();
    record->add_option("--config", rec->config_file, "TOML file overriding the defaults")->check(CLI::ExistingFile);
    record->add_option("--chunk-ticks", rec->chunk_ticks, "ticks per log chunk")->check(CLI::Range(1u, 1u << 20));
    record->add_flag("--json", rec->json, "print a JSON summary");
    record->add_option("--graph", rec->graph_file, "drive the puppet from this motion graph (.mgraph, or default: the embedded one)");
    on_parsed(record, exit_code, [rec] { return record_command(*rec); });

    auto rep = std::make_shared<ReplayCommandOptions>();
    CLI::App* replay = app.add_subcommand("replay", "Replay an input log exactly, with no clock");
    replay->add_option("log", rep->log_file, "input log")->required();
    replay->add_flag("--hash", rep->print_hash, "print the final state hash");
    replay->add_option("--trace", rep->trace_csv, "per-tick CSV: tick,hash,root_x,root_y,root_z");
    replay->add_option("--joints-csv", rep->joints_csv, "per-tick CSV of every joint's world position");
    replay->add_option("--bvh", rep->bvh, "export the performed motion as BVH");
    replay->add_flag("--json", rep->json, "print a JSON summary");
    replay->add_option("--graph", rep->graph_file,
                       "the motion graph (.mgraph, or default) the log was recorded with (default: the one the log names)");
    replay->add_flag("--no-verify", rep->no_verify, "replay on past a state-hash checkpoint that does not match");
    on_parsed(replay, exit_code, [rep] { return replay_command(*rep); });
}

}  // namespace marionette
