// The tuning UI's line-based TOML editor (app/ui/toml_edit.hpp): only the edited
// value changes; comments, blank lines, key order and other tables stay byte for byte.
#include <catch2/catch.hpp>
#include <toml++/toml.h>

#include <cstdint>
#include <string>
#include <vector>

#include "app/ui/toml_edit.hpp"

using namespace marionette;
using ui::set_toml_value;

namespace {
std::vector<std::string> lines_of(const std::string& text) {
    std::vector<std::string> out;
    std::size_t at = 0;
    while (at < text.size()) {
        std::size_t end = text.find('\n', at);
        if (end == std::string::npos) end = text.size();
        out.push_back(text.substr(at, end - at));
        at = end + 1;
    }
    return out;
}

// True when `small` is `big` with some lines left out (in order).
bool is_subsequence(const std::vector<std::string>& small, const std::vector<std::string>& big) {
    std::size_t i = 0;
    for (const std::string& line : big)
        if (i < small.size() && small[i] == line) ++i;
    return i == small.size();
}

const std::string kFile =
    "# my tuning\n"
    "\n"
    "[locomotion]\n"
    "max_speed = 3.0   # m/s\n"
    "\n"
    "[gait]                 # the walk\n"
    "# stride\n"
    "step_length_multiplier = 0.6    # longer steps\n"
    "walk_duty=0.62\n"
    "\n"
    "# trailing comment of gait\n"
    "[motion]\n"
    "source = \"gait\" # a # in a comment\n";
}  // namespace

TEST_CASE("set_toml_value replaces only the value, keeping spacing and the key's comment", "[ui][toml]") {
    const std::string out = set_toml_value(kFile, "gait", "step_length_multiplier", "0.62");
    std::string expected = kFile;
    expected.replace(expected.find("= 0.6 "), 5, "= 0.62");  // the spaces before the comment stay
    CHECK(out == expected);
    CHECK(set_toml_value(kFile, "gait", "walk_duty", "0.7").find("walk_duty=0.7\n") != std::string::npos);
    CHECK(set_toml_value(kFile, "motion", "source", "\"graph\"") ==
          kFile.substr(0, kFile.find("\"gait\" #")) + "\"graph\" # a # in a comment\n");
}

TEST_CASE("set_toml_value appends a missing key after its table's last key, a missing table at the end", "[ui][toml]") {
    const std::string with_key = set_toml_value(kFile, "gait", "swing_clearance", "0.1");
    CHECK(with_key.find("walk_duty=0.62\nswing_clearance = 0.1\n\n# trailing comment of gait\n") != std::string::npos);
    const std::string with_table = set_toml_value(kFile, "motion_graph", "horizon_s", "1.5");
    CHECK(with_table == kFile + "\n[motion_graph]\nhorizon_s = 1.5\n");
    CHECK(set_toml_value("", "gait", "walk_duty", "0.6") == "[gait]\nwalk_duty = 0.6\n");
    // A file without a final newline, and a table that is only a header.
    CHECK(set_toml_value("[gait]\nwalk_duty = 0.6", "gait", "walk_duty", "0.7") == "[gait]\nwalk_duty = 0.7");
    CHECK(set_toml_value("[gait]\n[motion]\n", "gait", "walk_duty", "0.7") == "[gait]\nwalk_duty = 0.7\n[motion]\n");
    // The same key in another table is not touched.
    CHECK(set_toml_value("[puppet]\npelvis_height = 1.0\n[gait]\npelvis_height = 0.9\n", "gait", "pelvis_height", "0.95") ==
          "[puppet]\npelvis_height = 1.0\n[gait]\npelvis_height = 0.95\n");
}

TEST_CASE("generated files: every edit parses back to the new value and leaves every other line alone", "[ui][toml]") {
    // Fixed-seed files of 1–6 tables with 0–6 keys each, comments and blank lines
    // scattered; each key of each table (and a missing one) set in turn.
    std::uint64_t state = 0x5eed'0019u;
    auto next = [&](std::uint64_t n) {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return (state >> 33) % n;
    };
    for (int file = 0; file < 200; ++file) {
        std::string text;
        std::vector<std::pair<std::string, std::string>> keys;
        if (next(2)) text += "# header comment\n";
        const int tables = 1 + static_cast<int>(next(6));
        for (int t = 0; t < tables; ++t) {
            const std::string table = "t" + std::to_string(t);
            text += "[" + table + "]" + (next(2) ? "   # c" : "") + "\n";
            const int count = static_cast<int>(next(7));
            for (int k = 0; k < count; ++k) {
                if (next(3) == 0) text += "# comment " + std::to_string(k) + "\n";
                const std::string key = "k" + std::to_string(k);
                text += key + (next(2) ? " = " : "=") + std::to_string(next(100)) + (next(2) ? "  # note" : "") + "\n";
                keys.emplace_back(table, key);
                if (next(4) == 0) text += "\n";
            }
        }
        keys.emplace_back("t0", "missing");
        keys.emplace_back("new_table", "k0");
        for (const auto& [table, key] : keys) {
            INFO("file " << file << " " << table << "." << key << "\n" << text);
            const std::string out = set_toml_value(text, table, key, "12.5");
            toml::table parsed;
            REQUIRE_NOTHROW(parsed = toml::parse(out));
            CHECK(parsed[table][key].value<double>() == 12.5);
            // Every other line is unchanged: a replaced value changes one line, an
            // added key adds one line (a new table three: blank, header, key).
            const std::vector<std::string> a = lines_of(text);
            const std::vector<std::string> b = lines_of(out);
            const bool existed = toml::parse(text)[table][key].node() != nullptr;
            if (existed) {
                REQUIRE(a.size() == b.size());
                int differing = 0;
                for (std::size_t i = 0; i < a.size(); ++i) differing += a[i] != b[i];
                CHECK(differing == 1);
            } else {
                CHECK(b.size() == a.size() + (table == "new_table" ? 3u : 1u) - (text.empty() ? 1u : 0u));
                CHECK(is_subsequence(a, b));
            }
            const toml::table before = toml::parse(text);
            for (const auto& [other_key, other] : keys)
                if (!(other_key == table && other == key) && before[other_key][other])
                    CHECK(parsed[other_key][other].value<std::int64_t>() == before[other_key][other].value<std::int64_t>());
            CHECK(out.size() >= text.size());
        }
    }
}

TEST_CASE("a key is added to its table, not to an array of tables that follows it", "[toml]") {
    const std::string text = "[terrain]   # ground\n[[terrain.box]]\nmin = [0.0, 0.0]\nmax = [1.0, 1.0]\ntop = 0.1\n";
    const std::string out = set_toml_value(text, "terrain", "name", "\"mine.toml\"");
    CHECK(out == "[terrain]   # ground\nname = \"mine.toml\"\n[[terrain.box]]\nmin = [0.0, 0.0]\nmax = [1.0, 1.0]\ntop = 0.1\n");
    const toml::table parsed = toml::parse(out);
    CHECK(parsed["terrain"]["name"].value<std::string>() == "mine.toml");
    CHECK(parsed["terrain"]["box"][0]["top"].value<double>() == 0.1);
}
