// Helpers for the deposition tests: drive a process along a motion given as functions of
// time, and compare fields cell by cell.
#pragma once

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

#include "core/toolpath.hpp"
#include "deposition/process.hpp"
#include "deposition/thickness_field.hpp"

namespace depotwin::test {

// advance `process` from t_begin to t_end in steps of dt; position(t) -> Vec3,
// open(t) -> aerosol open fraction, command(t) -> extrusion command, speed(t) -> desired speed
template <class PositionFn, class OpenFn, class CommandFn, class SpeedFn>
void drive(Process& process, double t_begin_s, double t_end_s, double dt_s,
           const PositionFn& position, const OpenFn& open, const CommandFn& command,
           const SpeedFn& speed) {
  const long long steps = std::llround((t_end_s - t_begin_s) / dt_s);
  for (long long k = 0; k < steps; ++k) {
    DepositionStep step;
    step.t0_s = t_begin_s + static_cast<double>(k) * dt_s;
    step.t1_s = t_begin_s + static_cast<double>(k + 1) * dt_s;
    step.p0_mm = position(step.t0_s);
    step.p1_mm = position(step.t1_s);
    step.open0 = open(step.t0_s);
    step.open1 = open(step.t1_s);
    // the command that holds during the step: its value at the step's midpoint
    const double t_mid = 0.5 * (step.t0_s + step.t1_s);
    step.flow_command = command(t_mid);
    step.desired_speed_mm_s = speed(t_mid);
    process.advance(step);
  }
}

// largest |a - b| over every cell either field holds (mm)
inline double max_abs_difference(const ThicknessField& a, const ThicknessField& b) {
  std::set<std::pair<int, int>> tiles;
  for (const auto& t : a.tiles().sorted_tiles()) tiles.insert(t);
  for (const auto& t : b.tiles().sorted_tiles()) tiles.insert(t);
  constexpr int kSize = ThicknessField::Tiles::kSize;
  double worst = 0.0;
  for (const auto& [tx, ty] : tiles) {
    const double* ta = a.tiles().find(tx, ty);
    const double* tb = b.tiles().find(tx, ty);
    for (int k = 0; k < kSize * kSize; ++k) {
      const double va = ta ? ta[k] : 0.0;
      const double vb = tb ? tb[k] : 0.0;
      worst = std::max(worst, std::abs(va - vb));
    }
  }
  return worst;
}

// largest cell value (mm)
inline double max_value(const ThicknessField& field) {
  double peak = 0.0;
  constexpr int kSize = ThicknessField::Tiles::kSize;
  for (const auto& [tx, ty] : field.tiles().sorted_tiles()) {
    const double* tile = field.tiles().find(tx, ty);
    for (int k = 0; k < kSize * kSize; ++k) peak = std::max(peak, tile[k]);
  }
  return peak;
}

// a toolpath of one straight print path from a to b (xy, mm)
inline Toolpath straight_toolpath(double ax, double ay, double bx, double by, double speed) {
  Toolpath toolpath;
  PrintPath path;
  path.points = {Vec3(ax, ay, 0.0), Vec3(bx, by, 0.0)};
  path.speed_mm_s = speed;
  toolpath.paths.push_back(path);
  toolpath.start_mm = path.points.front();
  toolpath.end_mm = path.points.back();
  return toolpath;
}

}  // namespace depotwin::test
