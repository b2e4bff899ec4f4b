// metrics.json: the key names are a contract (docs/ARCHITECTURE.md); keys are written in a
// fixed order so that the same run gives a byte-identical file.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "metrics/metrics_report.hpp"

namespace depotwin {

nlohmann::ordered_json to_json(const MetricsReport& report);
nlohmann::ordered_json to_json(const VelocityErrorStats& stats);
std::string metrics_json_text(const MetricsReport& report);

}  // namespace depotwin
