#include "planners/motion/jerk_time_law.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>

#include "core/error.hpp"
#include "motion/jerk.hpp"
#include "planners/motion/sampled_jerk.hpp"

namespace depotwin {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kTiny = 1e-12;
// the path jerk of a stretch along no jerk-limited axis: beyond any limit
constexpr double kNoJerkLimit = 1e12;

// What the limits ask at one grid point: |p'_k|, |p''_k|, |p'''_k| (the larger of both sides),
// the TCP limits of the intervals around it (the tighter; jerk 0: none), |q'_j|, |q''_j|.
struct PointTerms {
  Vec3 d1 = Vec3::Zero(), d2 = Vec3::Zero(), d3 = Vec3::Zero();
  Vec3 accel = Vec3::Constant(kInf), jerk = Vec3::Zero();
  std::vector<double> q1, q2;
};

std::vector<PointTerms> point_terms(const PathGrid& grid,
                                    const std::vector<MachineLimits>& interval_limits) {
  const size_t n = grid.points.size();
  std::vector<PointTerms> terms(n);
  // p''' per interval: the second derivatives' difference across it
  std::vector<Vec3> third(n - 1);
  for (size_t i = 0; i + 1 < n; ++i) {
    const double ds = grid.points[i + 1].s_mm - grid.points[i].s_mm;
    third[i] = (grid.points[i + 1].d2_before - grid.points[i].d2_after) / ds;
  }
  for (size_t i = 0; i < n; ++i) {
    const PathPoint& p = grid.points[i];
    PointTerms& t = terms[i];
    t.d1 = p.d1_after.cwiseAbs().cwiseMax(p.d1_before.cwiseAbs());
    t.d2 = p.d2_after.cwiseAbs().cwiseMax(p.d2_before.cwiseAbs());
    for (const size_t interval : {i - 1, i}) {
      if (interval >= n - 1) continue;  // (i - 1 wraps at i = 0)
      t.d3 = t.d3.cwiseMax(third[interval].cwiseAbs());
      const MachineLimits& limits = interval_limits[interval];
      for (int k = 0; k < 3; ++k) {
        t.accel[k] = std::min(t.accel[k], limits.axes[k].a_max_mm_s2);
        const double j = limits.axes[k].j_max_mm_s3;
        if (j > 0.0) t.jerk[k] = t.jerk[k] > 0.0 ? std::min(t.jerk[k], j) : j;
      }
    }
    if (!grid.has_joints()) continue;
    const size_t joints = grid.joint_limits.size();
    t.q1.resize(joints);
    t.q2.resize(joints);
    for (size_t j = 0; j < joints; ++j) {
      t.q1[j] = std::max(std::abs(grid.dq_after[i][j]), std::abs(grid.dq_before[i][j]));
      t.q2[j] = std::max(std::abs(grid.ddq_after[i][j]), std::abs(grid.ddq_before[i][j]));
    }
  }
  return terms;
}

// the x = sdot^2 the curvature terms' shares allow at a point (scale: its shares' factor)
double curvature_x_bound(const PointTerms& t, const PathGrid& grid, double accel_scale,
                         double scale) {
  double x = kInf;
  for (int k = 0; k < 3; ++k) {
    if (t.d2[k] > kTiny)
      x = std::min(x, kNormalAccelShare * t.accel[k] * accel_scale * scale / t.d2[k]);
    if (t.jerk[k] > 0.0 && t.d3[k] > kTiny)
      x = std::min(
          x, std::pow(kCurvatureJerkShare * kJerkShare * t.jerk[k] * scale / t.d3[k], 2.0 / 3.0));
  }
  for (size_t j = 0; j < t.q2.size(); ++j) {
    const double a = grid.joint_limits[j].a_max * accel_scale;
    if (a > 0.0 && t.q2[j] > kTiny) x = std::min(x, kNormalAccelShare * a / t.q2[j]);
  }
  return x;
}

// one stretch between two critical points, with its double-S in s
struct Stretch {
  size_t first = 0, last = 0;
  double v_cap = 0.0, accel = 0.0, jerk = 0.0;
  AxisProfile law;
  double t_begin = 0.0;
};

// the scalar limits of a stretch (see the header)
void stretch_limits(Stretch& st, const std::vector<PointTerms>& terms, const PathGrid& grid,
                    const std::vector<double>& x_lim, const std::vector<double>& scale,
                    double accel_scale) {
  double accel = kInf, v_cap = 0.0;
  for (size_t i = st.first; i <= st.last; ++i) {
    const PointTerms& t = terms[i];
    const double x = x_lim[i];
    v_cap = std::max(v_cap, std::sqrt(x));
    for (int k = 0; k < 3; ++k)
      if (t.d1[k] > kTiny)
        accel = std::min(
            accel, (kJerkAccelShare * t.accel[k] * accel_scale * scale[i] - t.d2[k] * x) / t.d1[k]);
    for (size_t j = 0; j < t.q1.size(); ++j) {
      const double a = grid.joint_limits[j].a_max * accel_scale;
      if (a > 0.0 && t.q1[j] > kTiny) accel = std::min(accel, (a - t.q2[j] * x) / t.q1[j]);
    }
  }
  // the cross term 3 p'' sdot sddot within its share
  for (size_t i = st.first; i <= st.last; ++i) {
    const PointTerms& t = terms[i];
    for (int k = 0; k < 3; ++k) {
      const double c = 3.0 * t.d2[k] * std::sqrt(x_lim[i]);
      const double share = kCrossJerkShare * kJerkShare * t.jerk[k] * scale[i];
      if (t.jerk[k] > 0.0 && c * accel > share) accel = share / c;
    }
  }
  double jerk = kInf;
  for (size_t i = st.first; i <= st.last; ++i) {
    const PointTerms& t = terms[i];
    const double x = x_lim[i];
    for (int k = 0; k < 3; ++k) {
      if (!(t.jerk[k] > 0.0) || t.d1[k] <= kTiny) continue;
      const double left = kJerkShare * t.jerk[k] * scale[i] - 3.0 * t.d2[k] * std::sqrt(x) * accel -
                          t.d3[k] * x * std::sqrt(x);
      jerk = std::min(jerk, left / t.d1[k]);
    }
  }
  if (!std::isfinite(jerk)) jerk = kNoJerkLimit;
  if (!(accel > 0.0) || !(jerk > 0.0) || !std::isfinite(accel))
    throw InternalError(grid.name + ": no path acceleration or jerk left for the jerk-limited law");
  st.accel = accel;
  st.jerk = jerk;
  st.v_cap = v_cap;
}

// a stretch's double-S with what it was planned from, and the grid point where it rises
// highest above the ceiling (0: nowhere)
struct PlannedStretch {
  Stretch stretch;
  double v_begin = 0.0, v_end = 0.0;
  size_t worst = 0;
  PlannedStretch() = default;
  PlannedStretch(const Stretch& st, double v0, double v1) : stretch(st), v_begin(v0), v_end(v1) {}
  bool same_as(const PlannedStretch& other) const {
    return v_begin == other.v_begin && v_end == other.v_end &&
           stretch.accel == other.stretch.accel && stretch.jerk == other.stretch.jerk &&
           stretch.v_cap == other.stretch.v_cap;
  }
};

double ramp_room(double va, double vb, double accel, double jerk) {
  if (va == vb) return 0.0;
  return 0.5 * (va + vb) * s_curve_duration(vb - va, accel, jerk);
}

// the critical speeds lowered until every stretch holds its S-curve (the room is not monotone
// in the lower speed: the sweeps repeat until nothing changes, each change lowering the higher
// speed of a stretch, which only shortens its S-curve)
void settle_speeds(std::vector<double>& v, const std::vector<Stretch>& stretches,
                   const PathGrid& grid) {
  const auto length = [&](size_t m) {
    return grid.points[stretches[m].last].s_mm - grid.points[stretches[m].first].s_mm;
  };
  const auto settle = [&](size_t m) {
    const Stretch& st = stretches[m];
    const double L = length(m);
    if (ramp_room(v[m], v[m + 1], st.accel, st.jerk) <= L * (1 + 1e-12)) return false;
    double& high = v[m] > v[m + 1] ? v[m] : v[m + 1];
    const double low = std::min(v[m], v[m + 1]);
    double lo = low, hi = high;
    for (int i = 0; i < 100; ++i) {
      const double mid = 0.5 * (lo + hi);
      if (mid <= lo || mid >= hi) break;
      (ramp_room(low, mid, st.accel, st.jerk) <= L ? lo : hi) = mid;
    }
    high = lo;
    return true;
  };
  for (int sweep = 0; sweep < 10000; ++sweep) {
    bool changed = false;
    for (size_t m = 0; m < stretches.size(); ++m) changed = settle(m) || changed;
    for (size_t m = stretches.size(); m-- > 0;) changed = settle(m) || changed;
    if (!changed) return;
  }
  throw InternalError(grid.name + ": jerk-limited critical speeds did not settle");
}

// the S-curve from speed va to vb (zero acceleration at both ends) appended to law, as
// motion/jerk.cpp builds it: triangular acceleration below the knee a^2 / j, else trapezoidal
void append_ramp(AxisProfile& law, double va, double vb, double accel, double jerk) {
  const double dv = std::abs(vb - va), sign = vb >= va ? 1.0 : -1.0;
  if (dv == 0.0) return;
  if (dv <= accel * accel / jerk) {
    const double t_ramp = std::sqrt(dv / jerk);
    law.append_jerk(t_ramp, sign * jerk);
    law.append_jerk(t_ramp, -sign * jerk);
  } else {
    const double t_ramp = accel / jerk;
    law.append_jerk(t_ramp, sign * jerk);
    law.append_jerk(dv / accel - t_ramp, 0.0);
    law.append_jerk(t_ramp, -sign * jerk);
  }
}

// The time-optimal double-S over length L from v0 to v1 (both >= 0, L holding their S-curve:
// settle_speeds) with speeds up to v_cap: S-curve up to the highest peak whose two S-curves
// fit in L, cruise there for the rest (Biagiotti & Melchiorri sec. 3.4; motion/jerk.hpp's
// jerk_min_time_move for this forward case, without its general feasible-duration search).
AxisProfile forward_double_s(double L, double v0, double v1, double v_cap, double accel,
                             double jerk) {
  const auto rooms = [&](double peak) {
    return ramp_room(v0, peak, accel, jerk) + ramp_room(peak, v1, accel, jerk);
  };
  double lo = std::max(v0, v1), hi = std::max(lo, v_cap);
  if (rooms(hi) <= L) {
    lo = hi;
  } else {
    for (int i = 0; i < 200; ++i) {
      const double mid = 0.5 * (lo + hi);
      if (mid <= lo || mid >= hi) break;
      (rooms(mid) <= L ? lo : hi) = mid;
    }
  }
  const double peak = lo;
  AxisProfile law(0.0, v0);
  append_ramp(law, v0, peak, accel, jerk);
  const double cruise_s = peak > 0.0 ? (L - rooms(peak)) / peak : 0.0;
  if (cruise_s > 1e-13 * (1.0 + law.duration_s())) law.append_jerk(cruise_s, 0.0);
  append_ramp(law, peak, v1, accel, jerk);
  return law;
}

// the path speed where a law reaches distance q (q within it: its speed is never negative)
double speed_at_distance(const AxisProfile& law, double q) {
  double lo = 0.0, hi = law.duration_s();
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    (law.at(mid).q < q ? lo : hi) = mid;
  }
  return law.at(0.5 * (lo + hi)).v;
}

