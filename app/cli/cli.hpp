#pragma once
// Command registration: each group of subcommands lives in its own file and adds
// itself to the CLI11 app through one register function, so main.cpp stays a
// list and the groups never touch each other.
#include <CLI/CLI.hpp>

#include <functional>
#include <memory>

namespace marionette {

// Runs `action` when `command` is parsed and stores its exit code in `exit_code`.
// Exceptions propagate to main(), which turns them into messages and exit codes.
inline void on_parsed(CLI::App* command, int& exit_code, std::function<int()> action) {
    command->callback([&exit_code, action = std::move(action)] { exit_code = action(); });
}

void register_run_command(CLI::App& app, int& exit_code);
void register_log_commands(CLI::App& app, int& exit_code);   // record, replay
void register_clip_commands(CLI::App& app, int& exit_code);  // clip info, clip fk, fill, fill-eval
void register_clip_fill_commands(CLI::App* clip, int& exit_code);  // clip fill, clip fill-eval (from the above)
void register_render_command(CLI::App& app, int& exit_code); // render (offline frames)
void register_input_commands(CLI::App& app, int& exit_code);  // input list|monitor|decode, sim-pad
void register_graph_commands(CLI::App& app, int& exit_code); // graph build, info, path
void register_gait_eval_command(CLI::App& app, int& exit_code);  // gait-eval
void register_doctor_command(CLI::App& app, int& exit_code);  // doctor (app/cli/doctor.hpp)

}  // namespace marionette
