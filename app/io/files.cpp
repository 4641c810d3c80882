#include "app/io/files.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace marionette {

std::vector<std::uint8_t> read_binary_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw ImportError(path, 0, std::string("cannot open file: ") + std::strerror(errno));
    return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string read_text_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw ImportError(path, 0, std::string("cannot open file: ") + std::strerror(errno));
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

void write_text_file(const std::string& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error(path + ": cannot create file: " + std::strerror(errno));
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.close();
    if (!out) throw std::runtime_error(path + ": write failed: " + std::strerror(errno));
}

InputLogFile::InputLogFile(const std::string& path, const InputLogHeader& header) : path_(path) {
    file_ = std::fopen(path.c_str(), "wb");
    if (!file_) throw std::runtime_error(path + ": cannot create input log: " + std::strerror(errno));
    buffer_ = InputLogEncoder::encode_header(header);
    encoder_.reserve(4096);
    flush();
}

InputLogFile::~InputLogFile() {
    try {
        close();
    } catch (...) {
        // A destructor cannot report; close() is called explicitly where errors matter.
    }
}

void InputLogFile::flush() {
    if (!file_) return;
    encoder_.finish_chunk(buffer_);
    if (buffer_.empty()) return;
    const size_t size = buffer_.size();
    const size_t written = std::fwrite(buffer_.data(), 1, size, file_);
    buffer_.clear();
    if (written != size || std::fflush(file_) != 0)
        throw std::runtime_error(path_ + ": write failed: " + std::strerror(errno));
}

void InputLogFile::close() {
    if (!file_) return;
    encoder_.append_end();
    flush();
    const int rc = std::fclose(file_);
    file_ = nullptr;
    if (rc != 0) throw std::runtime_error(path_ + ": close failed: " + std::strerror(errno));
}

}  // namespace marionette
