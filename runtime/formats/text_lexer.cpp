#include "runtime/formats/text_lexer.hpp"

#include <cstdint>
#include <istream>

namespace marionette::text {

namespace {
// Longest token quoted back in an error message.
constexpr std::size_t kMaxQuotedChars = 40;
constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t{512} << 20;
constexpr std::size_t kReadChunkBytes = std::size_t{1} << 16;
}  // namespace

bool iequals(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (ascii_lower(a[i]) != ascii_lower(b[i])) return false;
    return true;
}

bool istarts_with(std::string_view s, std::string_view prefix) {
    return s.size() >= prefix.size() && iequals(s.substr(0, prefix.size()), prefix);
}

std::string_view trim_blanks(std::string_view s) {
    while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
    return s;
}

std::string quote_token(std::string_view token) {
    if (token.size() > kMaxQuotedChars) return "'" + std::string(token.substr(0, kMaxQuotedChars)) + "...'";
    return "'" + std::string(token) + "'";
}

void split_blanks(std::string_view line, std::vector<std::string_view>& out) {
    out.clear();
    for_each_word(line, [&out](std::string_view word) { out.push_back(word); });
}

void TextLexer::reject_control_bytes(const char* kind) const {
    int line = 1;
    for (std::size_t i = 0; i < text_.size(); ++i) {
        const auto c = static_cast<unsigned char>(text_[i]);
        if (c == '\n' || (c == '\r' && (i + 1 == text_.size() || text_[i + 1] != '\n'))) {
            if (line < INT_MAX) ++line;
        } else if ((c < 0x20 && !is_space(static_cast<char>(c))) || c == 0x7F) {
            static constexpr char kHex[] = "0123456789ABCDEF";
            std::string byte = "0x";
            byte += kHex[c >> 4];
            byte += kHex[c & 15];
            fail(line, "unexpected control byte " + byte + " (expected " + kind + " text; is this a binary file?)");
        }
    }
}

bool TextLexer::next_content_line(Line& out) {
    std::string_view raw;
    int number = 0;
    while (read_raw_line(raw, number)) {
        if (const std::size_t hash = raw.find('#'); hash != std::string_view::npos) raw = raw.substr(0, hash);
        raw = trim_blanks(raw);
        if (raw.empty()) continue;
        out.text = raw;
        out.number = number;
        last_content_line_ = number;
        return true;
    }
    return false;
}

bool TextLexer::peek_content_line(Line& out) {
    const std::size_t pos = pos_;
    const int line = line_;
    const int last = last_content_line_;
    const bool have = next_content_line(out);
    pos_ = pos;
    line_ = line;
    last_content_line_ = last;
    return have;
}

std::string read_capped_text(std::istream& in, const std::string& path, std::string_view holder) {
    std::string text;
    std::vector<char> buf(kReadChunkBytes);
    while (in) {
        in.read(buf.data(), static_cast<std::streamsize>(kReadChunkBytes));
        const auto got = static_cast<std::size_t>(in.gcount());
        if (text.size() + got > kMaxFileBytes)
            throw ImportError(path, 0, "file is larger than the 512 MiB " + std::string(holder) + " may have");
        text.append(buf.data(), got);
    }
    if (in.bad()) throw ImportError(path, 0, "cannot read the file (a directory, or an I/O error)");
    return text;
}

}  // namespace marionette::text
