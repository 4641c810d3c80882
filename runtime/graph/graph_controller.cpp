#include "runtime/graph/graph_controller.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <utility>

#include "runtime/math/det_math.hpp"
#include "runtime/math/splitmix64.hpp"

namespace marionette {

namespace {
PlanarTransform placement(double angle, double dx, double dz) { return {angle, dx, dz}; }


constexpr float kUnreachableSeconds = 1e9f;
// Past this the heuristic stops growing: it only has to point the way.
constexpr double kHeuristicCapSeconds = 4.0;
// Per second still to go, it outweighs a full facing error (2) over a one-second horizon.
constexpr double kHeuristicWeight = 2.5;

// Seconds (edge_cost) from every node to the nearest goal node: Dijkstra on the
// reversed edges (construction time, allocates).
std::vector<float> seconds_to_goals(const MotionGraph& g, const std::vector<char>& goal, double transition_weight) {
    const size_t n = g.nodes.size();
    std::vector<std::vector<std::pair<std::int32_t, double>>> incoming(n);
    for (const GraphEdge& e : g.edges)
        incoming[static_cast<size_t>(e.to)].push_back({e.from, edge_cost(g, e, transition_weight)});
    std::vector<double> best(n, static_cast<double>(kUnreachableSeconds));
    using Item = std::pair<double, std::int32_t>;
    std::vector<Item> heap;
    for (size_t i = 0; i < n; ++i)
        if (goal[i]) best[i] = 0.0, heap.push_back({0.0, static_cast<std::int32_t>(i)});
    std::make_heap(heap.begin(), heap.end(), std::greater<Item>());
    while (!heap.empty()) {
        std::pop_heap(heap.begin(), heap.end(), std::greater<Item>());
        const Item top = heap.back();
        heap.pop_back();
        if (top.first > best[static_cast<size_t>(top.second)]) continue;
        for (const auto& [from, cost] : incoming[static_cast<size_t>(top.second)]) {
            const double d = top.first + cost;
            if (d < best[static_cast<size_t>(from)]) {
                best[static_cast<size_t>(from)] = d;
                heap.push_back({d, from});
                std::push_heap(heap.begin(), heap.end(), std::greater<Item>());
            }
        }
    }
    std::vector<float> out(n);
    for (size_t i = 0; i < n; ++i) out[i] = static_cast<float>(best[i]);
    return out;
}

int root_joint_of(const MotionGraph& g) {
    for (size_t j = 0; j < g.skeleton.parents.size(); ++j)
        if (g.skeleton.parents[j] == kNoParent) return static_cast<int>(j);
    return 0;
}
}  // namespace

double estimate_graph_facing(const MotionGraph& g, int* samples, double* agreement) {
    const size_t joints = static_cast<size_t>(g.joint_count());
    const size_t root = static_cast<size_t>(root_joint_of(g));
    const int walk = g.label_index("walk");
    // Travel over about a quarter second: long enough to average out the sway of a step.
    const int step = std::max(1, static_cast<int>(g.frame_rate / 4.0));
    double sum_sin = 0.0, sum_cos = 0.0, weight = 0.0;
    int used = 0;
    for (const GraphClip& clip : g.clips) {
        if (walk >= 0 && !((clip.label_mask >> walk) & 1u)) continue;
        const auto at = [&](int f) { return static_cast<size_t>(clip.first_frame + f) * joints + root; };
        double top = 0.0;
        for (int f = 0; f + step < clip.frame_count; ++f) {
            const vec3 d = g.translations[at(f + step)] - g.translations[at(f)];
            top = std::max(top, std::sqrt(static_cast<double>(d.x) * d.x + static_cast<double>(d.z) * d.z));
        }
        if (!(top > 0.0)) continue;
        for (int f = 0; f + step < clip.frame_count; ++f) {
            const vec3 d = g.translations[at(f + step)] - g.translations[at(f)];
            const double length = std::sqrt(static_cast<double>(d.x) * d.x + static_cast<double>(d.z) * d.z);
            if (length < 0.4 * top) continue;
            const vec3 forward = quat_rotate(g.rotations[at(f)], vec3(0.0f, 0.0f, 1.0f));
            const double facing = det::atan2(forward.x, forward.z);
            const double travel = det::atan2(d.x, d.z);
            const double angle = det::wrap_angle(travel - facing);
            sum_sin += length * det::sin(angle), sum_cos += length * det::cos(angle);
            weight += length;
            ++used;
        }
    }
    const double resultant = weight > 0.0 ? std::sqrt(sum_sin * sum_sin + sum_cos * sum_cos) / weight : 0.0;
    if (samples) *samples = used;
    if (agreement) *agreement = resultant;
    if (used == 0 || resultant < 0.5) return 0.0;
    const double mean = det::atan2(sum_sin, sum_cos);
    const double quarter = det::kHalfPi;
    const double axis = std::nearbyint(mean / quarter) * quarter;
    const double snapped = std::abs(mean - axis) <= 15.0 * det::kPi / 180.0 ? axis : mean;
    return det::wrap_angle(snapped);
}

GraphController::GraphController(const MotionGraph& graph, const GraphControllerConfig& config)
    : graph_(graph), config_(config), path_search_(graph, config.transition_weight) {
    if (const Outcome valid = validate_motion_graph(graph); !valid.ok())
        throw std::invalid_argument("motion graph: " + valid.problem());
    if (graph.nodes.empty() || graph.edges.empty()) throw std::invalid_argument("motion graph has no edges");
    for (size_t n = 0; n < graph.nodes.size(); ++n)
        if (graph.out_edges(static_cast<int>(n)).empty())
            throw std::invalid_argument("motion graph node " + std::to_string(n) + " has no way out (prune it)");
    const size_t joints = static_cast<size_t>(graph.joint_count());
    sample_rotations_.resize(joints), sample_translations_.resize(joints);
    const size_t frames = graph.contacts.size();
    frame_yaw_.resize(frames);
    const int root = root_joint_of(graph);
    facing_offset_ = estimate_graph_facing(graph);
    // Every transition's registration (time warp), once: the tick only reads it.
    // None where that is unaffordable (the blends stay plain).
    if (transition_warps_affordable(graph)) {
        const size_t width = 2 * static_cast<size_t>(graph.window_frames);
        transition_warps_.assign(graph.edges.size() * width, 0.0f);
        for (size_t e = 0; e < graph.edges.size(); ++e)
            transition_time_warp(graph, graph.edges[e], std::span<float>(transition_warps_).subspan(e * width, width));
    }
    for (size_t f = 0; f < frames; ++f) {
        const vec3 forward = quat_rotate(graph.rotations[f * joints + static_cast<size_t>(root)], vec3(0.0f, 0.0f, 1.0f));
        frame_yaw_[f] = static_cast<float>(det::wrap_angle(det::atan2(forward.x, forward.z) + facing_offset_));
    }
    // Ground speed of the root at each node's frame (over the next frame of its clip).
    std::vector<char> moving(graph.nodes.size(), 0), still(graph.nodes.size(), 0);
    for (size_t n = 0; n < graph.nodes.size(); ++n) {
        const GraphNode& node = graph.nodes[n];
        const GraphClip& clip = graph.clips[static_cast<size_t>(node.clip)];
        const int a = std::min(node.frame, clip.frame_count - 2), b = a + 1;
        if (a < 0) continue;
        const vec3 pa = graph.translations[static_cast<size_t>(clip.first_frame + a) * joints + static_cast<size_t>(root)];
        const vec3 pb = graph.translations[static_cast<size_t>(clip.first_frame + b) * joints + static_cast<size_t>(root)];
        const double dx = pb.x - pa.x, dz = pb.z - pa.z;
        const double speed = std::sqrt(dx * dx + dz * dz) * graph.frame_rate;
        moving[n] = speed > 0.35 * config.max_speed;
        still[n] = speed < 0.1 * config.max_speed;
    }
    seconds_to_moving_ = seconds_to_goals(graph, moving, config.transition_weight);
    seconds_to_still_ = seconds_to_goals(graph, still, config.transition_weight);
}

void GraphController::set_config(const GraphControllerConfig& config) {
    config_ = config;
    path_search_.set_transition_weight(config.transition_weight);
    path_search_label_ = -1;  // the scratch no longer matches any state
}

int GraphController::clip_edge_of(int node) const {
    for (const GraphEdge& e : graph_.out_edges(node))
        if (e.kind == GraphEdgeKind::clip) return graph_.edge_index(e);
    return -1;
}

GraphControllerState GraphController::initial_state() const {
    GraphControllerState s;
    s.rng = config_.seed;
    int edge = 0;
    for (size_t n = 0; n < graph_.nodes.size(); ++n) {
        const int e = clip_edge_of(static_cast<int>(n));
        if (e >= 0) { edge = e; break; }
    }
    // Start at the origin: undo the start frame's own ground position.
    const GraphNode& node = graph_.nodes[static_cast<size_t>(graph_.edges[static_cast<size_t>(edge)].from)];
    const int root_joint = 0;
    const size_t frame = static_cast<size_t>(graph_.clips[static_cast<size_t>(node.clip)].first_frame + node.frame);
    const vec3 p = graph_.translations[frame * static_cast<size_t>(graph_.joint_count()) + root_joint];
    s.world_dx = -p.x, s.world_dz = -p.z;
    s.edge = edge;
    return s;
}

vec3 GraphController::root_position(int node, const PlanarTransform& world) const {
    const GraphNode& n = graph_.nodes[static_cast<size_t>(node)];
    const size_t frame = static_cast<size_t>(graph_.clips[static_cast<size_t>(n.clip)].first_frame + n.frame);
    return apply_planar(world, graph_.translations[frame * static_cast<size_t>(graph_.joint_count())]);
}

double GraphController::root_heading(int node, const PlanarTransform& world) const {
    const GraphNode& n = graph_.nodes[static_cast<size_t>(node)];
    const size_t frame = static_cast<size_t>(graph_.clips[static_cast<size_t>(n.clip)].first_frame + n.frame);
    return det::wrap_angle(world.angle + frame_yaw_[frame]);
}

GraphSampleJob GraphController::sample_job(const GraphControllerState& s, LocalPoseOutput pose) {
    return {&graph_, s.edge, s.edge_position, placement(s.world_angle, s.world_dx, s.world_dz),
            {sample_rotations_, sample_translations_}, pose, transition_warps_};
}

bool GraphController::pose(const GraphControllerState& s, LocalPoseOutput pose) { return sample_job(s, pose).run(); }

void GraphController::start_edge(GraphControllerState& s, int edge) const {
    s.edge = edge;
    if (graph_.edges[static_cast<size_t>(edge)].kind == GraphEdgeKind::transition) ++s.transitions_taken;
    ++s.decisions;
}

void GraphController::search_start(GraphControllerState& s) const {
    const GraphEdge& e = graph_.edges[static_cast<size_t>(s.edge)];
    const PlanarTransform after = e.kind == GraphEdgeKind::transition
                                      ? compose_planar(placement(s.world_angle, s.world_dx, s.world_dz), edge_alignment(e))
                                      : placement(s.world_angle, s.world_dx, s.world_dz);
    GraphSearchLevel root;
    root.node = e.to;
    root.angle = after.angle, root.dx = after.dx, root.dz = after.dz;
    s.search[0] = root;
    s.search_depth = 0;
    s.best_edge = -1;
    s.best_score = 0.0f;
}

void GraphController::search_run(GraphControllerState& s, int budget) const {
    const GraphSearchLevel& origin = s.search[0];
    const PlanarTransform origin_world = placement(origin.angle, origin.dx, origin.dz);
    const vec3 p0 = root_position(origin.node, origin_world);
    const double speed2 = static_cast<double>(s.desired_vx) * s.desired_vx + static_cast<double>(s.desired_vz) * s.desired_vz;
    const bool steering = speed2 > 1e-4;
    const double desired_heading = steering ? det::atan2(s.desired_vx, s.desired_vz) : root_heading(origin.node, origin_world);
    const double scale = config_.max_speed * config_.horizon_s;
    const double inv_scale2 = scale > 0.0 ? 1.0 / (scale * scale) : 1.0;
    // A leaf's score: where the root ends up against where the stick's velocity
    // would have put it by then, the facing error, and the transitions' cost.
    auto score_leaf = [&](int node, const PlanarTransform& world, double seconds, double cost, int first_edge) {
        const vec3 p = root_position(node, world);
        const double ex = p.x - (p0.x + s.desired_vx * seconds);
        const double ez = p.z - (p0.z + s.desired_vz * seconds);
        const double heading_error = 1.0 - det::cos(root_heading(node, world) - desired_heading);
        const float to_goal = (steering ? seconds_to_moving_ : seconds_to_still_)[static_cast<size_t>(node)];
        const double beyond = kHeuristicWeight * std::min(static_cast<double>(to_goal), kHeuristicCapSeconds) ;
        const double score = (ex * ex + ez * ez) * inv_scale2 + config_.heading_weight * heading_error + cost + beyond;
        if (s.best_edge < 0 || score < s.best_score) {
            s.best_edge = first_edge;
            s.best_score = static_cast<float>(score);
        }
    };
    while (budget > 0 && s.search_depth >= 0) {
        GraphSearchLevel& level = s.search[static_cast<size_t>(s.search_depth)];
        const std::span<const GraphEdge> out = graph_.out_edges(level.node);
        int edge = -1;
        if (s.search_depth < config_.branch_depth) {
            if (level.next_edge < static_cast<int>(out.size())) edge = graph_.edge_index(out[static_cast<size_t>(level.next_edge++)]);
        } else if (level.next_edge == 0) {
            level.next_edge = 1;
            edge = clip_edge_of(level.node);
            if (edge < 0) edge = graph_.edge_index(out[0]);
        }
        if (edge < 0) {
            --s.search_depth;
            continue;
        }
        --budget;
        ++s.nodes_expanded;
        const GraphEdge& e = graph_.edges[static_cast<size_t>(edge)];
        GraphSearchLevel child;
        child.node = e.to;
        child.first_edge = s.search_depth == 0 ? edge : level.first_edge;
        child.seconds = level.seconds + static_cast<float>(e.frames / graph_.frame_rate);
        child.cost = level.cost + static_cast<float>(config_.transition_weight * e.cost);
        PlanarTransform world = placement(level.angle, level.dx, level.dz);
        if (e.kind == GraphEdgeKind::transition) world = compose_planar(world, edge_alignment(e));
        // Bound: the other terms are never negative, so the cost so far bounds the score.
        if (s.best_edge >= 0 && child.cost >= s.best_score) continue;
        if (s.search_depth + 1 >= config_.branch_depth || s.search_depth + 1 >= kGraphSearchDepth) {
            // Past the branching levels the clip plays on: follow its clip edges to
            // the horizon (a clip is cut into many short edges at its transition
            // points, so counting them as levels would stop well short of it).
            // Each edge followed counts against the budget; a roll-out is at most
            // kGraphRolloutEdges long, so a tick's work stays bounded.
            int node = child.node;
            double seconds = child.seconds;
            for (int followed = 0; seconds < config_.horizon_s && followed < kGraphRolloutEdges; ++followed) {
                int next = clip_edge_of(node);
                if (next < 0) break;  // the clip ends here: score where it stops
                const GraphEdge& c = graph_.edges[static_cast<size_t>(next)];
                seconds += c.frames / graph_.frame_rate;
                node = c.to;
                --budget;
                ++s.nodes_expanded;
            }
            score_leaf(node, world, seconds, child.cost, child.first_edge);
            continue;
        }
        child.angle = world.angle, child.dx = world.dx, child.dz = world.dz;
        if (child.seconds >= config_.horizon_s) {
            score_leaf(child.node, world, child.seconds, child.cost, child.first_edge);
            continue;
        }
        s.search[static_cast<size_t>(++s.search_depth)] = child;
    }
}

int GraphController::random_edge(GraphControllerState& s) const {
    const GraphEdge& current = graph_.edges[static_cast<size_t>(s.edge)];
    const std::span<const GraphEdge> out = graph_.out_edges(current.to);
    const double temperature = config_.attract_temperature > 0.0 ? config_.attract_temperature : 1.0;
    double total = 0.0;
    for (const GraphEdge& e : out) total += 1.0 / (1.0 + e.cost / temperature);
    double pick = splitmix64_unit(s.rng) * total;
    for (const GraphEdge& e : out) {
        pick -= 1.0 / (1.0 + e.cost / temperature);
        if (pick < 0.0) return graph_.edge_index(e);
    }
    return graph_.edge_index(out[out.size() - 1]);
}

int GraphController::choose_next_edge(GraphControllerState& s) {
    const GraphEdge& current = graph_.edges[static_cast<size_t>(s.edge)];
    const int node = current.to;
    if (s.mode == GraphMotionMode::to_action) {
        if (s.action_path_next < s.action_path_length) return s.action_path[static_cast<size_t>(s.action_path_next++)];
        s.mode = GraphMotionMode::action;
    }
    if (s.mode == GraphMotionMode::action) {
        const GraphClip& clip = graph_.clips[static_cast<size_t>(graph_.nodes[static_cast<size_t>(node)].clip)];
        const int next = clip_edge_of(node);
        if (next >= 0 && s.action_label >= 0 && (clip.label_mask >> s.action_label) & 1u) return next;
        s.mode = GraphMotionMode::locomotion;
        s.action_label = -1;
        ++s.actions_played;
    }
    if (s.mode == GraphMotionMode::attract) return random_edge(s);
    if (s.mode == GraphMotionMode::find_action) {
        // The edge ends before the path query did: give it what is left of this
        // tick's budget, as the look-ahead gets below.
        advance_action_search(s, config_.max_nodes_per_tick);
        if (s.mode == GraphMotionMode::to_action) return choose_next_edge(s);
    }
    // Locomotion: finish the look-ahead with what is left of this tick's budget; the best so far otherwise.
    if (s.search_depth >= 0) search_run(s, config_.max_nodes_per_tick);
    if (s.best_edge >= 0 && graph_.edges[static_cast<size_t>(s.best_edge)].from == node) return s.best_edge;
    const int clip = clip_edge_of(node);
    return clip >= 0 ? clip : graph_.edge_index(graph_.out_edges(node)[0]);
}

// Slices the action path query on by at most `budget` heap pops. The scratch is
// first made the pure function of the state it must be (start node = end of the
// edge, label, pops so far), re-deriving it when it belongs to another state.
void GraphController::advance_action_search(GraphControllerState& s, int budget) {
    const int from = graph_.edges[static_cast<size_t>(s.edge)].to;
    const bool same_query = path_search_label_ == s.action_label && path_search_.start() == from &&
                            path_search_.status() == PathSearchStatus::running;
    if (!same_query || path_search_.pops() > s.action_search_pops) {
        path_search_.clear_goals();
        path_search_.add_label_goal(s.action_label);
        path_search_.begin(from);
        path_search_label_ = s.action_label;
    }
    if (path_search_.pops() < s.action_search_pops) path_search_.advance(s.action_search_pops - path_search_.pops());
    const PathSearchStatus status = path_search_.advance(std::max(1, budget));
    s.action_search_pops = path_search_.pops();
    if (status == PathSearchStatus::running) return;
    s.action_search_pops = 0;
    if (status == PathSearchStatus::found && path_search_.path().size() <= static_cast<size_t>(kGraphActionPath)) {
        const std::span<const std::int32_t> path = path_search_.path();
        for (size_t i = 0; i < path.size(); ++i) s.action_path[i] = path[i];
        s.action_path_length = static_cast<std::int32_t>(path.size());
        s.action_path_next = 0;
        s.mode = GraphMotionMode::to_action;
    } else {  // unreachable, or a path longer than the state holds: the press is dropped
        s.mode = GraphMotionMode::locomotion;
        s.action_label = -1;
    }
    // A finished query is never resumed: a state still searching re-derives its own.
    path_search_label_ = -1;
}

bool GraphController::step(GraphControllerState& s, const GraphControllerInput& in, LocalPoseOutput pose) {
    if (!sample_job(s, pose).validate()) return false;
    const float deflection2 = in.stick_x * in.stick_x + in.stick_y * in.stick_y;
    const bool active = deflection2 > 0.01f || in.buttons != 0;
    s.idle_seconds = active ? 0.0f : s.idle_seconds + in.dt;
    if (s.mode == GraphMotionMode::attract && active) s.mode = GraphMotionMode::locomotion;
    if (s.mode == GraphMotionMode::locomotion && s.idle_seconds >= config_.attract_after_s)
        s.mode = GraphMotionMode::attract;

    // Actions: a newly pressed, mapped button plans the cheapest path to its label
    // from the end of the edge being played.
    const std::uint16_t pressed = static_cast<std::uint16_t>(in.buttons & ~s.last_buttons);
    s.last_buttons = in.buttons;
    if (pressed != 0 && (s.mode == GraphMotionMode::locomotion || s.mode == GraphMotionMode::attract)) {
        for (int b = 0; b < kGraphActionButtons; ++b) {
            const int label = config_.button_label[static_cast<size_t>(b)];
            if (!((pressed >> b) & 1u) || label < 0) continue;
            s.mode = GraphMotionMode::find_action;
            s.action_label = label;
            s.action_search_pops = 0;
            s.action_path_length = 0, s.action_path_next = 0;
            break;
        }
    }
    if (s.mode == GraphMotionMode::find_action) advance_action_search(s, config_.max_nodes_per_tick);

    // The velocity the stick asks for, on the ground plane as the gait reads it.
    const float vx = static_cast<float>(in.stick_x * config_.max_speed);
    const float vz = static_cast<float>(-in.stick_y * config_.max_speed);
    const float dvx = vx - s.desired_vx, dvz = vz - s.desired_vz;
    const double change = config_.max_speed * 0.25;
    s.desired_vx = vx, s.desired_vz = vz;
    if (steering(s)) {
        // A search restarts when the stick moved on; a finished one keeps its answer.
        if ((s.search_depth < 0 && s.best_edge < 0) || dvx * dvx + dvz * dvz > change * change) search_start(s);
        search_run(s, config_.max_nodes_per_tick);
    }

    s.edge_position += static_cast<float>(in.dt * graph_.frame_rate);
    for (;;) {
        const GraphEdge& e = graph_.edges[static_cast<size_t>(s.edge)];
        if (s.edge_position < static_cast<float>(e.frames)) break;
        s.edge_position -= static_cast<float>(e.frames);
        const int next = choose_next_edge(s);
        if (e.kind == GraphEdgeKind::transition) {
            const PlanarTransform w = compose_planar(placement(s.world_angle, s.world_dx, s.world_dz), edge_alignment(e));
            s.world_angle = det::wrap_angle(w.angle), s.world_dx = w.dx, s.world_dz = w.dz;
        }
        start_edge(s, next);
        s.search_depth = -1;
        s.best_edge = -1;
        if (steering(s)) search_start(s);
        // An unfinished path query starts again from the end of the new edge.
        if (s.mode == GraphMotionMode::find_action) s.action_search_pops = 0;
    }
    // Cannot fail: the spans were checked above and the state is on an edge again.
    if (!sample_job(s, pose).run()) return false;
    const GraphEdge& e = graph_.edges[static_cast<size_t>(s.edge)];
    const int index = static_cast<int>(s.edge_position);
    const GraphNode& from = graph_.nodes[static_cast<size_t>(e.from)];
    const size_t frame = static_cast<size_t>(graph_.clips[static_cast<size_t>(from.clip)].first_frame + from.frame + index);
    s.contacts = frame < graph_.contacts.size() ? graph_.contacts[frame] : 0;
    return true;
}

}  // namespace marionette
