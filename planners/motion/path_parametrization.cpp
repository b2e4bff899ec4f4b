#include "planners/motion/path_parametrization.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/error.hpp"

namespace depotwin {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// a row's coefficient on u below this is no coefficient: the row bounds x alone
constexpr double kTinyCoefficient = 1e-12;
// rounds of lowered accelerations where the sampled cubic cannot be fitted
constexpr int kMaxRepairRounds = 12;
// where they still fail, limits spread this many times over the failed window are a posture
// near a singularity (the job's), not the fit's failure
constexpr double kSingularLimitSpread = 2.0;
// the sampled cubic's acceleration / velocity counts as over a limit beyond these fractions
// (the planner contract allows 1e-6 and 1e-9); the velocity fit aims within half of them
constexpr double kAccelFlag = 1e-9, kSpeedFlag = 1e-12;
// the first kLateStartPeriods of a sampled law from rest plan with kLateStartScale of the TCP
// accelerations (besides kSampledAccelMargin): the slack that lets the velocity fit absorb the
// late start (the cubic from rest to the first sample's state)
constexpr double kLateStartScale = 0.85;
constexpr double kLateStartPeriods = 10.0;
// attach_joints halves the grid intervals where a joint moves more than this fraction of its
// range, down to kMinRefinedStepMm: a step that is still too large there is a jump
constexpr double kJointStepFraction = 1e-3;
constexpr double kMinRefinedStepMm = 1e-6;
constexpr int kMaxRefineRounds = 24;
// the most samples one path may have (2e7: 5.6 hours at 1 ms)
constexpr double kMaxSamples = 2e7;
// a repair lowers the TCP accelerations around a window it cannot fit by this factor
constexpr double kRepairScale = 0.85;

std::string where(const PathGrid& grid, size_t i) {
  const PathPoint& p = grid.points[i];
  char text[160];
  std::snprintf(text, sizeof text, "at s = %.4f mm of %.4f mm (%.4f, %.4f, %.4f)", p.s_mm,
                grid.length_mm(), p.position_mm.x(), p.position_mm.y(), p.position_mm.z());
  return text;
}

double scale_at(const std::vector<double>& scales, size_t i) {
  return scales.empty() ? 1.0 : scales[i];
}

// ---------------------------------------------------------------------------------------
// finite differences

// Fornberg's weights for the first and second derivative at z from nodes x[0..n-1] (n <= 4)
void fd_weights(double z, const double* x, int n, double* w1, double* w2) {
  double c[4][3] = {};
  double c1 = 1.0, c4 = x[0] - z;
  c[0][0] = 1.0;
  for (int i = 1; i < n; ++i) {
    const int mn = std::min(i, 2);
    double c2 = 1.0;
    const double c5 = c4;
    c4 = x[i] - z;
    for (int j = 0; j < i; ++j) {
      const double c3 = x[i] - x[j];
      c2 *= c3;
      if (j == i - 1) {
        for (int k = mn; k >= 1; --k) c[i][k] = c1 * (k * c[i - 1][k - 1] - c5 * c[i - 1][k]) / c2;
        c[i][0] = -c1 * c5 * c[i - 1][0] / c2;
      }
      for (int k = mn; k >= 1; --k) c[j][k] = (c4 * c[j][k] - k * c[j][k - 1]) / c3;
      c[j][0] = c4 * c[j][0] / c3;
    }
    c1 = c2;
  }
  for (int i = 0; i < n; ++i) {
    w1[i] = c[i][1];
    w2[i] = c[i][2];
  }
}

// ---------------------------------------------------------------------------------------
// the rows of one grid interval: lo <= a u + b x_i <= hi

struct Row {
  double a, b, lo, hi;
};

void interval_rows(const PathGrid& grid, const std::vector<MachineLimits>& limits,
                   const TimeLawOptions& options, size_t i, std::vector<Row>& rows) {
  rows.clear();
  const PathPoint& p0 = grid.points[i];
  const PathPoint& p1 = grid.points[i + 1];
  const double ds = p1.s_mm - p0.s_mm;
  const double scale0 = options.accel_scale * scale_at(options.tcp_accel_scale, i);
  const double scale1 = options.accel_scale * scale_at(options.tcp_accel_scale, i + 1);
  for (int axis = 0; axis < 3; ++axis) {
    const double a_max = limits[i].axes[axis].a_max_mm_s2;
    // at the start, with the start's right-hand derivatives; at the end with the end's
    // left-hand ones and x_{i+1} = x_i + 2 ds u
    rows.push_back({p0.d1_after[axis], p0.d2_after[axis], -a_max * scale0, a_max * scale0});
    rows.push_back({p1.d1_before[axis] + 2.0 * ds * p1.d2_before[axis], p1.d2_before[axis],
                    -a_max * scale1, a_max * scale1});
  }
  if (!grid.has_joints()) return;
  for (size_t j = 0; j < grid.joint_limits.size(); ++j) {
    const double a_max = grid.joint_limits[j].a_max * options.accel_scale;
    if (!(a_max > 0.0)) continue;
    rows.push_back({grid.dq_after[i][j], grid.ddq_after[i][j], -a_max, a_max});
    rows.push_back({grid.dq_before[i + 1][j] + 2.0 * ds * grid.ddq_before[i + 1][j],
                    grid.ddq_before[i + 1][j], -a_max, a_max});
  }
}

// the largest |f| on [0, 1] of the cubic with values f0, f1 and slopes m0, m1 (per unit t) at
// its ends: the ends and the real roots of its derivative inside
double cubic_peak(double f0, double m0, double f1, double m1) {
  // zero slopes: a smoothstep, monotone between its ends
  if (m0 == 0.0 && m1 == 0.0) return std::max(std::abs(f0), std::abs(f1));
  const double a = 2 * (f0 - f1) + m0 + m1, b = 3 * (f1 - f0) - 2 * m0 - m1, c = m0;
  double peak = std::max(std::abs(f0), std::abs(f1));
  const auto at = [&](double t) {
    if (t > 0.0 && t < 1.0) peak = std::max(peak, std::abs(((a * t + b) * t + c) * t + f0));
  };
  // 3 a t^2 + 2 b t + c = 0
  if (std::abs(a) > 1e-15 * (std::abs(b) + std::abs(c) + 1e-300)) {
    const double disc = b * b - 3 * a * c;
    if (disc >= 0.0) {
      const double root = std::sqrt(disc);
      at((-b + root) / (3 * a));
      at((-b - root) / (3 * a));
    }
  } else if (b != 0.0) {
    at(-c / (2 * b));
  }
  return peak;
}

// The largest x at grid point i that the velocity bounds allow; `reason` names the binding one.
// Each bound takes the largest rate (|p'_k|, |q'_j|) over both intervals at the point, from
// the cubic through the rates and their slopes at the intervals' ends: x is linear on an
// interval, so the limit then holds all along it, not only at its ends.
double point_x_max(const PathGrid& grid, const std::vector<MachineLimits>& limits,
                   const TimeLawOptions& options, size_t i, std::string* reason = nullptr) {
  static const char* kAxis[3] = {"x", "y", "z"};
  const PathPoint& p = grid.points[i];
  double x_max = kInf;
  // the binding bound: -3 none, -2 stop, -1 desired speed, 0..2 TCP axis, 3 + j joint j
  int binding = -3;
  const auto bound = [&](double x, int what) {
    if (x < x_max) {
      x_max = x;
      binding = what;
    }
  };
  if (std::isfinite(p.speed_mm_s)) {
    const double d1 = std::max(p.d1_after.squaredNorm(), p.d1_before.squaredNorm());
    if (p.speed_mm_s <= 0.0) bound(0.0, -2);
    if (d1 > 0.0) bound(p.speed_mm_s * p.speed_mm_s / d1, -1);
  }
  const double speed_scale = scale_at(options.tcp_speed_scale, i);
  const size_t last = grid.points.size() - 1;
  for (int side = 0; side < 2; ++side) {
    // the interval before (side 0) and after (side 1) the point: [a, a + 1]
    if ((side == 0 && i == 0) || (side == 1 && i == last)) continue;
    const size_t a = side == 0 ? i - 1 : i;
    const PathPoint& p0 = grid.points[a];
    const PathPoint& p1 = grid.points[a + 1];
    const double ds = p1.s_mm - p0.s_mm;
    const MachineLimits& lim = limits[a];
    for (int axis = 0; axis < 3; ++axis) {
      const double v = lim.axes[axis].v_max_mm_s * speed_scale;
      const double rate = cubic_peak(p0.d1_after[axis], ds * p0.d2_after[axis], p1.d1_before[axis],
                                     ds * p1.d2_before[axis]);
      if (rate > 0.0) bound(v * v / (rate * rate), axis);
    }
    if (!grid.has_joints()) continue;
    for (size_t j = 0; j < grid.joint_limits.size(); ++j) {
      const double v = grid.joint_limits[j].v_max;
      if (!(v > 0.0)) continue;
      const double rate = cubic_peak(grid.dq_after[a][j], ds * grid.ddq_after[a][j],
                                     grid.dq_before[a + 1][j], ds * grid.ddq_before[a + 1][j]);
      if (rate > 0.0) bound(v * v / (rate * rate), 3 + static_cast<int>(j));
    }
  }
  if (reason) {
    if (binding == -3) *reason = "nothing bounds the speed";
    if (binding == -2) *reason = "the path stops here (speed 0)";
    if (binding == -1) *reason = "the desired speed";
    if (binding >= 0 && binding < 3)
      *reason = std::string("the TCP's ") + kAxis[binding] + " velocity limit";
    if (binding >= 3)
      *reason = "joint '" + grid.joint_limits[binding - 3].name + "' velocity limit";
  }
  return x_max;
}

struct Linear {
  double c, m;  // c + m x
};

// The set of x at the start of interval i from which some u satisfies every row and lands
// x + 2 ds u in [next_lo, next_hi] (a 2-variable LP solved exactly: with u eliminated, each
// pair of a lower and an upper bound on u gives one inequality in x). False when empty.
bool controllable_interval(const std::vector<Row>& rows, double ds, double next_lo, double next_hi,
                           double x_max, std::vector<Linear>& lower, std::vector<Linear>& upper,
                           double& lo, double& hi) {
  lower.clear();
  upper.clear();
  lo = 0.0;
  hi = x_max;
  const double inv = 1.0 / (2.0 * ds);
  lower.push_back({next_lo * inv, -inv});
  if (std::isfinite(next_hi)) upper.push_back({next_hi * inv, -inv});
  for (const Row& row : rows) {
    if (std::abs(row.a) < kTinyCoefficient) {
      if (row.b > 0.0) {
        hi = std::min(hi, row.hi / row.b);
        lo = std::max(lo, row.lo / row.b);
      } else if (row.b < 0.0) {
        hi = std::min(hi, row.lo / row.b);
        lo = std::max(lo, row.hi / row.b);
      }
      continue;
    }
    const double m = -row.b / row.a;
    if (row.a > 0.0) {
      lower.push_back({row.lo / row.a, m});
      upper.push_back({row.hi / row.a, m});
    } else {
      lower.push_back({row.hi / row.a, m});
      upper.push_back({row.lo / row.a, m});
    }
  }
  for (const Linear& f : lower) {
    for (const Linear& g : upper) {
      // f(x) <= g(x)  <=>  (f.m - g.m) x <= g.c - f.c
      const double d = f.m - g.m, r = g.c - f.c;
      if (d > 0.0) {
        hi = std::min(hi, r / d);
      } else if (d < 0.0) {
        lo = std::max(lo, r / d);
      } else if (r < -1e-12 * (std::abs(f.c) + std::abs(g.c))) {
        return false;
      }
    }
  }
  const double tolerance = 1e-9 * std::max(1.0, std::abs(hi));
  if (lo > hi + tolerance) return false;
  if (lo > hi) lo = hi;
  return true;
}

// the range of u at x that satisfies every row and lands in [next_lo, next_hi]
void u_range(const std::vector<Row>& rows, double ds, double x, double next_lo, double next_hi,
             double& u_min, double& u_max) {
  u_min = (next_lo - x) / (2.0 * ds);
  u_max = std::isfinite(next_hi) ? (next_hi - x) / (2.0 * ds) : kInf;
  for (const Row& row : rows) {
    if (std::abs(row.a) < kTinyCoefficient) continue;
    const double first = (row.lo - row.b * x) / row.a, second = (row.hi - row.b * x) / row.a;
    u_min = std::max(u_min, std::min(first, second));
    u_max = std::min(u_max, std::max(first, second));
  }
}

// grid interval holding s (closed on both ends: the last interval whose start is <= s),
// searched forwards from hint
size_t interval_of(const PathGrid& grid, double s, size_t hint) {
  const size_t intervals = grid.points.size() - 1;
  size_t i = std::min(hint, intervals - 1);
  if (s < grid.points[i].s_mm) i = 0;
  while (i + 1 < intervals && grid.points[i + 1].s_mm <= s) ++i;
  return i;
}

// the first and last grid interval whose closed range holds s
void intervals_holding(const PathGrid& grid, double s, size_t hint, size_t& first, size_t& last) {
  last = interval_of(grid, s, hint);
  first = last;
  if (last > 0 && grid.points[last].s_mm == s) first = last - 1;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// joints

void joint_derivatives_by_differences(PathGrid& grid) {
  const size_t n = grid.points.size();
  if (grid.q.size() != n) throw InternalError("joint positions do not match the grid");
  const size_t joints = grid.joint_limits.size();
  grid.dq_after.assign(n, JointVector(joints, 0.0));
  grid.ddq_after = grid.dq_before = grid.ddq_before = grid.dq_after;
  size_t run_begin = 0;
  for (size_t i = 1; i < n; ++i) {
    if (!grid.points[i].is_break && i + 1 < n) continue;
    // the run [run_begin, i]
    const size_t run_end = i, count = run_end - run_begin + 1;
    for (size_t k = run_begin; k <= run_end; ++k) {
      // the stencil: three points around k inside the run, four at its ends
      size_t first = 0, size = 0;
      if (count <= 4) {
        first = run_begin;
        size = count;
      } else if (k == run_begin || k == run_end) {
        first = k == run_begin ? run_begin : run_end - 3;
        size = 4;
      } else {
        first = k - 1;
        size = 3;
      }
      double nodes[4], w1[4], w2[4];
      for (size_t m = 0; m < size; ++m) nodes[m] = grid.points[first + m].s_mm;
      fd_weights(grid.points[k].s_mm, nodes, static_cast<int>(size), w1, w2);
      JointVector d1(joints, 0.0), d2(joints, 0.0);
      for (size_t j = 0; j < joints; ++j) {
        for (size_t m = 0; m < size; ++m) {
          d1[j] += w1[m] * grid.q[first + m][j];
          d2[j] += (size < 3 ? 0.0 : w2[m]) * grid.q[first + m][j];
        }
      }
      if (k != run_end || k == n - 1) {
        grid.dq_after[k] = d1;
        grid.ddq_after[k] = d2;
      }
      if (k != run_begin || k == 0) {
        grid.dq_before[k] = d1;
        grid.ddq_before[k] = d2;
      }
    }
    run_begin = i;
  }
}

namespace {

// solve the joints at every grid pose; InputError saying where when one is unreachable
void solve_joints(PathGrid& grid, const JointMap& map) {
  std::vector<Pose> poses;
  poses.reserve(grid.points.size());
  for (const PathPoint& p : grid.points) poses.emplace_back(p.position_mm, p.tool_axis, p.roll_rad);
  std::string why;
  if (!map.solve(poses, grid.q, &why)) {
    // the joint map names the pose index: say where on the path that is
    size_t index = 0;
    std::string at;
    if (std::sscanf(why.c_str(), "pose %zu", &index) == 1 && index < grid.points.size())
      at = " " + where(grid, index);
    throw InputError(grid.name, "the machine cannot follow the path" + at + ": " + why);
  }
  if (grid.q.size() != grid.points.size())
    throw InternalError("the joint map returned a wrong number of joint vectors");
  for (const JointVector& q : grid.q)
    if (q.size() != grid.joint_limits.size())
      throw InternalError("the joint map returned joint vectors of a wrong size");
}

// a new grid point halfway along interval i, from the grid's own interpolation
PathPoint midpoint(const PathGrid& grid, size_t i) {
  const PathPoint& a = grid.points[i];
  const PathPoint& b = grid.points[i + 1];
  PathPoint mid;
  mid.s_mm = 0.5 * (a.s_mm + b.s_mm);
  size_t hint = i;
  path_derivatives(grid, mid.s_mm, mid.position_mm, mid.d1_after, mid.d2_after, &hint);
  mid.d1_before = mid.d1_after;
  mid.d2_before = mid.d2_after;
  if (grid.orientation_at) {
    grid.orientation_at(mid.s_mm, mid.tool_axis, mid.roll_rad);
  } else {
    mid.tool_axis = slerp_axis(a.tool_axis, b.tool_axis, 0.5);
    mid.roll_rad = 0.5 * (a.roll_rad + b.roll_rad);
  }
  // inside an interval: the speed bound of its ends (not a stop at either)
  mid.speed_mm_s = a.speed_mm_s > 0.0 && b.speed_mm_s > 0.0 ? std::min(a.speed_mm_s, b.speed_mm_s)
                                                            : std::max(a.speed_mm_s, b.speed_mm_s);
  return mid;
}

}  // namespace

void attach_joints(PathGrid& grid, const JointMap& map) {
  grid.joint_limits = map.limits;
  const size_t joints = map.limits.size();
  // the largest joint step between neighbouring grid points, per joint: a thousandth of its
  // range (2 pi when it has none)
  std::vector<double> max_step(joints);
  for (size_t j = 0; j < joints; ++j) {
    const double range = map.limits[j].max - map.limits[j].min;
    max_step[j] = kJointStepFraction * (std::isfinite(range) && range > 0.0 ? range : 2 * kPi);
  }
  for (int round = 0;; ++round) {
    solve_joints(grid, map);
    // intervals where a joint moves more than its step: halve them (the joints turn fast
    // there, near a singularity: the differences need the finer grid)
    std::vector<size_t> coarse;
    for (size_t i = 0; i + 1 < grid.points.size(); ++i) {
      for (size_t j = 0; j < joints; ++j) {
        const double step = std::abs(grid.q[i + 1][j] - grid.q[i][j]);
        if (step <= max_step[j]) continue;
        const double ds = grid.points[i + 1].s_mm - grid.points[i].s_mm;
        if (ds < 2 * kMinRefinedStepMm || round == kMaxRefineRounds) {
          // a step that does not shrink with the grid: the map changed configuration
          std::ostringstream msg;
          msg << "the machine's joint '" << map.limits[j].name << "' jumps by " << step
              << " between s = " << grid.points[i].s_mm << " and " << grid.points[i + 1].s_mm
              << " mm " << where(grid, i)
              << ": its joint map changes configuration there (or passes a singularity), which "
                 "the path cannot be printed through";
          throw InputError(grid.name, msg.str());
        }
        coarse.push_back(i);
        break;
      }
    }
    if (coarse.empty()) break;
    std::vector<PathPoint> refined;
    refined.reserve(grid.points.size() + coarse.size());
    size_t next = 0;
    for (size_t i = 0; i < grid.points.size(); ++i) {
      refined.push_back(grid.points[i]);
      if (next < coarse.size() && coarse[next] == i) {
        refined.push_back(midpoint(grid, i));
        ++next;
      }
    }
    grid.points = std::move(refined);
  }
  joint_derivatives_by_differences(grid);
}

std::vector<MachineLimits> interval_tcp_limits(const PathGrid& grid, const TcpLimits& limits,
                                               double chunk_mm) {
  const size_t intervals = grid.points.size() - 1;
  if (limits.uniform()) return std::vector<MachineLimits>(intervals, limits.requested());
  std::vector<MachineLimits> result(intervals);
  size_t first = 0;
  double length = 0.0, pad = 0.0;
  Vec3 lo = grid.points[0].position_mm, hi = lo;
  for (size_t i = 0; i < intervals; ++i) {
    const PathPoint& p0 = grid.points[i];
    const PathPoint& p1 = grid.points[i + 1];
    const double ds = p1.s_mm - p0.s_mm;
    length += ds;
    // the path leaves the chord between grid points by at most ds^2 |p''| / 8
    pad = std::max(pad, ds * ds * std::max(p0.d2_after.norm(), p1.d2_before.norm()) / 8.0);
    lo = lo.cwiseMin(p1.position_mm);
    hi = hi.cwiseMax(p1.position_mm);
    if (length < chunk_mm && i + 1 < intervals) continue;
    const Vec3 margin = Vec3::Constant(pad + 1e-9);
    const MachineLimits chunk = limits.over(lo - margin, hi + margin);
    for (size_t k = first; k <= i; ++k) result[k] = chunk;
    first = i + 1;
    length = pad = 0.0;
    lo = hi = p1.position_mm;
  }
  return result;
}

// ---------------------------------------------------------------------------------------
// the time law

double TimeLaw::sdot(size_t i) const {
  return std::sqrt(std::max(0.0, x[i]));
}

size_t TimeLaw::interval_at_time(double t, size_t hint) const {
  const size_t intervals = u.size();
  if (intervals == 0) return 0;
  size_t i = std::min(hint, intervals - 1);
  if (t < t_s[i]) i = 0;
  while (i + 1 < intervals && t_s[i + 1] <= t) ++i;
  return i;
}

void TimeLaw::state(double t, double& s, double& sdot_out, double& sddot, size_t* hint) const {
  if (u.empty()) {
    s = s_mm.empty() ? 0.0 : s_mm.front();
    sdot_out = s_mm.empty() ? 0.0 : sdot(0);
    sddot = 0.0;
    return;
  }
  t = std::clamp(t, 0.0, duration_s());
  const size_t i = interval_at_time(t, hint ? *hint : 0);
  if (hint) *hint = i;
  const double tau = t - t_s[i];
  const double v0 = sdot(i);
  sddot = u[i];
  sdot_out = std::max(0.0, v0 + u[i] * tau);
  s = std::min(s_mm[i + 1], s_mm[i] + v0 * tau + 0.5 * u[i] * tau * tau);
  if (t >= duration_s()) {
    s = s_mm.back();
    sdot_out = sdot(x.size() - 1);
  }
}

namespace {

// the velocity bounds of every grid point (point_x_max)
std::vector<double> velocity_bounds(const PathGrid& grid,
                                    const std::vector<MachineLimits>& interval_limits,
                                    const TimeLawOptions& options) {
  std::vector<double> x_max(grid.points.size());
  for (size_t i = 0; i < x_max.size(); ++i)
    x_max[i] = point_x_max(grid, interval_limits, options, i);
  return x_max;
}

// parametrize_path with the velocity bounds given (they do not change with the accelerations)
TimeLaw parametrize_bounded(const PathGrid& grid, const std::vector<MachineLimits>& interval_limits,
                            const TimeLawOptions& options, const std::vector<double>& x_max);

}  // namespace

TimeLaw parametrize_path(const PathGrid& grid, const std::vector<MachineLimits>& interval_limits,
                         const TimeLawOptions& options) {
  if (grid.points.size() < 2) throw InputError(grid.name, "a path needs at least two grid points");
  if (interval_limits.size() != grid.points.size() - 1)
    throw InternalError("interval limits do not match the path grid");
  return parametrize_bounded(grid, interval_limits, options,
                             velocity_bounds(grid, interval_limits, options));
}

namespace {

TimeLaw parametrize_bounded(const PathGrid& grid, const std::vector<MachineLimits>& interval_limits,
                            const TimeLawOptions& options, const std::vector<double>& x_max) {
  const size_t n = grid.points.size();
  if (n < 2) throw InputError(grid.name, "a path needs at least two grid points");
  if (interval_limits.size() != n - 1)
    throw InternalError("interval limits do not match the path grid");
  for (size_t i = 0; i + 1 < n; ++i)
    if (!(grid.points[i + 1].s_mm > grid.points[i].s_mm))
      throw InternalError("path grid is not strictly increasing " + where(grid, i));

  // backward pass: the controllable sets K_i = [k_lo, k_hi]
  std::vector<double> k_lo(n), k_hi(n);
  const double x_end = options.sdot_end * options.sdot_end;
  if (x_end > x_max[n - 1] * (1 + 1e-12)) {
    std::string reason;
    point_x_max(grid, interval_limits, options, n - 1, &reason);
    throw InputError(grid.name, "cannot end at the requested speed: " + reason);
  }
  k_lo[n - 1] = k_hi[n - 1] = std::min(x_end, x_max[n - 1]);
  std::vector<Row> rows;
  std::vector<Linear> lower, upper;
  rows.reserve(6 + 2 * grid.joint_limits.size());
  for (size_t i = n - 1; i-- > 0;) {
    interval_rows(grid, interval_limits, options, i, rows);
    const double ds = grid.points[i + 1].s_mm - grid.points[i].s_mm;
    if (!controllable_interval(rows, ds, k_lo[i + 1], k_hi[i + 1], x_max[i], lower, upper, k_lo[i],
                               k_hi[i]))
      throw InputError(grid.name, "no speed " + where(grid, i) +
                                      " lets the path reach its end within the limits");
  }

  // forward pass: the greedy largest step into the next controllable set
  TimeLaw law;
  law.s_mm.resize(n);
  law.x.resize(n);
  law.u.resize(n - 1);
  law.t_s.assign(n, 0.0);
  for (size_t i = 0; i < n; ++i) law.s_mm[i] = grid.points[i].s_mm;
  const double x_begin = options.sdot_begin * options.sdot_begin;
  if (x_begin > k_hi[0] * (1 + 1e-9) + 1e-12 || x_begin < k_lo[0] * (1 - 1e-9) - 1e-12)
    throw InputError(grid.name, "cannot start at the requested speed within the limits");
  law.x[0] = std::clamp(x_begin, k_lo[0], k_hi[0]);
  for (size_t i = 0; i + 1 < n; ++i) {
    interval_rows(grid, interval_limits, options, i, rows);
    const double ds = law.s_mm[i + 1] - law.s_mm[i];
    double u_min = 0.0, u_max = 0.0;
    u_range(rows, ds, law.x[i], k_lo[i + 1], k_hi[i + 1], u_min, u_max);
    const double u = u_max >= u_min ? u_max : 0.5 * (u_min + u_max);
    law.x[i + 1] = std::clamp(law.x[i] + 2.0 * ds * u, k_lo[i + 1], k_hi[i + 1]);
    law.x[i + 1] = std::max(0.0, law.x[i + 1]);
    law.u[i] = (law.x[i + 1] - law.x[i]) / (2.0 * ds);
  }

  // time: the speed is linear in time on each interval
  for (size_t i = 0; i + 1 < n; ++i) {
    const double ds = law.s_mm[i + 1] - law.s_mm[i];
    const double speeds = law.sdot(i) + law.sdot(i + 1);
    const double dt = 2.0 * ds / speeds;
    if (!(speeds > 0.0) || !std::isfinite(dt)) {
      const size_t stuck = x_max[i] <= x_max[i + 1] ? i : i + 1;
      std::string reason;
      point_x_max(grid, interval_limits, options, stuck, &reason);
      throw InputError(grid.name, "the path cannot go on " + where(grid, stuck) +
                                      ": the limits allow no speed there and next to it (" +
                                      reason + ")");
    }
    law.t_s[i + 1] = law.t_s[i] + dt;
  }
  if (!(law.duration_s() < 1e7))
    throw InputError(grid.name, "the path would take longer than 1e7 s within the limits");
  return law;
}

}  // namespace

double constant_speed_bound(const PathGrid& grid, const std::vector<MachineLimits>& interval_limits,
                            const TimeLawOptions& options) {
  const size_t n = grid.points.size();
  // at a constant TCP speed V: x = V^2 x1 with x1 = 1 / |p'|^2, u = V^2 u1 (x1's slope / 2)
  std::vector<double> x1(n);
  for (size_t i = 0; i < n; ++i) {
    const PathPoint& p = grid.points[i];
    const double d1 = std::max(p.d1_after.squaredNorm(), p.d1_before.squaredNorm());
    x1[i] = d1 > 0.0 ? 1.0 / d1 : 0.0;
  }
  const auto stopped = [&](size_t i) { return grid.points[i].speed_mm_s <= 0.0; };
  double bound2 = kInf;
  for (size_t i = 0; i < n; ++i) {
    if (stopped(i) || x1[i] <= 0.0) continue;
    bound2 = std::min(bound2, point_x_max(grid, interval_limits, options, i) / x1[i]);
  }
  std::vector<Row> rows;
  for (size_t i = 0; i + 1 < n; ++i) {
    const double ds = grid.points[i + 1].s_mm - grid.points[i].s_mm;
    const double u1 = (x1[i + 1] - x1[i]) / (2.0 * ds);
    interval_rows(grid, interval_limits, options, i, rows);
    // rows alternate: the interval's start, then its end
    for (size_t r = 0; r < rows.size(); ++r) {
      if (stopped(r % 2 == 0 ? i : i + 1)) continue;
      const double per_v2 = rows[r].a * u1 + rows[r].b * x1[i];
      if (per_v2 > 0.0) bound2 = std::min(bound2, rows[r].hi / per_v2);
      if (per_v2 < 0.0) bound2 = std::min(bound2, rows[r].lo / per_v2);
    }
  }
  return std::sqrt(std::max(0.0, bound2));
}

// ---------------------------------------------------------------------------------------
// resampling

void path_derivatives(const PathGrid& grid, double s, Vec3& position, Vec3& d1, Vec3& d2,
                      size_t* hint) {
  const size_t i = interval_of(grid, s, hint ? *hint : 0);
  if (hint) *hint = i;
  const PathPoint& a = grid.points[i];
  const PathPoint& b = grid.points[i + 1];
  const double h = b.s_mm - a.s_mm;
  const double t = std::clamp((s - a.s_mm) / h, 0.0, 1.0);
  const double t2 = t * t, t3 = t2 * t, t4 = t3 * t, t5 = t4 * t;
  // quintic Hermite basis: positions, first and second derivatives at both ends
  const double h0 = 1 - 10 * t3 + 15 * t4 - 6 * t5, h5 = 10 * t3 - 15 * t4 + 6 * t5;
  const double h1 = t - 6 * t3 + 8 * t4 - 3 * t5, h4 = -4 * t3 + 7 * t4 - 3 * t5;
  const double h2 = 0.5 * t2 - 1.5 * t3 + 1.5 * t4 - 0.5 * t5, h3 = 0.5 * t3 - t4 + 0.5 * t5;
  position = h0 * a.position_mm + h5 * b.position_mm + h * (h1 * a.d1_after + h4 * b.d1_before) +
             h * h * (h2 * a.d2_after + h3 * b.d2_before);
  const double g0 = -30 * t2 + 60 * t3 - 30 * t4;
  const double g1 = 1 - 18 * t2 + 32 * t3 - 15 * t4, g4 = -12 * t2 + 28 * t3 - 15 * t4;
  const double g2 = t - 4.5 * t2 + 6 * t3 - 2.5 * t4, g3 = 1.5 * t2 - 4 * t3 + 2.5 * t4;
  d1 = g0 * (a.position_mm - b.position_mm) / h + g1 * a.d1_after + g4 * b.d1_before +
       h * (g2 * a.d2_after + g3 * b.d2_before);
  const double k0 = -60 * t + 180 * t2 - 120 * t3;
  const double k1 = -36 * t + 96 * t2 - 60 * t3, k4 = -24 * t + 84 * t2 - 60 * t3;
  const double k2 = 1 - 9 * t + 18 * t2 - 10 * t3, k3 = 3 * t - 12 * t2 + 10 * t3;
  d2 = k0 * (a.position_mm - b.position_mm) / (h * h) + (k1 * a.d1_after + k4 * b.d1_before) / h +
       k2 * a.d2_after + k3 * b.d2_before;
  if (t == 0.0) position = a.position_mm;
  if (t == 1.0) position = b.position_mm;
}

void path_at(const PathGrid& grid, double s, Vec3& position, Vec3& d1, size_t* hint) {
  Vec3 d2;
  path_derivatives(grid, s, position, d1, d2, hint);
}

namespace {

// orientation at s: the path's own, or a slerp of the grid's axes and a linear roll
void orientation_at(const PathGrid& grid, double s, size_t& hint, Vec3& axis, double& roll) {
  if (grid.orientation_at) {
    grid.orientation_at(s, axis, roll);
    return;
  }
  const size_t i = interval_of(grid, s, hint);
  hint = i;
  const PathPoint& a = grid.points[i];
  const PathPoint& b = grid.points[i + 1];
  const double t = std::clamp((s - a.s_mm) / (b.s_mm - a.s_mm), 0.0, 1.0);
  axis = slerp_axis(a.tool_axis, b.tool_axis, t);
  roll = a.roll_rad + t * (b.roll_rad - a.roll_rad);
}

}  // namespace

PathSamples sample_time_law(const PathGrid& grid, const TimeLaw& law, double period_s) {
  if (!(period_s > 0.0)) throw InternalError("sample period must be positive");
  PathSamples out;
  out.period_s = period_s;
  const double duration = law.duration_s();
  const size_t periods = static_cast<size_t>(std::max(0.0, std::ceil(duration / period_s - 1e-9)));
  // the duration is rounded up to whole periods: at rest at the start, the law starts late by
  // less than a period; else at rest at the end, it holds its end; else it is slowed uniformly
  const double slack = double(periods) * period_s - duration;
  const bool rest_begin = law.x.front() == 0.0, rest_end = law.x.back() == 0.0;
  const double delay = rest_begin ? slack : 0.0;
  const double scale =
      (rest_begin || rest_end || periods == 0) ? 1.0 : duration / (double(periods) * period_s);
  const size_t count = periods + 1;
  out.s_mm.resize(count);
  out.sdot.resize(count);
  out.position_mm.resize(count);
  out.velocity_mm_s.resize(count);
  out.tool_axis.resize(count);
  out.roll_rad.resize(count);
  size_t law_hint = 0, path_hint = 0, axis_hint = 0;
  for (size_t k = 0; k < count; ++k) {
    double s = 0.0, sdot = 0.0, sddot = 0.0;
    const double t = (double(k) * period_s - delay) * scale;
    if (k + 1 == count) {
      s = law.s_mm.back();
      sdot = law.sdot(law.x.size() - 1);
    } else if (t <= 0.0) {
      s = law.s_mm.front();
      sdot = law.sdot(0);
    } else {
      law.state(t, s, sdot, sddot, &law_hint);
    }
    sdot *= scale;
    Vec3 d1;
    path_at(grid, s, out.position_mm[k], d1, &path_hint);
    out.s_mm[k] = s;
    out.sdot[k] = sdot;
    out.velocity_mm_s[k] = d1 * sdot;
    orientation_at(grid, s, axis_hint, out.tool_axis[k], out.roll_rad[k]);
  }
  out.position_mm.back() = grid.points.back().position_mm;
  out.position_mm.front() = grid.points.front().position_mm;
  out.tool_axis.front() = grid.points.front().tool_axis;
  out.tool_axis.back() = grid.points.back().tool_axis;
  out.roll_rad.front() = grid.points.front().roll_rad;
  out.roll_rad.back() = grid.points.back().roll_rad;
  return out;
}

namespace {

// ---------------------------------------------------------------------------------------
// the cubic Hermite interpolation of the samples against the TCP limits

struct SampleLimits {
  std::vector<Vec3> accel;  // per sample period k (samples k, k + 1): a_max over the intervals
  std::vector<Vec3> speed;  // per sample: v_max over the intervals holding it
};

SampleLimits sample_limits(const PathGrid& grid, const std::vector<MachineLimits>& limits,
                           const PathSamples& samples) {
  SampleLimits out;
  const size_t count = samples.size();
  out.speed.resize(count);
  out.accel.resize(count > 0 ? count - 1 : 0);
  std::vector<size_t> first(count), last(count);
  size_t hint = 0;
  for (size_t k = 0; k < count; ++k) {
    intervals_holding(grid, samples.s_mm[k], hint, first[k], last[k]);
    hint = last[k];
    Vec3 v = Vec3::Constant(kInf);
    for (size_t j = first[k]; j <= last[k]; ++j)
      for (int axis = 0; axis < 3; ++axis)
        v[axis] = std::min(v[axis], limits[j].axes[axis].v_max_mm_s);
    out.speed[k] = v;
  }
  for (size_t k = 0; k + 1 < count; ++k) {
    Vec3 a = Vec3::Constant(kInf);
    for (size_t j = std::min(first[k], first[k + 1]); j <= std::max(last[k], last[k + 1]); ++j)
      for (int axis = 0; axis < 3; ++axis)
        a[axis] = std::min(a[axis], limits[j].axes[axis].a_max_mm_s2);
    out.accel[k] = a;
  }
  return out;
}

// the cubic Hermite accelerations at both ends of period k on one axis
void hermite_accelerations(const PathSamples& samples, size_t k, int axis, double& a0, double& a1) {
  const double h = samples.period_s;
  const double c =
      6.0 * (samples.position_mm[k + 1][axis] - samples.position_mm[k][axis]) / (h * h);
  const double v0 = samples.velocity_mm_s[k][axis], v1 = samples.velocity_mm_s[k + 1][axis];
  a0 = c - (4.0 * v0 + 2.0 * v1) / h;
  a1 = -c + (2.0 * v0 + 4.0 * v1) / h;
}

struct Window {
  size_t first, last;  // sample indices; velocities at both are kept
};

// Per axis, the velocities of samples first+1 .. last-1 closest to the time law's for which
// the cubic on every period in the window stays within a_max at both ends (its acceleration
// is linear in between) and every sample within v_max: an interval chain. For period k with
// c = 6 (p_{k+1} - p_k) / h^2, both 4 v_k + 2 v_{k+1} and 2 v_k + 4 v_{k+1} must lie in
// [h (c - A), h (c + A)]. Backward: the sets of v_k from which the window's end is reachable;
// forward: the clamp of each law velocity into what the previous choice allows. False when
// the window has no such velocities.
bool fit_window(PathSamples& samples, const SampleLimits& limits, int axis, const Window& w) {
  const double h = samples.period_s;
  const size_t size = w.last - w.first + 1;
  std::vector<double> b_lo(size), b_hi(size);
  const double v_last = samples.velocity_mm_s[w.last][axis];
  b_lo[size - 1] = b_hi[size - 1] = v_last;
  const auto bounds = [&](size_t k, double& lo, double& hi) {
    const double a = limits.accel[k][axis] * (1 + 0.5 * kAccelFlag);
    const double c =
        6.0 * (samples.position_mm[k + 1][axis] - samples.position_mm[k][axis]) / (h * h);
    lo = h * (c - a);
    hi = h * (c + a);
  };
  for (size_t m = size - 1; m-- > 0;) {
    const size_t k = w.first + m;
    double lo = 0.0, hi = 0.0;
    bounds(k, lo, hi);
    // v' in [max(b_lo, (lo - 4v)/2, (lo - 2v)/4), min(b_hi, (hi - 4v)/2, (hi - 2v)/4)]
    const Linear lower[3] = {{b_lo[m + 1], 0.0}, {lo / 2, -2.0}, {lo / 4, -0.5}};
    const Linear upper[3] = {{b_hi[m + 1], 0.0}, {hi / 2, -2.0}, {hi / 4, -0.5}};
    const double v_max = limits.speed[k][axis] * (1 + 0.5 * kSpeedFlag);
    double v_lo = -v_max, v_hi = v_max;
    for (const Linear& f : lower) {
      for (const Linear& g : upper) {
        const double d = f.m - g.m, r = g.c - f.c;
        if (d > 0.0) v_hi = std::min(v_hi, r / d);
        if (d < 0.0) v_lo = std::max(v_lo, r / d);
        if (d == 0.0 && r < -1e-12 * (std::abs(f.c) + std::abs(g.c) + 1e-9)) return false;
      }
    }
    if (v_lo > v_hi) return false;
    b_lo[m] = v_lo;
    b_hi[m] = v_hi;
  }
  const double v_first = samples.velocity_mm_s[w.first][axis];
  const double slack = 1e-12 * (std::abs(v_first) + 1.0);
  if (v_first < b_lo[0] - slack || v_first > b_hi[0] + slack) return false;
  double previous = v_first;
  for (size_t m = 1; m + 1 < size; ++m) {
    const size_t k = w.first + m;
    double lo = 0.0, hi = 0.0;
    bounds(k - 1, lo, hi);
    const double r_lo = std::max({b_lo[m], (lo - 4.0 * previous) / 2, (lo - 2.0 * previous) / 4});
    const double r_hi = std::min({b_hi[m], (hi - 4.0 * previous) / 2, (hi - 2.0 * previous) / 4});
    double& v = samples.velocity_mm_s[k][axis];
    const double fitted = r_lo <= r_hi ? std::clamp(v, r_lo, r_hi) : 0.5 * (r_lo + r_hi);
    if (fitted != v) ++samples.adjusted_samples;
    v = fitted;
    previous = v;
  }
  return true;
}

// Checks the samples' cubic interpolation against the limits and fits velocities where it
// exceeds them; returns the windows (s ranges) that could not be fitted.
std::vector<std::pair<double, double>> fit_hermite(PathSamples& samples,
                                                   const SampleLimits& limits) {
  std::vector<std::pair<double, double>> failed;
  const size_t count = samples.size();
  if (count < 2) return failed;
  for (int axis = 0; axis < 3; ++axis) {
    // periods over a limit
    std::vector<size_t> bad;
    for (size_t k = 0; k + 1 < count; ++k) {
      double a0 = 0.0, a1 = 0.0;
      hermite_accelerations(samples, k, axis, a0, a1);
      const double a = limits.accel[k][axis] * (1 + kAccelFlag);
      const bool over_speed =
          std::abs(samples.velocity_mm_s[k][axis]) > limits.speed[k][axis] * (1 + kSpeedFlag) ||
          std::abs(samples.velocity_mm_s[k + 1][axis]) >
              limits.speed[k + 1][axis] * (1 + kSpeedFlag);
      if (std::abs(a0) > a || std::abs(a1) > a || over_speed) bad.push_back(k);
    }
    // windows around them, widened until the chain fits
    size_t next = 0;
    while (next < bad.size()) {
      size_t group_end = next;
      for (const size_t margin : {3, 8, 24, 64}) {
        // the bad periods within reach of the window grow it
        Window w{bad[next] >= margin ? bad[next] - margin : 0,
                 std::min(count - 1, bad[next] + 1 + margin)};
        group_end = next;
        while (group_end + 1 < bad.size() && bad[group_end + 1] <= w.last + margin) {
          ++group_end;
          w.last = std::min(count - 1, bad[group_end] + 1 + margin);
        }
        std::vector<double> saved(w.last - w.first + 1);
        for (size_t k = w.first; k <= w.last; ++k)
          saved[k - w.first] = samples.velocity_mm_s[k][axis];
        if (fit_window(samples, limits, axis, w)) break;
        for (size_t k = w.first; k <= w.last; ++k)
          samples.velocity_mm_s[k][axis] = saved[k - w.first];
        if (margin == 64) failed.emplace_back(samples.s_mm[w.first], samples.s_mm[w.last]);
      }
      next = group_end + 1;
    }
  }
  return failed;
}

}  // namespace

TimedPath time_path(const PathGrid& grid, const std::vector<MachineLimits>& interval_limits,
                    double period_s, const TimeLawOptions& options) {
  TimedPath out;
  out.interval_limits = interval_limits;
  TimeLawOptions current = options;
  const size_t n = grid.points.size();
  if (n < 2) throw InputError(grid.name, "a path needs at least two grid points");
  if (interval_limits.size() != n - 1)
    throw InternalError("interval limits do not match the path grid");
  // a little slack below every TCP acceleration limit for the velocity fit to work with, and
  // more on the first interval of a law from rest, which starts late by up to a period
  if (current.tcp_accel_scale.empty()) current.tcp_accel_scale.assign(n, 1.0);
  for (double& scale : current.tcp_accel_scale) scale *= kSampledAccelMargin;
  if (options.sdot_begin == 0.0) {
    // the stretch a ramp from rest covers in kLateStartPeriods at most (the path's
    // acceleration is below the norm of the axes' limits) plus the first interval
    const Vec3 a_max(interval_limits[0].axes[0].a_max_mm_s2, interval_limits[0].axes[1].a_max_mm_s2,
                     interval_limits[0].axes[2].a_max_mm_s2);
    const double reach = 0.5 * a_max.norm() * std::pow(kLateStartPeriods * period_s, 2);
    for (size_t i = 0; i < n && (i < 2 || grid.points[i - 1].s_mm <= reach); ++i)
      current.tcp_accel_scale[i] *= kLateStartScale;
  }
  const std::vector<double> x_max = velocity_bounds(grid, interval_limits, current);
  std::vector<double> repair(n, 1.0);
  for (int round = 0;; ++round) {
    out.law = parametrize_bounded(grid, interval_limits, current, x_max);
    if (out.law.duration_s() / period_s > kMaxSamples) {
      std::ostringstream msg;
      msg << "would take " << out.law.duration_s() << " s within the limits (more than "
          << kMaxSamples << " samples of " << period_s << " s); the limits allow almost no speed";
      throw InputError(grid.name, msg.str());
    }
    out.samples = sample_time_law(grid, out.law, period_s);
    const SampleLimits limits = sample_limits(grid, interval_limits, out.samples);
    const auto failed = fit_hermite(out.samples, limits);
    out.repair_rounds = round;
    out.tcp_accel_scale = current.tcp_accel_scale;
    out.repair_scale = repair;
    if (failed.empty()) return out;
    if (round == kMaxRepairRounds) {
      // limits that change several-fold within the window are the joints' mapped near a
      // singular posture (an arm over its base axis, stretched, or with a straight wrist): the
      // job's, exit 2; limits that hardly change there are this code's failure
      const auto [s_lo, s_hi] = failed.front();
      const size_t first = interval_of(grid, s_lo, 0), last = interval_of(grid, s_hi, first);
      double spread = 1.0;
      for (int axis = 0; axis < 3; ++axis) {
        double lo = kInf, hi = 0.0;
        for (size_t i = first; i <= last && i < interval_limits.size(); ++i) {
          const AxisLimits& limit = interval_limits[i].axes[axis];
          lo = std::min({lo, limit.a_max_mm_s2, limit.v_max_mm_s});
          hi = std::max({hi, limit.a_max_mm_s2, limit.v_max_mm_s});
        }
        if (lo > 0.0 && hi > 0.0) spread = std::max(spread, hi / lo);
      }
      std::ostringstream msg;
      msg << "the " << period_s * 1e3
          << " ms samples still exceed an acceleration limit between s = " << s_lo << " and "
          << s_hi << " mm after " << round << " rounds of lowered accelerations";
      if (spread < kSingularLimitSpread) throw InternalError(grid.name + ": " + msg.str());
      msg << ": the joints' limits, mapped to the tool, change " << spread
          << "-fold there, faster than the samples can follow (a posture near a singularity: "
             "over the arm's base axis, stretched out, or with its wrist straight); move the part "
             "(toolpath.surface.offset) or turn it";
      throw InputError(grid.name, msg.str());
    }
    // lower the accelerations allowed around each failed window and parametrise again
    std::vector<char> lowered(n, 0);
    for (const auto& [s_lo, s_hi] : failed) {
      // the grid points of every interval the window touches
      const size_t first = interval_of(grid, s_lo, 0), last = interval_of(grid, s_hi, first) + 1;
      for (size_t i = first; i <= last; ++i) lowered[i] = 1;
    }
    for (size_t i = 0; i < n; ++i)
      if (lowered[i]) {
        current.tcp_accel_scale[i] *= kRepairScale;
        repair[i] *= kRepairScale;
      }
  }
}

}  // namespace depotwin
