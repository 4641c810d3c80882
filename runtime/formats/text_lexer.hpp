#pragma once
// The characters, words and lines of the text formats we import (BVH, ASF/AMC),
// read the same way by both: "\r\n", "\n" and a lone "\r" each end one line (so
// CRLF, LF and mixed files count lines alike), keywords match without regard to
// case, and every error is an ImportError naming the file, the 1-based line and
// what was expected. Numbers are text_number.hpp's.
#include <climits>
#include <cstddef>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/errors/import_error.hpp"

namespace marionette::text {

inline bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f'; }
inline bool is_line_end(char c) { return c == '\n' || c == '\r'; }
inline bool is_space(char c) { return is_blank(c) || is_line_end(c); }

inline char ascii_lower(char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }

// Keywords are matched without regard to case ("End site", ":DEGREES", "Begin"):
// some writers vary, and nothing is lost by accepting them.
bool iequals(std::string_view a, std::string_view b);
bool istarts_with(std::string_view s, std::string_view prefix);

std::string_view trim_blanks(std::string_view s);

// The token in quotes for an error message, cut at kMaxQuotedChars.
std::string quote_token(std::string_view token);

// Calls `word(std::string_view)` for each blank-separated word of `line`, in order.
template <typename Word>
void for_each_word(std::string_view line, Word&& word) {
    std::size_t pos = 0;
    while (pos < line.size()) {
        while (pos < line.size() && is_blank(line[pos])) ++pos;
        if (pos == line.size()) break;
        const std::size_t start = pos;
        while (pos < line.size() && !is_blank(line[pos])) ++pos;
        word(line.substr(start, pos - start));
    }
}

// The blank-separated words of `line` into `out` (cleared first).
void split_blanks(std::string_view line, std::vector<std::string_view>& out);

// A word and the line it sits on.
struct Token {
    std::string_view text;
    int line = 0;
};

// A line with content: comment removed, blanks trimmed, never empty.
struct Line {
    std::string_view text;
    int number = 0;
};

// A position in the text plus its line number, read either word by word (BVH's
// hierarchy), raw line by raw line (BVH's motion) or content line by content
// line (ASF/AMC, where '#' starts a comment). Keeps a reference to `file`.
class TextLexer {
public:
    TextLexer(std::string_view text, const std::string& file) : text_(text), file_(file) {}

    [[noreturn]] void fail(int line, const std::string& message) const { throw ImportError(file_, line, message); }

    // Where "found end of file" is reported: the last line with any content
    // (not the empty line after a final line end).
    int end_line() const { return last_content_line_; }
    std::size_t remaining() const { return text_.size() - pos_; }

    void skip_utf8_bom() {
        if (text_.substr(pos_, 3) == "\xEF\xBB\xBF") pos_ += 3;
    }

    // Binary data shows itself by control bytes that text never has; refuse
    // them once, up front, so nothing later needs to think about them. `kind`
    // names the text expected ("BVH", "ASF").
    void reject_control_bytes(const char* kind) const;

    // Next token anywhere (line ends skipped); false at end of text.
    bool next_token(Token& out) {
        for (;;) {
            skip_blanks();
            if (!consume_line_end()) break;
        }
        return read_token(out);
    }

    // Next token on the current line; false at a line end or end of text (the
    // line end is not consumed).
    bool next_token_on_line(Token& out) {
        skip_blanks();
        return read_token(out);
    }

    // The rest of the current line, its line end consumed; false at end of text.
    bool next_line(std::string_view& out, int& line_no) {
        if (!read_raw_line(out, line_no)) return false;
        if (!trim_blanks(out).empty()) last_content_line_ = line_no;
        return true;
    }

    // The next line with content after removing a '#' comment; false at end of text.
    bool next_content_line(Line& out);
    // The same line without moving past it.
    bool peek_content_line(Line& out);

private:
    void skip_blanks() {
        while (pos_ < text_.size() && is_blank(text_[pos_])) ++pos_;
    }
    bool consume_line_end() {
        if (pos_ >= text_.size() || !is_line_end(text_[pos_])) return false;
        if (text_[pos_] == '\r' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '\n') ++pos_;
        ++pos_;
        if (line_ < INT_MAX) ++line_;
        return true;
    }
    bool read_token(Token& out) {
        if (pos_ >= text_.size() || is_line_end(text_[pos_])) return false;
        const std::size_t start = pos_;
        while (pos_ < text_.size() && !is_space(text_[pos_])) ++pos_;
        out.text = text_.substr(start, pos_ - start);
        out.line = line_;
        last_content_line_ = line_;
        return true;
    }
    // The rest of the current line, its line end consumed; leaves end_line() alone.
    bool read_raw_line(std::string_view& out, int& line_no) {
        if (pos_ >= text_.size()) return false;
        const std::size_t start = pos_;
        while (pos_ < text_.size() && !is_line_end(text_[pos_])) ++pos_;
        out = text_.substr(start, pos_ - start);
        line_no = line_;
        consume_line_end();
        return true;
    }

    std::string_view text_;
    const std::string& file_;
    std::size_t pos_ = 0;
    int line_ = 1;
    int last_content_line_ = 1;
};

// The whole of an opened file, refused past 512 MiB (a device or a mistaken
// path): "file is larger than the 512 MiB <holder> may have", e.g. holder "a BVH
// clip". Errors name `path`, line 0.
std::string read_capped_text(std::istream& in, const std::string& path, std::string_view holder);

}  // namespace marionette::text
