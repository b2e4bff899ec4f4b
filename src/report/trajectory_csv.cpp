#include "report/trajectory_csv.hpp"

#include <string>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/number_text.hpp"

namespace depotwin {

namespace {

// Every number as printf's "%.9g" would write it (the time as "%.6f"), by
// core/number_text.hpp's std::to_chars: a long job's file has millions of numbers. %.9g keeps
// nm / um-per-s resolution and a stable text.

// a comma before each of the vector's three components (and its norm)
void append_vector_and_norm(std::string& out, const Vec3& v, bool with_norm) {
  for (int i = 0; i < 3; ++i) {
    out += ',';
    append_number(out, v[i], 9);
  }
  if (with_norm) {
    out += ',';
    append_number(out, v.norm(), 9);
  }
}

// one row's planned columns
void append_planned(std::string& out, const MotionSamples& s, size_t k) {
  append_fixed(out, s.t_s[k], 6);
  append_vector_and_norm(out, s.position_mm[k], false);
  append_vector_and_norm(out, s.velocity_mm_s[k], true);
  out += ',';
  out += std::to_string(s.depositing[k]);
  out += ',';
  out += std::to_string(s.path_index[k]);
  out += ',';
  append_number(out, s.desired_speed_mm_s[k], 9);
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
    append_vector_and_norm(out, simulated.position_mm[k], false);
    append_vector_and_norm(out, simulated.velocity_mm_s[k], true);
    out += '\n';
  }
  return out;
}

}  // namespace depotwin
