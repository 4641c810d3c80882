// A fixed run of gait ticks for instruction counting: the same scenarios as
// marionette_bench_gait's BM_GaitTick (idle, walk and run on flat ground and on
// the same 180-box rubble, reversing every 960 ticks), a fixed number of ticks
// each, no timing. Run under callgrind and divide Simulation::step's inclusive
// instructions by the tick count (docs/architecture.md, Performance):
//   valgrind --tool=callgrind --toggle-collect='marionette::Simulation::step*'
//       build/release/bench/marionette_tick_instructions walk flat 1920   (one line)
// Prints the state hash after the last tick, so a cut that changes any bit shows.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "bench_rubble.hpp"
#include "runtime/sim/simulation.hpp"

using namespace marionette;

int main(int argc, char** argv) {
    if (argc != 4) {
        std::fprintf(stderr, "usage: %s idle|walk|run flat|rubble TICKS\n", argv[0]);
        return 2;
    }
    const bool known_gait = !std::strcmp(argv[1], "idle") || !std::strcmp(argv[1], "walk") || !std::strcmp(argv[1], "run");
    const bool known_ground = !std::strcmp(argv[2], "flat") || !std::strcmp(argv[2], "rubble");
    const long ticks = std::strtol(argv[3], nullptr, 10);
    if (!known_gait || !known_ground || ticks <= 0) {
        std::fprintf(stderr, "%s: expected idle|walk|run, flat|rubble and a positive tick count, got '%s' '%s' '%s'\n",
                     argv[0], argv[1], argv[2], argv[3]);
        return 2;
    }
    set_simulation_float_mode();
    const Terrain terrain = !std::strcmp(argv[2], "rubble") ? bench_rubble_terrain() : Terrain{};
    Simulation sim(SimConfig{}, terrain);
    TickInput in;
    in.left_y = !std::strcmp(argv[1], "idle") ? 0 : (!std::strcmp(argv[1], "walk") ? 20000 : 32767);
    for (long k = 1; k <= ticks; ++k) {
        if (in.left_y != 0 && k % 960 == 0) in.left_y = static_cast<std::int16_t>(-in.left_y);
        sim.step(in);
    }
    std::printf("%s %s %ld ticks: state hash %016llx\n", argv[1], argv[2], ticks,
                static_cast<unsigned long long>(hash_state(sim.state())));
    return 0;
}
