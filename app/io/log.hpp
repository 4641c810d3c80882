#pragma once
// Messages to stderr with a level. Under systemd, stderr is often the journal's
// stream (StandardError=journal): then every line starts with its syslog
// priority, "<3>" error, "<4>" warning, "<5>" notice, "<6>" info, "<7>" debug
// (sd-daemon(3)), so `journalctl -p warning` finds them. Elsewhere the lines
// are plain. docs/deploy.md "Logs".
#include <cstdio>
#include <string_view>

namespace marionette {

enum class LogLevel : int { error = 3, warning = 4, notice = 5, info = 6, debug = 7 };

// Whether stderr is the journal: JOURNAL_STREAM ("DEV:INODE", set by systemd
// for StandardError=journal) names the file behind fd 2.
bool stderr_is_journal();
// MARIONETTE_LOG_PREFIX=syslog (always), none (never) or auto (the default:
// when stderr_is_journal()). Called once by main(); returns whether prefixes are on.
bool init_log_prefixes_from_environment();
void set_log_prefixes(bool on);
bool log_prefixes();

// Writes `text` (one or more lines; a final newline is added when missing) to
// `out`, each line prefixed by "<N>" when prefixes are on.
void log_message(LogLevel level, std::string_view text, std::FILE* out = stderr);

}  // namespace marionette
