#include <catch2/catch.hpp>

#include <random>

#include "runtime/formats/input_log.hpp"

using namespace marionette;

namespace {
InputLogHeader header() {
    InputLogHeader h;
    h.tick_rate_hz = 240;
    h.clip_data_hash = 0x1234'5678'9abc'def0ull;
    h.config_text = "[simulation]\ntick_rate_hz = 240\n";
    return h;
}

std::vector<TickInput> varied_ticks(int count, unsigned seed) {
    std::mt19937 rng(seed);
    std::vector<TickInput> ticks;
    TickInput in;
    for (int i = 0; i < count; ++i) {
        if (rng() % 4 == 0) {  // runs of unchanged input, as real sticks produce
            in.left_x = static_cast<std::int16_t>(static_cast<int>(rng() % 65535) - 32767);
            in.left_y = static_cast<std::int16_t>(static_cast<int>(rng() % 65535) - 32767);
            in.right_trigger = static_cast<std::uint16_t>(rng());
            in.buttons = rng() % 3 == 0 ? (1u << (rng() % 15)) : 0u;
        }
        ticks.push_back(in);
    }
    return ticks;
}
}  // namespace

TEST_CASE("input log round trip preserves every tick and the header", "[input_log]") {
    const std::vector<TickInput> ticks = varied_ticks(5000, 7);
    const std::vector<std::uint8_t> bytes = encode_input_log(header(), ticks, 60);
    const DecodedInputLog log = decode_input_log(bytes, "mem.mlog");
    CHECK(log.warning.empty());
    CHECK(log.complete);
    CHECK(log.header.clip_data_hash == header().clip_data_hash);
    CHECK(log.header.config_text == header().config_text);
    CHECK(log.header.tick_rate_hz == 240);
    REQUIRE(log.ticks.size() == ticks.size());
    CHECK(log.ticks == ticks);
    CHECK(log.good_bytes == static_cast<std::int64_t>(bytes.size()));
}

TEST_CASE("extreme values survive the delta encoding", "[input_log]") {
    std::vector<TickInput> ticks(3);
    ticks[0].left_x = -32768;
    ticks[0].buttons = 0xffffffffu;
    ticks[1].left_x = 32767;
    ticks[1].left_trigger = 65535;
    ticks[2].right_y = -32768;
    const DecodedInputLog log = decode_input_log(encode_input_log(header(), ticks, 1), "x");
    CHECK(log.ticks == ticks);
}

TEST_CASE("an hour of mostly idle input at 240 Hz stays well under 1 MB", "[input_log]") {
    InputLogEncoder encoder;
    std::vector<std::uint8_t> out = InputLogEncoder::encode_header(header());
    const int ticks = 3600 * 240;
    TickInput in;
    for (int k = 0; k < ticks; ++k) {
        // A nudge of the stick every 20 s, otherwise idle; chunks every 250 ms as in a live run.
        in.left_y = (k % (240 * 20)) < 240 ? 12000 : 0;
        encoder.append_tick(in);
        if (encoder.pending_ticks() >= 60) encoder.finish_chunk(out);
    }
    encoder.append_end();
    encoder.finish_chunk(out);
    INFO("bytes: " << out.size());
    CHECK(out.size() < 1'000'000);
    const DecodedInputLog log = decode_input_log(out, "hour");
    CHECK(log.ticks.size() == static_cast<size_t>(ticks));
}

