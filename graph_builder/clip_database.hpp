#pragma once
// The clip database a motion graph is built from: clips loaded from BVH or
// ASF/AMC, checked to share one skeleton, labelled by file-name patterns, and
// resampled to the analysis rate. Offline code: reads files, allocates freely.
#include <cstdint>
#include <string>
#include <vector>

#include "retarget/humanoid.hpp"
#include "runtime/anim/clip.hpp"

namespace marionette::offline {

// A labels file (TOML, docs/motion-graph.md): [labels] maps clip-name patterns
// (shell globs, matched against the file name without extension) to label lists;
// [joint_weights] maps joint-name patterns to distance weights (default 1);
// [contacts] may name the left_foot and right_foot joints; [retarget] names
// source joints for the retargeter (docs/retarget.md) when clips are retargeted.
struct LabelRules {
    std::string origin;  // file name, for messages and the source hash
    std::string text;    // the TOML text
    std::vector<std::pair<std::string, std::vector<std::string>>> clip_patterns;
    std::vector<std::pair<std::string, float>> joint_weights;
    std::string left_foot;
    std::string right_foot;
    retarget::RetargetMap retarget_map;  // empty unless the file has [retarget]
};

// Throws ImportError naming the file, line and key on malformed input.
LabelRules parse_label_rules(const std::string& toml_text, const std::string& origin);

struct ClipDatabase {
    Skeleton skeleton;
    std::vector<bool> animated_translation;
    double length_unit = 1.0;
    double analysis_rate_hz = 30.0;
    std::vector<Clip> clips;                 // at the analysis rate
    std::vector<std::string> source_files;   // one per clip
    std::vector<std::string> labels;         // every label some clip carries, sorted
    std::vector<std::uint32_t> label_masks;  // per clip
    std::vector<float> joint_weights;        // per joint
    int left_foot = -1, right_foot = -1;
    std::uint64_t content_hash = 0;          // files' bytes (skeleton, clips, labels)

    std::int64_t frame_count() const;
};

// Loads every clip (BVH, or AMC with `asf_file`), checks one shared skeleton (the
// error names the first clip and joint that differ) and resamples. Throws ImportError.
// With `retarget_to` (the puppet's skeleton), every clip of another skeleton is
// first retargeted onto it (retarget/retarget.hpp, with the rules' [retarget]
// table), so any humanoid clips, of any mix of skeletons, make one database.
ClipDatabase load_clip_database(const std::vector<std::string>& clip_files, const std::string& asf_file,
                                const LabelRules& rules, double analysis_rate_hz, const Skeleton* retarget_to = nullptr);

// Same from clips already in memory (tests, benchmarks, generated clips).
ClipDatabase make_clip_database(std::vector<Clip> clips, const std::vector<std::string>& names_for_errors,
                                const LabelRules& rules, double analysis_rate_hz);

// Ok when `b` has the same joint names and hierarchy as `a`, else the first difference.
Outcome same_skeleton(const Skeleton& a, const Skeleton& b);

// Shell-glob match (*, ?, [...]) of a whole name.
bool name_matches(const std::string& pattern, const std::string& name);

}  // namespace marionette::offline
