#pragma once
// The one error type for every file the runtime reads (clips, logs, programs).
// It always says where (file, line or byte offset) and what was expected.
#include <cstdint>
#include <stdexcept>
#include <string>

namespace marionette {

class ImportError : public std::runtime_error {
public:
    // line is 1-based; 0 means "not a line-oriented location" (see byte_offset).
    ImportError(std::string file, int line, std::string message)
        : std::runtime_error(format(file, line, -1, message)),
          file_(std::move(file)), line_(line), message_(std::move(message)) {}
    ImportError(std::string file, std::int64_t byte_offset, std::string message, int /*tag*/)
        : std::runtime_error(format(file, 0, byte_offset, message)),
          file_(std::move(file)), byte_offset_(byte_offset), message_(std::move(message)) {}

    const std::string& file() const { return file_; }
    int line() const { return line_; }
    std::int64_t byte_offset() const { return byte_offset_; }
    const std::string& message() const { return message_; }

private:
    static std::string format(const std::string& file, int line, std::int64_t offset,
                              const std::string& message) {
        std::string out = file;
        if (line > 0) out += ":" + std::to_string(line);
        if (offset >= 0) out += ": at byte " + std::to_string(offset);
        out += ": " + message;
        return out;
    }
    std::string file_;
    int line_ = 0;
    std::int64_t byte_offset_ = -1;
    std::string message_;
};

inline ImportError import_error_at_byte(std::string file, std::int64_t offset, std::string message) {
    return ImportError(std::move(file), offset, std::move(message), 0);
}

}  // namespace marionette
