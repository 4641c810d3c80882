#include "graph_builder/key_pose_xml.hpp"

#include <fmt/format.h>
#include <libxml/parser.h>
#include <libxml/tree.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>

#include "runtime/errors/import_error.hpp"

namespace marionette::offline {

namespace {

std::string escape(const std::string& s) {
    std::string out;
    for (char c : s) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            default: out += c;
        }
    }
    return out;
}

std::string vec_text(vec3 v) { return fmt::format("{} {} {}", v.x, v.y, v.z); }

// One element being read: its attributes and numbers, errors naming the line.
struct Reader {
    const std::string& origin;

    [[noreturn]] void fail(const xmlNode* node, const std::string& message) const {
        throw ImportError(origin, node ? static_cast<int>(xmlGetLineNo(node)) : 0, message);
    }
    std::optional<std::string> attribute(const xmlNode* node, const char* name) const {
        xmlChar* value = xmlGetProp(node, reinterpret_cast<const xmlChar*>(name));
        if (!value) return std::nullopt;
        std::string out(reinterpret_cast<const char*>(value));
        xmlFree(value);
        return out;
    }
    std::string required(const xmlNode* node, const char* name) const {
        std::optional<std::string> v = attribute(node, name);
        if (!v) fail(node, fmt::format("<{}> needs the attribute {}", reinterpret_cast<const char*>(node->name), name));
        return *v;
    }
    template <typename T>
    T number(const xmlNode* node, const char* name) const {
        const std::string text = required(node, name);
        T value{};
        const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
        if (ec != std::errc() || end != text.data() + text.size() || text.empty())
            fail(node, fmt::format("<{}> attribute {}=\"{}\" is not a number", reinterpret_cast<const char*>(node->name),
                                   name, text));
        return value;
    }
    // Whitespace-separated floats of an attribute or of the element's text.
    std::vector<float> floats(const xmlNode* node, const std::string& text, const std::string& what, size_t expected) const {
        std::vector<float> out;
        const char* p = text.data();
        const char* end = text.data() + text.size();
        while (p < end) {
            while (p < end && std::strchr(" \t\r\n", *p)) ++p;
            if (p == end) break;
            float v = 0.0f;
            const auto [next, ec] = std::from_chars(p, end, v);
            if (ec != std::errc() || (next < end && !std::strchr(" \t\r\n", *next)))
                fail(node, fmt::format("{}: '{}' is not a number", what, std::string(p, std::min<size_t>(16, static_cast<size_t>(end - p)))));
            out.push_back(v);
            p = next;
        }
        if (out.size() != expected) fail(node, fmt::format("{}: expected {} numbers, found {}", what, expected, out.size()));
        return out;
    }
    vec3 vector(const xmlNode* node, const char* name) const {
        const std::vector<float> v = floats(node, required(node, name), fmt::format("attribute {}", name), 3);
        return vec3(v[0], v[1], v[2]);
    }
};

std::vector<const xmlNode*> elements(const xmlNode* parent) {
    std::vector<const xmlNode*> out;
    for (const xmlNode* n = parent->children; n; n = n->next)
        if (n->type == XML_ELEMENT_NODE) out.push_back(n);
    return out;
}

bool named(const xmlNode* n, const char* name) { return std::strcmp(reinterpret_cast<const char*>(n->name), name) == 0; }

std::string content(const xmlNode* n) {
    xmlChar* c = xmlNodeGetContent(n);
    std::string out = c ? reinterpret_cast<const char*>(c) : "";
    xmlFree(c);
    return out;
}

void read_skeleton(const Reader& r, const xmlNode* node, KeyPoseGraph& g) {
    for (const xmlNode* n : elements(node)) {
        if (named(n, "joint")) {
            const int parent = r.number<int>(n, "parent");
            const int index = g.skeleton.joint_count();
            if (parent != kNoParent && (parent < 0 || parent >= index))
                r.fail(n, fmt::format("joint {} has parent {}: expected -1 or an earlier joint (0..{})", index, parent, index - 1));
            g.skeleton.joint_names.push_back(r.required(n, "name"));
            g.skeleton.parents.push_back(parent);
            g.skeleton.rest_offsets.push_back(r.vector(n, "offset"));
            g.animated_translation.push_back(r.number<int>(n, "animated_translation") != 0);
            g.joint_weights.push_back(r.number<float>(n, "weight"));
        } else if (named(n, "end_site")) {
            const int parent = r.number<int>(n, "parent");
            if (parent < 0 || parent >= g.skeleton.joint_count())
                r.fail(n, fmt::format("end site parent {} is not a joint listed before it", parent));
            g.skeleton.end_site_parents.push_back(parent);
            g.skeleton.end_site_offsets.push_back(r.vector(n, "offset"));
        } else {
            r.fail(n, fmt::format("unexpected <{}> in <skeleton> (expected <joint> or <end_site>)", reinterpret_cast<const char*>(n->name)));
        }
    }
    if (g.skeleton.joint_count() == 0) r.fail(node, "<skeleton> has no <joint>");
}

