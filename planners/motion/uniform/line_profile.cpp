#include "planners/motion/uniform/line_profile.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/error.hpp"

namespace depotwin {

namespace {

// the lag rule's stages: each ends at r times its start speed, down to kLagFloor of the first
constexpr double kLagStageRatio = 0.7;
constexpr double kLagFloor = 0.02;
constexpr int kBisections = 80;

// one S-curve (no staging): duration, and its phases appended
double s_curve_time(double dv, double a, double j) {
  dv = std::abs(dv);
  if (dv <= 0.0) return 0.0;
  return dv * j <= a * a ? 2.0 * std::sqrt(dv / j) : dv / a + a / j;
}

void append_s_curve(AxisProfile& profile, double v0, double v1, double a, double j) {
  const double dv = std::abs(v1 - v0);
  if (dv <= 0.0) return;
  const double sign = v1 > v0 ? 1.0 : -1.0;
  if (dv * j <= a * a) {
    const double t = std::sqrt(dv / j);
    profile.append_jerk(t, sign * j);
    profile.append_jerk(t, -sign * j);
  } else {
    const double t = a / j;
    profile.append_jerk(t, sign * j);
    profile.append(dv / a - a / j, sign * a);
    profile.append_jerk(t, -sign * j);
  }
}

// the stages of a speed change: (from, to, acceleration) triples, visited in order
template <class Visit>
void for_each_stage(double v0, double v1, const LineLimits& limits, Visit&& visit) {
  if (v1 >= v0 || limits.lag_s <= 0.0) {
    visit(v0, v1, limits.a_max_mm_s2);
    return;
  }
  // decelerating under the lag rule
  const double floor = std::max(v1, kLagFloor * v0);
  double v = v0;
  while (v > floor) {
    const double next = std::max(floor, kLagStageRatio * v);
    visit(v, next, std::min(limits.a_max_mm_s2, next / limits.lag_s));
    v = next;
  }
  if (v1 < floor) visit(floor, v1, limits.a_max_mm_s2);
}

}  // namespace

double speed_change_duration(double v0, double v1, const LineLimits& limits) {
  double total = 0.0;
  for_each_stage(v0, v1, limits, [&](double a, double b, double acc) {
    total += s_curve_time(b - a, acc, limits.j_max_mm_s3);
  });
  return total;
}

double speed_change_distance(double v0, double v1, const LineLimits& limits) {
  double total = 0.0;
  for_each_stage(v0, v1, limits, [&](double a, double b, double acc) {
    total += 0.5 * (a + b) * s_curve_time(b - a, acc, limits.j_max_mm_s3);
  });
  return total;
}

void append_speed_change(AxisProfile& profile, double v0, double v1, const LineLimits& limits) {
  for_each_stage(v0, v1, limits, [&](double a, double b, double acc) {
    append_s_curve(profile, a, b, acc, limits.j_max_mm_s3);
  });
}

double reachable_speed(double other, double length, double cap, const LineLimits& limits,
                       bool at_start) {
  const auto distance = [&](double v) {
    return at_start ? speed_change_distance(v, other, limits)
                    : speed_change_distance(other, v, limits);
  };
  if (cap <= other) return cap;
  if (distance(cap) <= length) return cap;
  double lo = other, hi = cap;
  for (int k = 0; k < kBisections; ++k) {
    const double mid = 0.5 * (lo + hi);
    (distance(mid) <= length ? lo : hi) = mid;
  }
  return lo;
}

AxisProfile line_profile(double length, double v0, double v1, const LineLimits& limits) {
  const auto needed = [&](double peak) {
    return speed_change_distance(v0, peak, limits) + speed_change_distance(peak, v1, limits);
  };
  const double lowest = std::max(v0, v1);
  const double cap = std::max(lowest, limits.v_max_mm_s);
  if (needed(lowest) > length * (1 + 1e-9) + 1e-12) {
    std::ostringstream msg;
    msg << "uniform: a line of " << length << " mm cannot join " << v0 << " and " << v1 << " mm/s";
    throw InternalError(msg.str());
  }
  // the highest peak that fits, then the cruise that fills the line
  double peak = cap;
  if (needed(cap) > length) {
    double lo = lowest, hi = cap;
    for (int k = 0; k < kBisections; ++k) {
      const double mid = 0.5 * (lo + hi);
      (needed(mid) <= length ? lo : hi) = mid;
    }
    peak = lo;
  }
  AxisProfile profile(0.0, v0, 0.0);
  append_speed_change(profile, v0, peak, limits);
  const double cruise = std::max(0.0, length - needed(peak));
  if (cruise > 0.0 && peak > 0.0) profile.append(cruise / peak, 0.0);
  append_speed_change(profile, peak, v1, limits);
  return profile;
}

}  // namespace depotwin
