#include "app/ui/toml_edit.hpp"

#include <algorithm>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <vector>

namespace marionette::ui {

namespace {

bool is_space(char c) { return c == ' ' || c == '\t'; }

std::string_view trim(std::string_view s) {
    while (!s.empty() && (is_space(s.front()) || s.front() == '\r')) s.remove_prefix(1);
    while (!s.empty() && (is_space(s.back()) || s.back() == '\r')) s.remove_suffix(1);
    return s;
}

// Where a line's comment starts (outside strings), or npos.
std::size_t comment_start(std::string_view line) {
    char quote = 0;
    for (std::size_t i = 0; i < line.size(); ++i) {
        const char c = line[i];
        if (quote) {
            if (c == '\\' && quote == '"') ++i;
            else if (c == quote) quote = 0;
        } else if (c == '"' || c == '\'') {
            quote = c;
        } else if (c == '#') {
            return i;
        }
    }
    return std::string_view::npos;
}

// "[name]" (not "[[name]]"): the table's name, trimmed; else empty.
std::string_view header_name(std::string_view line) {
    std::string_view s = trim(line.substr(0, comment_start(line)));
    if (s.size() < 3 || s.front() != '[' || s[1] == '[' || s.back() != ']') return {};
    return trim(s.substr(1, s.size() - 2));
}

// A `key = value` line's key (bare or quoted), trimmed; else empty.
std::string_view key_of(std::string_view line) {
    const std::size_t eq = line.find('=');
    if (eq == std::string_view::npos) return {};
    std::string_view key = trim(line.substr(0, eq));
    if (key.size() >= 2 && (key.front() == '"' || key.front() == '\'') && key.back() == key.front())
        key = key.substr(1, key.size() - 2);
    return key;
}

struct Line {
    std::string_view text;  // without its newline
    bool has_newline = false;
};

std::vector<Line> split_lines(std::string_view text) {
    std::vector<Line> out;
    std::size_t at = 0;
    while (at < text.size()) {
        const std::size_t end = text.find('\n', at);
        if (end == std::string_view::npos) {
            out.push_back({text.substr(at), false});
            break;
        }
        out.push_back({text.substr(at, end - at), true});
        at = end + 1;
    }
    return out;
}

// The line with its value replaced: the key, the `=` and the spacing around
// them, and the trailing spaces and comment stay as they were.
std::string replace_value(std::string_view line, std::string_view value) {
    const std::size_t eq = line.find('=');
    std::size_t start = eq + 1;
    while (start < line.size() && is_space(line[start])) ++start;
    std::size_t end = comment_start(line);
    if (end == std::string_view::npos) end = line.size();
    while (end > start && (is_space(line[end - 1]) || line[end - 1] == '\r')) --end;
    std::string out(line.substr(0, start));
    out += value;
    out += line.substr(end);
    return out;
}

// '[' minus ']' in the line's code (outside strings and the comment).
int bracket_depth(std::string_view line) {
    int depth = 0;
    const std::size_t end = std::min(comment_start(line), line.size());
    char quote = 0;
    for (std::size_t i = 0; i < end; ++i) {
        const char c = line[i];
        if (quote) {
            if (c == '\\' && quote == '"') ++i;
            else if (c == quote) quote = 0;
        } else if (c == '"' || c == '\'') {
            quote = c;
        } else {
            depth += c == '[' ? 1 : c == ']' ? -1 : 0;
        }
    }
    return depth;
}

// The last line of the value that starts on line `first` (an array written
// over several lines ends where its brackets close).
std::size_t value_end(const std::vector<Line>& lines, std::size_t first) {
    const std::string_view line = lines[first].text;
    int depth = bracket_depth(line.substr(line.find('=') + 1));
    std::size_t i = first;
    while (depth > 0 && i + 1 < lines.size()) depth += bracket_depth(lines[++i].text);
    return i;
}

}  // namespace

std::string set_toml_value(std::string_view text, std::string_view table, std::string_view key, std::string_view value) {
    const std::vector<Line> lines = split_lines(text);
    std::string current;        // the table the line is in ("" before the first header)
    int found = -1;             // the key's line
    int last_in_table = -1;     // the table's header or its last key line
    for (std::size_t i = 0; i < lines.size(); ++i) {
        const std::string_view line = lines[i].text;
        if (const std::string_view h = header_name(line); !h.empty()) {
            current = std::string(h);
            if (current == table) last_in_table = static_cast<int>(i);
            continue;
        }
        if (trim(line).substr(0, 2) == "[[") {  // an array of tables ([[terrain.box]]): its keys are not the table's
            current = "[[";
            continue;
        }
        if (current != table) continue;
        const std::string_view k = key_of(line.substr(0, comment_start(line)));
        if (k.empty()) continue;
        last_in_table = static_cast<int>(i);
        if (k == key && found < 0) found = static_cast<int>(i);
    }
    const std::string assignment = std::string(key) + " = " + std::string(value);
    std::string out;
    out.reserve(text.size() + assignment.size() + table.size() + 8);
    const int insert_after = found < 0 ? last_in_table : -1;
    // A multi-line array: its first line keeps the key and spacing, its last
    // line's trailing comment stays; the lines between go.
    const std::size_t found_end = found < 0 ? 0 : value_end(lines, static_cast<std::size_t>(found));
    for (std::size_t i = 0; i < lines.size(); ++i) {
        if (found >= 0 && i > static_cast<std::size_t>(found) && i <= found_end) continue;
        if (static_cast<int>(i) == found && found_end > i) {
            const std::string_view first = lines[i].text, last = lines[found_end].text;
            const std::size_t comment = comment_start(last);
            out += replace_value(first.substr(0, std::min(comment_start(first), first.size())), value);
            if (comment != std::string_view::npos) out += " " + std::string(last.substr(comment));
            if (lines[found_end].has_newline) out += '\n';
            continue;
        }
        if (static_cast<int>(i) == found) out += replace_value(lines[i].text, value);
        else out += lines[i].text;
        if (static_cast<int>(i) == insert_after) {
            out += '\n';
            out += assignment;
        }
        if (lines[i].has_newline) out += '\n';
    }
    if (found < 0 && last_in_table < 0) {
        if (!out.empty() && out.back() != '\n') out += '\n';
        if (!out.empty()) out += '\n';
        out += "[" + std::string(table) + "]\n" + assignment + "\n";
    }
    return out;
}

// Written beside it and renamed over it: a reader (the watcher) never sees half
// a file. Empty: written; else what failed, naming the file.
std::string write_replacing(const std::string& path, const std::string& text) {
    const std::string temporary = path + ".tmp";
    {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        out << text;
        if (!out.flush()) return "cannot write " + temporary;
    }
    std::error_code ec;
    std::filesystem::rename(temporary, path, ec);
    if (ec) return "cannot replace " + path + ": " + ec.message();
    return {};
}

}  // namespace marionette::ui
