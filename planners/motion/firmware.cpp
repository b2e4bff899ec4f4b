#include "planners/motion/firmware.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"
#include "core/number_text.hpp"
#include "planners/motion/print_segments.hpp"
#include "planners/motion/transition.hpp"

namespace depotwin {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// the share of a move each junction blend may take at most (two blends: half of the move)
constexpr double kBlendShare = 0.25;

// S-curve mode: the axes' speed caps keep this share (the cubic interpolation between samples
// rounds a ramp's approach to its cruise by about 1e-6 of the speed)
constexpr double kSCurveSpeedShare = 1.0 - 1e-5;

// sin and cos of half of Marlin's junction angle theta, cos(theta) = -u_prev . u_next
void half_angle(const Vec3& u_prev, const Vec3& u_next, double& sin_half, double& cos_half) {
  const double cos_theta = std::clamp(-u_prev.dot(u_next), -1.0, 1.0);
  sin_half = std::sqrt(0.5 * (1.0 - cos_theta));
  cos_half = std::sqrt(0.5 * (1.0 + cos_theta));
}

// The largest time per unit junction speed over which the junction's velocity change is
// spread: tau = v * max_i |u_next,i - u_prev,i| / a_i (0 for collinear moves).
double blend_time_per_speed(const Vec3& u_prev, const Vec3& u_next, const Vec3& axis_accel) {
  double g = 0.0;
  for (int axis = 0; axis < 3; ++axis)
    g = std::max(g, std::abs(u_next[axis] - u_prev[axis]) / axis_accel[axis]);
  return g;
}

// Backward and forward passes (Marlin planner.cpp recalculate(): reverse_pass, forward_pass;
// Klipper toolhead.py LookAheadQueue): every junction speed within its cap, reachable from
// the previous one and able to reach the next, v_j^2 <= v_{j-1}^2 + 2 a d. Squared speeds.
std::vector<double> reachable_speeds_squared(const std::vector<double>& caps_squared,
                                             const std::vector<double>& accel,
                                             const std::vector<double>& length) {
  const size_t n = length.size();
  std::vector<double> v2 = caps_squared;
  v2.front() = 0.0;
  v2.back() = 0.0;
  for (size_t j = 1; j <= n; ++j)
    v2[j] = std::min(v2[j], v2[j - 1] + 2.0 * accel[j - 1] * length[j - 1]);
  for (size_t j = n; j-- > 0;) v2[j] = std::min(v2[j], v2[j + 1] + 2.0 * accel[j] * length[j]);
  return v2;
}

// Rest-to-rest trapezoid along a straight line of `length` (triangle when too short).
AxisProfile rest_to_rest(double length, double v, double a) {
  AxisProfile s(0.0, 0.0);
  const double peak = std::min(v, std::sqrt(a * length));
  s.append(peak / a, a);
  s.append((length - peak * peak / a) / peak, 0.0);
  s.append(peak / a, -a);
  return s;
}

// ---------------------------------------------------------------------------------------
// S_CURVE_ACCELERATION (jerk-limited mode): quintic Bezier ramps and junction blends

// a Bezier ramp between speeds va and vb fits in `length` (its distance is (va + vb) / 2 T)
bool s_curve_fits(double va, double vb, double length, double accel, double jerk) {
  return 0.5 * (va + vb) * s_curve_ramp_time(vb - va, accel, jerk) <= length * (1 + 1e-12) + 1e-12;
}

// the highest speed in [low, high] whose ramp to or from `low` fits in `length`
double s_curve_reach(double low, double high, double length, double accel, double jerk) {
  if (s_curve_fits(low, high, length, accel, jerk)) return high;
  // bisection on the higher speed; the ramp always starts from `low` itself
  double reached = low;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (reached + high);
    if (mid <= reached || mid >= high) break;
    (s_curve_fits(low, mid, length, accel, jerk) ? reached : high) = mid;
  }
  return reached;
}

// The passes with Bezier ramps: every junction speed within its cap (rest at both ends) and
// every move able to ramp between its end speeds. The distance a ramp needs is not monotone in
// its lower speed (a faster start can need more room: (va + vb) / 2 grows faster than T
// shrinks), so the passes repeat until nothing changes; each change lowers the higher speed of
// a move that cannot hold its ramp, which only shortens that ramp.
std::vector<double> s_curve_reachable_speeds(const std::vector<double>& caps,
                                             const std::vector<double>& accel,
                                             const std::vector<double>& jerk,
                                             const std::vector<double>& length) {
  const size_t n = length.size();
  std::vector<double> v = caps;
  v.front() = 0.0;
  v.back() = 0.0;
  const auto settle = [&](size_t k) {
    if (s_curve_fits(v[k], v[k + 1], length[k], accel[k], jerk[k])) return false;
    const bool first_higher = v[k] > v[k + 1];
    const double low = first_higher ? v[k + 1] : v[k], high = first_higher ? v[k] : v[k + 1];
    (first_higher ? v[k] : v[k + 1]) = s_curve_reach(low, high, length[k], accel[k], jerk[k]);
    return true;
  };
  for (int sweep = 0; sweep < 10000; ++sweep) {
    bool changed = false;
    for (size_t k = 0; k < n; ++k) changed = settle(k) || changed;
    for (size_t k = n; k-- > 0;) changed = settle(k) || changed;
    if (!changed) return v;
  }
  throw InternalError("firmware: S-curve look-ahead passes did not settle");
}