TEST_CASE("truncation at every byte replays up to the last good chunk", "[input_log]") {
    const std::vector<TickInput> ticks = varied_ticks(400, 3);
    const std::vector<std::uint8_t> bytes = encode_input_log(header(), ticks, 50);
    const size_t header_size = InputLogEncoder::encode_header(header()).size();
    std::uint64_t previous_ticks = 0;
    for (size_t cut = 0; cut < bytes.size(); ++cut) {
        const std::vector<std::uint8_t> part(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(cut));
        if (cut < header_size) {
            CHECK_THROWS_AS(decode_input_log(part, "cut.mlog"), ImportError);
            continue;
        }
        const DecodedInputLog log = decode_input_log(part, "cut.mlog");
        REQUIRE_FALSE(log.warning.empty());
        CHECK_THAT(log.warning, Catch::Contains("cut.mlog"));
        CHECK(log.ticks.size() % 50 == 0);  // whole chunks only
        CHECK(log.ticks.size() >= previous_ticks);
        CHECK(std::equal(log.ticks.begin(), log.ticks.end(), ticks.begin()));
        CHECK(log.good_bytes <= static_cast<std::int64_t>(cut));
        if (static_cast<std::int64_t>(cut) > log.good_bytes)
            CHECK_THAT(log.warning, Catch::Contains("at byte " + std::to_string(log.good_bytes)));
        previous_ticks = log.ticks.size();
    }
    CHECK(previous_ticks == 400);  // cutting only the end marker's chunk... loses at most that chunk
}

TEST_CASE("a corrupted byte stops replay at the chunk it hits", "[input_log]") {
    const std::vector<TickInput> ticks = varied_ticks(300, 11);
    const std::vector<std::uint8_t> bytes = encode_input_log(header(), ticks, 100);
    const size_t header_size = InputLogEncoder::encode_header(header()).size();
    for (size_t at = header_size; at < bytes.size(); at += 7) {
        std::vector<std::uint8_t> bad = bytes;
        bad[at] ^= 0x5a;
        const DecodedInputLog log = decode_input_log(bad, "bad.mlog");
        CHECK_FALSE(log.warning.empty());
        CHECK(std::equal(log.ticks.begin(), log.ticks.end(), ticks.begin()));
        CHECK(log.ticks.size() < ticks.size() + 1);
    }
    std::vector<std::uint8_t> bad_header = bytes;
    bad_header[30] ^= 1;
    CHECK_THROWS_WITH(decode_input_log(bad_header, "h.mlog"), Catch::Contains("header CRC mismatch"));
    std::vector<std::uint8_t> bad_magic = bytes;
    bad_magic[1] = 'X';
    CHECK_THROWS_WITH(decode_input_log(bad_magic, "m.mlog"), Catch::Contains("not a marionette input log"));
    std::vector<std::uint8_t> future = bytes;
    future[8] = 9;
    CHECK_THROWS_WITH(decode_input_log(future, "v.mlog"), Catch::Contains("unsupported input log version 9"));
}

TEST_CASE("configuration changes are placed at tick boundaries", "[input_log]") {
    std::vector<std::uint8_t> out = InputLogEncoder::encode_header(header());
    InputLogEncoder encoder;
    TickInput in;
    for (int k = 0; k < 10; ++k) encoder.append_tick(in);
    encoder.append_config_change("[locomotion]\nmax_speed = 2.0\n");
    for (int k = 0; k < 5; ++k) encoder.append_tick(in);
    encoder.append_end();
    encoder.finish_chunk(out);
    const DecodedInputLog log = decode_input_log(out, "c");
    REQUIRE(log.config_changes.size() == 1);
    CHECK(log.config_changes[0].before_tick == 10);
    CHECK(log.config_changes[0].config_text == "[locomotion]\nmax_speed = 2.0\n");
    CHECK(log.ticks.size() == 15);
}

TEST_CASE("a log without its end marker says so", "[input_log]") {
    std::vector<std::uint8_t> out = InputLogEncoder::encode_header(header());
    InputLogEncoder encoder;
    encoder.append_tick(TickInput{});
    encoder.finish_chunk(out);
    const DecodedInputLog log = decode_input_log(out, "open.mlog");
    CHECK_FALSE(log.complete);
    CHECK_THAT(log.warning, Catch::Contains("no end marker"));
    CHECK(log.ticks.size() == 1);
}
