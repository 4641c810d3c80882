#include "app/io/log.hpp"

#include <sys/stat.h>

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <string>

namespace marionette {

namespace {
std::atomic<bool> g_prefixes{false};
}

bool stderr_is_journal() {
    const char* stream = std::getenv("JOURNAL_STREAM");
    if (stream == nullptr) return false;
    unsigned long long dev = 0, ino = 0;
    char tail = 0;
    if (std::sscanf(stream, "%llu:%llu%c", &dev, &ino, &tail) != 2) return false;
    struct stat st {};
    if (fstat(2, &st) != 0) return false;
    return static_cast<unsigned long long>(st.st_dev) == dev && static_cast<unsigned long long>(st.st_ino) == ino;
}

bool init_log_prefixes_from_environment() {
    const char* mode = std::getenv("MARIONETTE_LOG_PREFIX");
    bool on = stderr_is_journal();
    if (mode != nullptr && std::strcmp(mode, "syslog") == 0) on = true;
    if (mode != nullptr && std::strcmp(mode, "none") == 0) on = false;
    set_log_prefixes(on);
    return on;
}

void set_log_prefixes(bool on) { g_prefixes.store(on, std::memory_order_relaxed); }
bool log_prefixes() { return g_prefixes.load(std::memory_order_relaxed); }

void log_message(LogLevel level, std::string_view text, std::FILE* out) {
    if (!text.empty() && text.back() == '\n') text.remove_suffix(1);
    std::string lines;
    lines.reserve(text.size() + 8);
    const bool prefix = log_prefixes();
    size_t at = 0;
    for (;;) {
        const size_t end = text.find('\n', at);
        if (prefix) {
            lines += '<';
            lines += static_cast<char>('0' + static_cast<int>(level));
            lines += '>';
        }
        lines.append(text.substr(at, end == std::string_view::npos ? std::string_view::npos : end - at));
        lines += '\n';
        if (end == std::string_view::npos) break;
        at = end + 1;
    }
    // One write per message, so lines from two threads do not interleave mid-line.
    std::fwrite(lines.data(), 1, lines.size(), out);
    std::fflush(out);
}

}  // namespace marionette
