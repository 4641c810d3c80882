// marionette: the command line. Parses arguments and hands each subcommand to
// its function in app/*_command(s).cpp; turns errors into messages and exit codes.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "app/commands.hpp"
#include "app/config.hpp"
#include "runtime/import_error.hpp"

int main(int argc, char** argv) {
    using namespace marionette;
    CLI::App app{"marionette: a controller-driven puppet runtime"};
    app.require_subcommand(1);

    RunOptions run;
    CLI::App* run_cmd = app.add_subcommand("run", "Run the puppet live (headless demo with a simulated controller by default)");
    run_cmd->add_option("--config", run.config_file, "TOML file overriding the defaults")->check(CLI::ExistingFile);
    run_cmd->add_option("--input", run.input, "sim:PROGRAM (a stick program file, or builtin:NAME)");
    run_cmd->add_option("--display", run.display, "auto|headless")->check(CLI::IsMember({"auto", "headless", "kms", "window"}));
    run_cmd->add_option("--record", run.record_file, "write the input log here");
    run_cmd->add_option("--trace", run.trace_file, "per-tick CSV: tick,hash,root_x,root_y,root_z");
    run_cmd->add_option("--duration", run.duration_s, "seconds to run (default: until the program ends)")->check(CLI::Range(0.0, 86400.0));
    run_cmd->add_flag("--fast", run.fast, "do not pace ticks in real time");

    RecordOptions record;
    CLI::App* record_cmd = app.add_subcommand("record", "Make an input log from a scripted stick program");
    record_cmd->add_option("--program", record.program_file, "stick program file (or builtin:NAME)")->required();
    record_cmd->add_option("-o,--output", record.output_file, "input log to write")->required();
    record_cmd->add_option("--config", record.config_file, "TOML file overriding the defaults")->check(CLI::ExistingFile);
    record_cmd->add_option("--chunk-ticks", record.chunk_ticks, "ticks per log chunk")->check(CLI::Range(1u, 1u << 20));
    record_cmd->add_flag("--json", record.json, "print a JSON summary");

    ReplayCommandOptions replay;
    CLI::App* replay_cmd = app.add_subcommand("replay", "Replay an input log exactly, with no clock");
    replay_cmd->add_option("log", replay.log_file, "input log")->required();
    replay_cmd->add_flag("--hash", replay.print_hash, "print the final state hash");
    replay_cmd->add_option("--trace", replay.trace_csv, "per-tick CSV: tick,hash,root_x,root_y,root_z");
    replay_cmd->add_option("--joints-csv", replay.joints_csv, "per-tick CSV of every joint's world position");
    replay_cmd->add_option("--bvh", replay.bvh, "export the performed motion as BVH");
    replay_cmd->add_flag("--json", replay.json, "print a JSON summary");

    ClipOptions clip;
    CLI::App* clip_cmd = app.add_subcommand("clip", "Inspect motion-capture clips (BVH, ASF/AMC)");
    clip_cmd->require_subcommand(1);
    CLI::App* info_cmd = clip_cmd->add_subcommand("info", "Skeleton and frame summary");
    CLI::App* fk_cmd = clip_cmd->add_subcommand("fk", "World-space joint positions of one frame");
    for (CLI::App* c : {info_cmd, fk_cmd}) {
        c->add_option("file", clip.file, "clip file (.bvh, .amc, .asf)")->required();
        c->add_option("--asf", clip.asf_file, "skeleton for an AMC file");
        c->add_flag("--json", clip.json, "print JSON");
    }
    fk_cmd->add_option("--frame", clip.frame, "0-based frame index in the file")->required();

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    }

    try {
        if (run_cmd->parsed()) return run_command(run);
        if (record_cmd->parsed()) return record_command(record);
        if (replay_cmd->parsed()) return replay_command(replay);
        if (info_cmd->parsed()) return clip_info_command(clip);
        if (fk_cmd->parsed()) return clip_fk_command(clip);
    } catch (const ImportError& e) {
        fmt::print(stderr, "error: {}\n", e.what());
        return 2;
    } catch (const ConfigError& e) {
        fmt::print(stderr, "error: {}\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        fmt::print(stderr, "error: {}\n", e.what());
        return 1;
    }
    return 1;
}
