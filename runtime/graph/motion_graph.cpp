#include "runtime/graph/motion_graph.hpp"

#include <xxhash.h>

#include <algorithm>
#include <cstring>
#include <limits>

#include "runtime/errors/import_error.hpp"

namespace marionette {

int MotionGraph::label_index(const std::string& label) const {
    for (size_t i = 0; i < labels.size(); ++i)
        if (labels[i] == label) return static_cast<int>(i);
    return -1;
}

int MotionGraph::clip_index(const std::string& name) const {
    for (size_t i = 0; i < clips.size(); ++i)
        if (clips[i].name == name) return static_cast<int>(i);
    return -1;
}

void index_edges(MotionGraph& g) {
    std::stable_sort(g.edges.begin(), g.edges.end(), [](const GraphEdge& a, const GraphEdge& b) {
        return a.from != b.from ? a.from < b.from : a.to < b.to;
    });
    g.edge_begin.assign(g.nodes.size() + 1, 0);
    for (const GraphEdge& e : g.edges) ++g.edge_begin[static_cast<size_t>(e.from) + 1];
    for (size_t n = 0; n < g.nodes.size(); ++n) g.edge_begin[n + 1] += g.edge_begin[n];
}

Outcome validate_motion_graph(const MotionGraph& g) {
    if (Outcome skeleton = validate_skeleton(g.skeleton); !skeleton.ok())
        return Outcome::failure("skeleton: " + skeleton.problem());
    const size_t joints = static_cast<size_t>(g.joint_count());
    if (g.animated_translation.size() != joints) return Outcome::failure("animated_translation needs one flag per joint");
    if (!(g.frame_rate > 0.0)) return Outcome::failure("frame rate must be positive");
    if (g.window_frames < 1) return Outcome::failure("window must be at least one frame");
    if (g.labels.size() > static_cast<size_t>(kMaxGraphLabels)) return Outcome::failure("more than 32 labels");
    const size_t frames = g.contacts.size();
    if (g.rotations.size() != frames * joints || g.translations.size() != frames * joints)
        return Outcome::failure("frame arrays do not hold frames × joints entries");
    std::int64_t next_first = 0;
    for (const GraphClip& c : g.clips) {
        if (c.first_frame != next_first || c.frame_count < 1) return Outcome::failure("clip '" + c.name + "' frames are not contiguous");
        next_first += c.frame_count;
    }
    if (static_cast<size_t>(next_first) != frames) return Outcome::failure("clips do not cover the frame arrays");
    for (const GraphNode& n : g.nodes) {
        if (n.clip < 0 || static_cast<size_t>(n.clip) >= g.clips.size()) return Outcome::failure("node with an invalid clip");
        if (n.frame < 0 || n.frame >= g.clips[static_cast<size_t>(n.clip)].frame_count) return Outcome::failure("node frame out of range");
    }
    if (g.edge_begin.size() != g.nodes.size() + 1) return Outcome::failure("edge index does not match the nodes");
    for (size_t i = 0; i < g.edges.size(); ++i) {
        const GraphEdge& e = g.edges[i];
        if (e.from < 0 || e.to < 0 || static_cast<size_t>(e.from) >= g.nodes.size() ||
            static_cast<size_t>(e.to) >= g.nodes.size())
            return Outcome::failure("edge " + std::to_string(i) + " names a missing node");
        if (i > 0 && g.edges[i - 1].from > e.from) return Outcome::failure("edges are not sorted by source");
        const GraphNode& a = g.nodes[static_cast<size_t>(e.from)];
        const GraphNode& b = g.nodes[static_cast<size_t>(e.to)];
        if (e.kind == GraphEdgeKind::clip) {
            if (a.clip != b.clip || b.frame <= a.frame || e.frames != b.frame - a.frame)
                return Outcome::failure("clip edge " + std::to_string(i) + " does not run forward inside one clip");
        } else if (e.kind == GraphEdgeKind::transition) {
            if (e.frames != g.window_frames) return Outcome::failure("transition edge " + std::to_string(i) + " is not k frames long");
            // In 64 bits: a file's window may be up to 2^31 - 1 (an int sum would overflow).
            if (static_cast<std::int64_t>(a.frame) + g.window_frames > g.clips[static_cast<size_t>(a.clip)].frame_count ||
                b.frame < g.window_frames)
                return Outcome::failure("transition edge " + std::to_string(i) + " runs past its clips");
        } else {
            return Outcome::failure("edge " + std::to_string(i) + " has an unknown kind");
        }
    }
    for (size_t n = 0; n < g.nodes.size(); ++n)
        if (g.edge_begin[n] > g.edge_begin[n + 1]) return Outcome::failure("edge index is not monotonic");
    if (!g.edge_begin.empty() && static_cast<size_t>(g.edge_begin.back()) != g.edges.size())
        return Outcome::failure("edge index does not cover the edges");
    return Outcome::success();
}

// ---- serialisation ---------------------------------------------------------------

namespace {

constexpr char kMagic[8] = {'M', 'G', 'R', 'A', 'P', 'H', '\r', '\n'};
constexpr size_t kHeaderSize = 8 + 4 + 4 + 8 + 8 + 8;  // magic, version, flags, source hash, payload size, payload hash

class Writer {
public:
    std::vector<std::uint8_t> bytes;
    template <typename T>
    void put(T v) {
        static_assert(std::is_trivially_copyable_v<T>);
        std::uint8_t b[sizeof(T)];
        std::memcpy(b, &v, sizeof(T));  // little-endian hosts only (checked in the reader's tests)
        bytes.insert(bytes.end(), b, b + sizeof(T));
    }
    void put_string(const std::string& s) {
        put(static_cast<std::uint32_t>(s.size()));
        bytes.insert(bytes.end(), s.begin(), s.end());
    }
    void put_vec3(vec3 v) { put(v.x), put(v.y), put(v.z); }
};

class Reader {
public:
    Reader(std::span<const std::uint8_t> b, const std::string& file, size_t base) : bytes_(b), file_(file), base_(base) {}
    template <typename T>
    T get(const char* what) {
        need(sizeof(T), what);
        T v;
        std::memcpy(&v, bytes_.data() + pos_, sizeof(T));
        pos_ += sizeof(T);
        return v;
    }
    std::string get_string(const char* what) {
        const auto n = get<std::uint32_t>(what);
        need(n, what);
        std::string s(reinterpret_cast<const char*>(bytes_.data() + pos_), n);
        pos_ += n;
        return s;
    }
    vec3 get_vec3(const char* what) {
        const float x = get<float>(what), y = get<float>(what), z = get<float>(what);
        return vec3(x, y, z);
    }
    // A count of items of `item_size` bytes each that must fit in what is left.
    std::uint32_t get_count(const char* what, size_t item_size) {
        const size_t at = pos_;
        const auto n = get<std::uint32_t>(what);
        if (static_cast<std::uint64_t>(n) * item_size > bytes_.size() - pos_)
            fail(at, std::string(what) + " count " + std::to_string(n) + " does not fit in the file");
        return n;
    }
    [[noreturn]] void fail(size_t at, const std::string& message) const {
        throw import_error_at_byte(file_, static_cast<std::int64_t>(base_ + at), message);
    }
    size_t pos() const { return pos_; }
    bool at_end() const { return pos_ == bytes_.size(); }

private:
    void need(size_t n, const char* what) {
        if (bytes_.size() - pos_ < n) fail(pos_, std::string("file ends inside ") + what);
    }
    std::span<const std::uint8_t> bytes_;
    const std::string& file_;
    size_t base_;
    size_t pos_ = 0;
};

void check_header(std::span<const std::uint8_t> bytes, const std::string& file, std::uint64_t& source_hash,
                  std::uint64_t& payload_size, std::uint64_t& payload_hash) {
    Reader r(bytes, file, 0);
    if (bytes.size() < 8 || std::memcmp(bytes.data(), kMagic, 8) != 0)
        r.fail(0, "not a motion graph: expected the .mgraph magic 'MGRAPH\\r\\n'");
    for (int i = 0; i < 8; ++i) r.get<char>("magic");
    const auto version = r.get<std::uint32_t>("header");
    if (version != kMotionGraphVersion)
        r.fail(8, "unsupported .mgraph version " + std::to_string(version) + " (this build reads version " +
                      std::to_string(kMotionGraphVersion) + "; rebuild the graph)");
    const auto flags = r.get<std::uint32_t>("header");
    if (flags != 0) r.fail(12, "unknown header flags " + std::to_string(flags) + " (expected 0)");
    source_hash = r.get<std::uint64_t>("header");
    payload_size = r.get<std::uint64_t>("header");
    payload_hash = r.get<std::uint64_t>("header");
    if (payload_size != bytes.size() - kHeaderSize)
        r.fail(24, "payload size " + std::to_string(payload_size) + " does not match the file (" +
                       std::to_string(bytes.size() - kHeaderSize) + " bytes after the header): truncated or padded");
}

}  // namespace

std::vector<std::uint8_t> serialize_motion_graph(const MotionGraph& g) {
    Writer w;
    w.put_string(g.source_asf);
    w.put(static_cast<std::uint32_t>(g.source_clips.size()));
    for (const std::string& s : g.source_clips) w.put_string(s);
    w.put_string(g.source_labels);

    w.put(g.frame_rate);
    w.put(g.window_frames);
    w.put(g.length_unit);
    w.put(g.leg_length);
    w.put(g.left_foot);
    w.put(g.right_foot);

    const Skeleton& s = g.skeleton;
    w.put(static_cast<std::uint32_t>(s.joint_count()));
    for (int j = 0; j < s.joint_count(); ++j) {
        const size_t u = static_cast<size_t>(j);
        w.put_string(s.joint_names[u]);
        w.put(static_cast<std::int32_t>(s.parents[u]));
        w.put_vec3(s.rest_offsets[u]);
        w.put(static_cast<std::uint8_t>(g.animated_translation[u] ? 1 : 0));
    }
    w.put(static_cast<std::uint32_t>(s.end_site_parents.size()));
    for (size_t e = 0; e < s.end_site_parents.size(); ++e) {
        w.put(static_cast<std::int32_t>(s.end_site_parents[e]));
        w.put_vec3(s.end_site_offsets[e]);
    }

    w.put(static_cast<std::uint32_t>(g.labels.size()));
    for (const std::string& l : g.labels) w.put_string(l);
    w.put(static_cast<std::uint32_t>(g.clips.size()));
    for (const GraphClip& c : g.clips) {
        w.put_string(c.name);
        w.put(c.label_mask);
        w.put(c.first_frame);
        w.put(c.frame_count);
    }

    w.put(static_cast<std::uint32_t>(g.contacts.size()));
    for (const quat& q : g.rotations) w.put(q.w), w.put(q.x), w.put(q.y), w.put(q.z);
    for (const vec3& t : g.translations) w.put_vec3(t);
    for (std::uint8_t c : g.contacts) w.put(c);

    w.put(static_cast<std::uint32_t>(g.nodes.size()));
    for (const GraphNode& n : g.nodes) w.put(n.clip), w.put(n.frame);
    w.put(static_cast<std::uint32_t>(g.edges.size()));
    for (const GraphEdge& e : g.edges) {
        w.put(e.from), w.put(e.to), w.put(static_cast<std::uint8_t>(e.kind)), w.put(e.frames);
        w.put(e.cost), w.put(e.align_angle), w.put(e.align_dx), w.put(e.align_dz);
    }

    const GraphBuildStats& st = g.stats;
    w.put(st.frames), w.put(st.pair_evaluations), w.put(st.candidates), w.put(st.nodes_before);
    w.put(st.edges_before), w.put(st.frames_kept), w.put(st.threshold), w.put(st.build_seconds);

    Writer out;
    for (char c : kMagic) out.put(c);
    out.put(kMotionGraphVersion);
    out.put(std::uint32_t{0});
    out.put(g.source_hash);
    out.put(static_cast<std::uint64_t>(w.bytes.size()));
    out.put(static_cast<std::uint64_t>(XXH64(w.bytes.data(), w.bytes.size(), 0)));
    out.bytes.insert(out.bytes.end(), w.bytes.begin(), w.bytes.end());
    return out.bytes;
}

std::uint64_t motion_graph_source_hash(std::span<const std::uint8_t> bytes, const std::string& file) {
    std::uint64_t source = 0, size = 0, hash = 0;
    check_header(bytes, file, source, size, hash);
    return source;
}

MotionGraph deserialize_motion_graph(std::span<const std::uint8_t> bytes, const std::string& file) {
    MotionGraph g;
    std::uint64_t payload_size = 0, payload_hash = 0;
    check_header(bytes, file, g.source_hash, payload_size, payload_hash);
    const std::span<const std::uint8_t> payload = bytes.subspan(kHeaderSize);
    if (XXH64(payload.data(), payload.size(), 0) != payload_hash)
        throw import_error_at_byte(file, static_cast<std::int64_t>(kHeaderSize),
                                   "payload checksum mismatch: the file is damaged");
    Reader r(payload, file, kHeaderSize);

    g.source_asf = r.get_string("sources");
    const std::uint32_t source_count = r.get_count("source clips", 4);
    for (std::uint32_t i = 0; i < source_count; ++i) g.source_clips.push_back(r.get_string("sources"));
    g.source_labels = r.get_string("sources");

    g.frame_rate = r.get<double>("parameters");
    g.window_frames = r.get<std::int32_t>("parameters");
    g.length_unit = r.get<double>("parameters");
    g.leg_length = r.get<float>("parameters");
    g.left_foot = r.get<std::int32_t>("parameters");
    g.right_foot = r.get<std::int32_t>("parameters");

    const std::uint32_t joints = r.get_count("joints", 21);
    for (std::uint32_t j = 0; j < joints; ++j) {
        g.skeleton.joint_names.push_back(r.get_string("joint"));
        g.skeleton.parents.push_back(r.get<std::int32_t>("joint"));
        g.skeleton.rest_offsets.push_back(r.get_vec3("joint"));
        g.animated_translation.push_back(r.get<std::uint8_t>("joint") != 0);
    }
    const std::uint32_t end_sites = r.get_count("end sites", 16);
    for (std::uint32_t e = 0; e < end_sites; ++e) {
        g.skeleton.end_site_parents.push_back(r.get<std::int32_t>("end site"));
        g.skeleton.end_site_offsets.push_back(r.get_vec3("end site"));
    }

    const std::uint32_t labels = r.get_count("labels", 4);
    for (std::uint32_t i = 0; i < labels; ++i) g.labels.push_back(r.get_string("label"));
    const std::uint32_t clips = r.get_count("clips", 16);
    for (std::uint32_t i = 0; i < clips; ++i) {
        GraphClip c;
        c.name = r.get_string("clip");
        c.label_mask = r.get<std::uint32_t>("clip");
        c.first_frame = r.get<std::int32_t>("clip");
        c.frame_count = r.get<std::int32_t>("clip");
        g.clips.push_back(std::move(c));
    }

    const size_t frame_bytes = static_cast<size_t>(joints) * 28 + 1;
    const std::uint32_t frames = r.get_count("frames", frame_bytes);
    const size_t samples = static_cast<size_t>(frames) * joints;
    g.rotations.resize(samples);
    g.translations.resize(samples);
    g.contacts.resize(frames);
    for (quat& q : g.rotations) {
        const float w = r.get<float>("rotations"), x = r.get<float>("rotations"), y = r.get<float>("rotations"),
                    z = r.get<float>("rotations");
        q = quat(w, x, y, z);
    }
    for (vec3& t : g.translations) t = r.get_vec3("translations");
    for (std::uint8_t& c : g.contacts) c = r.get<std::uint8_t>("contacts");

    const std::uint32_t nodes = r.get_count("nodes", 8);
    g.nodes.resize(nodes);
    for (GraphNode& n : g.nodes) n.clip = r.get<std::int32_t>("nodes"), n.frame = r.get<std::int32_t>("nodes");
    const size_t edges_at = r.pos();
    const std::uint32_t edges = r.get_count("edges", 29);
    g.edges.resize(edges);
    for (GraphEdge& e : g.edges) {
        e.from = r.get<std::int32_t>("edges");
        e.to = r.get<std::int32_t>("edges");
        e.kind = static_cast<GraphEdgeKind>(r.get<std::uint8_t>("edges"));
        e.frames = r.get<std::int32_t>("edges");
        e.cost = r.get<float>("edges");
        e.align_angle = r.get<float>("edges");
        e.align_dx = r.get<float>("edges");
        e.align_dz = r.get<float>("edges");
    }
    GraphBuildStats& st = g.stats;
    st.frames = r.get<std::int64_t>("statistics");
    st.pair_evaluations = r.get<std::int64_t>("statistics");
    st.candidates = r.get<std::int64_t>("statistics");
    st.nodes_before = r.get<std::int64_t>("statistics");
    st.edges_before = r.get<std::int64_t>("statistics");
    st.frames_kept = r.get<std::int64_t>("statistics");
    st.threshold = r.get<double>("statistics");
    st.build_seconds = r.get<double>("statistics");
    if (!r.at_end()) r.fail(r.pos(), "unexpected bytes after the statistics section");

    // Edge index: edges are stored sorted by source, so counting rebuilds it.
    g.edge_begin.assign(g.nodes.size() + 1, 0);
    for (const GraphEdge& e : g.edges) {
        if (e.from < 0 || static_cast<std::uint32_t>(e.from) >= nodes)
            r.fail(edges_at, "an edge names node " + std::to_string(e.from) + " of " + std::to_string(nodes));
        ++g.edge_begin[static_cast<size_t>(e.from) + 1];
    }
    for (size_t n = 0; n < g.nodes.size(); ++n) g.edge_begin[n + 1] += g.edge_begin[n];
    if (const Outcome valid = validate_motion_graph(g); !valid.ok()) r.fail(0, "inconsistent graph: " + valid.problem());
    return g;
}

}  // namespace marionette
