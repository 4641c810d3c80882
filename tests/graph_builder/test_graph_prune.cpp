// Offline pruning: Tarjan's components and keeping the largest one.
#include <catch2/catch.hpp>

#include <algorithm>
#include <vector>

#include "graph_builder/graph_prune.hpp"
#include "tests/runtime/graph/small_graph.hpp"

using namespace marionette;
using marionette::test::small_graph;

namespace {

// CSR from an edge list.
void to_csr(int n, const std::vector<std::pair<int, int>>& edges, std::vector<std::int32_t>& begin,
            std::vector<std::int32_t>& targets) {
    begin.assign(static_cast<size_t>(n) + 1, 0);
    for (auto [a, b] : edges) ++begin[static_cast<size_t>(a) + 1];
    for (int i = 0; i < n; ++i) begin[static_cast<size_t>(i) + 1] += begin[static_cast<size_t>(i)];
    targets.assign(edges.size(), 0);
    std::vector<std::int32_t> fill(begin.begin(), begin.end() - 1);
    for (auto [a, b] : edges) targets[static_cast<size_t>(fill[static_cast<size_t>(a)]++)] = b;
}

}  // namespace

TEST_CASE("Tarjan finds known components", "[graph][scc]") {
    std::vector<std::int32_t> begin, targets;
    // 0→1→2→0 (one component), 2→3, 3→4→3 (another), 5 alone.
    to_csr(6, {{0, 1}, {1, 2}, {2, 0}, {2, 3}, {3, 4}, {4, 3}}, begin, targets);
    const SccResult r = strongly_connected_components(begin, targets);
    CHECK(r.count == 3);  // {0,1,2}, {3,4}, {5}
    CHECK(r.component[0] == r.component[1]);
    CHECK(r.component[1] == r.component[2]);
    CHECK(r.component[3] == r.component[4]);
    CHECK(r.component[0] != r.component[3]);
    CHECK(r.component[5] != r.component[0]);
    CHECK(r.component[5] != r.component[3]);
    // Reverse topological completion: the sink component {3,4} closes before {0,1,2}.
    CHECK(r.component[3] < r.component[0]);
}

TEST_CASE("Tarjan handles a 1 000 000-node chain and cycle without recursion", "[graph][scc]") {
    const int n = 1000000;
    std::vector<std::int32_t> begin(static_cast<size_t>(n) + 1), targets(static_cast<size_t>(n) - 1);
    for (int i = 0; i <= n; ++i) begin[static_cast<size_t>(i)] = std::min(i, n - 1);
    for (int i = 0; i + 1 < n; ++i) targets[static_cast<size_t>(i)] = i + 1;
    const SccResult chain = strongly_connected_components(begin, targets);
    CHECK(chain.count == n);
    CHECK(chain.component[static_cast<size_t>(n - 1)] == 0);  // the deepest node completes first
    // Close the chain into one cycle: a single component.
    for (int i = 0; i <= n; ++i) begin[static_cast<size_t>(i)] = i;
    targets.push_back(0);
    const SccResult cycle = strongly_connected_components(begin, targets);
    CHECK(cycle.count == 1);
}

TEST_CASE("pruning keeps the largest component and reports a cut-off label", "[graph][prune]") {
    MotionGraph g = small_graph();
    REQUIRE(validate_motion_graph(g).ok());
    const PruneReport r = prune_to_largest_component(g);
    CHECK(r.nodes_before == 8);
    CHECK(r.nodes == 2);  // a4 and b4 form the only cycle
    CHECK(r.edges == 2);
    REQUIRE(validate_motion_graph(g).ok());
    for (const GraphEdge& e : g.edges) CHECK(e.kind == GraphEdgeKind::transition);
    bool wave_reported = false;
    for (const LabelReachability& l : r.labels)
        if (l.label == "wave") {
            wave_reported = true;
            CHECK(l.clips_kept == 0);
            CHECK(l.reason.find("none leaves") != std::string::npos);
        }
    CHECK(wave_reported);
}

