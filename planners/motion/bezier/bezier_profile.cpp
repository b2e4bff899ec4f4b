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

// The peak speeds a profile tries, highest first: 256 from the cap down, halvings below the
// lowest of those down to 2^-60 of it (a line too short for a 256th of the cap: 1e-5 mm at
// 3 mm/s, where one period at 3/256 mm/s is 1.2e-5 mm, had no profile, an internal error), and
// the boundary speeds themselves
std::vector<double> peak_candidates(double v_cap_mm_s, double v_in_mm_s, double v_out_mm_s) {
  constexpr int kScan = 256, kScanBelow = 60;
  std::vector<double> candidates;
  candidates.reserve(kScan + kScanBelow + 3);
  for (int i = 0; i < kScan; ++i) candidates.push_back(v_cap_mm_s * (1.0 - double(i) / kScan));
  for (int k = 1; k <= kScanBelow; ++k) candidates.push_back(std::ldexp(v_cap_mm_s / kScan, -k));
  for (double v : {v_in_mm_s, v_out_mm_s, std::max(v_in_mm_s, v_out_mm_s)})
    if (v > 0.0 && v <= v_cap_mm_s) candidates.push_back(v);
  std::sort(candidates.begin(), candidates.end(), std::greater<double>());
  return candidates;
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
  const std::vector<double> candidates = peak_candidates(v_cap_mm_s, v_in_mm_s, v_out_mm_s);
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

// ---------------------------------------------------------------------------------------
// jerk-limited grid profiles

namespace depotwin {

namespace {

// a step count beyond this is no plan (int steps, as the cruise's)
constexpr double kMaxJerkSteps = 1e9;

// distance of a grid S-curve between speeds va and vb
double s_curve_distance(double va, double vb, const GridSCurve& curve, double period_s) {
  return 0.5 * (va + vb) * curve.steps() * period_s;
}

}  // namespace

bool GridSCurve::holds(double dv, double a_max, double j_max, double period_s) const {
  dv = std::abs(dv);
  if (steps() == 0) return dv <= 1e-12;
  if (n_jerk <= 0) return false;
  const double m = n_jerk + n_flat;
  return dv / (m * period_s) <= a_max * (1 + 1e-9) &&
         dv / (n_jerk * m * period_s * period_s) <= j_max * (1 + 1e-9);
}

GridSCurve grid_s_curve(double dv, double a_max, double j_max, double period_s) {
  dv = std::abs(dv);
  if (dv == 0.0) return {};
  // n_jerk + n_flat >= dv / (a T), n_jerk (n_jerk + n_flat) >= dv / (j T^2); the continuous
  // optimum has n_jerk = min(a / j, sqrt(dv / j)) / T, the grid's lies within a few steps of it
  const double accel_steps = dv / (a_max * period_s);
  const double jerk_area = dv / (j_max * period_s * period_s);
  const double ideal = std::min(a_max / (j_max * period_s), std::sqrt(jerk_area));
  if (!(ideal < kMaxJerkSteps) || !(accel_steps < kMaxJerkSteps))
    return {static_cast<int>(kMaxJerkSteps), 0};
  GridSCurve best;
  long long best_total = -1;
  const long long lo = std::max<long long>(1, static_cast<long long>(std::floor(ideal)) - 3);
  const long long hi = static_cast<long long>(std::ceil(ideal)) + 3;
  for (long long n1 = lo; n1 <= hi; ++n1) {
    const long long m = std::max({n1, static_cast<long long>(std::ceil(accel_steps - 1e-9)),
                                  static_cast<long long>(std::ceil(jerk_area / n1 - 1e-9))});
    const long long total = n1 + m;
    if (best_total < 0 || total < best_total) {
      best_total = total;
      best = {static_cast<int>(n1), static_cast<int>(m - n1)};
    }
  }
  return best;
}

int JerkGridProfile::total_steps() const {
  int total = 0;
  for (const JerkPhase& phase : phases) total += phase.steps;
  return total;
}

void JerkGridProfile::at_step(int step, double period_s, double& speed_mm_s, double& accel_mm_s2,
                              double& jerk_mm_s3) const {
  double v = v_start_mm_s, a = 0.0;
  for (const JerkPhase& phase : phases) {
    const double j = phase.jerk_mm_s3;
    if (step < phase.steps) {
      const double t = step * period_s;
      speed_mm_s = v + t * (a + 0.5 * j * t);
      accel_mm_s2 = a + j * t;
      jerk_mm_s3 = j;
      return;
    }
    const double t = phase.steps * period_s;
    v += t * (a + 0.5 * j * t);
    a += j * t;
    step -= phase.steps;
  }
  speed_mm_s = v_after_mm_s;
  accel_mm_s2 = 0.0;
  jerk_mm_s3 = 0.0;
}

double JerkGridProfile::distance_mm(double period_s) const {
  return distance_after(total_steps(), period_s);
}

double JerkGridProfile::distance_after(int steps, double period_s) const {
  double v = v_start_mm_s, a = 0.0, distance = 0.0;
  for (const JerkPhase& phase : phases) {
    const int taken = std::min(steps, phase.steps);
    const double j = phase.jerk_mm_s3, t = taken * period_s;
    distance += t * (v + t * (0.5 * a + j * t / 6.0));
    v += t * (a + 0.5 * j * t);
    a += j * t;
    steps -= taken;
  }
  return distance + v_after_mm_s * steps * period_s;
}

void JerkGridProfile::append_s_curve(const GridSCurve& curve, double dv, double period_s) {
  if (curve.steps() == 0) return;
  if (dv == 0.0 || curve.n_jerk == 0) {
    append_cruise(curve.steps());
    return;
  }
  const double jerk =
      dv / (curve.n_jerk * double(curve.n_jerk + curve.n_flat) * period_s * period_s);
  phases.push_back({curve.n_jerk, jerk});
  if (curve.n_flat > 0) phases.push_back({curve.n_flat, 0.0});
  phases.push_back({curve.n_jerk, -jerk});
}

void JerkGridProfile::append_cruise(int steps) {
  if (steps > 0) phases.push_back({steps, 0.0});
}

std::optional<JerkGridProfile> plan_jerk_grid_profile(double distance_mm, double v_in_mm_s,
                                                      double v_out_mm_s, double v_cap_mm_s,
                                                      double a_max_mm_s2, double j_max_mm_s3,
                                                      double period_s, bool exact_end) {
  const double h = period_s, v_in = v_in_mm_s, v_out = v_out_mm_s;
  exact_end = exact_end || !(v_out > 0.0);
  // already at the end: only possible when no speed change is asked for
  if (exact_end && distance_mm <= 1e-12) {
    if (std::abs(v_in - v_out) > 1e-9) return std::nullopt;
    JerkGridProfile profile;
    profile.v_start_mm_s = v_in;
    profile.v_after_mm_s = v_out;
    return profile;
  }
  // the guards: kJerkGuardSteps at v_in after a moving entry and at v_out before an open end
  // (the S-curves keep clear of the joints, where the curve's jerk begins inside a period)
  const int lead_steps = v_in > 0.0 ? kJerkGuardSteps : 0;
  const int tail_steps = !exact_end ? kJerkGuardSteps : 0;
  const double guards_mm = (lead_steps * v_in + tail_steps * v_out) * h;
  const double guarded_mm = distance_mm - guards_mm;
  if (guarded_mm < 0.0) {
    // no room for the guards: only a line crossed at one speed
    if (std::abs(v_in - v_out) > 1e-12 * (1.0 + v_in) || exact_end) return std::nullopt;
    JerkGridProfile profile;
    profile.v_start_mm_s = v_in;
    profile.v_after_mm_s = v_out;
    return profile;
  }
  const auto curve = [&](double dv) { return grid_s_curve(dv, a_max_mm_s2, j_max_mm_s3, h); };
  const auto ramps_mm = [&](double v_peak) {
    return s_curve_distance(v_in, v_peak, curve(v_peak - v_in), h) +
           s_curve_distance(v_peak, v_out, curve(v_peak - v_out), h);
  };
  const auto fits = [&](double v_peak) {
    return v_peak > 0.0 && ramps_mm(v_peak) <= guarded_mm * (1 + 1e-12) + 1e-12;
  };

  // the highest peak whose two S-curves fit: candidates from the cap down, then bisection
  // towards the infeasible one above the first that fits
  const std::vector<double> candidates = peak_candidates(v_cap_mm_s, v_in, v_out);
  double v_peak = -1.0;
  for (size_t i = 0; i < candidates.size(); ++i) {
    if (!fits(candidates[i])) continue;
    v_peak = candidates[i];
    if (i > 0) {
      double high = candidates[i - 1];
      for (int iteration = 0; iteration < 40; ++iteration) {
        const double mid = 0.5 * (v_peak + high);
        (fits(mid) ? v_peak : high) = mid;
      }
    }
    break;
  }
  // a line too short for the lowest candidate (cap / 256): halve it until a peak fits, then
  // bisect towards the half above (the S-curves' distance falls with the peak, to 0)
  double high = candidates.back();
  for (int halving = 0; halving < 64 && !(v_peak > 0.0); ++halving, high *= 0.5) {
    const double low = 0.5 * high;
    if (!fits(low)) continue;
    v_peak = low;
    for (int iteration = 0; iteration < 40; ++iteration) {
      const double mid = 0.5 * (v_peak + high);
      (fits(mid) ? v_peak : high) = mid;
    }
  }
  if (!(v_peak > 0.0)) return std::nullopt;

  // a profile at this peak: S-curve up, whole cruise steps, S-curve down (exact end: through x)
  const auto build = [&](double peak) -> std::optional<JerkGridProfile> {
    const GridSCurve up = curve(peak - v_in), down = curve(peak - v_out);
    const double rest = guarded_mm - ramps_mm(peak);
    if (rest < -1e-12 * (1.0 + distance_mm)) return std::nullopt;
    const double cruise_steps = std::floor(std::max(0.0, rest) / (peak * h));
    if (!(cruise_steps < kMaxJerkSteps) || up.steps() >= kMaxJerkSteps ||
        down.steps() >= kMaxJerkSteps)
      return std::nullopt;
    JerkGridProfile profile;
    profile.v_start_mm_s = v_in;
    profile.v_after_mm_s = v_out;
    profile.append_cruise(lead_steps);
    profile.append_s_curve(up, peak - v_in, h);
    profile.append_cruise(static_cast<int>(cruise_steps));
    const double left = std::max(0.0, rest) - cruise_steps * peak * h;
    if (!exact_end || left <= 1e-12 * (1.0 + distance_mm)) {
      profile.append_s_curve(down, v_out - peak, h);
      profile.append_cruise(tail_steps);
      return profile;
    }
    // the final S-curve through x: peak -> x (steps A), x -> v_out (steps B), covering its own
    // distance plus `left`; with the step counts fixed the distance is affine in x
    const double target = s_curve_distance(peak, v_out, down, h) + left;
    GridSCurve a_curve = down, b_curve{1, 0};
    for (int iteration = 0; iteration < 60; ++iteration) {
      const double steps = a_curve.steps() + b_curve.steps();
      const double x = (target - 0.5 * h * (peak * a_curve.steps() + v_out * b_curve.steps())) /
                       (0.5 * h * steps);
      const bool a_ok = a_curve.holds(peak - x, a_max_mm_s2, j_max_mm_s3, h);
      const bool b_ok = b_curve.holds(x - v_out, a_max_mm_s2, j_max_mm_s3, h);
      if (a_ok && b_ok && x >= 0.0 && x <= v_cap_mm_s * (1 + 1e-12) && a_curve.steps() > 0 &&
          b_curve.steps() > 0) {
        profile.append_s_curve(a_curve, x - peak, h);
        profile.append_s_curve(b_curve, v_out - x, h);
        return profile;
      }
      // the step counts x needs, at least one jerk step each
      const double x_next = std::clamp(x, 0.0, v_cap_mm_s);
      GridSCurve a_next = curve(peak - x_next), b_next = curve(x_next - v_out);
      if (a_next.steps() == 0) a_next = {1, 0};
      if (b_next.steps() == 0) b_next = {1, 0};
      // grow only, so the counts settle
      if (a_next.steps() < a_curve.steps()) a_next = a_curve;
      if (b_next.steps() < b_curve.steps()) b_next = b_curve;
      if (a_next.n_jerk == a_curve.n_jerk && a_next.n_flat == a_curve.n_flat &&
          b_next.n_jerk == b_curve.n_jerk && b_next.n_flat == b_curve.n_flat)
        break;
      a_curve = a_next;
      b_curve = b_next;
    }
    return std::nullopt;
  };
  // the peak found, or (exact end, when the final S-curve cannot take up the rest) a little less
  for (int attempt = 0; attempt < 64; ++attempt) {
    const double peak = v_peak * (1.0 - 0.01 * attempt);
    if (!(peak > 0.0)) break;
    if (std::optional<JerkGridProfile> profile = build(peak)) return profile;
  }
  return std::nullopt;
}

double jerk_grid_room(double v_a_mm_s, double v_b_mm_s, double a_max_mm_s2, double j_max_mm_s3,
                      double period_s) {
  if (v_a_mm_s == v_b_mm_s) return 0.0;
  const GridSCurve curve = grid_s_curve(v_b_mm_s - v_a_mm_s, a_max_mm_s2, j_max_mm_s3, period_s);
  return s_curve_distance(v_a_mm_s, v_b_mm_s, curve, period_s) +
         kJerkGridMarginSteps * std::max(v_a_mm_s, v_b_mm_s) * period_s;
}

}  // namespace depotwin