// The time over which junction blends turn the velocity (S-curve mode): per unit of junction
// speed, the acceleration part 15/8 max_i |du_i| / a_i and the jerk part 10/sqrt(3) max_i
// |du_i| / j_i; tau(v) = max(v g_a, sqrt(v g_j), kSCurveMinTime_s), 0 for collinear moves.
struct SCurveBlend {
  double per_speed = 0.0;       // g_a, s per mm/s
  double per_speed_jerk = 0.0;  // g_j, s^2 per mm/s
  double time(double v) const {
    if (!(v > 0.0) || (per_speed <= 0.0 && per_speed_jerk <= 0.0)) return 0.0;
    return std::max({v * per_speed, std::sqrt(v * per_speed_jerk), kSCurveMinTime_s});
  }
  // the largest junction speed whose blend holds it for at most `room` on each side:
  // v tau(v) / 2 <= room
  double speed_cap(double room) const {
    if (per_speed <= 0.0 && per_speed_jerk <= 0.0) return kInfinity;
    double cap = 2.0 * room / kSCurveMinTime_s;
    if (per_speed > 0.0) cap = std::min(cap, std::sqrt(2.0 * room / per_speed));
    if (per_speed_jerk > 0.0) cap = std::min(cap, std::cbrt(4.0 * room * room / per_speed_jerk));
    return cap;
  }
};

SCurveBlend s_curve_blend(const Vec3& u_prev, const Vec3& u_next, const Vec3& axis_accel,
                          const Vec3& axis_jerk) {
  SCurveBlend blend;
  for (int axis = 0; axis < 3; ++axis) {
    const double du = std::abs(u_next[axis] - u_prev[axis]);
    blend.per_speed =
        std::max(blend.per_speed, kSCurvePeakAccel * du / (kSCurveLimitShare * axis_accel[axis]));
    if (axis_jerk[axis] > 0.0)
      blend.per_speed_jerk = std::max(blend.per_speed_jerk,
                                      kSCurvePeakJerk * du / (kSCurveLimitShare * axis_jerk[axis]));
  }
  return blend;
}

// One stretch of a sampled S-curve move: the velocity is v_base + dv B((offset + t) / shape)
// for t in [0, duration] (dv = 0: constant velocity), starting at p0.
struct SCurveStretch {
  double duration_s = 0.0;
  Vec3 p0 = Vec3::Zero();
  Vec3 v_base = Vec3::Zero();
  Vec3 dv = Vec3::Zero();
  double shape_s = 0.0;
  double offset_s = 0.0;

  void at(double t, Vec3& position, Vec3& velocity) const {
    if (shape_s <= 0.0 || dv == Vec3::Zero()) {
      position = p0 + v_base * t;
      velocity = v_base;
      return;
    }
    const double x0 = offset_s / shape_s, x = (offset_s + t) / shape_s;
    position =
        p0 + v_base * t + dv * (shape_s * (s_curve_shape_integral(x) - s_curve_shape_integral(x0)));
    velocity = v_base + dv * s_curve_shape(x);
  }
};

// A move's stretches, chained from p0: each starts where the previous one ends.
class SCurveMotion {
 public:
  explicit SCurveMotion(const Vec3& p0) : end_(p0) {}
  void add(double duration_s, const Vec3& v_base, const Vec3& dv, double shape_s,
           double offset_s = 0.0) {
    if (!(duration_s > 0.0)) return;
    SCurveStretch stretch{duration_s, end_, v_base, dv, shape_s, offset_s};
    Vec3 velocity;
    stretch.at(duration_s, end_, velocity);
    stretches_.push_back(stretch);
  }
  // the ramp from speed v0 to v1 along u
  void ramp(const Vec3& u, double v0, double v1, double time_s) {
    add(time_s, v0 * u, (v1 - v0) * u, time_s);
  }
  double duration_s() const {
    double total = 0.0;
    for (const SCurveStretch& s : stretches_) total += s.duration_s;
    return total;
  }
  // samples at most 1 ms apart, a whole number of them over the duration; the last one is put
  // exactly on `end_mm`, where the next piece starts
  SampledMotion sampled(const Vec3& end_mm) const {
    const double duration = duration_s();
    const int periods =
        std::max(1, static_cast<int>(std::ceil(duration / kSCurveSamplePeriod_s - 1e-9)));
    SampledMotion motion;
    motion.period_s = duration / periods;
    motion.position_mm.resize(periods + 1);
    motion.velocity_mm_s.resize(periods + 1);
    size_t index = 0;
    double stretch_begin = 0.0;
    for (int k = 0; k <= periods; ++k) {
      const double t = k == periods ? duration : k * motion.period_s;
      while (index + 1 < stretches_.size() && t > stretch_begin + stretches_[index].duration_s) {
        stretch_begin += stretches_[index].duration_s;
        ++index;
      }
      const SCurveStretch& s = stretches_[index];
      s.at(std::min(t - stretch_begin, s.duration_s), motion.position_mm[k],
           motion.velocity_mm_s[k]);
    }
    motion.position_mm.back() = end_mm;
    return motion;
  }

  static constexpr double kSCurveSamplePeriod_s = 0.001;

 private:
  Vec3 end_;
  std::vector<SCurveStretch> stretches_;
};

