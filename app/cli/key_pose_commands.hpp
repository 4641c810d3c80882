#pragma once
// Key-pose graphs on the command line (graph_builder/key_pose_graph.hpp,
// docs/motion-graph.md "Key-pose graphs"): `graph build --key-poses`,
// `graph build --from-xml`, `graph path` on a key-pose graph, `graph export --xml`.
// graph_commands.cpp owns the options and dispatches here.
#include <string>
#include <vector>

namespace marionette {

struct KeyPoseBuildOptions {
    std::string asf_file;
    std::vector<std::string> clip_files;
    std::string labels_file;
    std::string config_file;
    std::string from_xml;        // --from-xml: read the graph instead of building it
    std::string output_file;
    bool keep_skeleton = false;
    bool json = false;
    double thin = 0.0, link = 0.0;  // absolute thresholds (0: percentiles)
    double thin_percentile = 2.0, link_percentile = 20.0;
};

struct KeyPosePathOptions {
    std::string graph_file;
    std::string from, to;        // pose id or CLIP:FRAME
    std::string bvh_file;
    bool json = false;
};

// True when the file holds a key-pose graph (XML) rather than a .mgraph.
bool is_key_pose_graph_file(const std::string& path);

int key_pose_build_command(const KeyPoseBuildOptions& o);
int key_pose_path_command(const KeyPosePathOptions& o);
int key_pose_export_command(const std::string& graph_file, const std::string& xml_file);

}  // namespace marionette
