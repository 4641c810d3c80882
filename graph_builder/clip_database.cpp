#include "graph_builder/clip_database.hpp"

#include <fnmatch.h>
#include <xxhash.h>

#include <toml++/toml.h>

#include <algorithm>

#include "retarget/retarget.hpp"
#include "runtime/formats/asf_amc.hpp"
#include "runtime/formats/bvh.hpp"
#include "runtime/formats/file_names.hpp"
#include "runtime/errors/import_error.hpp"

namespace marionette::offline {

namespace {

int line_of(const toml::node& n) { return static_cast<int>(n.source().begin.line); }

std::string lower(std::string s) {
    for (char& c : s) c = static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
    return s;
}

// A foot joint by name when the labels file names none: the first joint whose
// lower-case name contains "foot" (or "ankle") and reads as left or right.
int guess_foot(const Skeleton& s, bool left) {
    for (int j = 0; j < s.joint_count(); ++j) {
        const std::string n = lower(s.joint_names[static_cast<size_t>(j)]);
        if (n.find("foot") == std::string::npos && n.find("ankle") == std::string::npos) continue;
        if (n.find("toe") != std::string::npos) continue;
        const bool is_left = n.find("left") != std::string::npos || n.front() == 'l' ||
                             (n.size() > 2 && n.substr(n.size() - 2) == "_l");
        const bool is_right = n.find("right") != std::string::npos || n.front() == 'r' ||
                              (n.size() > 2 && n.substr(n.size() - 2) == "_r");
        if (left ? (is_left && !is_right) : (is_right && !is_left)) return j;
    }
    return -1;
}

}  // namespace

bool name_matches(const std::string& pattern, const std::string& name) {
    return fnmatch(pattern.c_str(), name.c_str(), 0) == 0;
}

LabelRules parse_label_rules(const std::string& text, const std::string& origin) {
    LabelRules rules;
    rules.origin = origin;
    rules.text = text;
    toml::table doc;
    try {
        doc = toml::parse(text, origin);
    } catch (const toml::parse_error& e) {
        throw ImportError(origin, static_cast<int>(e.source().begin.line),
                          "TOML syntax error: " + std::string(e.description()));
    }
    for (const auto& [key, node] : doc) {
        const std::string table(key.str());
        const toml::table* t = node.as_table();
        if (t && table == "retarget") {
            rules.retarget_map = retarget::parse_retarget_map(text, origin, true);
            continue;
        }
        if (!t || (table != "labels" && table != "joint_weights" && table != "contacts"))
            throw ImportError(origin, line_of(node),
                              "unknown entry '" + table + "' (expected the tables [labels], [joint_weights], [contacts], [retarget])");
        for (const auto& [k, v] : *t) {
            const std::string name(k.str());
            const std::string full = table + "." + name;
            if (table == "labels") {
                const toml::array* list = v.as_array();
                if (!list) throw ImportError(origin, line_of(v), full + ": expected a list of label strings");
                std::vector<std::string> labels;
                for (const toml::node& item : *list) {
                    const auto* s = item.as_string();
                    if (!s || s->get().empty())
                        throw ImportError(origin, line_of(item), full + ": expected a non-empty label string");
                    labels.push_back(s->get());
                }
                rules.clip_patterns.emplace_back(name, std::move(labels));
            } else if (table == "joint_weights") {
                double w = 0.0;
                if (const auto* f = v.as_floating_point()) w = f->get();
                else if (const auto* i = v.as_integer()) w = static_cast<double>(i->get());
                else throw ImportError(origin, line_of(v), full + ": expected a number in [0, 100]");
                if (!(w >= 0.0 && w <= 100.0))
                    throw ImportError(origin, line_of(v), full + ": weight out of range: expected a number in [0, 100]");
                rules.joint_weights.emplace_back(name, static_cast<float>(w));
            } else {
                const auto* s = v.as_string();
                if (!s || (name != "left_foot" && name != "right_foot"))
                    throw ImportError(origin, line_of(v), full + ": expected left_foot or right_foot = \"JOINT\"");
                (name == "left_foot" ? rules.left_foot : rules.right_foot) = s->get();
            }
        }
    }
    return rules;
}

std::int64_t ClipDatabase::frame_count() const {
    std::int64_t n = 0;
    for (const Clip& c : clips) n += c.frame_count;
    return n;
}

Outcome same_skeleton(const Skeleton& a, const Skeleton& b) {
    const int n = std::min(a.joint_count(), b.joint_count());
    const auto parent_name = [](const Skeleton& s, int j) {
        const int p = s.parents[static_cast<size_t>(j)];
        return p == kNoParent ? std::string("no parent") : "parent '" + s.joint_names[static_cast<size_t>(p)] + "'";
    };
    for (int j = 0; j < n; ++j) {
        const size_t u = static_cast<size_t>(j);
        if (a.joint_names[u] != b.joint_names[u] || a.parents[u] != b.parents[u])
            return Outcome::failure("joint " + std::to_string(j) + " is '" + b.joint_names[u] + "' (" +
                                    parent_name(b, j) + ") where the first clip has '" + a.joint_names[u] + "' (" +
                                    parent_name(a, j) + ")");
    }
    if (a.joint_count() != b.joint_count())
        return Outcome::failure(std::to_string(b.joint_count()) + " joints where the first clip has " + std::to_string(a.joint_count()));
    return Outcome::success();
}

ClipDatabase make_clip_database(std::vector<Clip> clips, const std::vector<std::string>& names,
                                const LabelRules& rules, double rate) {
    if (clips.empty()) throw ImportError(rules.origin, 0, "a motion graph needs at least one clip");
    ClipDatabase db;
    db.skeleton = clips.front().skeleton;
    db.animated_translation = clips.front().animated_translation;
    db.length_unit = clips.front().length_unit;
    db.analysis_rate_hz = rate;
    for (size_t c = 0; c < clips.size(); ++c) {
        const std::string& where = c < names.size() ? names[c] : clips[c].name;
        if (const Outcome same = same_skeleton(db.skeleton, clips[c].skeleton); !same.ok())
            throw ImportError(where, 0, "skeleton differs from " + (names.empty() ? clips[0].name : names[0]) + ": " + same.problem() +
                                            " (every clip of a motion graph must share one skeleton)");
        for (size_t d = 0; d < c; ++d)
            if (clips[d].name == clips[c].name)
                throw ImportError(where, 0, "a second clip named '" + clips[c].name + "' (clip names must be unique)");
        if (clips[c].frame_count < 2) throw ImportError(where, 0, "clip has fewer than 2 frames");
    }
    // Labels: union over every matching pattern, in file order; the label list is sorted.
    std::vector<std::vector<std::string>> per_clip(clips.size());
    for (size_t c = 0; c < clips.size(); ++c)
        for (const auto& [pattern, labels] : rules.clip_patterns)
            if (name_matches(pattern, clips[c].name))
                for (const std::string& l : labels)
                    if (std::find(per_clip[c].begin(), per_clip[c].end(), l) == per_clip[c].end()) per_clip[c].push_back(l);
    for (const auto& ls : per_clip)
        for (const std::string& l : ls)
            if (std::find(db.labels.begin(), db.labels.end(), l) == db.labels.end()) db.labels.push_back(l);
    std::sort(db.labels.begin(), db.labels.end());
    if (db.labels.size() > 32)
        throw ImportError(rules.origin, 0, "more than 32 distinct labels (" + std::to_string(db.labels.size()) + ")");
    for (const auto& ls : per_clip) {
        std::uint32_t mask = 0;
        for (const std::string& l : ls)
            mask |= 1u << (std::find(db.labels.begin(), db.labels.end(), l) - db.labels.begin());
        db.label_masks.push_back(mask);
    }
    // Joint weights: the last matching pattern wins; unmatched joints weigh 1.
    for (const std::string& j : db.skeleton.joint_names) {
        float w = 1.0f;
        for (const auto& [pattern, weight] : rules.joint_weights)
            if (name_matches(pattern, j)) w = weight;
        db.joint_weights.push_back(w);
    }
    const auto foot = [&](const std::string& named, bool left) {
        if (named.empty()) return guess_foot(db.skeleton, left);
        const int j = db.skeleton.find(named);
        if (j < 0) throw ImportError(rules.origin, 0, "contacts: no joint named '" + named + "' in the skeleton");
        return j;
    };
    db.left_foot = foot(rules.left_foot, true);
    db.right_foot = foot(rules.right_foot, false);

    XXH64_state_t* h = XXH64_createState();
    XXH64_reset(h, 0x6772617068u);
    XXH64_update(h, rules.text.data(), rules.text.size());
    for (Clip& clip : clips) {
        XXH64_update(h, clip.name.data(), clip.name.size() + 1);
        XXH64_update(h, clip.rotations.data(), clip.rotations.size() * sizeof(quat));
        XXH64_update(h, clip.translations.data(), clip.translations.size() * sizeof(vec3));
        XXH64_update(h, &clip.frame_rate, sizeof clip.frame_rate);
        db.clips.push_back(clip.frame_rate == rate ? std::move(clip) : resample_clip(clip, rate));
    }
    db.content_hash = XXH64_digest(h);
    XXH64_freeState(h);
    db.source_files = names;
    return db;
}

ClipDatabase load_clip_database(const std::vector<std::string>& files, const std::string& asf_file,
                                const LabelRules& rules, double rate, const Skeleton* retarget_to) {
    std::vector<Clip> clips;
    std::vector<std::string> names;
    for (const std::string& f : files) {
        const std::string ext = lower_extension(f);
        if (ext == "asf") continue;  // a skeleton passed among the clips (shell globs): the --asf check covers it
        if (ext == "bvh") {
            clips.push_back(load_bvh_file(f));
        } else if (ext == "amc") {
            if (asf_file.empty()) throw ImportError(f, 0, "an AMC clip needs its skeleton: add --asf SKELETON.asf");
            clips.push_back(load_asf_amc_files(asf_file, f));
        } else {
            throw ImportError(f, 0, "unknown clip format '." + ext + "' (expected .bvh, or .amc with --asf)");
        }
        names.push_back(f);
        if (retarget_to && !retarget::is_puppet_skeleton(clips.back().skeleton, *retarget_to)) {
            retarget::RetargetOptions options;
            const bool mapped = !rules.retarget_map.roles.empty() || !rules.retarget_map.up.empty();
            if (mapped) options.map = &rules.retarget_map;
            clips.back() = retarget::retarget_clip(clips.back(), *retarget_to, f, options).clip;
        }
    }
    if (clips.empty()) throw ImportError(files.empty() ? rules.origin : files.front(), 0, "no clip files given");
    return make_clip_database(std::move(clips), names, rules, rate);
}

}  // namespace marionette::offline