// the fastest peak <= cap of a move from v0 to v1 whose two ramps fit in `length`
double s_curve_peak(double v0, double v1, double cap, double length, double accel, double jerk) {
  const auto fits = [&](double peak) {
    return 0.5 * (v0 + peak) * s_curve_ramp_time(peak - v0, accel, jerk) +
               0.5 * (peak + v1) * s_curve_ramp_time(peak - v1, accel, jerk) <=
           length * (1 + 1e-12) + 1e-12;
  };
  double low = std::max(v0, v1), high = std::max(low, cap);
  if (fits(high)) return high;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (low + high);
    if (mid <= low || mid >= high) break;
    (fits(mid) ? low : high) = mid;
  }
  return low;
}

// the move's jerk along unit direction u under per-axis limits (0 on an axis: none there)
double move_jerk(const Vec3& u, const MachineLimits& limits) {
  double jerk = kInfinity;
  for (int axis = 0; axis < 3; ++axis)
    if (std::abs(u[axis]) >= 1e-15 && limits.axes[axis].j_max_mm_s3 > 0.0)
      jerk = std::min(jerk, limits.axes[axis].j_max_mm_s3 / std::abs(u[axis]));
  return jerk;
}

// A travel (material off): rest to rest along the line at the machine's speed, the tool
// turning in time (smoothstep) as in transition_piece.
TrajectoryPiece travel_piece(double t_begin_s, const Vec3& from, const Vec3& to,
                             const TcpLimits& limits, const FirmwareSettings& settings,
                             const ToolOrientation& tool0, const ToolOrientation& tool1,
                             bool s_curve) {
  const double length = (to - from).norm();
  const Vec3 u = (to - from) / length;
  double v = 0.0, a = 0.0;
  const MachineLimits along_limits = limits.along(from, to);
  move_caps(u, along_limits, settings.max_velocity, settings.max_accel, v, a);
  if (s_curve) v *= kSCurveSpeedShare;
  TrajectoryPiece piece;
  piece.t_begin_s = t_begin_s;
  if (s_curve) {
    // Bezier ramps up to the highest peak both ramps leave room for, cruise, ramp down
    const double jerk = move_jerk(u, along_limits);
    const double peak = s_curve_peak(0.0, 0.0, v, length, a, jerk);
    const double ramp_s = s_curve_ramp_time(peak, a, jerk);
    SCurveMotion motion(from);
    motion.ramp(u, 0.0, peak, ramp_s);
    motion.add((length - peak * ramp_s) / peak, peak * u, Vec3::Zero(), 0.0);
    motion.ramp(u, peak, 0.0, ramp_s);
    piece.t_end_s = t_begin_s + motion.duration_s();
    piece.motion = motion.sampled(to);
  } else {
    const AxisProfile along = rest_to_rest(length, v, a);
    PhaseMotion motion;
    for (int axis = 0; axis < 3; ++axis) {
      AxisProfile profile(from[axis], 0.0);
      for (const Phase& phase : along.phases())
        profile.append(phase.duration_s, u[axis] * phase.a0);
      motion.axes[axis] = std::move(profile);
    }
    piece.t_end_s = t_begin_s + along.duration_s();
    piece.motion = std::move(motion);
  }
  piece.tool_axis.begin = tool0.axis;
  piece.tool_axis.end = tool1.axis;
  piece.tool_axis.roll_begin = tool0.roll_rad;
  piece.tool_axis.roll_end = tool1.roll_rad;
  return piece;
}

}  // namespace

void move_caps(const Vec3& u, const MachineLimits& limits, double max_velocity, double max_accel,
               double& speed_cap, double& accel_cap) {
  speed_cap = max_velocity > 0.0 ? max_velocity : kInfinity;
  accel_cap = max_accel > 0.0 ? max_accel : kInfinity;
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(u[axis]) < 1e-15) continue;
    speed_cap = std::min(speed_cap, limits.axes[axis].v_max_mm_s / std::abs(u[axis]));
    accel_cap = std::min(accel_cap, limits.axes[axis].a_max_mm_s2 / std::abs(u[axis]));
  }
}

double junction_speed_squared(const Vec3& u_prev, const Vec3& u_next, double accel_mm_s2,
                              double junction_deviation_mm) {
  double sin_half = 0.0, cos_half = 0.0;
  half_angle(u_prev, u_next, sin_half, cos_half);
  // collinear: no corner to slow for (Marlin skips the limit when cos(theta) < -0.999999)
  if (sin_half >= 1.0 - 1e-12) return kInfinity;
  return accel_mm_s2 * junction_deviation_mm * sin_half / (1.0 - sin_half);
}

namespace {

// a move's x, y, z and extruder speeds at speed v along it
void axis_speeds(const FirmwareMove& move, double v, double speeds[4]) {
  for (int axis = 0; axis < 3; ++axis) speeds[axis] = v * move.direction[axis];
  speeds[3] = v * move.e_per_mm;
}

// the fastest a move may start from rest with classic jerk: no axis's speed above its jerk
double classic_jerk_safe_speed(const FirmwareMove& move, const double jerk_mm_s[4]) {
  double speeds[4];
  axis_speeds(move, 1.0, speeds);
  double safe = move.cruise_speed_mm_s;
  for (int axis = 0; axis < 4; ++axis)
    if (std::abs(speeds[axis]) * safe > jerk_mm_s[axis])
      safe = jerk_mm_s[axis] / std::abs(speeds[axis]);
  return safe;
}

}  // namespace

