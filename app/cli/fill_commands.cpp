// `marionette clip fill` and `marionette clip fill-eval` (docs/fill.md).
#include <fmt/format.h>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "app/cli/cli.hpp"
#include "app/io/files.hpp"
#include "app/io/json.hpp"
#include "graph_builder/clip_fill.hpp"
#include "graph_builder/fill_eval.hpp"
#include "graph_builder/fill_retarget.hpp"
#include "runtime/formats/asf_amc.hpp"
#include "runtime/formats/bvh.hpp"
#include "runtime/formats/file_names.hpp"

namespace marionette {

namespace {

using namespace marionette::offline;

struct FillCommandOptions {
    std::string input, asf, output, method = "graph";
    std::vector<std::string> database, hide, frames;
    double piece_s = FillOptions{}.piece_s;
    bool allow_self = false, json = false;
};

struct FillEvalCommandOptions {
    std::string asf, hide, gaps = "0.25,0.5,1,2,4";
    std::vector<std::string> clips, database;
    std::uint64_t seed = 1;
    int trials = 3;
    double piece_s = FillOptions{}.piece_s;
    bool json = false, per_clip = false, oracle_match = false;
};

// --piece: 0 (whole gaps only) or 0.25..60 s.
double checked_piece_s(double s) {
    if (!(s == 0.0 || (s >= 0.25 && s <= 60.0)))
        throw ImportError("--piece", 0, fmt::format("{}: expected 0 (fill gaps whole only) or a piece length of 0.25 to 60 seconds", s));
    return s;
}

Clip load_any_clip(const std::string& file, const std::string& asf) {
    const std::string ext = lower_extension(file);
    if (ext == "bvh") return load_bvh_file(file);
    if (ext == "amc") {
        if (asf.empty()) throw ImportError(file, 0, "an AMC clip needs its skeleton: add --asf SKELETON.asf");
        return load_asf_amc_files(asf, file);
    }
    throw ImportError(file, 0, "unknown clip format '." + ext + "' (expected .bvh, or .amc with --asf)");
}

std::vector<double> parse_gaps(const std::string& text) {
    std::vector<double> out;
    size_t begin = 0;
    while (begin <= text.size()) {
        size_t end = text.find(',', begin);
        if (end == std::string::npos) end = text.size();
        const std::string item = text.substr(begin, end - begin);
        begin = end + 1;
        char* stop = nullptr;
        const double v = std::strtod(item.c_str(), &stop);
        if (item.empty() || stop != item.c_str() + item.size() || !(v > 0.0 && v <= 600.0))
            throw ImportError("--gaps", 0, "'" + item + "': expected comma-separated gap lengths in seconds, each in (0, 600]");
        out.push_back(v);
    }
    return out;
}

std::string names_json(const Skeleton& s, const std::vector<bool>& hidden) {
    std::string out;
    for (int j = 0; j < s.joint_count(); ++j)
        if (hidden[static_cast<size_t>(j)]) out += (out.empty() ? "" : ",") + json::quote(s.joint_names[static_cast<size_t>(j)]);
    return "[" + out + "]";
}

FillDatabase load_fill_database(const FillCommandOptions& o, const Clip& input) {
    const std::uint64_t input_hash = fill_content_hash(read_binary_file(o.input));
    std::vector<Clip> clips;
    for (const std::string& f : o.database) {
        if (lower_extension(f) == "asf") continue;  // a skeleton among shell-globbed clips
        if (!o.allow_self && fill_content_hash(read_binary_file(f)) == input_hash)
            throw ImportError(f, 0, "has the same content as the input " + o.input +
                                        ": the clip being filled must not be in its own database (add --allow-self to allow it)");
        Clip c = load_any_clip(f, o.asf);
        if (c.frame_count < 2) throw ImportError(f, 0, "a database clip needs at least 2 frames");
        if (!check_fill_skeleton(input.skeleton, c.skeleton).ok()) c = retarget_fill_clip(c, f, input, o.input);
        clips.push_back(std::move(c));
    }
    if (clips.empty()) throw ImportError("--database", 0, "no database clip given");
    return prepare_fill_database(std::move(clips));
}

int clip_fill_command(const FillCommandOptions& o) {
    const auto start = std::chrono::steady_clock::now();
    Clip clip = load_any_clip(o.input, o.asf);
    FillOptions fo;
    fo.method = parse_fill_method(o.method, "--method");
    fo.piece_s = checked_piece_s(o.piece_s);
    if (o.hide.size() != o.frames.size())
        throw ImportError("--hide", 0, fmt::format("{} --hide and {} --frames given: each --hide needs its --frames A:B",
                                                   o.hide.size(), o.frames.size()));
    std::vector<FillGap> gaps;
    for (size_t i = 0; i < o.hide.size(); ++i) {
        FillGap g = parse_fill_frames(o.frames[i], clip.frame_count, "--frames");
        g.hidden = resolve_hidden_joints(clip.skeleton, o.hide[i], "--hide");
        gaps.push_back(std::move(g));
    }
    FillDatabase db;
    if (fo.method == FillMethod::graph || !o.database.empty()) db = load_fill_database(o, clip);
    const auto searched = std::chrono::steady_clock::now();
    std::string report;
    for (const FillGap& g : gaps) {
        const FillMatch m = fill_gap(clip, g, &db, fo);
        std::string source = "null";
        if (m.found)
            source = fmt::format("{{\"clip\":{},\"start_s\":{},\"scale\":{},\"distance\":{},\"graph_weight\":{}}}",
                                 json::quote(db.clips[static_cast<size_t>(m.clip)].name), json::number(m.start_s),
                                 json::number(m.scale), json::number(m.distance), json::number(m.graph_weight));
        report += fmt::format("{}{{\"frames\":[{},{}],\"hidden\":{},\"method\":{},\"source\":{}}}", report.empty() ? "" : ",",
                              g.first, g.last, names_json(clip.skeleton, g.hidden),
                              json::quote(fo.method == FillMethod::graph && !m.found ? "slerp" : fill_method_name(fo.method)), source);
        if (!o.json)
            fmt::print("frames {}..{}: {}{}\n", g.first, g.last, fill_method_name(fo.method),
                       m.found ? fmt::format(" from {} at {:.3f} s (scale {:.2f}, distance {:.4g})",
                                             db.clips[static_cast<size_t>(m.clip)].name, m.start_s, m.scale, m.distance)
                               : (fo.method == FillMethod::graph ? " (no database segment fits: slerp)" : ""));
    }
    const auto filled = std::chrono::steady_clock::now();
    write_text_file(o.output, export_bvh(clip));
    const auto ms = [](auto a, auto b) { return std::chrono::duration<double, std::milli>(b - a).count(); };
    if (o.json)
        fmt::print("{{\"input\":{},\"output\":{},\"frames\":{},\"database_frames\":{},\"gaps\":[{}],\"load_ms\":{},\"fill_ms\":{}}}\n",
                   json::quote(o.input), json::quote(o.output), clip.frame_count, db.frame_count(), report,
                   json::number(ms(start, searched)), json::number(ms(searched, filled)));
    else
        fmt::print("wrote {} ({} frames)\n", o.output, clip.frame_count);
    return 0;
}

int clip_fill_eval_command(const FillEvalCommandOptions& o) {
    FillEvalOptions eo;
    eo.hide = o.hide;
    eo.gaps_s = parse_gaps(o.gaps);
    eo.seed = o.seed;
    eo.fill.oracle_match = o.oracle_match;
    eo.fill.piece_s = checked_piece_s(o.piece_s);
    if (o.trials < 1 || o.trials > 1000) throw ImportError("--trials", 0, "expected 1..1000 gaps per clip and length");
    eo.trials = o.trials;
    std::vector<Clip> clips;
    std::vector<std::string> names;
    for (const std::string& f : o.clips) {
        if (lower_extension(f) == "asf") continue;
        clips.push_back(load_any_clip(f, o.asf));
        names.push_back(f);
    }
    std::vector<Clip> extra;
    for (const std::string& f : o.database) {
        if (lower_extension(f) == "asf") continue;
        if (clips.empty()) break;
        Clip c = load_any_clip(f, o.asf);
        if (c.frame_count < 2) throw ImportError(f, 0, "a database clip needs at least 2 frames");
        if (!check_fill_skeleton(clips[0].skeleton, c.skeleton).ok()) c = retarget_fill_clip(c, f, clips[0], names[0]);
        extra.push_back(std::move(c));
    }
    const FillEvalResult r = evaluate_fill(clips, names, eo, extra);
    std::string rows;
    for (const FillEvalRow& row : r.rows) {
        if (o.json)
            rows += fmt::format("{}{{\"method\":{},\"gap_s\":{},\"cases\":{},\"mean_cm\":{},\"worst_cm\":{},"
                                "\"continuity_mean\":{},\"continuity_worst\":{}}}",
                                rows.empty() ? "" : ",", json::quote(fill_method_name(row.method)), json::number(row.gap_s),
                                row.cases, json::number(row.mean_cm), json::number(row.worst_cm),
                                json::number(row.continuity_mean), json::number(row.continuity_worst));
        else
            fmt::print("{:6} gap {:5.2f} s  cases {:3}  mean {:7.2f} cm  worst {:7.2f} cm  continuity mean {:5.2f} worst {:5.2f}\n",
                       fill_method_name(row.method), row.gap_s, row.cases, row.mean_cm, row.worst_cm,
                       row.continuity_mean, row.continuity_worst);
    }
    std::string per_clip;
    for (const FillEvalClipRow& row : r.per_clip) {
        const std::string& name = names[static_cast<size_t>(row.clip)];
        if (o.json)
            per_clip += fmt::format("{}{{\"clip\":{},\"method\":{},\"gap_s\":{},\"cases\":{},\"mean_cm\":{}}}",
                                    per_clip.empty() ? "" : ",", json::quote(name), json::quote(fill_method_name(row.method)),
                                    json::number(row.gap_s), row.cases, json::number(row.mean_cm));
        else if (o.per_clip)
            fmt::print("  {:40} {:6} gap {:5.2f} s  cases {:3}  mean {:7.2f} cm\n", name, fill_method_name(row.method),
                       row.gap_s, row.cases, row.mean_cm);
    }
    if (o.json)
        fmt::print("{{\"hide\":{},\"seed\":{},\"trials\":{},\"clips\":{},\"database_extra\":{},\"skipped\":{},\"cm_per_unit\":{},\"oracle_match\":{},\"rows\":[{}]{}}}\n",
                   json::quote(o.hide), o.seed, o.trials, clips.size(), extra.size(), r.skipped, json::number(r.cm_per_unit),
                   o.oracle_match ? "true" : "false", rows,
                   o.per_clip ? ",\"per_clip\":[" + per_clip + "]" : std::string());
    return 0;
}

}  // namespace

void register_clip_fill_commands(CLI::App* clip, int& exit_code) {
    auto o = std::make_shared<FillCommandOptions>();
    CLI::App* fill = clip->add_subcommand("fill", "Fill joints hidden over frame ranges from a motion database");
    fill->add_option("input", o->input, "clip to fill (.bvh, or .amc with --asf)")->required();
    fill->add_option("--asf", o->asf, "skeleton for AMC files (input and database)");
    fill->add_option("--database", o->database, "database clips (.bvh, .amc)");
    fill->add_option("--hide", o->hide, "joints or groups hidden (comma-separated; repeat with --frames)")
        ->required()->expected(1)->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    fill->add_option("--frames", o->frames, "A:B, 0-based inclusive frames where --hide applies")
        ->required()->expected(1)->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    fill->add_option("--method", o->method, "graph (default), slerp or hold");
    fill->add_option("-o,--output", o->output, "output BVH")->required();
    fill->add_option("--piece", o->piece_s, "graph: gaps longer than this many seconds are filled again in pieces this long (default 2; 0: whole only)");
    fill->add_flag("--allow-self", o->allow_self, "allow a database file with the input's content");
    fill->add_flag("--json", o->json, "print JSON");
    on_parsed(fill, exit_code, [o] { return clip_fill_command(*o); });

    auto e = std::make_shared<FillEvalCommandOptions>();
    CLI::App* eval = clip->add_subcommand("fill-eval", "Leave-one-out error of every fill method on random gaps");
    eval->add_option("--asf", e->asf, "skeleton for AMC files");
    eval->add_option("--clips", e->clips, "clips (.bvh, .amc)")->required();
    eval->add_option("--hide", e->hide, "joints or group to hide")->required();
    eval->add_option("--database", e->database,
                     "extra database clips in every leave-one-out database, never filled (other skeletons are retargeted)");
    eval->add_option("--gaps", e->gaps, "gap lengths in seconds, comma-separated");
    eval->add_option("--seed", e->seed, "seed of the gaps' positions (splitmix64)");
    eval->add_option("--trials", e->trials, "random gaps per clip and gap length (default 3)");
    eval->add_flag("--oracle-match", e->oracle_match,
                   "diagnosis: the graph method's search also sees the hidden joints' truth (the best match in hindsight)");
    eval->add_option("--piece", e->piece_s, "as clip fill --piece (default 2; 0: whole only)");
    eval->add_flag("--per-clip", e->per_clip, "also report each clip's mean error per method and gap length");
    eval->add_flag("--json", e->json, "print JSON");
    on_parsed(eval, exit_code, [e] { return clip_fill_eval_command(*e); });
}

}  // namespace marionette
