#pragma once
// The error for every file the runtime reads (clips, graphs, logs, programs) and
// for command-line values parsed like them: a ParseError (parse_error.hpp).
#include <cstdint>
#include <string>
#include <utility>

#include "runtime/errors/parse_error.hpp"

namespace marionette {

class ImportError : public ParseError {
public:
    // line is 1-based; 0 means "not a line-oriented location" (see import_error_at_byte).
    ImportError(std::string file, int line, std::string message)
        : ParseError(std::move(file), line, -1, {}, std::move(message)) {}
    ImportError(std::string file, std::int64_t byte_offset, std::string message, int /*tag*/)
        : ParseError(std::move(file), 0, byte_offset, {}, std::move(message)) {}
};

inline ImportError import_error_at_byte(std::string file, std::int64_t offset, std::string message) {
    return ImportError(std::move(file), offset, std::move(message), 0);
}

}  // namespace marionette