double classic_jerk_junction_speed(const FirmwareMove& prev, const FirmwareMove& next,
                                   const double jerk_mm_s[4]) {
  double v = std::min(prev.cruise_speed_mm_s, next.cruise_speed_mm_s);
  double exit_speeds[4], entry_speeds[4];
  axis_speeds(prev, v, exit_speeds);
  axis_speeds(next, next.cruise_speed_mm_s, entry_speeds);
  // each axis's jump: the difference when it keeps its way, the larger speed otherwise
  double factor = 1.0;
  for (int axis = 0; axis < 4; ++axis) {
    const double exit = exit_speeds[axis], entry = entry_speeds[axis];
    const bool same_way = (exit > 0.0 && entry > 0.0) || (exit < 0.0 && entry < 0.0);
    const double jump =
        same_way ? std::abs(entry - exit) : std::max(std::abs(exit), std::abs(entry));
    if (jump * factor > jerk_mm_s[axis]) factor = jerk_mm_s[axis] / jump;
  }
  v *= factor;
  // when both moves could start from rest faster, the outgoing move's safe speed
  const double safe_prev = classic_jerk_safe_speed(prev, jerk_mm_s);
  const double safe_next = classic_jerk_safe_speed(next, jerk_mm_s);
  if (safe_prev > 0.99 * v && safe_next > 0.99 * v) v = safe_next;
  return v;
}

FirmwareSettings resolved_firmware_settings(const FirmwareSettings& given,
                                            const MachineLimits& limits,
                                            double& junction_deviation_mm) {
  // the configured acceleration: max_accel, else the x and y axes' smaller a_max
  const double config_accel =
      given.max_accel > 0.0 ? given.max_accel
                            : std::min(limits.axes[0].a_max_mm_s2, limits.axes[1].a_max_mm_s2);
  FirmwareSettings settings = given;
  // Klipper's max_accel is the toolhead's, the same in every direction of the xy plane (its
  // cartesian kinematics caps z alone): a diagonal move is not allowed the per-axis limit
  // scaled by its direction, as Marlin's is (a 90 deg corner turned 30 deg off the axes was
  // taken at 5.37 mm/s where square_corner_velocity says 5)
  if (settings.mode == FirmwareMode::klipper && !(settings.max_accel > 0.0))
    settings.max_accel = config_accel;
  if (settings.mode == FirmwareMode::klipper && settings.max_accel_to_decel > 0.0)
    settings.minimum_cruise_ratio = 1.0 - std::min(1.0, settings.max_accel_to_decel / config_accel);
  // the junction deviation: Marlin's own, or Klipper's from the square-corner velocity at the
  // configured acceleration
  junction_deviation_mm =
      settings.mode == FirmwareMode::klipper
          ? klipper_junction_deviation(settings.square_corner_velocity, config_accel)
          : settings.junction_deviation_mm;
  return settings;
}

double klipper_junction_deviation(double square_corner_velocity, double max_accel_mm_s2) {
  return square_corner_velocity * square_corner_velocity * (std::sqrt(2.0) - 1.0) / max_accel_mm_s2;
}

double s_curve_shape(double x) {
  return x * x * x * (10.0 + x * (-15.0 + 6.0 * x));
}

double s_curve_shape_integral(double x) {
  const double x2 = x * x;
  return x2 * x2 * (2.5 + x * (-3.0 + x));
}

double s_curve_ramp_time(double dv, double accel_mm_s2, double jerk_mm_s3) {
  dv = std::abs(dv);
  if (dv == 0.0) return 0.0;
  double time = kSCurvePeakAccel * dv / (kSCurveLimitShare * accel_mm_s2);
  if (jerk_mm_s3 > 0.0 && std::isfinite(jerk_mm_s3))
    time = std::max(time, std::sqrt(kSCurvePeakJerk * dv / (kSCurveLimitShare * jerk_mm_s3)));
  return std::max(time, kSCurveMinTime_s);
}

