#pragma once
// Seeded fault injection for the simulated pad. Every fault is off unless named;
// the same list and seed give the same stream, byte for byte.
//
//   --faults noise=0.02,drift=0.05,quant=6,jitter=200us,drop=0.01,dup=0.01,
//            corrupt=0.005,unplug=2s+500ms,syn_dropped=1.5s,seed=7
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace marionette::firmware_sim {

struct FaultSpec {
    double noise = 0.0;          // stick noise, standard deviation (normalised units)
    double drift = 0.0;          // centre drift reached at the end of the stream (both sticks, x and y)
    int quant_bits = 0;          // sticks quantised to this many bits (0: off)
    double jitter_s = 0.0;       // report times move by up to ± this much
    double drop = 0.0;           // probability a report is lost
    double duplicate = 0.0;      // probability a report is sent twice
    double corrupt = 0.0;        // probability a report is garbled (same length, rejected by the parser)
    double unplug_at_s = -1.0;   // unplug at this time (< 0: never) ...
    double unplug_for_s = 0.0;   // ... and replug this much later
    std::vector<double> syn_dropped_at_s;  // evemu: the kernel's buffer overflows here
    std::uint64_t seed = 1;
    bool any() const;
};

// Throws ImportError naming "--faults" and the offending item.
FaultSpec parse_faults(std::string_view list);
std::string describe_faults(const FaultSpec& faults);

// Small deterministic generator (splitmix64): the stream must not depend on the
// standard library's distributions, which differ between implementations.
class SimRandom {
public:
    explicit SimRandom(std::uint64_t seed) : state_(seed) {}
    std::uint64_t next_u64();
    double uniform();            // [0, 1)
    double gaussian();           // mean 0, sd 1 (Box-Muller on uniform())
private:
    std::uint64_t state_;
};

}  // namespace marionette::firmware_sim
