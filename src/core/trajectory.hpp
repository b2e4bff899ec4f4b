// The planned trajectory: immutable plain data, sampled by time (Ruckig's
// at_time, Drake's value(t)). Every planner produces one; planned metrics,
// the controller and the plots read only this.
#pragma once

#include <array>
#include <string>
#include <variant>
#include <vector>

#include "core/pose.hpp"
#include "core/profile.hpp"
#include "core/types.hpp"

namespace depotwin {

// The tool axis over a piece: from `begin` to `end` by the shortest rotation. Along a print
// segment the rotation follows the TCP along the segment's chord (the fraction of the way from
// chord_begin to chord_end), so the axis belongs to the geometry, not to the timing; otherwise
// it follows time with zero rate at both ends (smoothstep). Planar work keeps it vertical.
// The roll about the axis (Pose::roll_rad) goes from roll_begin to roll_end linearly in the
// same fraction.
struct ToolAxisMotion {
  Vec3 begin = vertical_tool_axis();
  Vec3 end = vertical_tool_axis();
  double roll_begin = 0.0;
  double roll_end = 0.0;
  bool along_chord = false;
  Vec3 chord_begin_mm = Vec3::Zero();
  Vec3 chord_end_mm = Vec3::Zero();

  bool constant() const { return begin == end && roll_begin == roll_end; }
};

// Motion given per Cartesian axis as constant-jerk phases (LSPB, MTT, trapezoids with jerk 0,
// double-S moves under a jerk limit).
struct PhaseMotion {
  std::array<AxisProfile, 3> axes;  // x, y, z; time relative to the piece's start
};

// Motion given as TCP samples at a fixed period (Bezier with the Taylor update of u),
// interpolated by cubic Hermite segments between samples.
struct SampledMotion {
  double period_s = 0.001;
  std::vector<Vec3> position_mm;    // sample k at time k * period_s
  std::vector<Vec3> velocity_mm_s;  // same size as position_mm
  std::vector<Vec3> tool_axis;      // per sample (unit); empty: the piece's tool_axis motion
  std::vector<double> roll_rad;     // per sample; empty: the piece's tool_axis motion's roll
  // per sample, the commanded flow as a fraction of the nominal (extrusion flow control);
  // empty: the piece's flow_fraction
  std::vector<double> flow_fraction;
};

// One time interval of the trajectory with one meaning: printing path `path_index`,
// or a transition between paths (path_index = -1, nothing deposited).
struct TrajectoryPiece {
  double t_begin_s = 0.0;
  double t_end_s = 0.0;
  int path_index = -1;              // index into Toolpath::paths, -1 for a transition
  bool depositing = false;          // shutter open / flow on
  double desired_speed_mm_s = 0.0;  // 0 in transitions
  // while depositing, the commanded flow as a fraction of the nominal flow at the desired
  // speed (extrusion: 1 = nominal; a planner that slows a path may lower it, SampledMotion
  // may give it per sample). An aerosol stream cannot be modulated: it ignores this.
  double flow_fraction = 1.0;
  // >= 0: the commanded flow follows the planned speed instead, led by this time (pressure
  // advance over an extruder's flow lag tau: fraction (|v| + lead d|v|/dt) / desired speed,
  // never below 0 unless flow_may_retract), so the lagged flow is |v| / desired speed of the
  // nominal; -1: as above
  double flow_lead_s = -1.0;
  // with flow_lead_s: the led fraction goes below 0 where a deceleration calls for it (an
  // extruder that may retract, process.retract), instead of stopping at 0
  bool flow_may_retract = false;
  std::variant<PhaseMotion, SampledMotion> motion;
  ToolAxisMotion tool_axis;  // the orientation channel
};

// What the trajectory says at one instant.
struct TrajectorySample {
  double t_s = 0.0;
  Vec3 position_mm = Vec3::Zero();
  Vec3 velocity_mm_s = Vec3::Zero();
  Vec3 acceleration_mm_s2 = Vec3::Zero();
  Vec3 tool_axis = vertical_tool_axis();       // unit
  Vec3 angular_velocity_rad_s = Vec3::Zero();  // of the tool axis
  double roll_rad = 0.0;                       // about the tool axis (Pose::roll_rad)
  bool depositing = false;
  int path_index = -1;
  int piece_index = -1;
  double desired_speed_mm_s = 0.0;
  double flow_fraction = 0.0;  // commanded flow / nominal while depositing, else 0

