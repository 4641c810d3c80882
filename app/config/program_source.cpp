#include "app/config/program_source.hpp"

#include "app/config/embedded.hpp"

namespace marionette {

StickProgram load_program(const std::string& spec) {
    const std::string prefix = "builtin:";
    if (spec.rfind(prefix, 0) == 0) {
        const std::string name = spec.substr(prefix.size());
        const std::string path = "config/programs/" + name + ".prog";
        const std::string_view text = embedded::find(path);
        if (text.empty()) throw ImportError(spec, 0, "no built-in program named '" + name + "'");
        StickProgram program = parse_stick_program(text, path);
        program.name = name;
        return program;
    }
    return load_stick_program_file(spec);
}

}  // namespace marionette
