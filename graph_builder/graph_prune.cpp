#include "graph_builder/graph_prune.hpp"

#include <algorithm>
#include <limits>

namespace marionette {

// ---- Tarjan ------------------------------------------------------------------------

SccResult strongly_connected_components(std::span<const std::int32_t> begin, std::span<const std::int32_t> targets) {
    const size_t n = begin.empty() ? 0 : begin.size() - 1;
    constexpr std::int32_t kUnvisited = -1;
    SccResult out;
    out.component.assign(n, -1);
    std::vector<std::int32_t> index(n, kUnvisited), low(n, 0);
    std::vector<std::int32_t> stack;         // Tarjan's node stack
    std::vector<bool> on_stack(n, false);
    struct Frame {
        std::int32_t node;
        std::int32_t next_edge;
    };
    std::vector<Frame> call;                 // the explicit call stack
    std::int32_t counter = 0;
    for (size_t root = 0; root < n; ++root) {
        if (index[root] != kUnvisited) continue;
        call.push_back({static_cast<std::int32_t>(root), begin[root]});
        index[root] = low[root] = counter++;
        stack.push_back(static_cast<std::int32_t>(root));
        on_stack[root] = true;
        while (!call.empty()) {
            Frame& f = call.back();
            const size_t v = static_cast<size_t>(f.node);
            if (f.next_edge < begin[v + 1]) {
                const size_t w = static_cast<size_t>(targets[static_cast<size_t>(f.next_edge++)]);
                if (index[w] == kUnvisited) {
                    index[w] = low[w] = counter++;
                    stack.push_back(static_cast<std::int32_t>(w));
                    on_stack[w] = true;
                    call.push_back({static_cast<std::int32_t>(w), begin[w]});  // invalidates f
                } else if (on_stack[w]) {
                    low[v] = std::min(low[v], index[w]);
                }
                continue;
            }
            // v is finished: close its component if it is a root, then return to the caller.
            if (low[v] == index[v]) {
                std::int32_t w = -1;
                do {
                    w = stack.back();
                    stack.pop_back();
                    on_stack[static_cast<size_t>(w)] = false;
                    out.component[static_cast<size_t>(w)] = out.count;
                } while (static_cast<size_t>(w) != v);
                ++out.count;
            }
            call.pop_back();
            if (!call.empty()) {
                const size_t parent = static_cast<size_t>(call.back().node);
                low[parent] = std::min(low[parent], low[v]);
            }
        }
    }
    return out;
}

PruneReport prune_to_largest_component(MotionGraph& g) {
    index_edges(g);
    PruneReport report;
    report.nodes_before = static_cast<std::int64_t>(g.nodes.size());
    report.edges_before = static_cast<std::int64_t>(g.edges.size());
    std::vector<std::int32_t> targets(g.edges.size());
    for (size_t e = 0; e < g.edges.size(); ++e) targets[e] = g.edges[e].to;
    const SccResult scc = strongly_connected_components(g.edge_begin, targets);
    report.component_count = scc.count;

    // Largest by frames on internal clip edges (the motion it keeps), ties by node count, then lowest id.
    std::vector<std::int64_t> frames(static_cast<size_t>(scc.count), 0), sizes(static_cast<size_t>(scc.count), 0);
    for (size_t n = 0; n < g.nodes.size(); ++n) ++sizes[static_cast<size_t>(scc.component[n])];
    for (const GraphEdge& e : g.edges) {
        const std::int32_t c = scc.component[static_cast<size_t>(e.from)];
        if (e.kind == GraphEdgeKind::clip && c == scc.component[static_cast<size_t>(e.to)])
            frames[static_cast<size_t>(c)] += e.frames;
    }
    std::int32_t best = -1;
    for (std::int32_t c = 0; c < scc.count; ++c) {
        const size_t u = static_cast<size_t>(c);
        if (sizes[u] < 2 && frames[u] == 0) continue;  // a lone node with no cycle is no component to keep
        if (best < 0 || frames[u] > frames[static_cast<size_t>(best)] ||
            (frames[u] == frames[static_cast<size_t>(best)] && sizes[u] > sizes[static_cast<size_t>(best)]))
            best = c;
    }

    // Per clip: transitions out of and into it, before pruning (for the label report).
    std::vector<int> trans_out(g.clips.size(), 0), trans_in(g.clips.size(), 0);
    for (const GraphEdge& e : g.edges)
        if (e.kind == GraphEdgeKind::transition) {
            ++trans_out[static_cast<size_t>(g.nodes[static_cast<size_t>(e.from)].clip)];
            ++trans_in[static_cast<size_t>(g.nodes[static_cast<size_t>(e.to)].clip)];
        }

    std::vector<std::int32_t> renumber(g.nodes.size(), -1);
    std::vector<GraphNode> nodes;
    for (size_t n = 0; n < g.nodes.size(); ++n)
        if (best >= 0 && scc.component[n] == best) {
            renumber[n] = static_cast<std::int32_t>(nodes.size());
            nodes.push_back(g.nodes[n]);
        }
    std::vector<GraphEdge> edges;
    for (GraphEdge e : g.edges) {
        const std::int32_t a = renumber[static_cast<size_t>(e.from)], b = renumber[static_cast<size_t>(e.to)];
        if (a < 0 || b < 0) continue;
        e.from = a;
        e.to = b;
        edges.push_back(e);
    }
    g.nodes = std::move(nodes);
    g.edges = std::move(edges);
    index_edges(g);
    report.nodes = static_cast<std::int64_t>(g.nodes.size());
    report.edges = static_cast<std::int64_t>(g.edges.size());

    std::vector<bool> clip_kept(g.clips.size(), false);
    for (const GraphEdge& e : g.edges)
        if (e.kind == GraphEdgeKind::clip) clip_kept[static_cast<size_t>(g.nodes[static_cast<size_t>(e.from)].clip)] = true;
    for (size_t l = 0; l < g.labels.size(); ++l) {
        LabelReachability r;
        r.label = g.labels[l];
        int out_total = 0, in_total = 0;
        for (size_t c = 0; c < g.clips.size(); ++c) {
            if (!(g.clips[c].label_mask & (1u << l))) continue;
            ++r.clips;
            if (clip_kept[c]) ++r.clips_kept;
            out_total += trans_out[c];
            in_total += trans_in[c];
        }
        if (r.clips == 0) continue;
        if (r.clips_kept == 0) {
            if (out_total == 0 && in_total == 0) r.reason = "no transition leaves or enters its clips (threshold too low?)";
            else if (out_total == 0) r.reason = "transitions enter its clips but none leaves them back to the component";
            else if (in_total == 0) r.reason = "transitions leave its clips but none from the component enters them";
            else
                r.reason = "its clips' " + std::to_string(in_total) + " incoming and " + std::to_string(out_total) +
                           " outgoing transitions join a smaller component, not the largest";
        }
        report.labels.push_back(std::move(r));
    }
    return report;
}

std::vector<std::string> kept_clip_names(const MotionGraph& g) {
    std::vector<bool> kept(g.clips.size(), false);
    for (const GraphEdge& e : g.edges)
        if (e.kind == GraphEdgeKind::clip) kept[static_cast<size_t>(g.nodes[static_cast<size_t>(e.from)].clip)] = true;
    std::vector<std::string> out;
    for (size_t c = 0; c < g.clips.size(); ++c)
        if (kept[c]) out.push_back(g.clips[c].name);
    return out;
}
}  // namespace marionette
