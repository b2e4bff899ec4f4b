// metrics.json: the key names are a contract (docs/ARCHITECTURE.md); keys are written in a
// fixed order so that the same run gives a byte-identical file. Planned figures are named
// planned_*; the contract's motion keys (velocity_error, path_error_mm) are simulated and
// appear only once a simulation ran. A final "units" block has the same shape as the
// report with every number replaced by its unit ("layers": one object for every layer; a
// per-joint array: one unit per joint).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "metrics/metrics_report.hpp"

namespace depotwin {

nlohmann::ordered_json to_json(const MetricsReport& report);
nlohmann::ordered_json to_json(const VelocityErrorStats& stats);
std::string metrics_json_text(const MetricsReport& report);

}  // namespace depotwin