FirmwareProfile firmware_lookahead(const std::vector<FirmwareMove>& moves,
                                   const FirmwareSettings& settings, double junction_deviation_mm,
                                   bool s_curve) {
  const size_t n = moves.size();
  std::vector<double> length(n), accel(n), cruise2(n), jerk(n);
  for (size_t k = 0; k < n; ++k) {
    length[k] = moves[k].length_mm;
    accel[k] = moves[k].accel_mm_s2;
    cruise2[k] = moves[k].cruise_speed_mm_s * moves[k].cruise_speed_mm_s;
    jerk[k] = moves[k].jerk_mm_s3;
  }
  // each junction's cap: both moves' top speeds, the junction deviation, and room for the blend
  std::vector<double> cap2(n + 1, 0.0), blend_per_speed(n + 1, 0.0);
  std::vector<SCurveBlend> s_curve_blends(n + 1);
  for (size_t j = 1; j < n; ++j) {
    const FirmwareMove& prev = moves[j - 1];
    const FirmwareMove& next = moves[j];
    double c2 = std::min(cruise2[j - 1], cruise2[j]);
    if (settings.uses_classic_jerk()) {
      const double v = classic_jerk_junction_speed(prev, next, settings.classic_jerk_mm_s);
      c2 = std::min(c2, v * v);
    } else {
      c2 = std::min(c2, junction_speed_squared(prev.direction, next.direction,
                                               std::min(prev.accel_mm_s2, next.accel_mm_s2),
                                               junction_deviation_mm));
    }
    if (settings.mode == FirmwareMode::klipper) {
      // Klipper's limit for short moves: the virtual arc's centripetal acceleration within
      // each move's own, v^2 <= d tan(theta/2) a / 2 (toolhead.py calc_junction)
      double sin_half = 0.0, cos_half = 0.0;
      half_angle(prev.direction, next.direction, sin_half, cos_half);
      if (cos_half > 1e-12) {
        const double tan_half = sin_half / cos_half;
        c2 = std::min({c2, 0.5 * prev.length_mm * tan_half * prev.accel_mm_s2,
                       0.5 * next.length_mm * tan_half * next.accel_mm_s2});
      }
    }
    // the blend holds the junction speed for tau / 2 on each side: h = v^2 g / 2 <= share * d
    if (s_curve) {
      s_curve_blends[j] = s_curve_blend(prev.direction, next.direction, next.blend_accel_mm_s2,
                                        next.blend_jerk_mm_s3);
      const double room = kBlendShare * std::min(prev.length_mm, next.length_mm);
      const double blend_cap = s_curve_blends[j].speed_cap(room);
      c2 = std::min(c2, blend_cap * blend_cap);
      cap2[j] = c2;
      continue;
    }
    blend_per_speed[j] =
        blend_time_per_speed(prev.direction, next.direction, next.blend_accel_mm_s2);
    if (blend_per_speed[j] > 0.0)
      c2 = std::min(
          c2, 2.0 * kBlendShare * std::min(prev.length_mm, next.length_mm) / blend_per_speed[j]);
    cap2[j] = c2;
  }

  // Klipper's smoothed look-ahead: the same passes at accel * (1 - minimum_cruise_ratio); in
  // each hill of that smoothed profile (between its valleys) no move cruises above the hill's
  // peak, so short zig-zags keep a share of each move at constant speed (Klipper
  // docs/Config_Reference.md, [printer] minimum_cruise_ratio).
  const double cruise_ratio =
      settings.mode == FirmwareMode::klipper ? settings.minimum_cruise_ratio : 0.0;
  if (cruise_ratio > 0.0 && n > 0) {
    std::vector<double> smooth_accel(n), peak2(n);
    for (size_t k = 0; k < n; ++k) smooth_accel[k] = accel[k] * (1.0 - cruise_ratio);
    const std::vector<double> w2 = reachable_speeds_squared(cap2, smooth_accel, length);
    for (size_t k = 0; k < n; ++k)
      peak2[k] =
          std::min(cruise2[k], 0.5 * (w2[k] + w2[k + 1] + 2.0 * smooth_accel[k] * length[k]));
    size_t hill_start = 0;
    for (size_t k = 0; k < n; ++k) {
      const size_t j = k + 1;  // the junction after move k
      const bool valley = j == n || w2[j] <= 0.0 ||
                          (w2[j] < peak2[k] * (1 - 1e-12) && w2[j] < peak2[j] * (1 - 1e-12));
      if (!valley) continue;
      const double hill_peak2 =
          *std::max_element(peak2.begin() + hill_start, peak2.begin() + k + 1);
      for (size_t m = hill_start; m <= k; ++m) cruise2[m] = std::min(cruise2[m], hill_peak2);
      hill_start = j;
    }
    for (size_t j = 1; j < n; ++j) cap2[j] = std::min({cap2[j], cruise2[j - 1], cruise2[j]});
  }

  // S-curve mode: the same two rounds with the Bezier ramps' passes
  if (s_curve) {
    std::vector<double> caps(n + 1);
    for (size_t j = 0; j <= n; ++j) caps[j] = std::sqrt(cap2[j]);
    std::vector<double> v = s_curve_reachable_speeds(caps, accel, jerk, length);
    std::vector<double> free_length(length);
    for (size_t k = 0; k < n; ++k)
      free_length[k] = length[k] - 0.5 * v[k] * s_curve_blends[k].time(v[k]) -
                       0.5 * v[k + 1] * s_curve_blends[k + 1].time(v[k + 1]);
    v = s_curve_reachable_speeds(caps, accel, jerk, free_length);
    FirmwareProfile profile;
    profile.junction_speed_mm_s = v;
    profile.blend_time_s.resize(n + 1);
    for (size_t j = 0; j <= n; ++j) profile.blend_time_s[j] = s_curve_blends[j].time(v[j]);
    profile.cruise_speed_mm_s.resize(n);
    for (size_t k = 0; k < n; ++k) profile.cruise_speed_mm_s[k] = std::sqrt(cruise2[k]);
    return profile;
  }

  // the passes over the whole moves, then again over what the blends leave of each move (the
  // blends shrink with the speeds, so the second answer's blends fit where the first's did)
  std::vector<double> v2 = reachable_speeds_squared(cap2, accel, length);
  std::vector<double> free_length(length);
  for (size_t k = 0; k < n; ++k) {
    const double hold_begin = 0.5 * v2[k] * blend_per_speed[k];
    const double hold_end = 0.5 * v2[k + 1] * blend_per_speed[k + 1];
    free_length[k] = length[k] - hold_begin - hold_end;
  }
  v2 = reachable_speeds_squared(cap2, accel, free_length);

  FirmwareProfile profile;
  profile.junction_speed_mm_s.resize(n + 1);
  profile.blend_time_s.resize(n + 1);
  for (size_t j = 0; j <= n; ++j) {
    profile.junction_speed_mm_s[j] = std::sqrt(v2[j]);
    profile.blend_time_s[j] = profile.junction_speed_mm_s[j] * blend_per_speed[j];
  }
  profile.cruise_speed_mm_s.resize(n);
  for (size_t k = 0; k < n; ++k) profile.cruise_speed_mm_s[k] = std::sqrt(cruise2[k]);
  return profile;
}

