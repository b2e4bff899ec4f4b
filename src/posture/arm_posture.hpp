// Where the 6-DOF arm stands along a toolpath: the roll about the nozzle axis at every point
// and the inverse-kinematics branch of the whole job, chosen to keep away from joint limits,
// singularities and the part (ROS-Industrial Descartes' ladder graph; Shembekar et al. 2018
// checked the same by hand in RobotStudio: "singularity, position that is out of reachability,
// or trajectory that is not feasible").
//
// The nozzle is symmetric about its axis, so a print pose has five degrees of freedom and the
// roll is free (core/pose.hpp); arm6's nozzle is not coaxial with joint 6, so the roll moves
// joints 1-5 (kinematics/arm6.hpp). The ladder:
//  - stations: the job's start, points along every print path about sample_spacing_mm apart
//    (each path's ends always, and both ends of an edge longer than that), the job's end;
//  - rungs: at each station, the roll in steps of roll_step_deg, on one branch. A rung is
//    valid when the pose is reachable there with joints 1-5 at least min_joint_margin_deg
//    inside their ranges and the posture is not singular (wrist alignment |sin q5|, wrist
//    centre offset from the joint-1 axis, manipulability above their minima), and, checked
//    lazily where the search goes, the links and tool body at least min_clearance_mm from the
//    part (collision/part_clearance.hpp, an exact distance to the non-convex part);
//  - rung cost: how close the posture is to a limit or a singularity (inverse squares of the
//    margins against reference values); edge cost: the joint motion between stations. Along a
//    print path the roll moves at most one step between stations and no joint more than
//    max_joint_step_deg (the path stays continuous); between paths (travel) any roll. A travel
//    and a print edge longer than sample_spacing_mm are checked at poses in between (position
//    straight, axis and roll turning evenly): each valid, no joint step above the maximum;
//    the long print edges of the path found also clear of the part there (an edge too close
//    is closed and the path searched again; a travel is not: the planners lift over the part);
//  - the branch is one for the whole job: the cheapest branch whose ladder has a path. (Changing
//    branch means passing a singularity: only possible in a joint-space travel, which the
//    planners here do not make.)
// The shortest path through the ladder (dynamic programming, exact on the ladder) gives the
// roll at each station; the rolls are unwrapped and interpolated along each path by arc length.
// Every point of the toolpath is then solved on that branch, continuous from its neighbour.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "collision/part_clearance.hpp"
#include "core/recorded_run.hpp"
#include "core/toolpath.hpp"
#include "kinematics/arm6.hpp"
#include "metrics/metrics_report.hpp"

namespace depotwin {

struct ArmPostureSettings {
  bool optimize_roll = true;             // false: one roll for the whole job
  std::optional<double> fixed_roll_deg;  // with optimize_roll false: this roll, else the best one
  int branch = -1;                       // -1: the best branch; 0..7: this one (Arm6 bits)
  double roll_step_deg = 15.0;
  double sample_spacing_mm = 5.0;
  double min_joint_margin_deg = 2.0;
  double min_wrist_alignment = 0.1;   // |sin q5| (5.7 deg)
  double min_wrist_offset_mm = 20.0;  // wrist centre from the joint-1 axis
  double min_manipulability = 1e-4;   // Arm6::manipulability (linear rows in m)
  double min_clearance_mm = 1.0;      // links and tool body to the part
  double max_joint_step_deg = 10.0;   // between stations along a print path

  // "" when usable, else what is wrong (names the field)
  std::string validate() const;
};

// whether a roll step goes round a whole turn in whole steps (360 / step a whole number)
bool roll_step_divides_a_turn(double roll_step_deg);

// names point `point` of print path `path` for messages ("layer 3, line 12, point 40")
using PointNamer = std::function<std::string(size_t path, size_t point)>;

struct ArmPosture {
  Toolpath toolpath;  // the input with rolls at every point and at start and end
  int branch = 0;
  bool roll_optimized = true;
  double fixed_roll_deg = 0.0;  // the roll used when not optimized
  // at every station: the chosen rolls (their mean rung cost: lower is farther from trouble),
  // against one roll for the whole job: roll 0, and the best single roll
  ArmPostureStats chosen;
  double chosen_mean_cost = 0.0;
  double chosen_joint_travel_deg = 0.0;  // the joints' turn summed along the paths
  FixedRollComparison roll_zero, best_fixed;
  size_t stations = 0;
};

// Chooses the rolls and the branch (InputError listing, per point, why no posture works there:
// out of reach, beyond a joint limit, singular, or colliding with the part, naming each point by
// `name`). `part` may be null (no part: no clearance checks).
ArmPosture choose_arm_posture(const Arm6& arm, const PartClearance* part, const Toolpath& toolpath,
                              const ArmPostureSettings& settings, const PointNamer& name);

// What the arm did over a simulated run (the recorded joints, not the plan): the posture
// measures at every recorded state (clearance to the part every clearance_period_s, and at
// every state while it is below 0.5 mm), contact events with the part (clearance
// <= 0 starting) and MuJoCo's contacts (the run's ContactLog), and how often the branch
// changed. `posture` fills the roll comparison and the branch.
ArmStats arm_run_stats(const Arm6& arm, const PartClearance* part, const RecordedRun& record,
                       const ArmPosture& posture, double clearance_period_s);

// The posture measures of one joint position (clearance +infinity without a part)
ArmPostureStats posture_at(const Arm6& arm, const PartClearance* part, const JointVector& joints);
// the smaller of each measure
void keep_worst(ArmPostureStats& worst, const ArmPostureStats& next);
// a report's starting point: every measure at +infinity
ArmPostureStats best_possible_posture();

}  // namespace depotwin
