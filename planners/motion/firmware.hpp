// The firmware baseline: what a desktop printer's firmware does with the G-code. A trapezoid
// per straight move (accelerate, cruise, decelerate) under look-ahead over the whole queue of
// connected moves: each junction's speed is capped by junction deviation (Marlin,
// `mode: marlin`, `junction_deviation_mm`) or by Klipper's square-corner velocity (`mode:
// klipper`, `square_corner_velocity`, converted to a junction deviation) or by Marlin's
// classic jerk (`classic_jerk`; `inspect --limits file` on a file that sets jerks); a backward and
// a forward pass make every junction reachable from the previous one and able to stop in time for
// the next, and Klipper's `minimum_cruise_ratio` (older `max_accel_to_decel`) lowers the peak of
// short zig-zags. Travels between separate paths are rest-to-rest trapezoids along the line at the
// machine's speed, the material off; it is on on every print move.
//
// The firmware changes the velocity's direction instantly at a junction; the twin's machine
// cannot, so each junction's velocity change is spread over tau = max_i |dv_i| / a_i (every
// axis within its a_max), centred on the junction at the junction speed: the corner is cut by
// |dv| tau / 8, less than the junction deviation itself.
//
// Under a jerk limit (the limits carry a j_max) the planner is Marlin with S_CURVE_ACCELERATION
// (Marlin planner.cpp / stepper.cpp, `_calc_bezier_curve_coeffs`; the same polynomial as the
// Klipper S-curve branch's `acceleration_order: 6`, dmbutyugin/klipper scurve): every speed
// change follows the quintic Bezier in time whose control points are v0, v0, v0, v1, v1, v1,
//   v(t) = v0 + (v1 - v0) B(t / T),   B(x) = 10 x^3 - 15 x^4 + 6 x^5,
// so the acceleration (peak 15/8 (v1 - v0) / T) and the jerk (peak 10/sqrt(3) (v1 - v0) / T^2)
// start and end at 0. Marlin keeps the trapezoid's ramp time T = dv / a (its peak acceleration
// is then 1.875 a) and has no jerk limit; here T is stretched until both peaks are within the
// move's a_max and j_max (s_curve_ramp_time), and the look-ahead's passes use these ramps
// (a move can join its end speeds when (v0 + v1) / 2 T(|v1 - v0|) fits in it). Junction speeds
// stay Marlin's (or Klipper's) junction deviation. The junction's instantaneous direction change
// gets the same shape: the velocity turns from v u_prev to v u_next as v u_prev + v (u_next -
// u_prev) B(t / tau), centred on the junction, tau the least time in which every axis keeps
// 15/8 |dv_i| / tau <= a_i and 10/sqrt(3) |dv_i| / tau^2 <= j_i; the corner is cut by
// 5 |dv| tau / 64. Travels ramp the same way. Ramps and blends last at least kSCurveMinTime_s.
// The motion is then written as samples (at most 1 ms apart, a whole number per piece, so no
// piece changes its duration); every ramp keeps kSCurveLimitShare of a_max and j_max for the
// cubic interpolation between samples.
#pragma once

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "planners/planner.hpp"

