#include "planners/motion/firmware.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"
#include "planners/motion/print_segments.hpp"
#include "planners/motion/transition.hpp"

namespace depotwin {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// the share of a move each junction blend may take at most (two blends: half of the move)
constexpr double kBlendShare = 0.25;

// The largest move speed and acceleration along unit direction u under per-axis limits and
// the firmware's own caps (0: none): a firmware scales a move so that no axis exceeds its
// max feed rate or acceleration (Marlin's max_feedrate / max_acceleration per axis).
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

// A travel (material off): rest to rest along the line at the machine's speed, the tool
// turning in time (smoothstep) as in transition_piece.
TrajectoryPiece travel_piece(double t_begin_s, const Vec3& from, const Vec3& to,
                             const TcpLimits& limits, const FirmwareSettings& settings,
                             const ToolOrientation& tool0, const ToolOrientation& tool1) {
  const double length = (to - from).norm();
  const Vec3 u = (to - from) / length;
  double v = 0.0, a = 0.0;
  move_caps(u, limits.along(from, to), settings.max_velocity, settings.max_accel, v, a);
  const AxisProfile along = rest_to_rest(length, v, a);
  PhaseMotion motion;
  for (int axis = 0; axis < 3; ++axis) {
    AxisProfile profile(from[axis], 0.0);
    for (const Phase& phase : along.phases()) profile.append(phase.duration_s, u[axis] * phase.a0);
    motion.axes[axis] = std::move(profile);
  }
  TrajectoryPiece piece;
  piece.t_begin_s = t_begin_s;
  piece.t_end_s = t_begin_s + along.duration_s();
  piece.motion = std::move(motion);
  piece.tool_axis.begin = tool0.axis;
  piece.tool_axis.end = tool1.axis;
  piece.tool_axis.roll_begin = tool0.roll_rad;
  piece.tool_axis.roll_end = tool1.roll_rad;
  return piece;
}

}  // namespace

double junction_speed_squared(const Vec3& u_prev, const Vec3& u_next, double accel_mm_s2,
                              double junction_deviation_mm) {
  double sin_half = 0.0, cos_half = 0.0;
  half_angle(u_prev, u_next, sin_half, cos_half);
  // collinear: no corner to slow for (Marlin skips the limit when cos(theta) < -0.999999)
  if (sin_half >= 1.0 - 1e-12) return kInfinity;
  return accel_mm_s2 * junction_deviation_mm * sin_half / (1.0 - sin_half);
}

double klipper_junction_deviation(double square_corner_velocity, double max_accel_mm_s2) {
  return square_corner_velocity * square_corner_velocity * (std::sqrt(2.0) - 1.0) / max_accel_mm_s2;
}

FirmwareProfile firmware_lookahead(const std::vector<FirmwareMove>& moves,
                                   const FirmwareSettings& settings, double junction_deviation_mm) {
  const size_t n = moves.size();
  std::vector<double> length(n), accel(n), cruise2(n);
  for (size_t k = 0; k < n; ++k) {
    length[k] = moves[k].length_mm;
    accel[k] = moves[k].accel_mm_s2;
    cruise2[k] = moves[k].cruise_speed_mm_s * moves[k].cruise_speed_mm_s;
  }
  // each junction's cap: both moves' top speeds, the junction deviation, and room for the blend
  std::vector<double> cap2(n + 1, 0.0), blend_per_speed(n + 1, 0.0);
  for (size_t j = 1; j < n; ++j) {
    const FirmwareMove& prev = moves[j - 1];
    const FirmwareMove& next = moves[j];
    double c2 = std::min(cruise2[j - 1], cruise2[j]);
    c2 = std::min(c2, junction_speed_squared(prev.direction, next.direction,
                                             std::min(prev.accel_mm_s2, next.accel_mm_s2),
                                             junction_deviation_mm));
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

Trajectory FirmwarePlanner::plan(const Toolpath& toolpath, const TcpLimits& limits) const {
  const std::vector<PrintSegment> segments = split_into_segments(toolpath, limits);
  const MachineLimits& requested = limits.requested();
  // the junction deviation: Marlin's own, or Klipper's from the square-corner velocity at the
  // configured acceleration (max_accel, else the x and y axes' smaller a_max)
  const double config_accel = settings_.max_accel > 0.0 ? settings_.max_accel
                                                        : std::min(requested.axes[0].a_max_mm_s2,
                                                                   requested.axes[1].a_max_mm_s2);
  FirmwareSettings settings = settings_;
  if (settings.mode == FirmwareMode::klipper && settings.max_accel_to_decel > 0.0)
    settings.minimum_cruise_ratio = 1.0 - std::min(1.0, settings.max_accel_to_decel / config_accel);
  const double junction_deviation =
      settings.mode == FirmwareMode::klipper
          ? klipper_junction_deviation(settings.square_corner_velocity, config_accel)
          : settings.junction_deviation_mm;

  std::vector<TrajectoryPiece> pieces;
  double t = 0.0;
  Vec3 position = toolpath.start_mm;
  ToolOrientation tool = toolpath.start_orientation();
  const auto travel_to = [&](const Vec3& target, const ToolOrientation& target_tool) {
    if ((target - position).norm() > 1e-12) {
      pieces.push_back(travel_piece(t, position, target, limits, settings, tool, target_tool));
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
      move.cruise_speed_mm_s = std::min(s.speed_mm_s, speed_cap);
      // the blend at the move's start stays in the box of both moves: every axis within the
      // limits there (and within max_accel when given)
      if (i > first) {
        const PrintSegment& prev = segments[i - 1];
        const MachineLimits around =
            limits.uniform() ? requested
                             : limits.over(prev.p0.cwiseMin(prev.p1).cwiseMin(s.p0).cwiseMin(s.p1),
                                           prev.p0.cwiseMax(prev.p1).cwiseMax(s.p0).cwiseMax(s.p1));
        for (int axis = 0; axis < 3; ++axis)
          move.blend_accel_mm_s2[axis] =
              settings.max_accel > 0.0 ? std::min(settings.max_accel, around.axes[axis].a_max_mm_s2)
                                       : around.axes[axis].a_max_mm_s2;
      }
      moves.push_back(move);
    }
    const FirmwareProfile profile = firmware_lookahead(moves, settings, junction_deviation);
    const auto& speed = profile.junction_speed_mm_s;
    const auto& tau = profile.blend_time_s;
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
  return Trajectory("firmware", std::move(pieces));
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
  } else {
    refuse("junction_deviation_mm", "marlin");
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
  return std::make_unique<FirmwarePlanner>(settings);
}

}  // namespace depotwin
