// Fault injection on files: an input log and a .mgraph truncated at every byte
// offset and with every single bit flipped are refused with an ImportError or,
// for a log, replayed up to the last good chunk with a warning; never a crash,
// never a silently different result (docs/reliability.md, "Fault injection").
#include <catch2/catch.hpp>

#include <algorithm>

#include "app/config/config.hpp"
#include "runtime/formats/input_log.hpp"
#include "runtime/graph/motion_graph.hpp"
#include "tests/graph_fixture.hpp"

using namespace marionette;

namespace {

// A small log shaped like a live recording: chunks of 32 ticks, a checkpoint
// every 40 ticks, a configuration change before tick 50, the end marker.
struct SmallLog {
    std::vector<TickInput> ticks;
    std::vector<std::uint8_t> bytes;
};

SmallLog make_small_log() {
    SmallLog log;
    InputLogHeader header;
    header.config_text = "[locomotion]\nmax_speed = 3.0\n";
    header.provenance = "marionette fault test";
    header.motion_data = "";
    log.bytes = InputLogEncoder::encode_header(header);
    InputLogEncoder encoder;
    for (int k = 0; k < 160; ++k) {
        if (k == 50) encoder.append_config_change("[locomotion]\nmax_speed = 1.5\n");
        TickInput t;
        t.left_x = static_cast<std::int16_t>((k * 977) % 65536 - 32768);
        t.left_y = static_cast<std::int16_t>(k < 80 ? 20000 : -k * 100);
        t.right_trigger = static_cast<std::uint16_t>(k * 400);
        t.buttons = (k % 17 == 0) ? 1u << (k % 15) : 0u;
        log.ticks.push_back(t);
        encoder.append_tick(t);
        if ((k + 1) % 40 == 0) encoder.append_checkpoint(0x1234'5678'9abc'def0ull + static_cast<std::uint64_t>(k));
        if ((k + 1) % 32 == 0) encoder.finish_chunk(log.bytes);
    }
    encoder.append_end();
    encoder.finish_chunk(log.bytes);
    return log;
}

bool is_prefix(const std::vector<TickInput>& part, const std::vector<TickInput>& whole) {
    return part.size() <= whole.size() && std::equal(part.begin(), part.end(), whole.begin());
}

// What the decoder made of damaged bytes: refused, or a prefix with a warning.
struct Verdict {
    bool refused = false;
    bool prefix_with_warning = false;
    std::string what;
};

Verdict judge_log(const std::vector<std::uint8_t>& damaged, const SmallLog& original) {
    Verdict v;
    try {
        const DecodedInputLog log = decode_input_log(damaged, "damaged.mlog");
        v.prefix_with_warning = is_prefix(log.ticks, original.ticks) && !log.warning.empty() &&
                                log.good_bytes <= static_cast<std::int64_t>(damaged.size()) &&
                                log.config_changes.size() <= 1 && log.checkpoints.size() <= 4;
        v.what = log.warning;
    } catch (const ImportError& e) {
        v.refused = true;
        v.what = e.what();
    }
    return v;
}

}  // namespace

TEST_CASE("an input log truncated at every byte or with any one bit flipped is refused or replayed up to the last good chunk",
          "[faults][sweep]") {
    const SmallLog original = make_small_log();
    const DecodedInputLog whole = decode_input_log(original.bytes, "whole.mlog");
    REQUIRE(whole.warning.empty());
    REQUIRE(whole.ticks == original.ticks);
    REQUIRE(whole.config_changes.size() == 1);
    REQUIRE(whole.checkpoints.size() == 4);
    const size_t n = original.bytes.size();
    size_t refused = 0, replayed = 0, longest_prefix = 0;
    for (size_t length = 0; length < n; ++length) {
        const std::vector<std::uint8_t> cut(original.bytes.begin(), original.bytes.begin() + static_cast<long>(length));
        const Verdict v = judge_log(cut, original);
        INFO("truncated to " << length << " of " << n << " bytes: " << v.what);
        REQUIRE((v.refused || v.prefix_with_warning));
        (v.refused ? refused : replayed) += 1;
        if (!v.refused) longest_prefix = std::max(longest_prefix, decode_input_log(cut, "cut").ticks.size());
    }
    CHECK(refused > 0);
    CHECK(replayed > 0);
    CHECK(longest_prefix == original.ticks.size());  // cut inside the end marker: every tick is still there
    size_t flips_refused = 0, flips_replayed = 0;
    std::vector<std::uint8_t> flipped = original.bytes;
    for (size_t bit = 0; bit < n * 8; ++bit) {
        flipped[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
        const Verdict v = judge_log(flipped, original);
        flipped[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
        INFO("bit " << bit << " (byte " << bit / 8 << ") flipped: " << v.what);
        REQUIRE((v.refused || v.prefix_with_warning));
        (v.refused ? flips_refused : flips_replayed) += 1;
    }
    CHECK(flips_refused > 0);
    CHECK(flips_replayed > 0);
    WARN("input log of " << n << " bytes: truncations refused " << refused << ", replayed to the last good chunk "
                         << replayed << "; bit flips refused " << flips_refused << ", replayed " << flips_replayed);
}

TEST_CASE("a .mgraph truncated at every byte or with any one bit flipped is refused, or intact but for its source hash",
          "[faults][sweep]") {
    const std::vector<std::uint8_t> bytes = serialize_motion_graph(test::make_locomotion_graph());
    const MotionGraph original = deserialize_motion_graph(bytes, "whole.mgraph");
    const size_t n = bytes.size();
    // Refused (true, with the reason), or decoded into `graph` (false).
    auto refused = [](std::span<const std::uint8_t> damaged, std::string& why, MotionGraph& graph) {
        try {
            graph = deserialize_motion_graph(damaged, "damaged.mgraph");
        } catch (const ImportError& e) {
            why = e.what();
            return true;
        }
        return false;
    };
    std::string why;
    MotionGraph decoded;
    for (size_t length = 0; length < n; ++length) {
        INFO("truncated to " << length << " of " << n << " bytes");
        REQUIRE(refused(std::span<const std::uint8_t>(bytes.data(), length), why, decoded));
    }
    CHECK_THAT(why, Catch::Contains("damaged.mgraph"));
    // The 8-byte source hash in the header (bytes 16-23) is under no checksum
    // (the payload's xxHash64 covers the payload only): a flip there loads a
    // graph identical to the original but for that hash, which the staleness
    // check (app/graph/graph_rebuild.hpp) then sees as different sources.
    std::vector<std::uint8_t> flipped = bytes;
    size_t flips_refused = 0, flips_in_source_hash = 0;
    for (size_t bit = 0; bit < n * 8; ++bit) {
        flipped[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
        const bool r = refused(flipped, why, decoded);
        flipped[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
        INFO("bit " << bit << " (byte " << bit / 8 << ") flipped");
        if (r) {
            ++flips_refused;
            continue;
        }
        ++flips_in_source_hash;
        REQUIRE(bit / 8 >= 16);
        REQUIRE(bit / 8 < 24);
        CHECK(decoded.source_hash != original.source_hash);
        decoded.source_hash = original.source_hash;
        REQUIRE(serialize_motion_graph(decoded) == bytes);
    }
    CHECK(flips_in_source_hash == 64);
    WARN(".mgraph of " << n << " bytes: all " << n << " truncations refused; of " << n * 8 << " bit flips "
                       << flips_refused << " refused, " << flips_in_source_hash
                       << " (the header's source hash) load an intact graph with another source hash");
}
