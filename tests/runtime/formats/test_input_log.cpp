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

// ---- version 2: provenance, motion data, state-hash checkpoints ------------------

TEST_CASE("version 2 logs carry provenance, motion data and checkpoints at their ticks", "[input_log][checkpoint]") {
    InputLogHeader h = header();
    h.provenance = "marionette 0.1.0; GCC 12.2.0; x86_64; RelWithDebInfo";
    h.motion_data = "graph-file 0123456789abcdef /tmp/my graph.mgraph";
    const std::vector<TickInput> ticks = varied_ticks(1000, 3);
    std::vector<std::uint8_t> out = InputLogEncoder::encode_header(h);
    InputLogEncoder encoder;
    std::vector<InputLogCheckpoint> written;
    for (std::size_t k = 0; k < ticks.size(); ++k) {
        encoder.append_tick(ticks[k]);
        if ((k + 1) % kCheckpointIntervalTicks == 0 || k + 1 == ticks.size()) {
            written.push_back({k + 1, 0x9e37'79b9'7f4a'7c15ull * (k + 1)});
            encoder.append_checkpoint(written.back().state_hash);
        }
        if (encoder.pending_ticks() >= 100) encoder.finish_chunk(out);  // checkpoints straddle chunk ends
    }
    encoder.append_end();
    encoder.finish_chunk(out);
    const DecodedInputLog log = decode_input_log(out, "v2.mlog");
    REQUIRE(log.warning.empty());
    CHECK(log.header.version == 2);
    CHECK(log.header.provenance == h.provenance);
    CHECK(log.header.motion_data == h.motion_data);
    CHECK(log.ticks == ticks);
    REQUIRE(log.checkpoints.size() == written.size());
    for (std::size_t i = 0; i < written.size(); ++i) {
        CHECK(log.checkpoints[i].after_ticks == written[i].after_ticks);
        CHECK(log.checkpoints[i].state_hash == written[i].state_hash);
    }
}

TEST_CASE("version 1 logs (no provenance, no checkpoints) still decode", "[input_log][checkpoint]") {
    InputLogHeader h = header();
    h.version = 1;
    h.provenance = "ignored: version 1 has no such field";
    const std::vector<TickInput> ticks = varied_ticks(600, 5);
    const std::vector<std::uint8_t> bytes = encode_input_log(h, ticks, 60);
    CHECK(bytes[8] == 1);
    const DecodedInputLog log = decode_input_log(bytes, "v1.mlog");
    CHECK(log.warning.empty());
    CHECK(log.header.version == 1);
    CHECK(log.header.provenance.empty());
    CHECK(log.checkpoints.empty());
    CHECK(log.ticks == ticks);
}

TEST_CASE("a version 2 header cut inside its provenance fields is refused with the byte", "[input_log][checkpoint]") {
    InputLogHeader h = header();
    h.provenance = "marionette test";
    const std::vector<std::uint8_t> full = encode_input_log(h, varied_ticks(10, 1), 60);
    const std::size_t provenance_at = 8 + 4 + 4 + 8 + 4 + h.config_text.size();
    for (std::size_t cut = provenance_at; cut < provenance_at + 4 + h.provenance.size() + 8; ++cut) {
        const std::vector<std::uint8_t> bytes(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(cut));
        CHECK_THROWS_AS(decode_input_log(bytes, "cut.mlog"), ImportError);
    }
    std::vector<std::uint8_t> long_text = full;
    long_text[provenance_at + 3] = 0x7f;  // a provenance length far past the file
    CHECK_THROWS_WITH(decode_input_log(long_text, "len.mlog"), Catch::Contains("exceeds the file"));
}
