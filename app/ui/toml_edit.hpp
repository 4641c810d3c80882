#pragma once
// A small line-based TOML editor for saving tuned values: it replaces only the
// value of the edited key and keeps everything else (comments, blank lines, key
// order, the key's own trailing comment) byte for byte. A key the file lacks is
// appended after the last key of its table; a table the file lacks is appended
// at the end. Handles what marionette's configuration files use: `[table]`
// headers and `key = value` lines with a number, boolean or one-line string; a
// key written as a dotted key or inside an inline table is not found and is
// appended to its table instead (TOML then rejects the duplicate on load, and
// the UI reports that when it checks the saved file).
#include <string>
#include <string_view>

namespace marionette::ui {

// `text` with `table.key` set to `value` (TOML text of the value, e.g. "0.62").
std::string set_toml_value(std::string_view text, std::string_view table, std::string_view key, std::string_view value);

// Writes `text` to `path` beside it (path + ".tmp") and renames it over it: a
// reader (the config watcher) never sees half a file. Empty: written; else what
// failed, naming the file.
std::string write_replacing(const std::string& path, const std::string& text);

}  // namespace marionette::ui
