// The firmware baseline: what a desktop printer's firmware does with the G-code. A trapezoid
// per straight move (accelerate, cruise, decelerate) under look-ahead over the whole queue of
// connected moves: each junction's speed is capped by junction deviation (Marlin,
// `mode: marlin`, `junction_deviation_mm`) or by Klipper's square-corner velocity (`mode:
// klipper`, `square_corner_velocity`, converted to a junction deviation), a backward and a
// forward pass make every junction reachable from the previous one and able to stop in time
// for the next, and Klipper's `minimum_cruise_ratio` (older `max_accel_to_decel`) lowers the
// peak of short zig-zags. Travels between separate paths are rest-to-rest trapezoids along
// the line at the machine's speed, the material off; it is on on every print move.
//
// The firmware changes the velocity's direction instantly at a junction; the twin's machine
// cannot, so each junction's velocity change is spread over tau = max_i |dv_i| / a_i (every
// axis within its a_max), centred on the junction at the junction speed: the corner is cut by
// |dv| tau / 8, less than the junction deviation itself.
#pragma once

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
};

// One straight move of a connected chain as the look-ahead sees it.
struct FirmwareMove {
  double length_mm = 0.0;
  Vec3 direction = Vec3::UnitX();         // unit
  double accel_mm_s2 = 0.0;               // the move's acceleration (no axis beyond its own)
  double cruise_speed_mm_s = 0.0;         // the move's top speed (feed, max_velocity, axes)
  Vec3 blend_accel_mm_s2 = Vec3::Zero();  // per-axis a_max around its start junction
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
// Klipper's conversion of square_corner_velocity to a junction deviation (Klipper
// docs/Kinematics.md, "Look-ahead"; toolhead.py): jd = scv^2 (sqrt(2) - 1) / max_accel, so a
// 90 deg corner is taken at exactly scv.
double klipper_junction_deviation(double square_corner_velocity, double max_accel_mm_s2);

// The look-ahead over one chain of connected moves: junction caps, the smoothed pass of
// minimum_cruise_ratio (klipper), backward and forward passes, and the junction blends.
FirmwareProfile firmware_lookahead(const std::vector<FirmwareMove>& moves,
                                   const FirmwareSettings& settings, double junction_deviation_mm);

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
