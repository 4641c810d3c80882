// The motion-matching database and its search: features in the root frame,
// per-group normalisation, and the accelerated search returning exactly the
// brute-force answer (ties to the lower frame) on generated queries.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <vector>

#include "runtime/matching/matching_search.hpp"
#include "tests/runtime/matching/matching_fixture.hpp"

using namespace marionette;

namespace {
MatchingDatabase build(const test::MatchingFixture& f, const MatchingWeights& w = {}) {
    MatchingDatabase db;
    const Outcome built = build_matching_database(f.source(), w, db);
    INFO(built.problem());
    REQUIRE(built.ok());
    return db;
}
}  // namespace

TEST_CASE("matching database: a bad source is refused with a reason", "[matching]") {
    test::MatchingFixture f = test::make_matching_fixture(2, 40, 1);
    MatchingDatabase db;
    MatchingSource s = f.source();
    s.left_foot = -1;
    CHECK_THAT(build_matching_database(s, {}, db).problem(), Catch::Contains("foot"));
    s = f.source();
    s.contacts = s.contacts.first(3);
    CHECK_THAT(build_matching_database(s, {}, db).problem(), Catch::Contains("frame count"));
    s = f.source();
    const MatchingClipRange outside[] = {{70, 20}};
    s.clips = outside;
    CHECK_THAT(build_matching_database(s, {}, db).problem(), Catch::Contains("outside"));
    MatchingWeights w;
    w.hips_velocity = -1.0f;
    CHECK_THAT(build_matching_database(f.source(), w, db).problem(), Catch::Contains("weights"));
    f.translations[5].x = NAN;
    CHECK_THAT(build_matching_database(f.source(), {}, db).problem(), Catch::Contains("not finite"));
    CHECK(db.frame_count == 0);  // a failed build leaves the output alone
}

TEST_CASE("matching database: features are in the root frame and normalised per group", "[matching]") {
    const test::MatchingFixture f = test::make_matching_fixture(12, 90, 7);
    MatchingWeights w;
    w.trajectory_facing = 2.0f;
    const MatchingDatabase db = build(f, w);
    REQUIRE(db.frame_count == 12 * 90);
    CHECK(db.trajectory_frames == std::array<std::int32_t, 3>{10, 20, 30});
    // Searchable: every frame with 1/3 s of its clip ahead.
    CHECK(db.searchable[0] == 1);
    CHECK(db.searchable[79] == 1);
    CHECK(db.searchable[80] == 0);
    CHECK(db.searchable[90] == 1);
    // A straight clip walking +Z in the world has its trajectory straight ahead (+Z) in
    // its root frame whatever its heading: check the facing of the 1 s point is about +Z
    // for slow turns and the left foot is on +X.
    for (int frame = 0; frame < db.frame_count; frame += 37) {
        const float* raw = db.frame_raw(frame);
        CHECK(raw[0] > 0.0f);   // left foot on the left (+X)
        CHECK(raw[3] < 0.0f);   // right foot on the right
        CHECK(raw[kMatchGroupBegin[kMatchTrajectoryFacing] + 1] > 0.5f);  // facing roughly ahead after 1/3 s
    }
    // Normalised: each feature's mean is 0 and each group's mean variance is its weight².
    for (int g = 0; g < kMatchGroupCount; ++g) {
        double var = 0.0;
        for (int k = kMatchGroupBegin[g]; k < kMatchGroupBegin[g + 1]; ++k) {
            double mean = 0.0;
            for (int i = 0; i < db.frame_count; ++i) mean += db.frame_features(i)[k];
            CHECK(std::fabs(mean / db.frame_count) < 1e-3);
            for (int i = 0; i < db.frame_count; ++i) var += static_cast<double>(db.frame_features(i)[k]) * db.frame_features(i)[k];
        }
        var /= static_cast<double>(db.frame_count) * (kMatchGroupBegin[g + 1] - kMatchGroupBegin[g]);
        CHECK(std::sqrt(var) == Approx(w.of(g)).epsilon(1e-3));
    }
    // Deterministic: a second build is bit-identical.
    const MatchingDatabase again = build(f, w);
    CHECK(again.features == db.features);
}

