#pragma once
// The sweep generator's two halves (app/eval/gait_sweep_cases.cpp: the ground;
// app/eval/gait_sweep_program.cpp: the stick program), joined by
// generate_sweep_case in app/eval/gait_sweep.cpp.
#include <string>

#include "app/eval/gait_sweep.hpp"

namespace marionette::sweep_detail {

// The ground of a case: its parameters in `g`, its terrain in `t`; returns a
// one-line description. Sets `first_dir`, the program's first stick direction
// (a stick angle in degrees: the feature's axis plus the approach angle).
std::string make_ground(SweepRandom& r, SweepGroundParams& g, Terrain& t, double& first_dir);

// A stick program of kMinCaseS–kMaxCaseS seconds that starts toward `first_dir`
// and then does anything: holds, ramps, circles, reversals, pulses, noise,
// values near `deadzone`, button presses. Text in the stick-program format;
// `summary` gets a few words on its shape.
std::string make_program(SweepRandom& r, double first_dir, double deadzone, std::string& summary);

}  // namespace marionette::sweep_detail