void read_pose(const Reader& r, const xmlNode* n, KeyPoseGraph& g) {
    if (!named(n, "pose")) r.fail(n, fmt::format("unexpected <{}> in <poses> (expected <pose>)", reinterpret_cast<const char*>(n->name)));
    const int id = r.number<int>(n, "id");
    if (id != static_cast<int>(g.poses.size()))
        r.fail(n, fmt::format("pose id {}: ids must count up from 0 in order (expected {})", id, g.poses.size()));
    KeyPose pose;
    pose.clip = r.required(n, "clip");
    pose.frame = r.number<std::int32_t>(n, "frame");
    pose.speed = r.number<double>(n, "speed");
    const size_t J = static_cast<size_t>(g.skeleton.joint_count());
    bool have_rotations = false, have_translations = false;
    for (const xmlNode* c : elements(n)) {
        if (named(c, "rotations")) {
            const std::vector<float> v = r.floats(c, content(c), fmt::format("pose {} <rotations> (w x y z per joint)", id), 4 * J);
            for (size_t j = 0; j < J; ++j) pose.rotations.push_back(quat(v[4 * j], v[4 * j + 1], v[4 * j + 2], v[4 * j + 3]));
            have_rotations = true;
        } else if (named(c, "translations")) {
            const std::vector<float> v = r.floats(c, content(c), fmt::format("pose {} <translations> (x y z per joint)", id), 3 * J);
            for (size_t j = 0; j < J; ++j) pose.translations.push_back(vec3(v[3 * j], v[3 * j + 1], v[3 * j + 2]));
            have_translations = true;
        } else {
            r.fail(c, fmt::format("unexpected <{}> in <pose>", reinterpret_cast<const char*>(c->name)));
        }
    }
    if (!have_rotations || !have_translations) r.fail(n, fmt::format("pose {} needs <rotations> and <translations>", id));
    g.poses.push_back(std::move(pose));
}

void read_edges(const Reader& r, const xmlNode* node, KeyPoseGraph& g) {
    const int n_poses = static_cast<int>(g.poses.size());
    for (const xmlNode* n : elements(node)) {
        if (!named(n, "edge")) r.fail(n, fmt::format("unexpected <{}> in <edges> (expected <edge>)", reinterpret_cast<const char*>(n->name)));
        KeyPoseEdge e{r.number<std::int32_t>(n, "from"), r.number<std::int32_t>(n, "to"), r.number<double>(n, "cost")};
        for (const std::int32_t id : {e.from, e.to})
            if (id < 0 || id >= n_poses) r.fail(n, fmt::format("edge names unknown pose id {} (poses are 0..{})", id, n_poses - 1));
        if (e.from >= e.to) r.fail(n, fmt::format("edge {} → {}: from must be below to (edges are undirected, listed once)", e.from, e.to));
        if (!g.edges.empty() && !(std::pair(g.edges.back().from, g.edges.back().to) < std::pair(e.from, e.to)))
            r.fail(n, fmt::format("edge {} → {}: edges must be sorted by (from, to) without repeats", e.from, e.to));
        if (!(e.cost >= 0.0) || !std::isfinite(e.cost)) r.fail(n, fmt::format("edge {} → {}: cost must be a finite number >= 0", e.from, e.to));
        g.edges.push_back(e);
    }
}

KeyPoseGraph read_graph(const Reader& r, const xmlNode* root) {
    if (!named(root, "key_pose_graph"))
        r.fail(root, fmt::format("the root element is <{}>, expected <key_pose_graph>", reinterpret_cast<const char*>(root->name)));
    if (const int version = r.number<int>(root, "version"); version != 1)
        r.fail(root, fmt::format("key_pose_graph version {} is not supported (this build reads version 1)", version));
    KeyPoseGraph g;
    g.frame_rate = r.number<double>(root, "frame_rate");
    g.length_unit = r.number<double>(root, "length_unit");
    g.leg_length = r.number<double>(root, "leg_length");
    g.thin_threshold = r.number<double>(root, "thin_threshold");
    g.link_threshold = r.number<double>(root, "link_threshold");
    g.step = r.number<double>(root, "step");
    const xmlNode *skeleton = nullptr, *poses = nullptr, *edges = nullptr;
    for (const xmlNode* n : elements(root)) {
        const xmlNode** slot = named(n, "skeleton") ? &skeleton : named(n, "poses") ? &poses : named(n, "edges") ? &edges : nullptr;
        if (!slot) r.fail(n, fmt::format("unexpected <{}> in <key_pose_graph> (expected <skeleton>, <poses>, <edges>)", reinterpret_cast<const char*>(n->name)));
        if (*slot) r.fail(n, fmt::format("a second <{}>", reinterpret_cast<const char*>(n->name)));
        *slot = n;
    }
    if (!skeleton) r.fail(root, "<key_pose_graph> has no <skeleton>");
    if (!poses) r.fail(root, "<key_pose_graph> has no <poses>");
    read_skeleton(r, skeleton, g);
    for (const xmlNode* n : elements(poses)) read_pose(r, n, g);
    if (edges) read_edges(r, edges, g);
    if (const Outcome o = validate_key_pose_graph(g); !o.ok()) r.fail(root, o.problem());
    if (!edges) link_key_poses(g);
    return g;
}

}  // namespace