TEST_CASE("matching search: the accelerated search returns exactly the brute-force answer", "[matching]") {
    const test::MatchingFixture f = test::make_matching_fixture(40, 150, 11);
    const MatchingDatabase db = build(f);
    std::uint64_t rng = 2024;
    int ties = 0;
    for (int q = 0; q < 3000; ++q) {
        std::array<float, kMatchFeatureCount> query{};
        const int kind = q % 3;
        const int near = static_cast<int>(test::fixture_next(rng) % static_cast<std::uint64_t>(db.frame_count));
        for (int k = 0; k < kMatchFeatureCount; ++k) {
            const double u = test::fixture_unit(rng) * 2.0 - 1.0;
            // Whole range (and past it), near a frame, or exactly a frame (a zero-cost answer).
            query[static_cast<size_t>(k)] = kind == 0 ? static_cast<float>(u * 4.0)
                                          : kind == 1 ? db.frame_features(near)[k] + static_cast<float>(u * 0.2)
                                                      : db.frame_features(near)[k];
        }
        MatchingResult start;
        if (q % 5 == 0) start = {near, matching_cost(db, query, near)};  // a current-frame candidate
        const MatchingResult brute = search_matching_brute_force(db, query, start);
        const MatchingResult fast = search_matching_accelerated(db, query, start);
        INFO("query " << q);
        REQUIRE(fast.frame == brute.frame);
        REQUIRE(fast.cost == brute.cost);
        if (kind == 2 && db.searchable[static_cast<size_t>(near)]) {
            CHECK(brute.cost == 0.0f);
            ties += brute.frame != near;
        }
    }
    CHECK(ties == 0);
}

TEST_CASE("matching search: equal costs go to the lower frame in both searches", "[matching]") {
    // The same clip twice: every frame of the second copy ties with the first's.
    test::MatchingFixture f = test::make_matching_fixture(3, 80, 5);
    f.clips.push_back(f.clips[1]);
    f.clips.push_back(f.clips[0]);
    const MatchingDatabase db = build(f);
    for (int frame = 240; frame < 400; frame += 7) {
        if (!db.searchable[static_cast<size_t>(frame)]) continue;
        std::array<float, kMatchFeatureCount> query{};
        for (int k = 0; k < kMatchFeatureCount; ++k) query[static_cast<size_t>(k)] = db.frame_features(frame)[k];
        const int original = frame < 320 ? frame - 160 : frame - 320;
        // Starting from the higher copy as the current frame, both still answer the lower one.
        const MatchingResult start{frame, 0.0f};
        CHECK(search_matching_brute_force(db, query, start).frame == original);
        CHECK(search_matching_accelerated(db, query, start).frame == original);
    }
}

namespace {
// Bit pattern of a cost: the searches must agree to the last bit.
std::uint32_t bits(float c) {
    std::uint32_t u = 0;
    std::memcpy(&u, &c, sizeof u);
    return u;
}

// The envelope's databases: sizes that are not whole boxes (padding), a constant
// (zero-weight) group, duplicated clips (exact ties between frames), and raw
// features snapped to a coarse grid (many equal frames, flat boxes).
std::vector<MatchingDatabase> envelope_databases() {
    std::vector<MatchingDatabase> dbs;
    dbs.push_back(build(test::make_matching_fixture(7, 73, 3)));
    MatchingWeights still;
    still.hips_velocity = 0.0f;
    dbs.push_back(build(test::make_matching_fixture(30, 200, 9), still));
    test::MatchingFixture twice = test::make_matching_fixture(9, 90, 21);
    for (int c = 0; c < 9; ++c) twice.clips.push_back(twice.clips[static_cast<size_t>(c)]);
    dbs.push_back(build(twice));
    MatchingDatabase grid = build(test::make_matching_fixture(10, 100, 4));
    for (float& x : grid.raw_features) x = std::round(x * 4.0f) / 4.0f;
    normalise_matching_database(grid, {});
    dbs.push_back(grid);
    return dbs;
}
}  // namespace