namespace depotwin {

enum class FirmwareMode { marlin, klipper };

struct FirmwareSettings {
  FirmwareMode mode = FirmwareMode::marlin;
  double junction_deviation_mm = 0.013;  // Marlin's JUNCTION_DEVIATION_MM default
  double square_corner_velocity = 5.0;   // Klipper's [printer] square_corner_velocity, mm/s
  double minimum_cruise_ratio = 0.5;     // Klipper's [printer] minimum_cruise_ratio (klipper)
  double max_accel_to_decel = 0.0;       // Klipper < 0.12's name for it, mm/s^2; 0: not given
  double max_accel = 0.0;                // mm/s^2; 0: from the scenario's limits
  double max_velocity = 0.0;             // mm/s; 0: from the scenario's limits
  // Marlin's classic jerk (CLASSIC_JERK; M205 X Y Z E, mm/s): the largest instant change of the
  // x, y, z and extruder speeds at a junction, which then decides the junction speeds in place
  // of the junction deviation (marlin); all 0: not used (the planner's `classic_jerk`, and
  // `inspect --limits file` on a file that sets them)
  double classic_jerk_mm_s[4] = {0.0, 0.0, 0.0, 0.0};
  bool uses_classic_jerk() const {
    return mode == FirmwareMode::marlin &&
           (classic_jerk_mm_s[0] > 0.0 || classic_jerk_mm_s[1] > 0.0 ||
            classic_jerk_mm_s[2] > 0.0 || classic_jerk_mm_s[3] > 0.0);
  }
};
// Marlin's defaults for the classic jerks a file does not set (Configuration.h DEFAULT_XJERK,
// DEFAULT_YJERK, DEFAULT_ZJERK, DEFAULT_EJERK), mm/s
constexpr double kMarlinDefaultJerk_mm_s[4] = {10.0, 10.0, 0.3, 5.0};

// One straight move of a connected chain as the look-ahead sees it.
struct FirmwareMove {
  double length_mm = 0.0;
  Vec3 direction = Vec3::UnitX();         // unit
  double accel_mm_s2 = 0.0;               // the move's acceleration (no axis beyond its own)
  double cruise_speed_mm_s = 0.0;         // the move's top speed (feed, max_velocity, axes)
  Vec3 blend_accel_mm_s2 = Vec3::Zero();  // per-axis a_max around its start junction
  // S-curve mode only: the move's jerk limit along it (infinity: none) and the per-axis j_max
  // around its start junction (0: none)
  double jerk_mm_s3 = std::numeric_limits<double>::infinity();
  Vec3 blend_jerk_mm_s3 = Vec3::Zero();
  // classic jerk only: the extruder's travel per mm of the move (its speed there is the move's
  // times this)
  double e_per_mm = 0.0;
};

// The look-ahead's answer for one chain of n moves (rest at both ends).
struct FirmwareProfile {
  std::vector<double> junction_speed_mm_s;  // n + 1: 0 at both ends
  std::vector<double> cruise_speed_mm_s;    // n: each move's peak speed cap
  std::vector<double> blend_time_s;         // n + 1: the time over which the junction turns
};

// Marlin's junction deviation: the speed at which a circle tangent to both moves, deviating
// jd from the corner, is travelled at centripetal acceleration a. With cos(theta) =
// -u_prev . u_next (theta the angle between the reversed incoming and the outgoing direction,
// so 180 deg for a straight line, 0 for a reversal): v^2 = a jd sin(theta/2) / (1 -
// sin(theta/2)) (Marlin planner.cpp; Sonny Jeon, "Improving grbl's cornering algorithm").
// Infinite for collinear moves, 0 for a reversal.
double junction_speed_squared(const Vec3& u_prev, const Vec3& u_next, double accel_mm_s2,
                              double junction_deviation_mm);
// Marlin's classic jerk at the junction of two moves, each at its top speed (Marlin
// planner.cpp with CLASSIC_JERK, after Prusa's firmware): the junction speed v starts at the
// smaller top speed; each axis's speed jumps from the incoming move's at v to the outgoing
// move's at its own top speed, by their difference when both run the same way and by the larger
// of the two otherwise (a reversal or a start), and every jump over the axis's jerk scales v
// down by jerk / jump. When both moves' safe speeds (the fastest each may start from rest at:
// no axis's speed above its jerk) exceed 0.99 v, the outgoing move's safe speed is taken
// instead. Speeds in mm/s; the extruder's from each move's e_per_mm.
double classic_jerk_junction_speed(const FirmwareMove& prev, const FirmwareMove& next,
                                   const double jerk_mm_s[4]);
// The largest move speed and acceleration along unit direction u under per-axis limits and
// the firmware's own caps (0: none): a firmware scales a move so that no axis exceeds its
// max feed rate or acceleration (Marlin's max_feedrate / max_acceleration per axis; Klipper's
// max_accel, the same in every xy direction, is such a cap).
void move_caps(const Vec3& u, const MachineLimits& limits, double max_velocity, double max_accel,
               double& speed_cap, double& accel_cap);
// The settings as the firmware applies them over the machine's limits, and its junction
// deviation: Klipper's max_accel (when not given, the x and y axes' smaller a_max) the same in
// every xy direction, its older max_accel_to_decel as minimum_cruise_ratio, and the junction
// deviation Marlin's own or Klipper's from square_corner_velocity at that acceleration (the
// planner and `inspect`'s estimate both take them from here)
FirmwareSettings resolved_firmware_settings(const FirmwareSettings& given,
                                            const MachineLimits& limits,
                                            double& junction_deviation_mm);
// Klipper's conversion of square_corner_velocity to a junction deviation (Klipper
// docs/Kinematics.md, "Look-ahead"; toolhead.py): jd = scv^2 (sqrt(2) - 1) / max_accel, so a
// 90 deg corner is taken at exactly scv.
double klipper_junction_deviation(double square_corner_velocity, double max_accel_mm_s2);

// The look-ahead over one chain of connected moves: junction caps, the smoothed pass of
// minimum_cruise_ratio (klipper), backward and forward passes, and the junction blends. With
// s_curve, the passes and blends are those of the quintic Bezier ramps (see the top).
FirmwareProfile firmware_lookahead(const std::vector<FirmwareMove>& moves,
                                   const FirmwareSettings& settings, double junction_deviation_mm,
                                   bool s_curve = false);

// S_CURVE_ACCELERATION's speed shape B(x) = 10 x^3 - 15 x^4 + 6 x^5 on [0, 1], and its
// integral from 0 to x, 5/2 x^4 - 3 x^5 + x^6
double s_curve_shape(double x);
double s_curve_shape_integral(double x);
// max B' and max |B''|: the ramp's peak acceleration and jerk per dv / T and dv / T^2
constexpr double kSCurvePeakAccel = 1.875;
constexpr double kSCurvePeakJerk = 5.773502691896258;  // 10 / sqrt(3)
// the shortest ramp or junction blend (s), so that 1 ms samples follow its jerk closely
constexpr double kSCurveMinTime_s = 0.008;
// the share of a_max and j_max the ramps plan with (the rest: the cubic interpolation of the
// samples)
constexpr double kSCurveLimitShare = 0.97;
// the time of a Bezier ramp changing the speed by dv: the least with peak acceleration and jerk
// within kSCurveLimitShare of accel and jerk (jerk infinity: none), and at least
// kSCurveMinTime_s; 0 for dv = 0
double s_curve_ramp_time(double dv, double accel_mm_s2, double jerk_mm_s3);

class FirmwarePlanner : public Planner {
 public:
  explicit FirmwarePlanner(FirmwareSettings settings) : settings_(settings) {}
  Trajectory plan(const Toolpath& toolpath, const TcpLimits& limits) const override;
  const FirmwareSettings& settings() const { return settings_; }

 private:
  FirmwareSettings settings_;
};

// the parameters `firmware` declares (describe planners prints them)
std::vector<PlannerParameter> firmware_parameters();
// throws InputError naming the parameter when a setting belongs to the other mode
std::unique_ptr<Planner> make_firmware_planner(const PlannerSpec& spec);

}  // namespace depotwin
