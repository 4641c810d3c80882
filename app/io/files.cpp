#include "app/io/files.hpp"

#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>
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

std::vector<std::string> input_log_files(const std::string& path) {
    std::vector<std::string> out{path};
    for (size_t n = 1;; ++n) {
        const std::string next = path + "." + std::to_string(n);
        std::error_code ec;
        if (!std::filesystem::is_regular_file(next, ec)) break;
        out.push_back(next);
    }
    return out;
}

std::vector<std::uint8_t> read_input_log_bytes(const std::string& path) {
    std::vector<std::uint8_t> bytes = read_binary_file(path);
    const std::vector<std::string> files = input_log_files(path);
    for (size_t i = 1; i < files.size(); ++i) {
        const std::vector<std::uint8_t> more = read_binary_file(files[i]);
        bytes.insert(bytes.end(), more.begin(), more.end());
    }
    return bytes;
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

std::string local_date_time_stamp() {
    const std::time_t now = std::time(nullptr);
    std::tm local{};
    localtime_r(&now, &local);
    char stamp[32];
    std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &local);
    return stamp;
}

}  // namespace marionette