namespace {

// The print moves of one chain in S-curve mode (see the header): per move, the second half of
// its start junction's blend, the Bezier ramp to its peak, the cruise, the ramp to its end
// speed and the first half of its end junction's blend; a piece runs from the middle of one
// blend to the middle of the next (off the corner by 5 |dv| tau / 64), sampled.
void append_s_curve_chain(const std::vector<PrintSegment>& segments, size_t first,
                          const std::vector<FirmwareMove>& moves, const FirmwareProfile& profile,
                          double& t, std::vector<TrajectoryPiece>& pieces) {
  const auto& speed = profile.junction_speed_mm_s;
  const auto& tau = profile.blend_time_s;
  // the middle of junction j's blend (j between moves j - 1 and j), or the move's end point
  const auto blend_middle = [&](size_t j, const Vec3& corner) -> Vec3 {
    if (!(tau[j] > 0.0)) return corner;
    const Vec3 dv = speed[j] * (moves[j].direction - moves[j - 1].direction);
    return corner + dv * (tau[j] * s_curve_shape_integral(0.5));
  };
  for (size_t k = 0; k < moves.size(); ++k) {
    const PrintSegment& s = segments[first + k];
    const FirmwareMove& move = moves[k];
    const Vec3& u = move.direction;
    const double v0 = speed[k], v1 = speed[k + 1];
    const double hold0 = tau[k] > 0.0 ? 0.5 * v0 * tau[k] : 0.0;
    const double hold1 = tau[k + 1] > 0.0 ? 0.5 * v1 * tau[k + 1] : 0.0;
    const double free_length = move.length_mm - hold0 - hold1;
    const double peak = s_curve_peak(v0, v1, profile.cruise_speed_mm_s[k], free_length,
                                     move.accel_mm_s2, move.jerk_mm_s3);
    const double t_up = s_curve_ramp_time(peak - v0, move.accel_mm_s2, move.jerk_mm_s3);
    const double t_down = s_curve_ramp_time(peak - v1, move.accel_mm_s2, move.jerk_mm_s3);
    const double ramps_mm = 0.5 * (v0 + peak) * t_up + 0.5 * (peak + v1) * t_down;
    const double t_cruise = peak > 0.0 ? std::max(0.0, free_length - ramps_mm) / peak : 0.0;

    SCurveMotion motion(blend_middle(k, s.p0));
    if (tau[k] > 0.0) {
      // the second half of the start junction's blend: from the middle of its turn
      const Vec3& u_prev = moves[k - 1].direction;
      motion.add(0.5 * tau[k], v0 * u_prev, v0 * (u - u_prev), tau[k], 0.5 * tau[k]);
    }
    motion.ramp(u, v0, peak, t_up);
    motion.add(t_cruise, peak * u, Vec3::Zero(), 0.0);
    motion.ramp(u, peak, v1, t_down);
    if (tau[k + 1] > 0.0)
      motion.add(0.5 * tau[k + 1], v1 * u, v1 * (moves[k + 1].direction - u), tau[k + 1]);
    TrajectoryPiece piece;
    piece.t_begin_s = t;
    piece.t_end_s = t + motion.duration_s();
    piece.path_index = s.path_index;
    piece.depositing = true;
    piece.flow_lead_s = 0.0;  // the E axis tied to the motion, as in the look-ahead mode
    piece.desired_speed_mm_s = s.speed_mm_s;
    piece.motion = motion.sampled(blend_middle(k + 1, s.p1));
    piece.tool_axis = segment_tool_axis(s.p0, s.tool0, s.p1, s.tool1);
    pieces.push_back(std::move(piece));
    t = pieces.back().t_end_s;
  }
}

}  // namespace

