#include "planners/motion/bezier/bezier_profile.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/error.hpp"
#include "core/number_text.hpp"

namespace depotwin {

int GridProfile::total_steps() const {
  int total = 0;
  for (const GridPhase& phase : phases) total += phase.steps;
  return total;
}

void GridProfile::at_step(int step, double period_s, double& speed_mm_s,
                          double& accel_mm_s2) const {
  // walk the phases, accumulating the speed at each phase start
  double v = v_start_mm_s;
  for (const GridPhase& phase : phases) {
    if (step < phase.steps) {
      speed_mm_s = v + phase.accel_mm_s2 * step * period_s;
      accel_mm_s2 = phase.accel_mm_s2;
      return;
    }
    step -= phase.steps;
    v += phase.accel_mm_s2 * phase.steps * period_s;
  }
  speed_mm_s = v_after_mm_s;
  accel_mm_s2 = 0.0;
}

double GridProfile::distance_mm(double period_s) const {
  double v = v_start_mm_s, distance = 0.0;
  for (const GridPhase& phase : phases) {
    const double duration = phase.steps * period_s;
    distance += v * duration + 0.5 * phase.accel_mm_s2 * duration * duration;
    v += phase.accel_mm_s2 * duration;
  }
  return distance;
}

double GridProfile::distance_after(int steps, double period_s) const {
  double v = v_start_mm_s, distance = 0.0;
  for (const GridPhase& phase : phases) {
    const int taken = std::min(steps, phase.steps);
    const double duration = taken * period_s;
    distance += v * duration + 0.5 * phase.accel_mm_s2 * duration * duration;
    v += phase.accel_mm_s2 * duration;
    steps -= taken;
  }
  return distance + v_after_mm_s * steps * period_s;
}

namespace {

// sample periods needed to change speed by dv at acceleration a (exact multiples stay exact);
// a count beyond an int (a tiny a_max or period) is refused before it is converted
int steps_for(double dv, double a, double period_s) {
  const double steps = std::ceil(std::abs(dv) / (a * period_s) - 1e-9);
  if (!(steps <= 1e9))
    throw InputError("limits.a_max",
                     "bezier: changing speed by " + message_number(std::abs(dv)) + " mm/s at " +
                         message_number(a) +
                         " mm/s^2 takes more than 1e9 samples of its period; raise a_max or the "
                         "period_s");
  return static_cast<int>(steps);
}

double phase_accel(double dv, int steps, double period_s) {
  return steps > 0 ? dv / (steps * period_s) : 0.0;
}

// cruise steps are counted in int; a peak this slow for this far is not a plan
constexpr double kMaxSteps = 1e9;

// ramp to v_peak, cruise, ramp to v_out, then cruise at v_out to the line end
std::optional<GridProfile> open_end_profile(double distance, double v_in, double v_out,
                                            double v_peak, double a, double period) {
  if (!(v_peak > 0.0)) return std::nullopt;
  const int n1 = steps_for(v_peak - v_in, a, period);
  const int n2 = steps_for(v_peak - v_out, a, period);
  const double d1 = 0.5 * (v_in + v_peak) * n1 * period;
  const double d2 = 0.5 * (v_peak + v_out) * n2 * period;
  double rest = distance - d1 - d2;
  if (rest < -1e-12 * (1.0 + distance)) return std::nullopt;
  rest = std::max(rest, 0.0);
  const double cruise_steps = std::floor(rest / (v_peak * period));
  if (cruise_steps > kMaxSteps) return std::nullopt;
  GridProfile profile;
  profile.v_start_mm_s = v_in;
  profile.phases[0] = {n1, phase_accel(v_peak - v_in, n1, period)};
  profile.phases[1] = {static_cast<int>(cruise_steps), 0.0};
  profile.phases[3] = {n2, phase_accel(v_out - v_peak, n2, period)};
  profile.v_after_mm_s = v_out;
  return profile;
}

// ramp to v_peak, cruise, knee from v_peak to x, ramp from x to v_out ending exactly at the
// line end: the knee's depth x absorbs the part of a cruise step the grid cannot hold
std::optional<GridProfile> exact_end_profile(double distance, double v_in, double v_out,
                                             double v_peak, double a, double period) {
  if (!(v_peak > 0.0)) return std::nullopt;
  const int n1 = steps_for(v_peak - v_in, a, period);
  const double d1 = 0.5 * (v_in + v_peak) * n1 * period;
  int n2 = std::max(1, steps_for(v_peak - v_out, a, period));
  int knee = 1;
  // the knee and the ramp together must be able to absorb one full cruise step
  double x_low = 0.0;
  for (int guard = 0; guard < 1000000; ++guard) {
    const double by_knee = v_peak - knee * a * period;
    const double by_ramp = v_out - n2 * a * period;
    x_low = std::max({by_knee, by_ramp, 0.0});
    const double width = 0.5 * (knee + n2) * period * (v_peak - x_low);
    if (width >= v_peak * period) break;
    if (by_ramp > by_knee && by_ramp > 0.0)
      ++n2;
    else
      ++knee;
  }
  // distance covered by knee + ramp as a function of the knee's end speed x
  auto tail = [&](double x) {
    return 0.5 * knee * period * (v_peak + x) + 0.5 * n2 * period * (x + v_out);
  };
  const double after_ramp = distance - d1;
  const double tolerance = 1e-12 * (1.0 + distance);
  if (after_ramp < tail(x_low) - tolerance) return std::nullopt;
  double cruise_steps = 0.0;
  if (after_ramp > tail(v_peak))
    cruise_steps = std::ceil((after_ramp - tail(v_peak)) / (v_peak * period));
  if (cruise_steps > kMaxSteps) return std::nullopt;
  const double rest = after_ramp - cruise_steps * v_peak * period;
  double x = (rest - 0.5 * knee * period * v_peak - 0.5 * n2 * period * v_out) /
             (0.5 * (knee + n2) * period);
  x = std::clamp(x, x_low, v_peak);
  GridProfile profile;
  profile.v_start_mm_s = v_in;
  profile.phases[0] = {n1, phase_accel(v_peak - v_in, n1, period)};
  profile.phases[1] = {static_cast<int>(cruise_steps), 0.0};
  profile.phases[2] = {knee, phase_accel(x - v_peak, knee, period)};
  profile.phases[3] = {n2, phase_accel(v_out - x, n2, period)};
  profile.v_after_mm_s = v_out;
  return profile;
}

}  // namespace

std::optional<GridProfile> plan_grid_profile(double distance_mm, double v_in_mm_s,
                                             double v_out_mm_s, double v_cap_mm_s,
                                             double a_max_mm_s2, double period_s, bool exact_end) {
  exact_end = exact_end || !(v_out_mm_s > 0.0);
  // already at the end: only possible when no speed change is asked for
  if (exact_end && distance_mm <= 1e-12) {
    if (std::abs(v_in_mm_s - v_out_mm_s) > 1e-9) return std::nullopt;
    GridProfile profile;
    profile.v_start_mm_s = v_in_mm_s;
    profile.v_after_mm_s = v_out_mm_s;
    return profile;
  }
  auto attempt = [&](double v_peak) {
    return exact_end ? exact_end_profile(distance_mm, v_in_mm_s, v_out_mm_s, v_peak, a_max_mm_s2,
                                         period_s)
                     : open_end_profile(distance_mm, v_in_mm_s, v_out_mm_s, v_peak, a_max_mm_s2,
                                        period_s);
  };
  // candidate peaks from the cap down, plus the boundary speeds themselves
  constexpr int kScan = 256;
  std::vector<double> candidates;
  candidates.reserve(kScan + 3);
  for (int i = 0; i < kScan; ++i) candidates.push_back(v_cap_mm_s * (1.0 - double(i) / kScan));
  for (double v : {v_in_mm_s, v_out_mm_s, std::max(v_in_mm_s, v_out_mm_s)})
    if (v > 0.0 && v <= v_cap_mm_s) candidates.push_back(v);
  std::sort(candidates.begin(), candidates.end(), std::greater<double>());
  // the first feasible one, then bisect towards the infeasible one above it
  for (size_t i = 0; i < candidates.size(); ++i) {
    std::optional<GridProfile> found = attempt(candidates[i]);
    if (!found) continue;
    if (i == 0) return found;
    double low = candidates[i], high = candidates[i - 1];
    for (int iteration = 0; iteration < 40; ++iteration) {
      const double mid = 0.5 * (low + high);
      if (std::optional<GridProfile> better = attempt(mid)) {
        found = better;
        low = mid;
      } else {
        high = mid;
      }
    }
    return found;
  }
  return std::nullopt;
}

double reachable_speed(double v_mm_s, double length_mm, double a_max_mm_s2, double period_s) {
  // v'^2 + 8 a T v' <= v^2 + 2 a L (the ramp plus 4 periods at the higher speed v'), or
  // no change of speed at all
  const double margin = 4.0 * a_max_mm_s2 * period_s;
  const double ramped =
      std::sqrt(margin * margin + 2.0 * a_max_mm_s2 * std::max(length_mm, 0.0) + v_mm_s * v_mm_s) -
      margin;
  return std::max(v_mm_s, ramped);
}

}  // namespace depotwin
