#pragma once
// Key-pose graphs as XML (libxml2; the format is documented in
// docs/motion-graph.md, "Key-pose graphs"). Numbers are written in their
// shortest round-trip form, so writing what was read gives the same text.
#include <string>

#include "graph_builder/key_pose_graph.hpp"

namespace marionette::offline {

std::string write_key_pose_xml(const KeyPoseGraph& g);

// Throws ImportError naming `origin`, the line and what is wrong: malformed XML
// (libxml2's message), a missing or malformed element or attribute, an edge
// naming an unknown pose id. A file without <edges> gets its edges computed from
// its poses and link_threshold (link_key_poses).
KeyPoseGraph parse_key_pose_xml(const std::string& text, const std::string& origin);

}  // namespace marionette::offline