  Pose pose() const { return Pose(position_mm, tool_axis, roll_rad); }
};

// A choice a planner made that the report shows (metrics.json "planner.decisions"), e.g. how a
// corner was taken: where (print path, point index), what kind of place, the choice, and the
// figures behind it, each with its unit.
struct PlanFigure {
  std::string name;
  double value = 0.0;
  std::string unit;  // "mm", "s", "deg", "mm/s", "ratio", ...
};
struct PlanDecision {
  int path_index = -1;
  int point_index = -1;
  std::string kind;
  std::string choice;
  std::vector<PlanFigure> figures;
};

class Trajectory {
 public:
  Trajectory() = default;
  // pieces must be contiguous in time starting at 0; warnings are carried to metrics.json
  Trajectory(std::string planner, std::vector<TrajectoryPiece> pieces,
             std::vector<std::string> warnings = {}, std::vector<PlanDecision> decisions = {});

  const std::string& planner() const { return planner_; }
  double duration_s() const { return pieces_.empty() ? 0.0 : pieces_.back().t_end_s; }
  const std::vector<TrajectoryPiece>& pieces() const { return pieces_; }
  const std::vector<std::string>& warnings() const { return warnings_; }
  const std::vector<PlanDecision>& decisions() const { return decisions_; }

  // state at time t, clamped to [0, duration]; at a piece boundary the later piece wins
  TrajectorySample at(double t) const;
  // index of the piece containing t (clamped)
  int piece_at(double t) const;

  // total time with depositing on / off
  double depositing_time_s() const;
  double transition_time_s() const;

 private:
  std::string planner_;
  std::vector<TrajectoryPiece> pieces_;
  std::vector<std::string> warnings_;
  std::vector<PlanDecision> decisions_;
};

// Samples one trajectory at non-decreasing times (a simulation's steps) without searching the
// pieces from the start each time: the same samples as Trajectory::at, bit for bit. A time
// before the previous one searches again (still correct). The trajectory must outlive it.
class TrajectoryCursor {
 public:
  explicit TrajectoryCursor(const Trajectory& trajectory) : trajectory_(&trajectory) {}
  TrajectorySample at(double t);

 private:
  const Trajectory* trajectory_;
  int piece_ = 0;                  // the piece of the last sample
  std::array<size_t, 3> phase_{};  // per axis, the phase of the last sample (PhaseMotion)
};

// Evaluate one piece's motion at local time tau (seconds since the piece started).
void evaluate_motion(const TrajectoryPiece& piece, double tau, Vec3& position_mm,
                     Vec3& velocity_mm_s, Vec3& acceleration_mm_s2);
// The tool axis, its angular velocity and the roll at local time tau, where the TCP is at
// position_mm moving at velocity_mm_s (evaluate_motion's).
void evaluate_tool_axis(const TrajectoryPiece& piece, double tau, const Vec3& position_mm,
                        const Vec3& velocity_mm_s, Vec3& tool_axis, Vec3& angular_velocity_rad_s,
                        double& roll_rad);
// The commanded flow fraction at local time tau (0 when the piece does not deposit).
double evaluate_flow_fraction(const TrajectoryPiece& piece, double tau);
// the same where the motion there is known (velocity and acceleration at tau)
double evaluate_flow_fraction(const TrajectoryPiece& piece, double tau, const Vec3& velocity_mm_s,
                              const Vec3& acceleration_mm_s2);

}  // namespace depotwin
