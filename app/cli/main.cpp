// marionette: the command line. Each command group registers itself (app/cli/cli.hpp);
// main turns errors into messages and exit codes: 0 ok, 1 failure, 2 bad input.
#include <fmt/format.h>

#include "app/cli/cli.hpp"
#include "app/io/log.hpp"
#include "app/eval/log_provenance.hpp"
#include "runtime/errors/parse_error.hpp"

int main(int argc, char** argv) {
    using namespace marionette;
    CLI::App app{"marionette: a controller-driven puppet runtime"};
    app.require_subcommand(1);
    int exit_code = 1;
    register_run_command(app, exit_code);
    register_log_commands(app, exit_code);
    register_clip_commands(app, exit_code);
    register_render_command(app, exit_code);
    register_input_commands(app, exit_code);
    register_graph_commands(app, exit_code);
    register_gait_eval_command(app, exit_code);
    register_doctor_command(app, exit_code);

    // "<N>" priority prefixes when stderr is the journal (docs/deploy.md "Logs").
    init_log_prefixes_from_environment();
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    } catch (const ReplayDesync& e) {
        log_message(LogLevel::error, fmt::format("error: {}", e.what()));
        return 3;  // the replay is not exact (docs/determinism.md)
    } catch (const ParseError& e) {  // a bad file, configuration or option value
        log_message(LogLevel::error, fmt::format("error: {}", e.what()));
        return 2;
    } catch (const std::exception& e) {
        log_message(LogLevel::error, fmt::format("error: {}", e.what()));
        return 1;
    }
    return exit_code;
}
