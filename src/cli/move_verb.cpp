#include "cli/move_verb.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "core/error.hpp"
#include "motion/sync.hpp"

namespace depotwin {

std::vector<double> parse_number_list(const std::string& text, const std::string& option) {
  std::vector<double> values;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    char* end = nullptr;
    const double value = std::strtod(item.c_str(), &end);
    // the whole item (an embedded NUL byte would end strtod's text early)
    if (item.empty() || end != item.c_str() + item.size() || !std::isfinite(value))
      throw InputError(option, "'" + item + "' is not a finite number (expected e.g. 0,5.5)");
    values.push_back(value);
  }
  if (values.empty()) throw InputError(option, "no value given");
  return values;
}

namespace {

// the ranges the move is computed in: beyond them its times and displacements (ratios such as
// v_max / a_max and a_max / j_max) leave what doubles hold with the precision the profile needs
constexpr double kMaxPosition = 1e9;  // |q0|, |q1|
constexpr double kMinLimit = 1e-6;    // v_max, a_max and a non-zero j_max
constexpr double kMaxLimit = 1e9;

// "1 value", "3 values"
std::string count_text(size_t count) {
  return std::to_string(count) + (count == 1 ? " value" : " values");
}

// a one-value list stands for every axis (velocities and limits only); otherwise one per axis
double value_for_axis(const std::vector<double>& list, size_t axis) {
  return list.size() == 1 ? list[0] : list[axis];
}

// the phases of a profile; a jerk-limited one adds the constant jerk and the acceleration at
// the phase end ("acceleration" is the one at the phase start)
nlohmann::ordered_json phases_json(const AxisProfile& profile, bool jerk_limited) {
  nlohmann::ordered_json phases = nlohmann::ordered_json::array();
  for (const Phase& phase : profile.phases()) {
    nlohmann::ordered_json entry{{"t_start_s", phase.t_begin_s}, {"duration_s", phase.duration_s},
                                 {"acceleration", phase.a0},     {"v_start", phase.v0},
                                 {"v_end", phase.v_end()},       {"q_start", phase.q0},
                                 {"q_end", phase.q_end()}};
    if (jerk_limited) {
      entry["jerk"] = phase.jerk;
      entry["acceleration_end"] = phase.a_end();
    }
    phases.push_back(entry);
  }
  return phases;
}

}  // namespace

nlohmann::ordered_json minimum_time_move_json(const MoveRequest& request) {
  using Json = nlohmann::ordered_json;
  // the positions give the axes, one each: they are never broadcast
  const size_t axes = request.q0.size();
  if (axes == 0) throw InputError("--q0", "no value given");
  if (request.q1.size() != axes)
    throw InputError("--q1", "has " + count_text(request.q1.size()) + " but --q0 has " +
                                 count_text(axes) + " (one position per axis in each)");
  if (axes > 6) throw InputError("--q0", "has " + count_text(axes) + ": at most six axes");
  // velocities and limits: one per axis, or one for every axis; --jmax is optional
  const std::vector<std::pair<std::string, const std::vector<double>*>> lists{
      {"--v0", &request.v0},
      {"--v1", &request.v1},
      {"--vmax", &request.v_max},
      {"--amax", &request.a_max},
      {"--jmax", &request.j_max}};
  std::vector<Problem> problems;
  for (const auto& [name, list] : lists) {
    if (list->size() > 1 && list->size() != axes)
      problems.push_back({"", 0, name,
                          "has " + count_text(list->size()) + " but --q0 and --q1 have " +
                              count_text(axes) + " (give one per axis, or one for every axis)"});
    if (list->empty() && name != "--jmax") problems.push_back({"", 0, name, "no value given"});
  }
  if (!problems.empty()) throw InputError(problems);

  // per axis: limits and boundary velocities, then the synchronised move
  std::vector<AxisMove> moves(axes);
  for (size_t i = 0; i < axes; ++i) {
    AxisMove& m = moves[i];
    m.boundary = AxisBoundary{value_for_axis(request.q0, i), value_for_axis(request.q1, i),
                              value_for_axis(request.v0, i), value_for_axis(request.v1, i)};
    m.v_max = value_for_axis(request.v_max, i);
    m.a_max = value_for_axis(request.a_max, i);
    const std::string axis = " of axis " + std::to_string(i);
    const std::string limit_range = " (at least 1e-6, at most 1e9)";
    for (const auto& [name, position] : {std::pair{"--q0", m.boundary.q0}, {"--q1", m.boundary.q1}})
      if (std::abs(position) > kMaxPosition)
        problems.push_back({"", 0, name, "must be at most 1e9 in magnitude" + axis});
    if (!(m.v_max > 0.0)) problems.push_back({"", 0, "--vmax", "must be > 0" + axis});
    if (!(m.a_max > 0.0)) problems.push_back({"", 0, "--amax", "must be > 0" + axis});
    if (m.v_max > 0.0 && (m.v_max < kMinLimit || m.v_max > kMaxLimit))
      problems.push_back({"", 0, "--vmax", "out of range" + axis + limit_range});
    if (m.a_max > 0.0 && (m.a_max < kMinLimit || m.a_max > kMaxLimit))
      problems.push_back({"", 0, "--amax", "out of range" + axis + limit_range});
    if (m.v_max > 0.0 && std::abs(m.boundary.v0) > m.v_max)
      problems.push_back({"", 0, "--v0", "|v0| exceeds v_max" + axis});
    if (m.v_max > 0.0 && std::abs(m.boundary.v1) > m.v_max)
      problems.push_back({"", 0, "--v1", "|v1| exceeds v_max" + axis});
    if (!request.j_max.empty()) {
      const double j_max = value_for_axis(request.j_max, i);
      if (!(j_max >= 0.0))
        problems.push_back({"", 0, "--jmax", "must be >= 0 (0: no jerk limit)" + axis});
      else if (j_max > 0.0 && (j_max < kMinLimit || j_max > kMaxLimit))
        problems.push_back({"", 0, "--jmax", "out of range" + axis + limit_range + ", or 0"});
    }
  }
  if (!problems.empty()) throw InputError(problems);
  // the jerk limits (0: none); "j_max" is reported once any axis has one
  bool any_jerk_limit = false;
  for (size_t i = 0; i < axes; ++i) {
    if (!request.j_max.empty()) moves[i].j_max = value_for_axis(request.j_max, i);
    any_jerk_limit = any_jerk_limit || moves[i].j_max > 0.0;
  }
  const SynchronizedMove move = synchronized_move(moves);

  Json out;
  out["duration_s"] = move.duration_s;
  Json axes_json = Json::array();
  for (size_t i = 0; i < axes; ++i) {
    const AxisMove& m = moves[i];
    Json axis{{"q0", m.boundary.q0}, {"q1", m.boundary.q1}, {"v0", m.boundary.v0},
              {"v1", m.boundary.v1}, {"v_max", m.v_max},    {"a_max", m.a_max}};
    if (any_jerk_limit) axis["j_max"] = m.j_max;
    axis["min_duration_s"] = axis_feasible_durations(m).t_min();
    axis["phases"] = phases_json(move.axes[i], m.j_max > 0.0);
    axes_json.push_back(axis);
  }
  out["axes"] = axes_json;
  return out;
}

}  // namespace depotwin
