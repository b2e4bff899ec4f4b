#include "planners/ordering/transition_cost.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"
#include "core/number_text.hpp"
#include "motion/mtt.hpp"
#include "motion/sync.hpp"
#include "planners/motion/transition.hpp"

namespace depotwin {

namespace {

const char* const kAxisNames[3] = {"x", "y", "z"};

// unit direction in which the path leaves through its back (or, reversed, its front):
// the last polyline edge of non-zero length
bool outward_direction(const std::vector<Vec3>& points, bool at_back, Vec3& direction) {
  const int n = static_cast<int>(points.size());
  const Vec3& tip = at_back ? points[n - 1] : points[0];
  for (int k = 1; k < n; ++k) {
    const Vec3& inner = at_back ? points[n - 1 - k] : points[k];
    const Vec3 step = tip - inner;
    if (step.norm() > kJoinTolerance_mm) {
      direction = step.normalized();
      return true;
    }
  }
  return false;
}

}  // namespace

CostModel parse_cost_model(const std::string& name) {
  if (name == "machine") return CostModel::machine;
  if (name == "along_line") return CostModel::along_line;
  throw InputError("order.cost_model",
                   "unknown cost model '" + name + "' (expected machine or along_line)");
}

TransitionCost::TransitionCost(const Toolpath& toolpath, const TcpLimits& tcp_limits,
                               CostModel model)
    : model_(model), tcp_limits_(tcp_limits) {
  const MachineLimits& requested = tcp_limits.requested();
  const std::string limit_problem = requested.validate();
  if (!limit_problem.empty()) throw InputError("limits", limit_problem);

  const int path_count = static_cast<int>(toolpath.paths.size());
  positions_.resize(2 * path_count + 2);
  exit_velocity_.assign(2 * path_count + 2, Vec3::Zero());
  speed_mm_s_.assign(2 * path_count + 2, 0.0);
  std::vector<Problem> problems;
  // paths too fast for the machine at their ends: the first kListedTooFast named, the rest
  // counted with the lowest speed any of them allows
  constexpr int kListedTooFast = 10;
  int too_fast_count = 0;
  double lowest_allowed_mm_s = 0.0;
  for (int i = 0; i < path_count; ++i) {
    const PrintPath& path = toolpath.paths[i];
    const std::string key = "toolpath.paths[" + std::to_string(path.source_index) + "]";
    Vec3 front_out, back_out;
    if (path.points.size() < 2 || !outward_direction(path.points, true, back_out) ||
        !outward_direction(path.points, false, front_out)) {
      problems.push_back({"", 0, key, "a print path needs two distinct points"});
      continue;
    }
    if (!(path.speed_mm_s > 0.0) || !std::isfinite(path.speed_mm_s)) {
      problems.push_back({"", 0, key + ".speed", "print speed must be a positive number (mm/s)"});
      continue;
    }
    positions_[2 * i] = path.front();
    positions_[2 * i + 1] = path.back();
    exit_velocity_[2 * i] = path.speed_mm_s * front_out;
    exit_velocity_[2 * i + 1] = path.speed_mm_s * back_out;
    speed_mm_s_[2 * i] = speed_mm_s_[2 * i + 1] = path.speed_mm_s;
    print_length_mm_ += path.length_mm();
    print_time_s_ += path.length_mm() / path.speed_mm_s;

    // the print velocity at the ends must be reachable: per axis (machine) or along
    // the line (the paper's model uses the x-axis limits as its single v_max), under the
    // limits over the path's box
    Vec3 lo, hi;
    path.bounds(lo, hi);
    const MachineLimits limits = tcp_limits.over(lo, hi);
    const int too_fast_axis = clamp_exit_velocities(2 * i, limits, model);
    if (too_fast_axis < 0) continue;
    const double allowed_mm_s = limits.axes[too_fast_axis].v_max_mm_s;
    lowest_allowed_mm_s =
        too_fast_count == 0 ? allowed_mm_s : std::min(lowest_allowed_mm_s, allowed_mm_s);
    if (++too_fast_count > kListedTooFast) continue;
    // a machine whose joints set the TCP's limits where the path is (an arm, a delta) says so
    const bool from_joints = allowed_mm_s < requested.axes[too_fast_axis].v_max_mm_s;
    problems.push_back(
        {"", 0, key + ".speed",
         "print speed " + message_number(path.speed_mm_s) +
             " mm/s exceeds v_max = " + message_number(allowed_mm_s) + " mm/s of axis " +
             kAxisNames[too_fast_axis] + " at its ends" +
             (from_joints ? " (the machine's joint limits mapped over this path; limits v_max is " +
                                message_number(requested.axes[too_fast_axis].v_max_mm_s) + ")"
                          : "")});
  }
  if (too_fast_count > kListedTooFast)
    problems.push_back({"", 0, "toolpath",
                        "... and " + std::to_string(too_fast_count - kListedTooFast) +
                            " more print paths too fast at their ends (" +
                            std::to_string(too_fast_count) + " in all): print them at " +
                            message_number(lowest_allowed_mm_s) + " mm/s or less"});
  if (!problems.empty()) throw InputError(std::move(problems));
  positions_[start_node()] = toolpath.start_mm;
  positions_[end_node()] = toolpath.end_mm;

  // every move is at least |d_axis| / v_max(axis); over x-y Chebyshev distance r that
  // is at least r / max(v_x, v_y), and r / v_max along the line (the user's limits: no
  // move's limits are looser)
  bound_speed_mm_s_ = model == CostModel::machine
                          ? std::max(requested.axes[0].v_max_mm_s, requested.axes[1].v_max_mm_s)
                          : requested.axes[0].v_max_mm_s;
}

int TransitionCost::clamp_exit_velocities(int front_node, const MachineLimits& limits,
                                          CostModel model) {
  for (int node = front_node; node <= front_node + 1; ++node) {
    for (int axis = 0; axis < 3; ++axis) {
      const double v_max = limits.axes[axis].v_max_mm_s;
      const double v = model == CostModel::machine ? std::abs(exit_velocity_[node][axis])
                                                   : (axis == 0 ? speed_mm_s_[node] : 0.0);
      if (v > v_max * (1.0 + 1e-9)) return axis;
      // roundoff only: keep the motion core's |v| <= v_max precondition exact
      exit_velocity_[node][axis] = std::clamp(exit_velocity_[node][axis], -v_max, v_max);
    }
  }
  return -1;
}

double TransitionCost::along_line_time(double d, double v0, double v1,
                                       const MachineLimits& limits) const {
  const double v_max = limits.axes[0].v_max_mm_s, a = limits.axes[0].a_max_mm_s2;
  // eq. (2) with a1 = a, a2 = -a: the triangular profile's peak speed
  const double v_peak = std::sqrt(a * d + 0.5 * (v0 * v0 + v1 * v1));
  if (v_peak >= std::max(v0, v1)) {
    if (v_peak <= v_max) return (2.0 * v_peak - v0 - v1) / a;  // eq. (1)
    // trapezoid, the transition time below eq. (3) with v_m = v_max
    return d / v_max +
           ((v_max - v0) * (v_max - v0) + (v_max - v1) * (v_max - v1)) / (2.0 * a * v_max);
  }
  // too short to change speed without overshooting: the exact 1-D minimum time
  return feasible_durations(AxisBoundary{0.0, d, v0, v1}, v_max, a).t_min();
}

double TransitionCost::operator()(int from, int to) const {
  // two paths' ends at one point (neither the job's start nor its end): the print goes on
  // through the joint, as the planners join such paths (split_into_segments'
  // joined_to_previous), with no transition; else a zero-length move at the two paths'
  // speeds would be charged, and the order's cost and lower bound would exceed the plans
  if (from < start_node() && to < start_node() &&
      (positions_[to] - positions_[from]).norm() <= kJoinTolerance_mm)
    return 0.0;
  // the limits over the box the move may sweep, as the planners' transitions take them
  const MachineLimits limits = tcp_limits_.for_transition(positions_[from], exit_velocity_[from],
                                                          positions_[to], -exit_velocity_[to]);
  if (model_ == CostModel::along_line)
    return along_line_time((positions_[to] - positions_[from]).norm(), speed_mm_s_[from],
                           speed_mm_s_[to], limits);
  // leave `from` along its outward direction, enter `to` against its outward direction
  return synchronized_duration(axis_moves(positions_[from], exit_velocity_[from], positions_[to],
                                          -exit_velocity_[to], limits));
}

double TransitionCost::bound(int from, int to) const {
  const Vec3 offset = positions_[to] - positions_[from];
  const MachineLimits& limits = tcp_limits_.requested();
  if (model_ == CostModel::along_line) return offset.norm() / limits.axes[0].v_max_mm_s;
  double time_s = 0.0;
  for (int axis = 0; axis < 3; ++axis)
    time_s = std::max(time_s, std::abs(offset[axis]) / limits.axes[axis].v_max_mm_s);
  return time_s;
}

std::vector<int> order_nodes(const TransitionCost& cost, const OrderResult& order) {
  std::vector<int> nodes;
  nodes.reserve(2 * order.order.size() + 2);
  nodes.push_back(cost.start_node());
  for (size_t k = 0; k < order.order.size(); ++k) {
    nodes.push_back(TransitionCost::entry_node(order.order[k], order.reversed[k]));
    nodes.push_back(TransitionCost::exit_node(order.order[k], order.reversed[k]));
  }
  nodes.push_back(cost.end_node());
  return nodes;
}

double TransitionCost::order_cost(const OrderResult& order) const {
  const std::vector<int> nodes = order_nodes(*this, order);
  double total_s = print_time_s_;
  for (size_t k = 0; k + 1 < nodes.size(); k += 2) total_s += (*this)(nodes[k], nodes[k + 1]);
  return total_s;
}

double TransitionCost::transition_length_mm(const OrderResult& order) const {
  const std::vector<int> nodes = order_nodes(*this, order);
  double length_mm = 0.0;
  for (size_t k = 0; k + 1 < nodes.size(); k += 2)
    length_mm += (positions_[nodes[k + 1]] - positions_[nodes[k]]).norm();
  return length_mm;
}

}  // namespace depotwin