// local minima of x over the grid (both ends of a flat bottom), and both ends of the path
std::vector<size_t> ceiling_minima(const std::vector<double>& x) {
  const size_t n = x.size();
  std::vector<size_t> minima{0};
  size_t i = 1;
  while (i + 1 < n) {
    size_t j = i;
    while (j + 1 < n - 1 && x[j + 1] == x[i]) ++j;  // a flat run [i, j]
    if (x[i - 1] > x[i] && x[j + 1] > x[j]) {
      minima.push_back(i);
      if (j != i) minima.push_back(j);
    }
    i = j + 1;
  }
  minima.push_back(n - 1);
  return minima;
}

// the grid interval holding s, searched forwards from hint
size_t interval_holding(const PathGrid& grid, double s, size_t hint) {
  const size_t intervals = grid.points.size() - 1;
  size_t i = std::min(hint, intervals - 1);
  if (s < grid.points[i].s_mm) i = 0;
  while (i + 1 < intervals && grid.points[i + 1].s_mm <= s) ++i;
  return i;
}

}  // namespace

double jerk_constant_speed_bound(const PathGrid& grid,
                                 const std::vector<MachineLimits>& interval_limits,
                                 const TimeLawOptions& options) {
  double bound = constant_speed_bound(grid, interval_limits, options);
  const std::vector<PointTerms> terms = point_terms(grid, interval_limits);
  for (size_t i = 0; i < grid.points.size(); ++i) {
    if (grid.points[i].speed_mm_s <= 0.0) continue;
    const double scale = options.tcp_accel_scale.empty() ? 1.0 : options.tcp_accel_scale[i];
    bound =
        std::min(bound, std::sqrt(curvature_x_bound(terms[i], grid, options.accel_scale, scale)));
  }
  return bound;
}

