#pragma once
// The renderer draws between two simulation ticks: the pipeline's render thread
// hands it the previous and current PuppetState and the fixed-step alpha (the
// fraction of a tick since the current one ran).
#include "runtime/sim/simulation.hpp"

namespace marionette::render {

// out = previous + alpha·(current − previous): positions lerp, rotations slerp
// (runtime/math/math.hpp), heading along the shorter arc; everything else (tick, input,
// phases) comes from `current`. alpha is clamped to [0, 1]. No allocation; `out`
// may alias neither input.
void interpolate_state(const PuppetState& previous, const PuppetState& current, float alpha, PuppetState& out);

// out = current carried on along the last tick's motion by `ahead` ticks, clamped
// to [0, 1]: the same blend with alpha = 1 + ahead (positions extrapolate
// linearly, rotations along the same great arc). [timing] interpolation = "extrapolate".
void extrapolate_state(const PuppetState& previous, const PuppetState& current, float ahead, PuppetState& out);

}  // namespace marionette::render