std::string write_key_pose_xml(const KeyPoseGraph& g) {
    std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    out += fmt::format(
        "<key_pose_graph version=\"1\" frame_rate=\"{}\" length_unit=\"{}\" leg_length=\"{}\" thin_threshold=\"{}\" "
        "link_threshold=\"{}\" step=\"{}\">\n  <skeleton>\n",
        g.frame_rate, g.length_unit, g.leg_length, g.thin_threshold, g.link_threshold, g.step);
    const size_t J = static_cast<size_t>(g.skeleton.joint_count());
    for (size_t j = 0; j < J; ++j)
        out += fmt::format("    <joint name=\"{}\" parent=\"{}\" offset=\"{}\" animated_translation=\"{}\" weight=\"{}\"/>\n",
                           escape(g.skeleton.joint_names[j]), g.skeleton.parents[j], vec_text(g.skeleton.rest_offsets[j]),
                           g.animated_translation[j] ? 1 : 0, g.joint_weights[j]);
    for (size_t e = 0; e < g.skeleton.end_site_parents.size(); ++e)
        out += fmt::format("    <end_site parent=\"{}\" offset=\"{}\"/>\n", g.skeleton.end_site_parents[e],
                           vec_text(g.skeleton.end_site_offsets[e]));
    out += "  </skeleton>\n  <poses>\n";
    for (size_t p = 0; p < g.poses.size(); ++p) {
        const KeyPose& k = g.poses[p];
        out += fmt::format("    <pose id=\"{}\" clip=\"{}\" frame=\"{}\" speed=\"{}\">\n      <rotations>", p, escape(k.clip),
                           k.frame, k.speed);
        for (size_t j = 0; j < J; ++j) {
            const quat q = k.rotations[j];
            out += fmt::format("{}{} {} {} {}", j ? " " : "", q.w, q.x, q.y, q.z);
        }
        out += "</rotations>\n      <translations>";
        for (size_t j = 0; j < J; ++j) out += (j ? " " : "") + vec_text(k.translations[j]);
        out += "</translations>\n    </pose>\n";
    }
    out += "  </poses>\n  <edges>\n";
    for (const KeyPoseEdge& e : g.edges) out += fmt::format("    <edge from=\"{}\" to=\"{}\" cost=\"{}\"/>\n", e.from, e.to, e.cost);
    return out + "  </edges>\n</key_pose_graph>\n";
}

KeyPoseGraph parse_key_pose_xml(const std::string& text, const std::string& origin) {
    if (text.size() > static_cast<size_t>(std::numeric_limits<int>::max()))
        throw ImportError(origin, 0, "the file is larger than 2 GiB, more than the XML reader takes");
    const std::unique_ptr<xmlParserCtxt, void (*)(xmlParserCtxtPtr)> context(xmlNewParserCtxt(), xmlFreeParserCtxt);
    if (!context) throw ImportError(origin, 0, "cannot create an XML parser (out of memory)");
    const std::unique_ptr<xmlDoc, void (*)(xmlDocPtr)> doc(
        xmlCtxtReadMemory(context.get(), text.data(), static_cast<int>(text.size()), origin.c_str(), nullptr,
                          XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING),
        xmlFreeDoc);
    if (!doc) {
        const xmlError* e = xmlCtxtGetLastError(context.get());
        std::string message = e && e->message ? e->message : "not well-formed XML";
        while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
        throw ImportError(origin, e ? e->line : 0, "malformed XML: " + message);
    }
    const xmlNode* root = xmlDocGetRootElement(doc.get());
    if (!root) throw ImportError(origin, 0, "the XML document has no root element");
    return read_graph(Reader{origin}, root);
}

}  // namespace marionette::offline