Trajectory FirmwarePlanner::plan(const Toolpath& toolpath, const TcpLimits& limits) const {
  const std::vector<PrintSegment> segments = split_into_segments(toolpath, limits);
  const MachineLimits& requested = limits.requested();
  double junction_deviation = 0.0;
  const FirmwareSettings settings =
      resolved_firmware_settings(settings_, requested, junction_deviation);

  // a jerk limit in force anywhere on the job: Marlin's S_CURVE_ACCELERATION (see the header)
  Vec3 job_lo = toolpath.start_mm.cwiseMin(toolpath.end_mm);
  Vec3 job_hi = toolpath.start_mm.cwiseMax(toolpath.end_mm);
  for (const PrintSegment& s : segments) {
    job_lo = job_lo.cwiseMin(s.p0).cwiseMin(s.p1);
    job_hi = job_hi.cwiseMax(s.p0).cwiseMax(s.p1);
  }
  const bool s_curve = requested.jerk_limited() || limits.over(job_lo, job_hi).jerk_limited();

  std::vector<TrajectoryPiece> pieces;
  double t = 0.0;
  Vec3 position = toolpath.start_mm;
  ToolOrientation tool = toolpath.start_orientation();
  const auto travel_to = [&](const Vec3& target, const ToolOrientation& target_tool) {
    if ((target - position).norm() > 1e-12) {
      pieces.push_back(
          travel_piece(t, position, target, limits, settings, tool, target_tool, s_curve));
      t = pieces.back().t_end_s;
    }
    position = target;
    tool = target_tool;
  };

  for (size_t first = 0; first < segments.size();) {
    // a chain: the segments printed in one go, at rest at both ends
    size_t end = first + 1;
    while (end < segments.size() && segments[end].joined_to_previous) ++end;
    travel_to(segments[first].p0, segments[first].tool0);

    std::vector<FirmwareMove> moves;
    std::vector<Vec3> directions;
    for (size_t i = first; i < end; ++i) {
      const PrintSegment& s = segments[i];
      FirmwareMove move;
      move.length_mm = s.length_mm;
      move.direction = (s.p1 - s.p0) / s.length_mm;
      double speed_cap = 0.0;
      move_caps(move.direction, s.limits, settings.max_velocity, settings.max_accel, speed_cap,
                move.accel_mm_s2);
      if (s_curve) {
        speed_cap *= kSCurveSpeedShare;
        move.jerk_mm_s3 = move_jerk(move.direction, s.limits);
      }
      move.cruise_speed_mm_s = std::min(s.speed_mm_s, speed_cap);
      // the blend at the move's start stays in the box of both moves: every axis within the
      // limits there (and within max_accel when given)
      if (i > first) {
        const PrintSegment& prev = segments[i - 1];
        const MachineLimits around =
            limits.uniform() ? requested
                             : limits.over(prev.p0.cwiseMin(prev.p1).cwiseMin(s.p0).cwiseMin(s.p1),
                                           prev.p0.cwiseMax(prev.p1).cwiseMax(s.p0).cwiseMax(s.p1));
        for (int axis = 0; axis < 3; ++axis) {
          move.blend_accel_mm_s2[axis] =
              settings.max_accel > 0.0 ? std::min(settings.max_accel, around.axes[axis].a_max_mm_s2)
                                       : around.axes[axis].a_max_mm_s2;
          move.blend_jerk_mm_s3[axis] = around.axes[axis].j_max_mm_s3;
        }
      }
      moves.push_back(move);
    }
    const FirmwareProfile profile =
        firmware_lookahead(moves, settings, junction_deviation, s_curve);
    const auto& speed = profile.junction_speed_mm_s;
    const auto& tau = profile.blend_time_s;
    if (s_curve) {
      append_s_curve_chain(segments, first, moves, profile, t, pieces);
      position = segments[end - 1].p1;
      tool = segments[end - 1].tool1;
      first = end;
      continue;
    }
    // the velocity change of junction j (between moves j-1 and j), spread over tau_j
    const auto blend_accel = [&](size_t j) -> Vec3 {
      return speed[j] * (moves[j].direction - moves[j - 1].direction) / tau[j];
    };

    for (size_t k = 0; k < moves.size(); ++k) {
      const PrintSegment& s = segments[first + k];
      const FirmwareMove& move = moves[k];
      const Vec3& u = move.direction;
      const double a = move.accel_mm_s2;
      const double v0 = speed[k], v1 = speed[k + 1];
      // the trapezoid over what the blends leave of the move
      const double free_length = move.length_mm - 0.5 * v0 * tau[k] - 0.5 * v1 * tau[k + 1];
      const double cap = profile.cruise_speed_mm_s[k];
      double peak = std::sqrt(std::min(cap * cap, 0.5 * (v0 * v0 + v1 * v1) + a * free_length));
      peak = std::max({peak, v0, v1});
      const double cruise_length = std::max(
          0.0, free_length - (peak * peak - v0 * v0) / (2 * a) - (peak * peak - v1 * v1) / (2 * a));
      const double t_accel = (peak - v0) / a, t_decel = (peak - v1) / a;
      const double t_cruise = peak > 0.0 ? cruise_length / peak : 0.0;

      // the start: the middle of junction k's blend (off the corner by dv tau / 8), or the
      // move's first point at rest or on a straight joint
      Vec3 q0 = s.p0, qd0 = v0 * u;
      if (tau[k] > 0.0) {
        const Vec3 dv = v0 * (u - moves[k - 1].direction);
        q0 = s.p0 + dv * tau[k] / 8.0;
        qd0 = 0.5 * v0 * (u + moves[k - 1].direction);
      }
      PhaseMotion motion;
      for (int axis = 0; axis < 3; ++axis) {
        AxisProfile profile_axis(q0[axis], qd0[axis]);
        if (tau[k] > 0.0) profile_axis.append(0.5 * tau[k], blend_accel(k)[axis]);
        profile_axis.append(t_accel, a * u[axis]);
        profile_axis.append(t_cruise, 0.0);
        profile_axis.append(t_decel, -a * u[axis]);
        if (tau[k + 1] > 0.0) profile_axis.append(0.5 * tau[k + 1], blend_accel(k + 1)[axis]);
        motion.axes[axis] = std::move(profile_axis);
      }
      TrajectoryPiece piece;
      piece.t_begin_s = t;
      piece.t_end_s = t + 0.5 * tau[k] + t_accel + t_cruise + t_decel + 0.5 * tau[k + 1];
      piece.path_index = s.path_index;
      // the flow is on over the whole print move, tied to the motion as the firmware's E axis
      // is (no pressure advance: led by 0 s)
      piece.depositing = true;
      piece.flow_lead_s = 0.0;
      piece.desired_speed_mm_s = s.speed_mm_s;
      piece.motion = std::move(motion);
      piece.tool_axis = segment_tool_axis(s.p0, s.tool0, s.p1, s.tool1);
      pieces.push_back(std::move(piece));
      t = pieces.back().t_end_s;
    }
    position = segments[end - 1].p1;
    tool = segments[end - 1].tool1;
    first = end;
  }
  travel_to(toolpath.end_mm, toolpath.end_orientation());
  // a max_velocity below print speeds slows those segments, as a firmware's M203 would: said,
  // since every other planner refuses a speed above its limit
  std::vector<std::string> warnings;
  if (settings.max_velocity > 0.0) {
    std::size_t capped = 0;
    double fastest = 0.0;
    for (const PrintSegment& s : segments)
      if (s.speed_mm_s > settings.max_velocity) {
        ++capped;
        fastest = std::max(fastest, s.speed_mm_s);
      }
    if (capped > 0)
      warnings.push_back("max_velocity " + message_number(settings.max_velocity) +
                         " mm/s is below the print speed of " + std::to_string(capped) + " of " +
                         std::to_string(segments.size()) + " segments (up to " +
                         message_number(fastest) + " mm/s): they print at most at " +
                         message_number(settings.max_velocity) + " mm/s");
  }
  return Trajectory("firmware", std::move(pieces), std::move(warnings));
}

