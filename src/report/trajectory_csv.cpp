#include "report/trajectory_csv.hpp"

#include <cstdio>

#include "core/error.hpp"
#include "core/interrupt.hpp"

namespace depotwin {

namespace {

// one row's planned columns; %.9g keeps nm / um-per-s resolution and a stable text
void append_planned(std::string& out, const MotionSamples& s, size_t k) {
  char line[320];
  const Vec3& p = s.position_mm[k];
  const Vec3& v = s.velocity_mm_s[k];
  std::snprintf(line, sizeof line, "%.6f,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%d,%d,%.9g", s.t_s[k],
                p.x(), p.y(), p.z(), v.x(), v.y(), v.z(), v.norm(), s.depositing[k],
                s.path_index[k], s.desired_speed_mm_s[k]);
  out += line;
}

// rows written between two looks at the interrupt flag
constexpr size_t kInterruptCheckRows = 4096;

}  // namespace

std::string planned_trajectory_csv(const MotionSamples& planned) {
  std::string out = std::string(kPlannedColumns) + "\n";
  out.reserve(planned.size() * 110);
  for (size_t k = 0; k < planned.size(); ++k) {
    append_planned(out, planned, k);
    out += '\n';
  }
  return out;
}

std::string planned_and_simulated_csv(const MotionSamples& planned,
                                      const MotionSamples& simulated) {
  if (planned.size() != simulated.size())
    throw InternalError("trajectory.csv: planned and simulated samples differ in count");
  std::string out = std::string(kPlannedColumns) + "," + kSimulatedColumns + "\n";
  out.reserve(planned.size() * 200);
  for (size_t k = 0; k < planned.size(); ++k) {
    // a long job's file takes seconds: a signal that asked to stop ends it (core/interrupt.hpp)
    if (k % kInterruptCheckRows == 0) throw_if_interrupted();
    append_planned(out, planned, k);
    char line[200];
    const Vec3& p = simulated.position_mm[k];
    const Vec3& v = simulated.velocity_mm_s[k];
    std::snprintf(line, sizeof line, ",%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", p.x(), p.y(), p.z(),
                  v.x(), v.y(), v.z(), v.norm());
    out += line;
  }
  return out;
}

}  // namespace depotwin
