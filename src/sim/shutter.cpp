#include "sim/shutter.hpp"

#include <algorithm>

#include "core/error.hpp"

namespace depotwin {

double shutter_open_fraction(double angle_rad, const ShutterGeometry& geometry) {
  const double travel = geometry.open_angle_rad - geometry.closed_angle_rad;
  const double fraction = (angle_rad - geometry.closed_angle_rad) / travel;
  return std::clamp(fraction, 0.0, 1.0);
}

ShutterReference::ShutterReference(const Trajectory& trajectory, double time_s, double overtravel)
    : time_s_(time_s), overtravel_(overtravel) {
  if (!(time_s > 0.0)) throw InternalError("shutter open/close time must be positive");
  if (!(overtravel >= 0.0)) throw InternalError("shutter overtravel must be >= 0");
  // depositing pieces, touching ones merged into one interval
  for (const TrajectoryPiece& piece : trajectory.pieces()) {
    if (!piece.depositing || piece.t_end_s <= piece.t_begin_s) continue;
    if (!intervals_.empty() && piece.t_begin_s <= intervals_.back().second + 1e-12)
      intervals_.back().second = std::max(intervals_.back().second, piece.t_end_s);
    else
      intervals_.emplace_back(piece.t_begin_s, piece.t_end_s);
  }
}

bool ShutterReference::depositing_at(double t_s) const {
  // first interval ending after t
  auto it = std::upper_bound(
      intervals_.begin(), intervals_.end(), t_s,
      [](double t, const std::pair<double, double>& interval) { return t < interval.second; });
  return it != intervals_.end() && it->first <= t_s;
}

double ShutterReference::overlap(double from_s, double to_s) const {
  double total = 0.0;
  auto it = std::upper_bound(
      intervals_.begin(), intervals_.end(), from_s,
      [](double t, const std::pair<double, double>& interval) { return t < interval.second; });
  for (; it != intervals_.end() && it->first < to_s; ++it)
    total += std::min(to_s, it->second) - std::max(from_s, it->first);
  return total;
}

void ShutterReference::at(double t_s, double& travel_fraction, double& rate_1_s) const {
  // r(t) = -e + overlap(window) / T over the window [t - e T, t + (1 + e) T]
  const double window_begin = t_s - overtravel_ * time_s_;
  const double window_end = t_s + (1.0 + overtravel_) * time_s_;
  travel_fraction = -overtravel_ + overlap(window_begin, window_end) / time_s_;
  // dr/dt = (d(window end) - d(window begin)) / T
  rate_1_s = ((depositing_at(window_end) ? 1.0 : 0.0) - (depositing_at(window_begin) ? 1.0 : 0.0)) /
             time_s_;
}

double ShutterReference::open_fraction(double t_s) const {
  double fraction = 0.0, rate = 0.0;
  at(t_s, fraction, rate);
  return std::clamp(fraction, 0.0, 1.0);
}

}  // namespace depotwin
