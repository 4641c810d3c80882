// `marionette clip info`, `marionette clip fk` and `marionette clip retarget` (fill and fill-eval: fill_commands.cpp).
#include <fmt/format.h>

#include <cstdio>
#include <string>

#include "app/cli/cli.hpp"
#include "app/cli/commands.hpp"
#include "app/io/files.hpp"
#include "app/io/json.hpp"
#include "app/config/config.hpp"
#include "retarget/retarget.hpp"
#include "runtime/gait/puppet.hpp"
#include "runtime/formats/asf_amc.hpp"
#include "runtime/formats/bvh.hpp"
#include "runtime/formats/file_names.hpp"

namespace marionette {

namespace {
// BVH, AMC (with its ASF) or a bare ASF (skeleton only, zero frames).
Clip load_clip(const ClipOptions& o) {
    const std::string ext = lower_extension(o.file);
    if (ext == "bvh") return load_bvh_file(o.file);
    if (ext == "amc") {
        if (o.asf_file.empty()) throw ImportError(o.file, 0, "an AMC file needs its skeleton: add --asf SKELETON.asf");
        return load_asf_amc_files(o.asf_file, o.file);
    }
    if (ext == "asf") {
        Clip clip;
        clip.skeleton = import_asf_skeleton(read_text_file(o.file), o.file);
        clip.frame_count = 0;
        clip.frame_rate = 120.0;
        return clip;
    }
    throw ImportError(o.file, 0, "unknown clip format '." + ext + "' (expected .bvh, .amc with --asf, or .asf)");
}

std::string format_name(const std::string& path) {
    const std::string ext = lower_extension(path);
    return ext == "bvh" ? "bvh" : (ext == "amc" ? "asf/amc" : "asf");
}
}  // namespace

int clip_info_command(const ClipOptions& o) {
    const Clip clip = load_clip(o);
    const Skeleton& s = clip.skeleton;
    if (o.json) {
        std::string names;
        for (const std::string& n : s.joint_names) names += (names.empty() ? "" : ",") + json::quote(n);
        fmt::print("{{\"file\":{},\"format\":{},\"joints\":{},\"end_sites\":{},\"frames\":{},\"frame_rate\":{},"
                   "\"duration_s\":{},\"root\":{},\"length_unit\":{},\"joint_names\":[{}]}}\n",
                   json::quote(o.file), json::quote(format_name(o.file)), s.joint_count(), s.end_site_parents.size(),
                   clip.frame_count, json::number(clip.frame_rate), json::number(clip.duration()),
                   json::quote(s.joint_names.empty() ? "" : s.joint_names[0]), json::number(clip.length_unit), names);
    } else {
        fmt::print("{}: {} skeleton, {} joints (root {}), {} end sites\n", o.file, format_name(o.file), s.joint_count(),
                   s.joint_names.empty() ? "-" : s.joint_names[0], s.end_site_parents.size());
        fmt::print("{} frames at {} Hz ({:.3f} s)\n", clip.frame_count, clip.frame_rate, clip.duration());
    }
    return 0;
}

int clip_fk_command(const ClipOptions& o) {
    const Clip clip = load_clip(o);
    if (o.frame < 0 || o.frame >= clip.frame_count)
        throw ImportError(o.file, 0,
                          fmt::format("frame {} is out of range: the clip has {} frames (0-based indices 0..{})", o.frame,
                                      clip.frame_count, clip.frame_count - 1));
    const size_t n = static_cast<size_t>(clip.joint_count());
    std::vector<quat> model_rotations(n);
    std::vector<vec3> model_positions(n);
    const LocalToModelJob fk{clip.skeleton.parents,
                             {std::span<const quat>(clip.frame_rotations(o.frame), n),
                              std::span<const vec3>(clip.frame_translations(o.frame), n)},
                             {model_rotations, model_positions}};
    // The importers validate the skeleton, so this holds for every loaded clip.
    if (!fk.run()) throw ImportError(o.file, 0, "the skeleton's parents are not in topological order");
    const Skeleton& s = clip.skeleton;
    if (o.json) {
        std::string out = "{\"joints\":[";
        for (size_t j = 0; j < n; ++j) {
            const int p = s.parents[j];
            out += fmt::format("{}{{\"name\":{},\"parent\":{},\"position\":[{},{},{}]}}", j ? "," : "",
                               json::quote(s.joint_names[j]),
                               p == kNoParent ? std::string("null") : json::quote(s.joint_names[static_cast<size_t>(p)]),
                               json::number(model_positions[j].x), json::number(model_positions[j].y),
                               json::number(model_positions[j].z));
        }
        fmt::print("{}]}}\n", out);
    } else {
        fmt::print("{} frame {} (world space, file units)\n", o.file, o.frame);
        for (size_t j = 0; j < n; ++j)
            fmt::print("{:>24} {:12.5f} {:12.5f} {:12.5f}\n", s.joint_names[j], model_positions[j].x,
                       model_positions[j].y, model_positions[j].z);
    }
    return 0;
}

int clip_retarget_command(const ClipOptions& o) {
    const std::string ext = lower_extension(o.file);
    if (ext != "bvh" && ext != "amc")
        throw ImportError(o.file, 0, "clip retarget needs a motion: a .bvh, or an .amc with --asf SKELETON.asf");
    const Clip source = load_clip(o);
    if (source.frame_count < 1) throw ImportError(o.file, 0, "the clip has no frames to retarget");
    const AppConfig config = load_config(o.config_file);
    const Skeleton puppet = make_puppet_skeleton(config.sim);
    retarget::RetargetMap map;
    retarget::RetargetOptions options;
    if (!o.map_file.empty()) {
        map = retarget::parse_retarget_map(read_text_file(o.map_file), o.map_file);
        options.map = &map;
    }
    const retarget::RetargetResult r = retarget::retarget_clip(source, puppet, o.file, options);
    write_text_file(o.output_file, export_bvh(r.clip));
    const retarget::HumanoidChains& h = r.chains;
    const Skeleton& s = source.skeleton;
    double worst_mean = 1.0, worst_min = 1.0;
    for (const retarget::BoneAgreement& b : r.bones) {
        worst_mean = std::min(worst_mean, b.mean_cos);
        worst_min = std::min(worst_min, b.min_cos);
    }
    if (o.json) {
        std::string roles, bones, notes;
        const auto& names = retarget::role_names();
        for (size_t k = 0; k < names.size(); ++k)
            roles += fmt::format("{}{}:{}", k ? "," : "", json::quote(names[k]), json::quote(s.joint_names[static_cast<size_t>(h.joint[k])]));
        for (const retarget::BoneAgreement& b : r.bones)
            bones += fmt::format("{}{{\"puppet\":{},\"source\":{},\"mean_cos\":{},\"min_cos\":{}}}", bones.empty() ? "" : ",",
                                 json::quote(b.puppet_joint), json::quote(b.source_joint), json::number(b.mean_cos),
                                 json::number(b.min_cos));
        for (const std::string& n : h.notes) notes += (notes.empty() ? "" : ",") + json::quote(n);
        const char* effector_names[5] = {"head", "left_foot", "right_foot", "left_hand", "right_hand"};
        std::string effectors;
        for (size_t k = 0; k < 5; ++k)
            effectors += fmt::format("{}{}:{}", k ? "," : "", json::quote(effector_names[k]),
                                     json::quote(s.joint_names[static_cast<size_t>(h.effectors[k])]));
        fmt::print("{{\"file\":{},\"output\":{},\"frames\":{},\"frame_rate\":{},\"scale\":{},\"source_leg_length\":{},\"ground_shift_m\":{},"
                   "\"side_from\":{},\"names_agree\":{},\"effectors\":{{{}}},\"chains\":{{{}}},\"notes\":[{}],\"bones\":[{}],"
                   "\"min_mean_cos\":{},\"min_cos\":{},\"contacts\":{{\"runs\":{},\"frames\":{},\"max_drift_m\":{},\"mean_drift_m\":{},"
                   "\"max_drift_before_ik_m\":{},\"max_root_drop_m\":{}}}}}\n",
                   json::quote(o.file), json::quote(o.output_file), r.clip.frame_count, json::number(r.clip.frame_rate),
                   json::number(r.scale), json::number(h.source_leg_length), json::number(r.ground_shift_m), json::quote(h.side_from), h.names_agree ? "true" : "false",
                   effectors, roles, notes, bones, json::number(worst_mean), json::number(worst_min), r.contacts.runs,
                   r.contacts.frames, json::number(r.contacts.max_drift_m), json::number(r.contacts.mean_drift_m),
                   json::number(r.contacts.max_drift_before_ik_m), json::number(r.contacts.max_root_drop_m));
    } else {
        fmt::print("{}: humanoid found (sides from {}), {} frames at {} Hz, scale {:.4g}, pelvis lowered {:.1f} mm onto the ground\n",
                   o.file, h.side_from, r.clip.frame_count, r.clip.frame_rate, r.scale, r.ground_shift_m * 1000.0);
        for (size_t k = 0; k < r.bones.size(); ++k)
            fmt::print("{:>12} <- {:<24} mean cos {:.4f}  min {:.4f}\n", r.bones[k].puppet_joint, r.bones[k].source_joint,
                       r.bones[k].mean_cos, r.bones[k].min_cos);
        fmt::print("contacts: {} runs, {} foot-frames, drift max {:.2f} mm mean {:.2f} mm (before IK {:.1f} mm)\n",
                   r.contacts.runs, r.contacts.frames, r.contacts.max_drift_m * 1000.0, r.contacts.mean_drift_m * 1000.0,
                   r.contacts.max_drift_before_ik_m * 1000.0);
        fmt::print("wrote {}\n", o.output_file);
    }
    return 0;
}

void register_clip_commands(CLI::App& app, int& exit_code) {
    auto o = std::make_shared<ClipOptions>();
    CLI::App* clip = app.add_subcommand("clip", "Inspect motion-capture clips (BVH, ASF/AMC)");
    clip->require_subcommand(1);
    CLI::App* info = clip->add_subcommand("info", "Skeleton and frame summary");
    CLI::App* fk = clip->add_subcommand("fk", "World-space joint positions of one frame");
    for (CLI::App* c : {info, fk}) {
        c->add_option("file", o->file, "clip file (.bvh, .amc, .asf)")->required();
        c->add_option("--asf", o->asf_file, "skeleton for an AMC file");
        c->add_flag("--json", o->json, "print JSON");
    }
    fk->add_option("--frame", o->frame, "0-based frame index in the file")->required();
    on_parsed(info, exit_code, [o] { return clip_info_command(*o); });
    on_parsed(fk, exit_code, [o] { return clip_fk_command(*o); });
    CLI::App* rt = clip->add_subcommand("retarget", "Retarget a humanoid clip onto the puppet's skeleton (docs/retarget.md)");
    rt->add_option("file", o->file, "clip file (.bvh, or .amc with --asf)")->required();
    rt->add_option("--asf", o->asf_file, "skeleton for an AMC file");
    rt->add_option("--map", o->map_file, "TOML file with a [retarget] table naming source joints per puppet joint");
    rt->add_option("--config", o->config_file, "TOML file whose [gait] proportions shape the puppet");
    rt->add_option("-o,--output", o->output_file, "the BVH file to write")->required();
    rt->add_flag("--json", o->json, "print the chains found and per-bone direction agreement as JSON");
    on_parsed(rt, exit_code, [o] { return clip_retarget_command(*o); });
    register_clip_fill_commands(clip, exit_code);
}

}  // namespace marionette