TEST_CASE("matching search: accelerated equals brute force across the envelope of queries", "[matching]") {
    // Fixed seed. Per database 400 queries: the whole range, far outside the data
    // (up to 1e6, and 1e20 whose squares overflow to infinite costs, all tied), exact
    // frames (zero cost, ties across duplicated clips), near frames, degenerate
    // queries (all zero, one feature set) and a NaN feature (no frame can win); each
    // with no candidate, the current frame, or a candidate tying the answer's cost.
    std::uint64_t rng = 77;
    int queries = 0, exact_ties = 0, infinite = 0;
    for (const MatchingDatabase& db : envelope_databases()) {
        // The search layout holds every searchable frame exactly once.
        std::vector<int> seen(static_cast<size_t>(db.frame_count), 0);
        for (std::int32_t f : db.block_frame)
            if (f >= 0) ++seen[static_cast<size_t>(f)];
        for (int f = 0; f < db.frame_count; ++f) REQUIRE(seen[static_cast<size_t>(f)] == db.searchable[static_cast<size_t>(f)]);
        for (int q = 0; q < 400; ++q, ++queries) {
            std::array<float, kMatchFeatureCount> query{};
            const int kind = q % 8;
            const int near = static_cast<int>(test::fixture_next(rng) % static_cast<std::uint64_t>(db.frame_count));
            const int one = static_cast<int>(test::fixture_next(rng) % kMatchFeatureCount);
            const double scale = kind == 1 ? std::pow(10.0, 1.0 + 5.0 * test::fixture_unit(rng)) : 1.0;
            for (int k = 0; k < kMatchFeatureCount; ++k) {
                const double u = test::fixture_unit(rng) * 2.0 - 1.0;
                const float x = db.frame_features(near)[k];
                float v = 0.0f;
                switch (kind) {
                    case 0: v = static_cast<float>(u * 4.0); break;
                    case 1: v = static_cast<float>(u * scale); break;
                    case 2: v = static_cast<float>(u * 1e20); break;
                    case 3: case 4: v = x; break;
                    case 5: v = x + static_cast<float>(u * 0.05); break;
                    case 6: v = k == one ? static_cast<float>(u * 3.0) : 0.0f; break;
                    default: v = k == one ? NAN : x; break;
                }
                query[static_cast<size_t>(k)] = v;
            }
            MatchingResult start;
            if (q % 3 == 1) start = {near, matching_cost(db, query, near)};
            if (q % 3 == 2) {  // a candidate with exactly the answer's cost, above or below its frame
                const MatchingResult answer = search_matching_brute_force(db, query);
                if (answer.frame >= 0) start = {answer.frame + ((q / 3) % 2 == 0 ? 1 : -1), answer.cost};
            }
            const MatchingResult brute = search_matching_brute_force(db, query, start);
            const MatchingResult fast = search_matching_accelerated(db, query, start);
            INFO("database of " << db.frame_count << " frames, query " << q << " kind " << kind);
            REQUIRE(fast.frame == brute.frame);
            REQUIRE(bits(fast.cost) == bits(brute.cost));
            if (kind == 2) {
                CHECK(std::isinf(brute.cost));
                infinite += brute.frame >= 0;
            }
            if (kind == 7) CHECK(brute.frame == start.frame);  // NaN: nothing beats the candidate
            exact_ties += kind == 3 && brute.cost == 0.0f && brute.frame < near;
        }
    }
    CHECK(queries >= 1000);
    CHECK(exact_ties > 0);  // the duplicated clips and the grid did produce ties
    CHECK(infinite > 0);
}