std::vector<PlannerParameter> firmware_parameters() {
  return {
      {"mode",
       0.0,
       0.0,
       0.0,
       "whose look-ahead: marlin (junction deviation) or klipper (square-corner velocity)",
       false,
       {"marlin", "klipper"}},
      {"junction_deviation_mm",
       0.013,
       0.0,
       10.0,
       "marlin: JUNCTION_DEVIATION_MM, the corner's virtual arc deviation; a junction is taken "
       "at v^2 = a jd sin(theta/2) / (1 - sin(theta/2))",
       false,
       {},
       "mm"},
      {"classic_jerk",
       0.0,
       0.0,
       1000.0,
       "marlin with CLASSIC_JERK (Prusa's firmware): the x and y axes' jerk, the largest instant "
       "change of their speeds at a junction, in place of the junction deviation (z: Marlin's "
       "0.3 mm/s); 0: junction deviation",
       false,
       {},
       "mm/s"},
      {"square_corner_velocity",
       5.0,
       0.0,
       1000.0,
       "klipper: the speed of a 90 deg corner; jd = scv^2 (sqrt(2) - 1) / max_accel",
       false,
       {},
       "mm/s"},
      {"minimum_cruise_ratio",
       0.5,
       0.0,
       0.99,
       "klipper (>= v0.12): the least share of a move at cruising speed in short zig-zags",
       false,
       {},
       ""},
      {"max_accel_to_decel",
       0.0,
       0.0,
       1e6,
       "klipper (< v0.12): the older name, minimum_cruise_ratio = 1 - max_accel_to_decel / "
       "max_accel; 0: not given",
       false,
       {},
       "mm/s^2"},
      {"max_accel",
       0.0,
       0.0,
       1e6,
       "the firmware's acceleration cap over the axes' own; 0: the scenario's limits",
       false,
       {},
       "mm/s^2"},
      {"max_velocity",
       0.0,
       0.0,
       1e5,
       "the firmware's speed cap over the axes' own; 0: the scenario's limits",
       false,
       {},
       "mm/s"},
  };
}

std::unique_ptr<Planner> make_firmware_planner(const PlannerSpec& spec) {
  FirmwareSettings settings;
  const std::string mode = spec.get_choice("mode", "marlin");
  settings.mode = mode == "klipper" ? FirmwareMode::klipper : FirmwareMode::marlin;
  // a setting of the other firmware is a mistake worth saying
  const auto refuse = [&](const std::string& key, const std::string& owner) {
    if (spec.params.count(key) != 0)
      throw InputError("planners.firmware." + key,
                       "belongs to mode: " + owner + " (this planner is in mode: " + mode + ")");
  };
  if (settings.mode == FirmwareMode::marlin) {
    refuse("square_corner_velocity", "klipper");
    refuse("minimum_cruise_ratio", "klipper");
    refuse("max_accel_to_decel", "klipper");
    if (spec.params.count("classic_jerk") != 0 && spec.params.count("junction_deviation_mm") != 0)
      throw InputError("planners.firmware.classic_jerk",
                       "give junction_deviation_mm or classic_jerk, not both (Marlin corners by "
                       "one of them)");
  } else {
    refuse("junction_deviation_mm", "marlin");
    refuse("classic_jerk", "marlin");
    if (spec.params.count("minimum_cruise_ratio") != 0 &&
        spec.params.count("max_accel_to_decel") != 0)
      throw InputError("planners.firmware.max_accel_to_decel",
                       "give minimum_cruise_ratio or the older max_accel_to_decel, not both");
  }
  settings.junction_deviation_mm =
      spec.get("junction_deviation_mm", settings.junction_deviation_mm);
  settings.square_corner_velocity =
      spec.get("square_corner_velocity", settings.square_corner_velocity);
  settings.minimum_cruise_ratio = spec.get("minimum_cruise_ratio", settings.minimum_cruise_ratio);
  settings.max_accel_to_decel = spec.get("max_accel_to_decel", settings.max_accel_to_decel);
  settings.max_accel = spec.get("max_accel", settings.max_accel);
  settings.max_velocity = spec.get("max_velocity", settings.max_velocity);
  // classic jerk: x and y as given, z and E at Marlin's defaults (the flow is no axis here)
  const double classic_jerk = spec.get("classic_jerk", 0.0);
  if (classic_jerk > 0.0) {
    settings.classic_jerk_mm_s[0] = settings.classic_jerk_mm_s[1] = classic_jerk;
    settings.classic_jerk_mm_s[2] = kMarlinDefaultJerk_mm_s[2];
    settings.classic_jerk_mm_s[3] = kMarlinDefaultJerk_mm_s[3];
  }
  return std::make_unique<FirmwarePlanner>(settings);
}

}  // namespace depotwin