TimedPath jerk_limited_time_path(const PathGrid& grid,
                                 const std::vector<MachineLimits>& interval_limits, double period_s,
                                 const TimeLawOptions& options) {
  const size_t n = grid.points.size();
  if (n < 2) throw InputError(grid.name, "a path needs at least two grid points");
  if (interval_limits.size() != n - 1)
    throw InternalError("interval limits do not match the path grid");
  TimedPath out;
  out.interval_limits = interval_limits;
  // the ceiling: TOPP-RA's law with the sampling margin on the TCP accelerations
  TimeLawOptions ceiling_options = options;
  if (ceiling_options.tcp_accel_scale.empty()) ceiling_options.tcp_accel_scale.assign(n, 1.0);
  for (double& scale : ceiling_options.tcp_accel_scale) scale *= kSampledAccelMargin;
  out.law = parametrize_path(grid, interval_limits, ceiling_options);
  out.tcp_accel_scale = ceiling_options.tcp_accel_scale;
  const std::vector<PointTerms> terms = point_terms(grid, interval_limits);

  // the shares' factors per grid point (lowered by repairs) and the TCP limits per axis over
  // the whole path (for the finite-difference check)
  std::vector<double> scale(n, 1.0);
  // and the ceiling's factors (lowered where a sample's speed passed an axis' v_max: between
  // grid points the S-curves can rise a little above a ceiling that binds on speed, which
  // lowered shares do not change)
  std::vector<double> ceiling_scale(n, 1.0);
  Vec3 j_min = Vec3::Zero();
  for (const MachineLimits& limits : interval_limits)
    for (int k = 0; k < 3; ++k) {
      const double j = limits.axes[k].j_max_mm_s3;
      if (j > 0.0) j_min[k] = j_min[k] > 0.0 ? std::min(j_min[k], j) : j;
    }

  for (int round = 0;; ++round) {
    // the ceiling with the curvature terms' shares
    std::vector<double> x_lim(n);
    for (size_t i = 0; i < n; ++i) {
      const double topp_scale = options.tcp_accel_scale.empty() ? 1.0 : options.tcp_accel_scale[i];
      x_lim[i] = ceiling_scale[i] *
                 std::min(out.law.x[i], curvature_x_bound(terms[i], grid, options.accel_scale,
                                                          topp_scale * scale[i]));
    }
    const std::vector<double> share_scale = [&] {
      std::vector<double> s(n);
      for (size_t i = 0; i < n; ++i)
        s[i] = scale[i] * (options.tcp_accel_scale.empty() ? 1.0 : options.tcp_accel_scale[i]);
      return s;
    }();

    // critical points, stretches and their double-S moves; a stretch whose S-curve rises above
    // the ceiling gets a critical point where it does most, and all are planned again
    // (a stretch planned in an earlier insertion round with the same ends, speeds and limits
    // is taken from `planned` as it was: most stay as they were when a few points are added)
    std::vector<size_t> critical = ceiling_minima(x_lim);
    std::vector<Stretch> stretches;
    std::map<std::pair<size_t, size_t>, PlannedStretch> planned;
    for (size_t insertion = 0;; ++insertion) {
      stretches.assign(critical.size() - 1, Stretch{});
      for (size_t m = 0; m + 1 < critical.size(); ++m) {
        stretches[m].first = critical[m];
        stretches[m].last = critical[m + 1];
        stretch_limits(stretches[m], terms, grid, x_lim, share_scale, options.accel_scale);
      }
      std::vector<double> v(critical.size());
      for (size_t m = 0; m < critical.size(); ++m) v[m] = std::sqrt(x_lim[critical[m]]);
      v.front() = options.sdot_begin;
      v.back() = options.sdot_end;
      settle_speeds(v, stretches, grid);
      std::vector<size_t> added;
      for (size_t m = 0; m < stretches.size(); ++m) {
        Stretch& st = stretches[m];
        const double s0 = grid.points[st.first].s_mm;
        const double length = grid.points[st.last].s_mm - s0;
        const PlannedStretch key{st, v[m], v[m + 1]};
        auto found = planned.find({st.first, st.last});
        if (found != planned.end() && found->second.same_as(key)) {
          st.law = found->second.stretch.law;
          if (found->second.worst > 0) added.push_back(found->second.worst);
          continue;
        }
        st.law = forward_double_s(length, v[m], v[m + 1], st.v_cap, st.accel, st.jerk);
        size_t worst = 0;
        double worst_ratio = 1.0 + 1e-9;
        for (size_t i = st.first + 1; i < st.last; ++i) {
          const double sdot = speed_at_distance(st.law, grid.points[i].s_mm - s0);
          const double ratio = sdot * sdot / std::max(x_lim[i], 1e-300);
          if (sdot * sdot > x_lim[i] + 1e-12 && ratio > worst_ratio) {
            worst_ratio = ratio;
            worst = i;
          }
        }
        if (worst > 0) added.push_back(worst);
        PlannedStretch& entry = planned[{st.first, st.last}];
        entry = PlannedStretch{st, v[m], v[m + 1]};
        entry.worst = worst;
      }
      if (added.empty()) break;
      if (insertion > n)
        throw InternalError(grid.name + ": the jerk-limited law does not settle under its ceiling");
      critical.insert(critical.end(), added.begin(), added.end());
      std::sort(critical.begin(), critical.end());
      critical.erase(std::unique(critical.begin(), critical.end()), critical.end());
    }
    double duration = 0.0;
    for (Stretch& st : stretches) {
      st.t_begin = duration;
      duration += st.law.duration_s();
    }

    // the samples: a law from rest starts late by what rounds its duration up to whole periods
    PathSamples& samples = out.samples;
    samples = PathSamples{};
    samples.period_s = period_s;
    const size_t periods =
        static_cast<size_t>(std::max(1.0, std::ceil(duration / period_s - 1e-9)));
    const double delay = double(periods) * period_s - duration;
    const size_t count = periods + 1;
    samples.s_mm.resize(count);
    samples.sdot.resize(count);
    samples.position_mm.resize(count);
    samples.velocity_mm_s.resize(count);
    samples.tool_axis.resize(count);
    samples.roll_rad.resize(count);
    size_t stretch = 0, path_hint = 0, axis_hint = 0;
    std::vector<size_t> phase_hint(stretches.size(), 0);
    for (size_t k = 0; k < count; ++k) {
      const double t = double(k) * period_s - delay;
      double s = 0.0, sdot = 0.0;
      if (k + 1 == count) {
        s = grid.length_mm();
        sdot = options.sdot_end;
      } else if (t > 0.0) {
        while (stretch + 1 < stretches.size() &&
               t >= stretches[stretch].t_begin + stretches[stretch].law.duration_s())
          ++stretch;
        const Stretch& st = stretches[stretch];
        const AxisState state = st.law.at(t - st.t_begin, phase_hint[stretch]);
        s = std::min(grid.length_mm(), grid.points[st.first].s_mm + state.q);
        sdot = std::max(0.0, state.v);
      } else {
        sdot = options.sdot_begin;
      }
      Vec3 d1, d2;
      path_derivatives(grid, s, samples.position_mm[k], d1, d2, &path_hint);
      samples.s_mm[k] = s;
      samples.sdot[k] = sdot;
      samples.velocity_mm_s[k] = d1 * sdot;
      if (grid.orientation_at) {
        grid.orientation_at(s, samples.tool_axis[k], samples.roll_rad[k]);
      } else {
        const size_t i = interval_holding(grid, s, axis_hint);
        axis_hint = i;
        const PathPoint& a = grid.points[i];
        const PathPoint& b = grid.points[i + 1];
        const double f = std::clamp((s - a.s_mm) / (b.s_mm - a.s_mm), 0.0, 1.0);
        samples.tool_axis[k] = slerp_axis(a.tool_axis, b.tool_axis, f);
        samples.roll_rad[k] = a.roll_rad + f * (b.roll_rad - a.roll_rad);
      }
    }
    samples.position_mm.front() = grid.points.front().position_mm;
    samples.position_mm.back() = grid.points.back().position_mm;
    samples.tool_axis.front() = grid.points.front().tool_axis;
    samples.tool_axis.back() = grid.points.back().tool_axis;
    samples.roll_rad.front() = grid.points.front().roll_rad;
    samples.roll_rad.back() = grid.points.back().roll_rad;
    out.repair_rounds = round;
    out.repair_scale = scale;

    // the samples' cubic interpolation against the TCP limits: acceleration at both ends of
    // every period, speed at every sample, jerk by 1 ms finite differences
    std::vector<char> bad(periods, 0);
    std::vector<double> speed_excess(periods, 1.0);  // |v| / v_max where above 1
    size_t hint = 0;
    const double h = period_s;
    for (size_t k = 0; k < periods; ++k) {
      const size_t i0 = interval_holding(grid, samples.s_mm[k], hint);
      const size_t i1 = interval_holding(grid, samples.s_mm[k + 1], i0);
      hint = i0;
      for (int axis = 0; axis < 3; ++axis) {
        double a_max = kInf, v_max = kInf;
        for (size_t i = i0; i <= i1; ++i) {
          a_max = std::min(a_max, interval_limits[i].axes[axis].a_max_mm_s2);
          v_max = std::min(v_max, interval_limits[i].axes[axis].v_max_mm_s);
        }
        const double c =
            6.0 * (samples.position_mm[k + 1][axis] - samples.position_mm[k][axis]) / (h * h);
        const double v0 = samples.velocity_mm_s[k][axis], v1 = samples.velocity_mm_s[k + 1][axis];
        const double a0 = c - (4.0 * v0 + 2.0 * v1) / h, a1 = -c + (2.0 * v0 + 4.0 * v1) / h;
        // (relative 1e-9: the law's cruise at a speed limit meets it but for rounding)
        const double speed_ratio = std::max(std::abs(v0), std::abs(v1)) / v_max;
        if (std::max(std::abs(a0), std::abs(a1)) > a_max * (1 + 1e-9) || speed_ratio > 1 + 1e-9)
          bad[k] = 1;
        if (speed_ratio > 1 + 1e-9) speed_excess[k] = std::max(speed_excess[k], speed_ratio);
      }
    }
    std::vector<double> jerk_ratio;
    sampled_jerk_ratio(samples.position_mm, samples.velocity_mm_s, period_s, j_min, &jerk_ratio);
    for (size_t k = 0; k < periods; ++k)
      if (jerk_ratio[k] > 1.0 + 1e-3) bad[k] = 1;
    if (std::none_of(bad.begin(), bad.end(), [](char b) { return b != 0; })) return out;
    if (round == kJerkRepairRounds) {
      std::ostringstream msg;
      msg << grid.name << ": the jerk-limited samples still exceed a TCP limit after " << round
          << " rounds of lowered shares";
      throw InternalError(msg.str());
    }
    // lower the shares around every bad period (a few periods either side: a finite
    // difference spans three)
    // (by kJerkRepairScale, or where a period's jerk is over the limit by more, by that much
    // and a little: the excess falls in proportion to the shares, and 0.85 a round left a
    // 10-fold excess 1.45-fold after all its rounds, an internal error, on a corner under a
    // j_max of the y axis alone)
    std::vector<double> factor(n, 1.0);
    for (size_t k = 0; k < periods; ++k) {
      if (!bad[k]) continue;
      const double lower = jerk_ratio[k] > 1.0 + 1e-3
                               ? std::min(kJerkRepairScale, kJerkRepairMargin / jerk_ratio[k])
                               : kJerkRepairScale;
      const double s_lo = samples.s_mm[k >= 3 ? k - 3 : 0];
      const double s_hi = samples.s_mm[std::min(periods, k + 4)];
      const size_t first = interval_holding(grid, s_lo, 0);
      const size_t last = interval_holding(grid, s_hi, first) + 1;
      for (size_t i = first; i <= last; ++i) {
        factor[i] = std::min(factor[i], lower);
        // x = sdot^2: the speed's excess squared, and a little more
        if (speed_excess[k] > 1.0)
          ceiling_scale[i] =
              std::min(ceiling_scale[i], (1.0 - 1e-6) / (speed_excess[k] * speed_excess[k]));
      }
    }
    for (size_t i = 0; i < n; ++i) scale[i] *= factor[i];
  }
}

}  // namespace depotwin
