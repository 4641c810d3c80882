#pragma once
// The spline editor's model (docs/ui.md, "Spline editor"): edits of the gait's
// walk and run prototypes ([gait.walk] / [gait.run], runtime/gait/
// gait_prototype.hpp) that always leave them valid for the configuration's
// loader: phases stay increasing (at least kMinKeyGap apart), the first key at
// phase 0 and the last at 1, the swing's end keys on [0, 0, 0, 0] and
// [1, 0, 0, 1], a looping path's last values equal to its first, every value
// finite and within ±kSplineValueLimit. Plain functions on plain data; the UI
// calls them and hands the result over as a configuration change.
#include <string>

#include "runtime/gait/gait_config.hpp"

namespace marionette::ui {

enum class SplineGait { walk, run };
enum class SplinePath { swing_foot, pelvis, hand };

inline constexpr float kMinKeyGap = 0.02f;          // phase between neighbouring keys, at least
inline constexpr float kSplineValueLimit = 1.0f;    // |x|, |y|, |z| an edit leaves (files allow ±10)
inline constexpr float kSplinePhaseStep = 0.01f;    // phase per pad step
inline constexpr float kSplineValueStep = 0.005f;   // value per pad step (m; the swing's z: fraction)
inline constexpr float kSplineQuantum = 1.0e4f;     // an edited phase or value lands on a multiple of 1/this

const char* gait_table(SplineGait gait);  // "gait.walk", "gait.run"
const char* path_key(SplinePath path);    // "swing_foot", "pelvis", "hand"
inline bool path_loops(SplinePath path) { return path != SplinePath::swing_foot; }
SplinePrototype& prototype_of(GaitConfig& config, SplineGait gait, SplinePath path);
const SplinePrototype& prototype_of(const GaitConfig& config, SplineGait gait, SplinePath path);

// Whether key `index` may change its phase (not the first or last key), and
// its values (not the swing's end keys).
bool phase_editable(const SplinePrototype& p, int index);
bool values_editable(const SplinePrototype& p, SplinePath path, int index);

// Moves key `index` by `dphase` in phase and `dvalue` on `channel` (0 x, 1 y,
// 2 z), clamped into what stays valid (a looping path's end keys move
// together). False (nothing changes) when the key or channel does not exist,
// a delta is not finite, or the clamped key equals the old one.
bool move_key(SplinePrototype& p, SplinePath path, int index, float dphase, int channel, float dvalue);
// The same to an absolute phase and value (a mouse drag), clamped likewise.
// A phase or value that changes is rounded to a multiple of 1/kSplineQuantum.
bool set_key(SplinePrototype& p, SplinePath path, int index, float phase, int channel, float value);

// Empty when the loader would take `p` for `path`; else what is wrong.
std::string validate_prototype(const SplinePrototype& p, SplinePath path);

// The TOML value of the prototype: [[phase, x, y, z], ...], numbers written so
// they read back to the same float bits.
std::string prototype_toml(const SplinePrototype& p);

}  // namespace marionette::ui
