#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/error.hpp"
#include "planners/motion/bezier/bezier.hpp"
#include "planners/motion/conformal.hpp"
#include "planners/motion/firmware.hpp"
#include "planners/motion/lspb_mtt.hpp"
#include "planners/motion/stop_and_go.hpp"
#include "planners/motion/uniform/uniform_planner.hpp"
#include "planners/planner.hpp"

namespace depotwin {

double PlannerSpec::get(const std::string& key, double fallback) const {
  auto it = params.find(key);
  return it == params.end() || it->second.empty() ? fallback : it->second.front();
}

bool PlannerSpec::get_switch(const std::string& key, bool fallback) const {
  const double value = get(key, fallback ? 1.0 : 0.0);
  if (value != 0.0 && value != 1.0)
    throw InputError("planners." + name + "." + key, "must be 0 or 1");
  return value == 1.0;
}

std::string PlannerSpec::get_choice(const std::string& key, const std::string& fallback) const {
  auto it = choices.find(key);
  return it == choices.end() ? fallback : it->second;
}

const std::vector<PlannerInfo>& planner_registry() {
  static const std::vector<PlannerInfo> registry = {
      {"lspb_mtt",
       "Thompson & Yoon 2014: LSPB on print segments, minimum-time transitions",
       {},
       [](const PlannerSpec&) { return std::make_unique<LspbMttPlanner>(); },
       /*honours_jerk_limit=*/true},
      {"stop_and_go",
       "naive baseline: rest-to-rest trapezoid per print segment, material on throughout",
       {},
       [](const PlannerSpec&) { return std::make_unique<StopAndGoPlanner>(); },
       /*honours_jerk_limit=*/true},
      {"bezier", "Giberti et al. 2017: lines with Bezier corner blends at constant speed",
       bezier_parameters(), [](const PlannerSpec& spec) { return make_bezier_planner(spec); },
       /*honours_jerk_limit=*/true, /*consumes_arcs=*/true},
      {"conformal",
       "Shembekar et al. 2018: conformal paths flown by with zone blends, time-optimal under TCP "
       "and joint limits (TOPP-RA), speed and flow control",
       conformal_parameters(), [](const PlannerSpec& spec) { return make_conformal_planner(spec); },
       /*honours_jerk_limit=*/true},
      {"firmware",
       "the printer's own firmware as baseline: Marlin (junction deviation) or Klipper "
       "(square-corner velocity) trapezoidal look-ahead, material on while printing",
       firmware_parameters(), [](const PlannerSpec& spec) { return make_firmware_planner(spec); },
       /*honours_jerk_limit=*/true},
      {"uniform",
       "beyond the papers: deposit-aware, time-optimal and jerk-limited; clothoid corner blends "
       "within tolerance_mm (a chorded circle's corners that cannot keep the print speed one by "
       "one: one clothoid-arc-clothoid curve; a hole printed from rest to rest: one such curve "
       "with its speed changing on it), each corner blended, slowed, looped "
       "(aerosol: the shutter closed at print speed; extrusion: rest to rest with the flow off) "
       "or stopped (extrusion) by the predicted thickness error plus time_weight x time "
       "(aerosol: or a whole chain at one constant speed, by the same cost), extrusion flow led "
       "by the nozzle lag (pressure advance)",
       uniform_parameters(), [](const PlannerSpec& spec) { return make_uniform_planner(spec); },
       true, /*consumes_arcs=*/true},
  };
  return registry;
}

const PlannerInfo* find_planner(const std::string& name) {
  for (const PlannerInfo& info : planner_registry())
    if (info.name == name) return &info;
  return nullptr;
}

std::string check_planner_spec(const PlannerSpec& spec) {
  const PlannerInfo* info = find_planner(spec.name);
  if (!info) {
    std::string known;
    for (const PlannerInfo& p : planner_registry()) known += (known.empty() ? "" : ", ") + p.name;
    return "unknown planner '" + spec.name + "' (known: " + known + ")";
  }
  const auto find_parameter = [&](const std::string& key) -> const PlannerParameter* {
    auto it = std::find_if(info->parameters.begin(), info->parameters.end(),
                           [&](const PlannerParameter& p) { return p.name == key; });
    return it == info->parameters.end() ? nullptr : &*it;
  };
  const auto unknown = [&](const std::string& key) {
    std::string known;
    for (const PlannerParameter& p : info->parameters)
      known += (known.empty() ? "" : ", ") + p.name;
    return "planner '" + spec.name + "' has no parameter '" + key + "'" +
           (known.empty() ? std::string(" (it takes none)") : " (known: " + known + ")");
  };
  const auto choice_list = [](const PlannerParameter& p) {
    std::string list;
    for (const std::string& c : p.choices) list += (list.empty() ? "" : " | ") + c;
    return list;
  };
  for (const auto& [key, word] : spec.choices) {
    const PlannerParameter* parameter = find_parameter(key);
    if (!parameter) return unknown(key);
    if (parameter->choices.empty()) return "parameter '" + key + "' takes a number, not a word";
    if (std::find(parameter->choices.begin(), parameter->choices.end(), word) ==
        parameter->choices.end())
      return "parameter '" + key + "' = '" + word + "' is not one of " + choice_list(*parameter);
  }
  for (const auto& [key, values] : spec.params) {
    const PlannerParameter* it = find_parameter(key);
    if (!it) return unknown(key);
    if (!it->choices.empty())
      return "parameter '" + key + "' takes one of " + choice_list(*it) + ", not a number";
    if (values.empty()) return "parameter '" + key + "' has no value";
    if (values.size() > 1 && !it->list_allowed)
      return "parameter '" + key + "' takes a single number, not a list";
    for (double v : values) {
      if (!std::isfinite(v) || v < it->min_value || v > it->max_value) {
        std::ostringstream msg;
        msg << "parameter '" << key << "' = " << v << " is outside [" << it->min_value << ", "
            << it->max_value << "]";
        return msg.str();
      }
      // a switch or a count takes whole numbers only
      if (it->whole_number && std::floor(v) != v) {
        std::ostringstream msg;
        msg << "parameter '" << key << "' = " << v << " must be a whole number in ["
            << it->min_value << ", " << it->max_value << "]";
        return msg.str();
      }
    }
  }
  return "";
}

std::string check_planner_limits(const PlannerSpec& spec, const MachineLimits& limits) {
  const PlannerInfo* info = find_planner(spec.name);
  if (info == nullptr || info->honours_jerk_limit || !limits.jerk_limited()) return "";
  std::string honouring;
  for (const PlannerInfo& p : planner_registry())
    if (p.honours_jerk_limit) honouring += (honouring.empty() ? "" : ", ") + p.name;
  return "planner '" + spec.name +
         "' does not honour j_max (its motion is acceleration-limited only); remove j_max from "
         "limits or use a planner that honours it (" +
         honouring + ")";
}

std::unique_ptr<Planner> make_planner(const PlannerSpec& spec) {
  const std::string problem = check_planner_spec(spec);
  if (!problem.empty()) throw InputError("planners", problem);
  return find_planner(spec.name)->make(spec);
}

}  // namespace depotwin
