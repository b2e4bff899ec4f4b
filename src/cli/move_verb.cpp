#include "cli/move_verb.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "core/error.hpp"
#include "core/input_ranges.hpp"
#include "core/number_text.hpp"
#include "motion/sync.hpp"

namespace depotwin {

std::vector<double> parse_number_list(const std::string& text, const std::string& option) {
  std::vector<double> values;
  // (getline drops an empty last item: "0," would read as one value)
  if (!text.empty() && text.back() == ',')
    throw InputError(option, "'" + printable_text(text) +
                                 "' ends with a comma: a value is missing (expected e.g. 0,5.5)");
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    // the whole item as a number, whatever the locale
    const std::optional<double> value = parse_double(item);
    if (!value || !std::isfinite(*value))
      throw InputError(
          option, "'" + printable_text(item) + "' is not a finite number (expected e.g. 0,5.5)");
    values.push_back(*value);
  }
  if (values.empty()) throw InputError(option, "no value given");
  return values;
}

namespace {

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

  // per axis: limits and boundary velocities within the ranges a scenario accepts
  // (core/input_ranges.hpp), then the synchronised move
  namespace ranges = input_ranges;
  const auto within = [](double value, double lo, double hi) { return value >= lo && value <= hi; };
  const auto range_text = [](double lo, double hi) {
    return "in [" + message_number(lo) + ", " + message_number(hi) + "]";
  };
  std::vector<AxisMove> moves(axes);
  for (size_t i = 0; i < axes; ++i) {
    AxisMove& m = moves[i];
    m.boundary = AxisBoundary{value_for_axis(request.q0, i), value_for_axis(request.q1, i),
                              value_for_axis(request.v0, i), value_for_axis(request.v1, i)};
    m.v_max = value_for_axis(request.v_max, i);
    m.a_max = value_for_axis(request.a_max, i);
    const std::string axis = " (axis " + std::to_string(i) + ")";
    // a value outside [lo, hi] with the digits that tell it from the end it passes
    const auto got = [&](double value, double lo, double hi) {
      return ", got " + message_number_outside(value, lo, hi) + axis;
    };
    for (const auto& [name, q] : {std::pair<const char*, double>{"--q0", m.boundary.q0},
                                  std::pair<const char*, double>{"--q1", m.boundary.q1}})
      if (!within(q, -ranges::kMaxCoordinate_mm, ranges::kMaxCoordinate_mm))
        problems.push_back(
            {"", 0, name,
             "must be " + range_text(-ranges::kMaxCoordinate_mm, ranges::kMaxCoordinate_mm) +
                 " mm" + got(q, -ranges::kMaxCoordinate_mm, ranges::kMaxCoordinate_mm)});
    const bool v_ok = within(m.v_max, ranges::kMinLimit, ranges::kMaxSpeed_mm_s);
    if (!v_ok)
      problems.push_back({"", 0, "--vmax",
                          "must be " + range_text(ranges::kMinLimit, ranges::kMaxSpeed_mm_s) +
                              " mm/s" + got(m.v_max, ranges::kMinLimit, ranges::kMaxSpeed_mm_s)});
    if (!within(m.a_max, ranges::kMinLimit, ranges::kMaxAcceleration_mm_s2))
      problems.push_back(
          {"", 0, "--amax",
           "must be " + range_text(ranges::kMinLimit, ranges::kMaxAcceleration_mm_s2) + " mm/s^2" +
               got(m.a_max, ranges::kMinLimit, ranges::kMaxAcceleration_mm_s2)});
    // a boundary speed over v_max, with the digits that tell them apart
    for (const auto& [name, v] : {std::pair<const char*, double>{"--v0", m.boundary.v0},
                                  std::pair<const char*, double>{"--v1", m.boundary.v1}})
      if (v_ok && std::abs(v) > m.v_max)
        problems.push_back({"", 0, name,
                            std::string("|") + (name + 2) + "| exceeds v_max " +
                                message_number(m.v_max) + ", got " +
                                message_number_beside(v, std::copysign(m.v_max, v)) + axis});
    if (!request.j_max.empty()) {
      const double j_max = value_for_axis(request.j_max, i);
      if (!(j_max == 0.0 || within(j_max, ranges::kMinLimit, ranges::kMaxJerk_mm_s3)))
        problems.push_back({"", 0, "--jmax",
                            "must be 0 (no jerk limit) or " +
                                range_text(ranges::kMinLimit, ranges::kMaxJerk_mm_s3) + " mm/s^3" +
                                got(j_max, ranges::kMinLimit, ranges::kMaxJerk_mm_s3)});
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
