#pragma once
// The one exception family for reading files, configurations and command lines.
// Every error says where (the file, then a 1-based line or a byte offset) and
// what was expected. ImportError (file formats) and ConfigError (TOML settings)
// derive from it, so one `catch (const ParseError&)` handles any bad input.
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>

namespace marionette {

class ParseError : public std::runtime_error {
public:
    // what() is "FILE[:LINE][: at byte N][: SUBJECT]: MESSAGE". line is 1-based, 0
    // when the place is not a line; byte is -1 when the place is not a byte
    // offset; subject names the key or option at fault, or is empty.
    ParseError(std::string file, int line, std::int64_t byte, const std::string& subject, std::string message)
        : std::runtime_error(describe(file, line, byte, subject, message)),
          file_(std::move(file)), line_(line), byte_(byte), message_(std::move(message)) {}

    const std::string& file() const { return file_; }
    int line() const { return line_; }
    std::int64_t byte() const { return byte_; }
    // What was expected (or found), without the place.
    const std::string& message() const { return message_; }

private:
    static std::string describe(const std::string& file, int line, std::int64_t byte, const std::string& subject,
                                const std::string& message) {
        std::string out = file;
        if (line > 0) out += ":" + std::to_string(line);
        if (byte >= 0) out += ": at byte " + std::to_string(byte);
        if (!subject.empty()) out += ": " + subject;
        out += ": " + message;
        return out;
    }
    std::string file_;
    int line_ = 0;
    std::int64_t byte_ = -1;
    std::string message_;
};

}  // namespace marionette
