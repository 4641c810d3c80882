#pragma once
// Where stick programs come from: a file path, or `builtin:NAME` for the programs
// compiled into the binary from config/programs/NAME.prog.
#include <string>

#include "runtime/formats/stick_program.hpp"

namespace marionette {
StickProgram load_program(const std::string& spec);
}  // namespace marionette
