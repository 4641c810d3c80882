#pragma once
// Shared check for the sliced path query (GraphPathSearch::begin/advance): for
// every start node and every label of a graph, slices of each budget reach the
// one-shot run()'s answer bit for bit (status, goal, cost, path), and a query
// re-derived by popping the same count again stands where the sliced one stood.
#include <catch2/catch.hpp>

#include <cstring>
#include <vector>

#include "runtime/graph/graph_path.hpp"

namespace marionette::test {

struct SlicedQueryStats {
    std::int64_t queries = 0, found = 0, max_pops = 0, max_path_edges = 0;
};

inline bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

inline SlicedQueryStats check_sliced_queries(const MotionGraph& g, std::vector<int> budgets, int node_stride = 1) {
    SlicedQueryStats stats;
    GraphPathSearch one_shot(g, 1.0), sliced(g, 1.0), replayed(g, 1.0);
    for (size_t label = 0; label < g.labels.size(); ++label) {
        for (GraphPathSearch* s : {&one_shot, &sliced, &replayed}) s->clear_goals(), s->add_label_goal(static_cast<int>(label));
        for (size_t start = 0; start < g.nodes.size(); start += static_cast<size_t>(node_stride)) {
            const int from = static_cast<int>(start);
            const bool found = one_shot.run(from);
            const std::vector<std::int32_t> path(one_shot.path().begin(), one_shot.path().end());
            ++stats.queries;
            stats.found += found;
            stats.max_pops = std::max(stats.max_pops, one_shot.pops());
            stats.max_path_edges = std::max(stats.max_path_edges, static_cast<std::int64_t>(path.size()));
            if (found) {  // the path runs from the start to a node of a clip with the label
                int at = from;
                for (const std::int32_t e : path) {
                    REQUIRE(g.edges[static_cast<size_t>(e)].from == at);
                    at = g.edges[static_cast<size_t>(e)].to;
                }
                CHECK(at == one_shot.goal_node());
                CHECK(((g.clips[static_cast<size_t>(g.nodes[static_cast<size_t>(at)].clip)].label_mask >> label) & 1u) == 1u);
            }
            for (const int budget : budgets) {
                sliced.begin(from);
                std::int64_t slices = 0;
                while (sliced.advance(budget) == PathSearchStatus::running) {
                    ++slices;
                    // A second search popping the same count from scratch stands where this one does.
                    if (slices % 3 == 1) {
                        replayed.begin(from);
                        REQUIRE(replayed.advance(sliced.pops()) == PathSearchStatus::running);
                        REQUIRE(replayed.pops() == sliced.pops());
                    }
                    REQUIRE(slices <= one_shot.pops() + 1);
                }
                INFO("label " << g.labels[label] << " from node " << from << " budget " << budget);
                REQUIRE(sliced.status() == (found ? PathSearchStatus::found : PathSearchStatus::unreachable));
                CHECK(sliced.pops() == one_shot.pops());
                CHECK(sliced.settled_nodes() == one_shot.settled_nodes());
                if (!found) continue;
                CHECK(sliced.goal_node() == one_shot.goal_node());
                CHECK(same_bits(sliced.cost(), one_shot.cost()));
                CHECK(std::vector<std::int32_t>(sliced.path().begin(), sliced.path().end()) == path);
            }
        }
    }
    return stats;
}

}  // namespace marionette::test
