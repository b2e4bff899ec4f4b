#include "posture/arm_posture.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <sstream>
#include <unordered_map>

#include "core/error.hpp"
#include "core/interrupt.hpp"

namespace depotwin {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr int kBranches = 8;
// reference values of the rung cost: a posture this far from each limit costs 1 per measure,
// and the cost grows with the fourth power of how much closer it is (nearly flat where the arm
// is comfortable, steep near a limit: the worst station weighs more than many good ones)
constexpr double kMarginReference_deg = 30.0;
constexpr double kAlignmentReference = 0.3;  // |sin q5| at 17.5 deg
constexpr double kOffsetReference_mm = 100.0;
constexpr double kManipulabilityReference = 0.005;
constexpr double kClearanceReference_mm = 5.0;
// edge costs: joint motion between stations, in units of these steps, squared
constexpr double kPrintJointStep_deg = 20.0;
constexpr double kTravelJointStep_deg = 60.0;
// a roll step between stations along a print path costs this much (a rung at the reference
// distances from every limit costs 4)
constexpr double kRollStepCost = 5.0;
// a travel this long pays half of that per roll step, longer ones less
constexpr double kLongTravel_mm = 10.0;
// closer to the part than this, the run's clearance is measured at every state
constexpr double kNearPart_mm = 0.5;
// pass 2 ranks at most this many branches (the most promising by pass 1) once one works
constexpr int kBranchesCompared = 2;
// a station also where the tool axis has turned this much since the last one
constexpr double kStationTurn_deg = 5.0;
// a joint step along a path is a jump (a branch or a wrap flipping) above max_joint_step_deg plus
// this many times the tool's own turn (axis and roll) between the two points
constexpr double kJointStepPerToolTurn = 4.0;
// a travel between two rolls is checked at intermediate poses at most this far apart in tool
// turn (deg) and in distance (mm)
constexpr double kTravelCheckTurn_deg = 5.0;
constexpr double kTravelCheckDistance_mm = 10.0;
// at most this many points are named in an error
constexpr size_t kMaxNamedPoints = 20;

// why a rung is not valid, most fundamental first
enum class Reason : uint8_t { ok, unreachable, joint_limit, singular, collides };

const char* reason_text(Reason reason) {
  switch (reason) {
    case Reason::unreachable:
      return "out of the arm's reach";
    case Reason::joint_limit:
      return "beyond a joint's range";
    case Reason::singular:
      return "at a singularity";
    case Reason::collides:
      return "too close to the part";
    default:
      return "reachable";
  }
}

std::string format(const char* pattern, double value) {
  char text[64];
  std::snprintf(text, sizeof text, pattern, value);
  return text;
}

std::string point_text(const Vec3& p) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.3f, %.3f, %.3f) mm", p.x(), p.y(), p.z());
  return text;
}

// one station of the ladder
struct Station {
  Pose pose;                 // roll 0
  int path = -1;             // -1: the job's start or end
  size_t point = 0;          // index in the path
  bool after_travel = true;  // the edge from the previous station is a travel
  // the edge from the previous station is one print edge longer than the station spacing: its
  // poses in between are checked as a travel's are (a 300 mm line in two points)
  bool after_long_edge = false;
};

// the job's start, points along every path about `spacing` apart or where the tool axis has
// turned by kStationTurn_deg (a fillet), both ends of an edge longer than `spacing`, a path's
// ends always, the job's end
std::vector<Station> make_stations(const Toolpath& toolpath, double spacing_mm) {
  std::vector<Station> stations;
  stations.push_back(Station{Pose(toolpath.start_mm), -1, 0, true});
  for (size_t p = 0; p < toolpath.paths.size(); ++p) {
    const PrintPath& path = toolpath.paths[p];
    double since = 0.0;
    Vec3 axis = path.tool_axis(0);
    for (size_t i = 0; i < path.points.size(); ++i) {
      if (i > 0) since += (path.points[i] - path.points[i - 1]).norm();
      const bool last = i + 1 == path.points.size();
      const bool turned = axis_angle_rad(axis, path.tool_axis(i)) >= deg_to_rad(kStationTurn_deg);
      const bool before_long = !last && (path.points[i + 1] - path.points[i]).norm() > spacing_mm;
      if (i > 0 && !last && since < spacing_mm && !turned && !before_long) continue;
      const bool long_edge = i > 0 && (path.points[i] - path.points[i - 1]).norm() > spacing_mm;
      stations.push_back(Station{Pose(path.points[i], path.tool_axis(i)), static_cast<int>(p), i,
                                 i == 0, long_edge});
      since = 0.0;
      axis = path.tool_axis(i);
    }
  }
  stations.push_back(Station{Pose(toolpath.end_mm), -1, 0, true});
  return stations;
}

Arm6Joints to_array(const JointVector& q) {
  Arm6Joints a{};
  for (size_t j = 0; j < 6; ++j) a[j] = q[j];
  return a;
}

JointVector to_vector(const Arm6Joints& q) {
  return JointVector(q.begin(), q.end());
}

// the smallest distance of joints 1-5 to their range's ends (rad): joint 6 turns +-400 deg,
// so one of its turns is always well inside
double margin_1_to_5(const Arm6& arm, const Arm6Joints& q) {
  double margin = kInfinity;
  const std::vector<JointLimit>& limits = arm.joint_limits();
  for (size_t j = 0; j < 5; ++j)
    margin = std::min({margin, q[j] - limits[j].min, limits[j].max - q[j]});
  return margin;
}

// the angle difference a - b wrapped into (-pi, pi] (joint 6's turns are equivalent here)
double wrapped(double a, double b) {
  return std::remainder(a - b, 2.0 * kPi);
}

// squared joint motion between two postures in units of `step`
double motion_cost(const Arm6Joints& a, const Arm6Joints& b, double step_rad) {
  double sum = 0.0;
  for (size_t j = 0; j < 6; ++j) {
    const double d = (j == 5 ? wrapped(a[j], b[j]) : a[j] - b[j]) / step_rad;
    sum += d * d;
  }
  return sum;
}

// the largest joint step allowed between two poses along a path (rad): the fixed allowance
// plus what the tool's own turn may take
double allowed_step(const Pose& a, const Pose& b, double max_step_rad) {
  const double turn =
      axis_angle_rad(a.tool_axis, b.tool_axis) + std::abs(wrapped(a.roll_rad, b.roll_rad));
  return max_step_rad + kJointStepPerToolTurn * turn;
}

double largest_step(const Arm6Joints& a, const Arm6Joints& b) {
  double largest = 0.0;
  for (size_t j = 0; j < 6; ++j)
    largest = std::max(largest, std::abs(j == 5 ? wrapped(a[j], b[j]) : a[j] - b[j]));
  return largest;
}

// A rung's validity and cost without the part: reach, joint ranges, singularity
struct RungCheck {
  Reason reason = Reason::ok;
  double cost = kInfinity;
};

RungCheck check_rung(const Arm6& arm, const Arm6Joints& q, const ArmPostureSettings& s) {
  RungCheck check;
  const double margin = margin_1_to_5(arm, q);
  if (margin < deg_to_rad(s.min_joint_margin_deg)) {
    check.reason = Reason::joint_limit;
    return check;
  }
  const JointVector joints = to_vector(q);
  const double alignment = arm.wrist_alignment(joints);
  const double offset = arm.wrist_centre_offset_mm(joints);
  const double manipulability = arm.manipulability(joints);
  if (alignment < s.min_wrist_alignment || offset < s.min_wrist_offset_mm ||
      manipulability < s.min_manipulability) {
    check.reason = Reason::singular;
    return check;
  }
  const auto fourth = [](double x) { return x * x * x * x; };
  check.cost = fourth(deg_to_rad(kMarginReference_deg) / margin) +
               fourth(kAlignmentReference / alignment) + fourth(kOffsetReference_mm / offset) +
               fourth(kManipulabilityReference / manipulability);
  return check;
}

// the pose of a station at roll index k
Pose rolled(const Station& station, double roll_rad) {
  Pose pose = station.pose;
  pose.roll_rad = roll_rad;
  return pose;
}

// The ladder of one branch: per station and roll, the posture, its cost (infinite: invalid)
// and why, and the clearance once measured.
struct Ladder {
  int rolls = 0;
  double step_rad = 0.0;      // between rolls
  std::vector<Arm6Joints> q;  // station-major
  std::vector<double> cost;
  std::vector<Reason> reason;
  std::vector<double> clearance;  // NaN until measured
  size_t index(size_t station, int roll) const { return station * rolls + roll; }
};

// whether the travel into station s from roll `from` (at s - 1) to roll k can be made: null
// accepts every travel
using TravelCheck = std::function<bool(size_t s, int from, int k)>;

// The shortest path through a ladder: one roll index per station, or empty when none exists.
// Along a print path the roll moves at most one step between stations and no joint more than
// max_step; between paths any roll the travel check accepts.
std::vector<int> shortest_path(const Ladder& ladder, const std::vector<Station>& stations,
                               double max_step_rad, bool joint_costs,
                               const TravelCheck& travel_ok = nullptr, size_t* stuck_at = nullptr) {
  const int K = ladder.rolls;
  const size_t n = stations.size();
  std::vector<double> total(K, kInfinity), next(K);
  std::vector<int16_t> back(n * K, -1);
  for (int k = 0; k < K; ++k) total[k] = ladder.cost[ladder.index(0, k)];
  const double print_step = deg_to_rad(kPrintJointStep_deg);
  const double travel_step = deg_to_rad(kTravelJointStep_deg);
  for (size_t s = 1; s < n; ++s) {
    throw_if_interrupted();  // a signal asked to stop (core/interrupt.hpp)
    const bool travel = stations[s].after_travel;
    for (int k = 0; k < K; ++k) {
      next[k] = kInfinity;
      const double here = ladder.cost[ladder.index(s, k)];
      if (!std::isfinite(here)) continue;
      const Arm6Joints& q = ladder.q[ladder.index(s, k)];
      // the previous station's rungs this one may follow
      const int reach = travel ? K / 2 : 1;
      for (int d = -reach; d <= reach; ++d) {
        if (travel && d == reach && K % 2 == 0 && reach != 0) continue;  // each roll once
        const int from = ((k + d) % K + K) % K;
        const double before = total[from];
        if (!std::isfinite(before)) continue;
        const Arm6Joints& p = ladder.q[ladder.index(s - 1, from)];
        double edge = 0.0;
        if (travel) {
          // a short travel (the next hatch line) turns the roll in a short move too
          const double distance =
              (stations[s].pose.position_mm - stations[s - 1].pose.position_mm).norm();
          edge = (joint_costs ? motion_cost(p, q, travel_step) : 0.0) +
                 kRollStepCost * d * d / (1.0 + distance / kLongTravel_mm);
          // the travel's own check (inverse kinematics along it) only where it would win
          if (!(before + edge + here < next[k])) continue;
          if (travel_ok && !travel_ok(s, from, k)) continue;
        } else if (stations[s].after_long_edge && joint_costs) {
          // a long print edge: its poses in between, as a travel's, where it would win
          edge = motion_cost(p, q, print_step) + kRollStepCost * d * d;
          if (!(before + edge + here < next[k])) continue;
          if (travel_ok && !travel_ok(s, from, k)) continue;
        } else {
          if (joint_costs &&
              largest_step(p, q) > allowed_step(rolled(stations[s - 1], from * ladder.step_rad),
                                                rolled(stations[s], k * ladder.step_rad),
                                                max_step_rad))
            continue;
          // a roll change while printing costs the time law too (the joints turn for it): it
          // is made only where it buys a clearly better posture
          edge = (joint_costs ? motion_cost(p, q, print_step) : 0.0) + kRollStepCost * d * d;
        }
        const double candidate = before + edge + here;
        if (candidate < next[k]) {
          next[k] = candidate;
          back[s * K + k] = static_cast<int16_t>(from);
        }
      }
    }
    total.swap(next);
    // no rung of station s is reached: the sequence breaks between s - 1 and s
    if (std::none_of(total.begin(), total.end(), [](double t) { return std::isfinite(t); })) {
      if (stuck_at) *stuck_at = s;
      return {};
    }
  }
  int best = -1;
  for (int k = 0; k < K; ++k)
    if (std::isfinite(total[k]) && (best < 0 || total[k] < total[best])) best = k;
  if (best < 0) return {};
  std::vector<int> path(n);
  path[n - 1] = best;
  for (size_t s = n - 1; s > 0; --s) path[s - 1] = back[s * K + path[s]];
  return path;
}

double path_cost(const Ladder& ladder, const std::vector<int>& path) {
  double sum = 0.0;
  for (size_t s = 0; s < path.size(); ++s) sum += ladder.cost[ladder.index(s, path[s])];
  return sum;
}

}  // namespace

bool roll_step_divides_a_turn(double roll_step_deg) {
  return std::fmod(360.0, roll_step_deg) < 1e-9;
}

std::string ArmPostureSettings::validate() const {
  if (!(roll_step_deg >= 1.0 && roll_step_deg <= 90.0 && roll_step_divides_a_turn(roll_step_deg)))
    return "roll_step_deg must divide 360 and lie in [1, 90]";
  if (!(sample_spacing_mm > 0.0) || !std::isfinite(sample_spacing_mm))
    return "sample_spacing_mm must be > 0";
  if (!(min_joint_margin_deg >= 0.0) || !std::isfinite(min_joint_margin_deg))
    return "min_joint_margin_deg must be >= 0";
  if (!(min_wrist_alignment >= 0.0 && min_wrist_alignment < 1.0))
    return "min_wrist_alignment must lie in [0, 1)";
  if (!(min_wrist_offset_mm >= 0.0) || !std::isfinite(min_wrist_offset_mm))
    return "min_wrist_offset_mm must be >= 0";
  if (!(min_manipulability >= 0.0) || !std::isfinite(min_manipulability))
    return "min_manipulability must be >= 0";
  if (!std::isfinite(min_clearance_mm)) return "min_clearance_mm must be finite";
  if (!(max_joint_step_deg > 0.0) || !std::isfinite(max_joint_step_deg))
    return "max_joint_step_deg must be > 0";
  if (branch < -1 || branch > 7) return "branch must be -1 (the best) or 0..7";
  if (fixed_roll_deg && !std::isfinite(*fixed_roll_deg)) return "fixed_roll_deg must be finite";
  return "";
}

ArmPostureStats best_possible_posture() {
  ArmPostureStats stats;
  stats.min_joint_margin_deg = kInfinity;
  stats.min_manipulability = kInfinity;
  stats.min_wrist_centre_offset_mm = kInfinity;
  stats.min_wrist_alignment = kInfinity;
  stats.min_clearance_mm = kInfinity;
  return stats;
}

void keep_worst(ArmPostureStats& worst, const ArmPostureStats& next) {
  worst.min_joint_margin_deg = std::min(worst.min_joint_margin_deg, next.min_joint_margin_deg);
  worst.min_manipulability = std::min(worst.min_manipulability, next.min_manipulability);
  worst.min_wrist_centre_offset_mm =
      std::min(worst.min_wrist_centre_offset_mm, next.min_wrist_centre_offset_mm);
  worst.min_wrist_alignment = std::min(worst.min_wrist_alignment, next.min_wrist_alignment);
  if (next.min_clearance_mm < worst.min_clearance_mm) {
    worst.min_clearance_mm = next.min_clearance_mm;
    worst.nearest_shape = next.nearest_shape;
  }
}

ArmStats arm_run_stats(const Arm6& arm, const PartClearance* part, const RecordedRun& record,
                       const ArmPosture& posture, double clearance_period_s) {
  ArmStats stats;
  stats.run = best_possible_posture();
  stats.branch = posture.branch;
  stats.clearance_period_s = clearance_period_s;
  stats.roll_strategy = posture.roll_optimized ? "optimized" : "fixed";
  stats.fixed_roll_deg = posture.fixed_roll_deg;
  stats.chosen_mean_cost = posture.chosen_mean_cost;
  stats.chosen_joint_travel_deg = posture.chosen_joint_travel_deg;
  stats.roll_zero = posture.roll_zero;
  stats.best_fixed = posture.best_fixed;
  stats.chosen_roll = posture.chosen;
  if (record.joint_count != 6 || record.size() == 0) return stats;

  // every state's joints (rad); the measures that need the Jacobian or the part at a period
  const long stride =
      std::max(1L, std::lround(clearance_period_s / std::max(record.timestep_s, 1e-9)));
  JointVector q(6);
  int previous_branch = -1;
  bool in_contact = false;
  double last_clearance = kInfinity;
  for (size_t k = 0; k < record.size(); ++k) {
    if (k % static_cast<size_t>(stride) == 0) throw_if_interrupted();  // core/interrupt.hpp
    for (int j = 0; j < 6; ++j) q[j] = record.joint(record.joint_position, k, j);
    stats.run.min_joint_margin_deg =
        std::min(stats.run.min_joint_margin_deg, rad_to_deg(arm.joint_margin_rad(q)));
    stats.run.min_wrist_alignment = std::min(stats.run.min_wrist_alignment, arm.wrist_alignment(q));
    // a branch change: the shoulder, elbow or wrist crossing its singular boundary
    const int branch = arm.branch_of(q);
    if (previous_branch >= 0 && branch != previous_branch) ++stats.branch_changes;
    previous_branch = branch;
    const bool periodic = k % static_cast<size_t>(stride) == 0 || k + 1 == record.size();
    const bool near_part = last_clearance < kNearPart_mm;
    if (!periodic && !near_part) continue;
    stats.run.min_manipulability = std::min(stats.run.min_manipulability, arm.manipulability(q));
    stats.run.min_wrist_centre_offset_mm =
        std::min(stats.run.min_wrist_centre_offset_mm, arm.wrist_centre_offset_mm(q));
    if (!part) continue;
    const PartClearance::Result nearest =
        part->clearance(arm.collision_shapes(), arm.link_frames(q));
    last_clearance = nearest.distance_mm;
    if (nearest.distance_mm < stats.run.min_clearance_mm) {
      stats.run.min_clearance_mm = nearest.distance_mm;
      if (nearest.shape >= 0) stats.run.nearest_shape = arm.collision_shapes()[nearest.shape].name;
    }
    // a contact with the part starts
    const bool touching = nearest.distance_mm <= 0.0;
    if (touching && !in_contact) ++stats.part_contacts;
    in_contact = touching;
  }
  stats.self_contacts = record.contacts.self_events;
  stats.table_contacts = record.contacts.other_events;
  stats.collisions = stats.part_contacts + stats.self_contacts + stats.table_contacts;
  return stats;
}

ArmPostureStats posture_at(const Arm6& arm, const PartClearance* part, const JointVector& joints) {
  ArmPostureStats stats;
  stats.min_joint_margin_deg = rad_to_deg(arm.joint_margin_rad(joints));
  stats.min_manipulability = arm.manipulability(joints);
  stats.min_wrist_centre_offset_mm = arm.wrist_centre_offset_mm(joints);
  stats.min_wrist_alignment = arm.wrist_alignment(joints);
  stats.min_clearance_mm = kInfinity;
  if (part) {
    const PartClearance::Result nearest =
        part->clearance(arm.collision_shapes(), arm.link_frames(joints));
    stats.min_clearance_mm = nearest.distance_mm;
    if (nearest.shape >= 0) stats.nearest_shape = arm.collision_shapes()[nearest.shape].name;
  }
  return stats;
}

ArmPosture choose_arm_posture(const Arm6& arm, const PartClearance* part, const Toolpath& toolpath,
                              const ArmPostureSettings& settings, const PointNamer& name) {
  const std::string problem = settings.validate();
  if (!problem.empty()) throw InputError("arm", problem);
  const int K = static_cast<int>(std::lround(360.0 / settings.roll_step_deg));
  const double step_rad = deg_to_rad(settings.roll_step_deg);
  const std::vector<Station> stations = make_stations(toolpath, settings.sample_spacing_mm);
  const size_t n = stations.size();
  const auto station_name = [&](size_t s) {
    const Station& st = stations[s];
    const std::string where = st.path < 0
                                  ? (s == 0 ? std::string("the start") : std::string("the end"))
                                  : name(static_cast<size_t>(st.path), st.point);
    return where + " " + point_text(st.pose.position_mm);
  };

  // every point above the table's top: one below it is an error of the input, named before
  // the ladder is built (between stations too), then how far to raise them
  std::vector<Problem> below;
  size_t below_count = 0;
  size_t print_points_below = 0;  // the summary's: raising the print points lifts these
  double lowest_z = 0.0;
  const auto check_above_table = [&](const Vec3& p, const std::function<std::string()>& where,
                                     bool print_point) {
    if (!arm.below_table(p)) return;
    if (print_point) {
      lowest_z = std::min(lowest_z, p.z());
      ++print_points_below;
    }
    if (++below_count <= kMaxNamedPoints)
      below.push_back(Problem{"", 0, "toolpath",
                              where() + " " + point_text(p) +
                                  " is below the table's top (z = 0 of the work frame, where "
                                  "the part stands): the nozzle would be inside the table"});
  };
  check_above_table(
      toolpath.start_mm, [] { return std::string("the start"); }, false);
  for (size_t p = 0; p < toolpath.paths.size(); ++p)
    for (size_t i = 0; i < toolpath.paths[p].points.size(); ++i)
      check_above_table(
          toolpath.paths[p].points[i], [&] { return name(p, i); }, true);
  check_above_table(
      toolpath.end_mm, [] { return std::string("the end"); }, false);
  // how far to raise the print points (a start or end below the table is its own problem)
  if (print_points_below > 0)
    below.push_back(Problem{
        "", 0, "toolpath",
        std::to_string(print_points_below) +
            " print point(s) below the table's top, the lowest at z = " + format("%.3f", lowest_z) +
            " mm: raise the toolpath by at least " + format("%.3f", -lowest_z) +
            " mm (toolpath.offset's z; a part: toolpath.surface.offset's)"});
  if (!below.empty()) throw InputError(below);

  // pass 1, every branch: rung validity and cost from the kinematics alone
  std::vector<double> cost(static_cast<size_t>(kBranches) * n * K, kInfinity);
  std::vector<Reason> reason(cost.size(), Reason::unreachable);
  const auto at = [&](int b, size_t s, int k) { return (static_cast<size_t>(b) * n + s) * K + k; };
  Arm6Branches solved;
  for (size_t s = 0; s < n; ++s) {
    throw_if_interrupted();  // a signal asked to stop (core/interrupt.hpp)
    for (int k = 0; k < K; ++k) {
      if (!arm.branch_solutions(rolled(stations[s], k * step_rad), solved)) continue;
      for (int b = 0; b < kBranches; ++b) {
        const RungCheck check = check_rung(arm, solved[b], settings);
        cost[at(b, s, k)] = check.cost;
        reason[at(b, s, k)] = check.reason;
      }
    }
  }

  // stations no branch and no roll can take: the job cannot be printed; say where and why
  std::vector<Problem> problems;
  // every such station counted by its reason, and the box they span, for the summary
  std::array<size_t, 5> failed_by_reason{};
  size_t failed = 0;
  Vec3 failed_lo = Vec3::Constant(kInfinity), failed_hi = Vec3::Constant(-kInfinity);
  for (size_t s = 0; s < n; ++s) {
    Reason best = Reason::unreachable;
    bool any = false;
    for (int b = 0; b < kBranches && !any; ++b)
      for (int k = 0; k < K; ++k) {
        const size_t i = at(b, s, k);
        if (std::isfinite(cost[i])) {
          any = true;
          break;
        }
        best = std::max(best, reason[i]);
      }
    if (any) continue;
    ++failed;
    ++failed_by_reason[static_cast<size_t>(best)];
    failed_lo = failed_lo.cwiseMin(stations[s].pose.position_mm);
    failed_hi = failed_hi.cwiseMax(stations[s].pose.position_mm);
    if (problems.size() < kMaxNamedPoints)
      problems.push_back(Problem{"", 0, "toolpath",
                                 station_name(s) + " is " + reason_text(best) +
                                     " for every roll and branch of " + arm.name()});
  }
  if (failed > 0) {
    // how many, why, where they are, and where the arm works best
    std::string reasons;
    for (const Reason r :
         {Reason::unreachable, Reason::joint_limit, Reason::singular, Reason::collides}) {
      const size_t count = failed_by_reason[static_cast<size_t>(r)];
      if (count == 0) continue;
      reasons += (reasons.empty() ? "" : ", ") + std::to_string(count) + " " + reason_text(r);
    }
    const auto span = [&](int axis) {
      return format("%.1f", failed_lo[axis]) + " to " + format("%.1f", failed_hi[axis]);
    };
    problems.push_back(Problem{
        "", 0, "toolpath",
        std::to_string(failed) + " of " + std::to_string(n) +
            " points checked along the toolpath cannot be posed (" + reasons + "), spanning x " +
            span(0) + ", y " + span(1) + ", z " + span(2) + " mm; " + arm.name() +
            " works best on a part centred at the work frame's origin, " +
            "within about 150 x 130 mm and 40 mm high (move the toolpath with toolpath.offset; a " +
            "part: toolpath.surface.offset)"});
    throw InputError(problems);
  }

  ArmPosture result;
  result.stations = n;
  result.roll_optimized = settings.optimize_roll;
  const int requested_roll =
      settings.fixed_roll_deg
          ? static_cast<int>(
                ((std::lround(*settings.fixed_roll_deg / settings.roll_step_deg) % K) + K) % K)
          : -1;

  // One roll for the whole job, for comparison (or as the user asks): `only_roll` >= 0 that roll,
  // else the best; the branch whose stations are all valid at the lowest cost, else the one with
  // the fewest failures (and the first of them named)
  const auto fixed_roll_on_best_branch = [&](int only_roll) {
    FixedRollComparison fixed;
    int best_branch = -1, best_roll = 0, fewest_branch = 0, fewest_roll = 0;
    size_t fewest_invalid = n + 1;
    double best_sum = kInfinity;
    for (int b = 0; b < kBranches; ++b) {
      if (settings.branch >= 0 && b != settings.branch) continue;
      for (int k = 0; k < K; ++k) {
        if (only_roll >= 0 && k != only_roll) continue;
        double sum = 0.0;
        size_t invalid = 0;
        for (size_t s = 0; s < n; ++s) {
          const double c = cost[at(b, s, k)];
          if (std::isfinite(c))
            sum += c;
          else
            ++invalid;
        }
        if (invalid < fewest_invalid) {
          fewest_invalid = invalid;
          fewest_branch = b;
          fewest_roll = k;
        }
        if (invalid == 0 && sum < best_sum) {
          best_sum = sum;
          best_branch = b;
          best_roll = k;
        }
      }
    }
    fixed.feasible = best_branch >= 0;
    fixed.branch = fixed.feasible ? best_branch : fewest_branch;
    const int roll = fixed.feasible ? best_roll : fewest_roll;
    fixed.roll_deg = roll * settings.roll_step_deg;
    fixed.mean_cost = fixed.feasible ? best_sum / static_cast<double>(n) : kInfinity;
    if (!fixed.feasible) {
      for (size_t s = 0; s < n; ++s) {
        const size_t i = at(fixed.branch, s, roll);
        if (std::isfinite(cost[i])) continue;
        fixed.problem = std::to_string(fewest_invalid) + " of " + std::to_string(n) +
                        " stations fail on the best branch (" + std::to_string(fixed.branch) +
                        "), the first " + station_name(s) + ": " + reason_text(reason[i]);
        break;
      }
    }
    return fixed;
  };
  result.roll_zero = fixed_roll_on_best_branch(0);
  result.best_fixed = fixed_roll_on_best_branch(-1);
  const FixedRollComparison used_fixed =
      requested_roll >= 0 ? fixed_roll_on_best_branch(requested_roll) : result.best_fixed;
  const int fixed_roll =
      static_cast<int>(std::lround(used_fixed.roll_deg / settings.roll_step_deg));

  // the branch: the cheapest whose ladder (roll moving one step at a time along paths) has a
  // path; a forced one as given
  std::vector<int> branches;
  if (settings.branch >= 0) {
    branches.push_back(settings.branch);
  } else {
    std::vector<std::pair<double, int>> ranked;
    for (int b = 0; b < kBranches; ++b) {
      Ladder ladder;
      ladder.rolls = K;
      ladder.step_rad = step_rad;
      ladder.cost.assign(cost.begin() + at(b, 0, 0), cost.begin() + at(b, 0, 0) + n * K);
      ladder.q.assign(n * K, Arm6Joints{});
      const std::vector<int> path = shortest_path(ladder, stations, kInfinity, false);
      if (!path.empty()) ranked.emplace_back(path_cost(ladder, path), b);
    }
    std::sort(ranked.begin(), ranked.end());
    for (const auto& [c, b] : ranked) branches.push_back(b);
    // none has a path: the branch with the fewest stations no roll can pose is searched, for
    // its failure to be named (the first such station, or where the rolls cannot follow)
    if (branches.empty()) {
      std::size_t fewest = n + 1;
      int closest = 0;
      for (int b = 0; b < kBranches; ++b) {
        std::size_t unposed = 0;
        for (size_t st = 0; st < n; ++st) {
          bool any = false;
          for (int k = 0; k < K && !any; ++k) any = std::isfinite(cost[at(b, st, k)]);
          unposed += any ? 0 : 1;
        }
        if (unposed < fewest) {
          fewest = unposed;
          closest = b;
        }
      }
      branches.push_back(closest);
    }
  }

  // pass 2 on the most promising branches: postures stored, joint-motion edges, clearance
  // checked where the path goes (a colliding station's every roll measured, then search again);
  // of those that print the job, the one whose postures cost least
  // one branch's ladder solved, with the part's clearance or (to rank branches) without:
  // the path and its posture cost, or nothing (last_failure says why)
  std::string last_failure;
  const auto solve_branch =
      [&](int b, bool with_clearance) -> std::optional<std::pair<double, std::vector<int>>> {
    const PartClearance* check_part = with_clearance ? part : nullptr;
    Ladder ladder;
    ladder.rolls = K;
    ladder.step_rad = step_rad;
    ladder.q.assign(n * K, Arm6Joints{});
    ladder.cost.assign(cost.begin() + at(b, 0, 0), cost.begin() + at(b, 0, 0) + n * K);
    ladder.reason.assign(reason.begin() + at(b, 0, 0), reason.begin() + at(b, 0, 0) + n * K);
    ladder.clearance.assign(n * K, std::numeric_limits<double>::quiet_NaN());
    if (!settings.optimize_roll) {
      // one roll for the whole job: every other rung removed
      const int keep = requested_roll >= 0 ? requested_roll : fixed_roll;
      for (size_t s = 0; s < n; ++s)
        for (int k = 0; k < K; ++k)
          if (k != keep) ladder.cost[ladder.index(s, k)] = kInfinity;
    }
    for (size_t s = 0; s < n; ++s)
      for (int k = 0; k < K; ++k) {
        if (!std::isfinite(ladder.cost[ladder.index(s, k)])) continue;
        arm.branch_solutions(rolled(stations[s], k * step_rad), solved);
        ladder.q[ladder.index(s, k)] = solved[b];
      }
    const auto measure = [&](size_t s, int k) {
      const size_t i = ladder.index(s, k);
      if (!check_part || !std::isnan(ladder.clearance[i])) return;
      const double distance =
          check_part
              ->clearance(arm.collision_shapes(), arm.link_frames(to_vector(ladder.q[i])),
                          settings.min_clearance_mm)
              .distance_mm;
      ladder.clearance[i] = distance;
      if (distance < settings.min_clearance_mm) {
        ladder.cost[i] = kInfinity;
        ladder.reason[i] = Reason::collides;
      } else {
        ladder.cost[i] += std::pow(kClearanceReference_mm / std::max(distance, 1e-3), 4);
      }
    };
    const double max_step = deg_to_rad(settings.max_joint_step_deg);
    // a travel's intermediate poses (position straight, axis and roll turning evenly, as the
    // planners move) must stay on the branch, off the limits and singularities, continuously;
    // a long print edge's too, checked at the station spacing
    std::unordered_map<uint64_t, bool> travel_memo;
    const auto edge_key = [&](size_t s, int from, int k) {
      return (static_cast<uint64_t>(s) * K + from) * K + k;
    };
    // the poses checked between station s - 1 at roll `from` and station s at roll k: how
    // many, and pose i of them (1..count)
    const auto checks_between = [&](size_t s, int from, int k) {
      const Pose a = rolled(stations[s - 1], from * step_rad);
      const Pose end = rolled(stations[s], k * step_rad);
      const double turn = rad_to_deg(axis_angle_rad(a.tool_axis, end.tool_axis) +
                                     std::abs(wrapped(end.roll_rad, a.roll_rad)));
      const double distance = (end.position_mm - a.position_mm).norm();
      const double check_distance_mm =
          stations[s].after_travel ? kTravelCheckDistance_mm
                                   : std::min(kTravelCheckDistance_mm, settings.sample_spacing_mm);
      return 1 + static_cast<int>(std::ceil(turn / kTravelCheckTurn_deg)) +
             static_cast<int>(std::ceil(distance / check_distance_mm));
    };
    const auto pose_between = [&](size_t s, int from, int k, int i, int checks) {
      const Pose a = rolled(stations[s - 1], from * step_rad);
      const Pose end = rolled(stations[s], k * step_rad);
      const double f = static_cast<double>(i) / (checks + 1);
      return Pose(a.position_mm + f * (end.position_mm - a.position_mm),
                  slerp_axis(a.tool_axis, end.tool_axis, f),
                  a.roll_rad + f * wrapped(end.roll_rad, a.roll_rad));
    };
    const TravelCheck travel_ok = [&](size_t s, int from, int k) {
      const uint64_t key = edge_key(s, from, k);
      const auto known = travel_memo.find(key);
      if (known != travel_memo.end()) return known->second;
      const int checks = checks_between(s, from, k);
      Arm6Joints previous = ladder.q[ladder.index(s - 1, from)];
      Pose previous_pose = rolled(stations[s - 1], from * step_rad);
      bool ok = true;
      Arm6Branches mid_solved;
      for (int i = 1; i <= checks + 1 && ok; ++i) {
        Pose mid = rolled(stations[s], k * step_rad);
        Arm6Joints q = ladder.q[ladder.index(s, k)];
        if (i <= checks) {
          mid = pose_between(s, from, k, i, checks);
          ok = arm.branch_solutions(mid, mid_solved) &&
               check_rung(arm, mid_solved[b], settings).reason == Reason::ok;
          if (!ok) break;
          q = mid_solved[b];
        }
        ok = largest_step(previous, q) <= allowed_step(previous_pose, mid, max_step);
        previous = q;
        previous_pose = mid;
      }
      travel_memo.emplace(key, ok);
      return ok;
    };
    // A long print edge of the path clear of the part at its poses in between (the stations
    // are measured on their own), as the planners move along it. Travels are not: the planners
    // lift over the part there, which the straight poses checked for the joints do not follow.
    // An edge too close is closed to the search (travel_memo) and the path searched again.
    std::unordered_map<uint64_t, double> edge_clearance;  // the smallest, per edge measured
    const auto long_edges_clear = [&](const std::vector<int>& candidate) {
      bool clear = true;
      Arm6Branches mid_solved;
      for (size_t s = 1; s < n; ++s) {
        if (!stations[s].after_long_edge || stations[s].after_travel) continue;
        const int from = candidate[s - 1], k = candidate[s];
        const uint64_t key = edge_key(s, from, k);
        if (edge_clearance.count(key) == 0) {
          throw_if_interrupted();
          double nearest = kInfinity;
          const int checks = checks_between(s, from, k);
          for (int i = 1; i <= checks && nearest >= settings.min_clearance_mm; ++i)
            if (arm.branch_solutions(pose_between(s, from, k, i, checks), mid_solved))
              nearest = std::min(nearest, check_part
                                              ->clearance(arm.collision_shapes(),
                                                          arm.link_frames(to_vector(mid_solved[b])),
                                                          settings.min_clearance_mm)
                                              .distance_mm);
          edge_clearance.emplace(key, nearest);
        }
        if (edge_clearance[key] < settings.min_clearance_mm) {
          travel_memo[key] = false;
          clear = false;
        }
      }
      return clear;
    };
    std::vector<int> path;
    size_t stuck_at = 0;  // where no roll sequence gets past, when none does
    for (int round = 0; round < 64; ++round) {
      path = shortest_path(ladder, stations, max_step, true, travel_ok, &stuck_at);
      if (path.empty() || !check_part) break;
      // measure along the path; where it is too close, every roll of that station
      bool clear = true;
      for (size_t s = 0; s < n; ++s) {
        throw_if_interrupted();
        measure(s, path[s]);
        if (std::isfinite(ladder.cost[ladder.index(s, path[s])])) continue;
        clear = false;
        for (int k = 0; k < K; ++k)
          if (std::isfinite(ladder.cost[ladder.index(s, k)])) measure(s, k);
      }
      // the stations clear: the long edges between them too
      if (clear) clear = long_edges_clear(path);
      if (clear) {
        // the clearance costs changed the path's cost: one more search settles it
        const std::vector<int> again = shortest_path(ladder, stations, max_step, true, travel_ok);
        bool same = again == path;
        if (!same && !again.empty()) {
          for (size_t s = 0; s < n; ++s) measure(s, again[s]);
          same = true;
          for (size_t s = 0; s < n && same; ++s)
            same = std::isfinite(ladder.cost[ladder.index(s, again[s])]);
          if (same && long_edges_clear(again)) path = again;
        }
        break;
      }
    }
    if (!path.empty()) {
      bool valid = true;
      for (size_t s = 0; s < n && valid; ++s)
        valid = std::isfinite(ladder.cost[ladder.index(s, path[s])]);
      if (valid && check_part) valid = long_edges_clear(path);
      if (valid) return std::make_pair(path_cost(ladder, path), path);
    }
    // name the station where this branch fails: the first with no valid rung, else a gap
    last_failure = "branch " + std::to_string(b) + ": ";
    bool named = false;
    for (size_t s = 0; s < n && !named; ++s) {
      Reason why = Reason::ok;
      bool any = false;
      for (int k = 0; k < K; ++k) {
        any = any || std::isfinite(ladder.cost[ladder.index(s, k)]);
        why = std::max(why, ladder.reason[ladder.index(s, k)]);
      }
      if (any) continue;
      last_failure += station_name(s) + " is " + reason_text(why) + " for every roll";
      named = true;
    }
    if (!named) {
      // where the rolls cannot follow: a print step, a long edge or a travel between two
      // stations every rung of which is valid on its own
      const std::string within = format("%.3g", settings.max_joint_step_deg) + " deg";
      // (a print edge's poses in between are also kept clear of the part; a travel's are not)
      const auto why_between = [&](bool with_part) {
        return " (a pose on it is beyond a joint's range or the reach, at a singularity, " +
               (with_part ? "or within arm.min_clearance_mm " +
                                format("%.3g", settings.min_clearance_mm) + " mm of the part, "
                          : std::string()) +
               "or a joint jumps by more than " + within + " between two of them)";
      };
      if (stuck_at == 0) {
        last_failure += "no roll sequence keeps every joint within " + within +
                        " between neighbouring points along the paths";
      } else {
        const Station& from = stations[stuck_at - 1];
        const Station& to = stations[stuck_at];
        const std::string ends =
            " from " + station_name(stuck_at - 1) + " to " + station_name(stuck_at);
        if (to.after_travel)
          last_failure += "no roll sequence gets over the travel" + ends + why_between(false);
        else if (to.after_long_edge)
          last_failure += "no roll sequence gets along the " +
                          format("%.4g", (to.pose.position_mm - from.pose.position_mm).norm()) +
                          " mm edge" + ends + why_between(check_part != nullptr);
        else
          last_failure += "no roll sequence keeps every joint within " + within + ends;
      }
    }
    return std::nullopt;
  };
  // rank the most promising branches without the part (cheap), then check the part's clearance
  // on the best first: the first that passes is the job's
  std::vector<std::pair<double, int>> by_cost;
  for (int b : branches) {
    if (!by_cost.empty() && static_cast<int>(by_cost.size()) >= kBranchesCompared) break;
    if (const auto solved_branch = solve_branch(b, false))
      by_cost.emplace_back(solved_branch->first, b);
  }
  std::sort(by_cost.begin(), by_cost.end());
  std::vector<int> chosen;
  int branch = -1;
  for (const auto& [ranked_cost, b] : by_cost) {
    const auto solved_branch = part ? solve_branch(b, true) : solve_branch(b, false);
    if (!solved_branch) continue;
    chosen = solved_branch->second;
    branch = b;
    break;
  }
  if (branch < 0)
    throw InputError("toolpath", "no posture of " + arm.name() + " prints the whole job on one " +
                                     "branch without a joint limit, a singularity or the part (" +
                                     last_failure + ")");
  result.branch = branch;
  result.fixed_roll_deg = settings.optimize_roll ? 0.0 : used_fixed.roll_deg;

  // the rolls: unwrapped along each path (one step at a time), the shortest way round between
  // paths, then interpolated by arc length between stations with a C1 cubic (tangents from the
  // neighbouring stations, zero at a path's ends): a piecewise-linear roll would kink at every
  // station, and the kinks' joint accelerations would slow the time law
  std::vector<double> station_roll(n);
  for (size_t s = 0; s < n; ++s) {
    double roll = chosen[s] * step_rad;
    if (s > 0) roll = station_roll[s - 1] + wrapped(roll, station_roll[s - 1]);
    station_roll[s] = roll;
  }
  result.toolpath = toolpath;
  Toolpath& out = result.toolpath;
  out.start_roll_rad = station_roll.front();
  out.end_roll_rad = station_roll.back();
  size_t s = 1;
  for (size_t p = 0; p < out.paths.size(); ++p) {
    PrintPath& path = out.paths[p];
    path.rolls.assign(path.points.size(), 0.0);
    // the stations of this path, in order
    size_t first = s;
    while (s < n && stations[s].path == static_cast<int>(p)) ++s;
    std::vector<double> arc(path.points.size(), 0.0);
    for (size_t i = 1; i < path.points.size(); ++i)
      arc[i] = arc[i - 1] + (path.points[i] - path.points[i - 1]).norm();
    // the roll's slope at station t (rad/mm): central difference, 0 at the path's ends
    const auto slope = [&](size_t t) {
      if (t == first || t + 1 == s) return 0.0;
      const double span = arc[stations[t + 1].point] - arc[stations[t - 1].point];
      return span > 0.0 ? (station_roll[t + 1] - station_roll[t - 1]) / span : 0.0;
    };
    for (size_t t = first; t + 1 < s; ++t) {
      const size_t i0 = stations[t].point, i1 = stations[t + 1].point;
      const double h = arc[i1] - arc[i0];
      const double m0 = slope(t) * h, m1 = slope(t + 1) * h;
      for (size_t i = i0; i <= i1; ++i) {
        const double f = h > 0.0 ? (arc[i] - arc[i0]) / h : 0.0;
        const double f2 = f * f, f3 = f2 * f;
        path.rolls[i] = (2 * f3 - 3 * f2 + 1) * station_roll[t] + (f3 - 2 * f2 + f) * m0 +
                        (-2 * f3 + 3 * f2) * station_roll[t + 1] + (f3 - f2) * m1;
      }
    }
    if (s == first + 1) path.rolls.assign(path.points.size(), station_roll[first]);
  }

  // every point solved on the branch, each from its neighbour; posture measures at the stations
  // for the chosen and the best fixed roll
  JointVector seed, joints;
  Arm6Solutions all;
  const auto solve_on_branch = [&](const Pose& pose, JointVector& q) {
    const int count = arm.solutions(pose, all);
    double best = kInfinity;
    for (int i = 0; i < count; ++i) {
      if (all[i].branch != branch) continue;
      double distance = 0.0;
      for (size_t j = 0; j < 6; ++j)
        distance += seed.empty() ? (j == 5 ? all[i].q[j] * all[i].q[j] : 0.0)
                                 : std::pow(all[i].q[j] - seed[j], 2);
      if (distance < best) {
        best = distance;
        q = to_vector(all[i].q);
      }
    }
    return std::isfinite(best);
  };
  const double max_dense_step = deg_to_rad(settings.max_joint_step_deg);
  Pose previous_pose;
  std::vector<Problem> dense_problems;
  // `travel`: reached by a travel from the previous point (any joint motion allowed)
  // point `point` of path `path` (-1: the start, -2: the end), named only when it fails;
  // `inside`: a pose on the long edge that ends at that point
  const auto where = [&](long path, size_t point, bool inside) {
    if (path == -1) return std::string("the start");
    if (path == -2) return std::string("the end");
    return (inside ? "the edge to " : "") + name(static_cast<size_t>(path), point);
  };
  const auto visit = [&](const Pose& pose, long path, size_t point, bool travel,
                         bool inside = false) {
    if (!solve_on_branch(pose, joints)) {
      if (dense_problems.size() < kMaxNamedPoints)
        dense_problems.push_back(Problem{
            "", 0, "toolpath",
            where(path, point, inside) + " " + point_text(pose.position_mm) +
                " is beyond a joint's range on branch " + std::to_string(branch) +
                " at the chosen roll " + format("%.1f", rad_to_deg(pose.roll_rad)) + " deg"});
      return;
    }
    const bool jump = !travel && !seed.empty() &&
                      largest_step(to_array(seed), to_array(joints)) >
                          allowed_step(previous_pose, pose, max_dense_step);
    previous_pose = pose;
    if (jump && dense_problems.size() < kMaxNamedPoints)
      dense_problems.push_back(Problem{
          "", 0, "toolpath",
          where(path, point, inside) + " " + point_text(pose.position_mm) +
              ": a joint would jump by more than " + format("%.3g", settings.max_joint_step_deg) +
              " deg from the previous point"});
    seed = joints;
  };
  visit(Pose(out.start_mm, vertical_tool_axis(), out.start_roll_rad), -1, 0, true);
  for (size_t p = 0; p < out.paths.size(); ++p) {
    const PrintPath& path = out.paths[p];
    for (size_t i = 0; i < path.points.size(); ++i) {
      // a long edge's poses in between, at the station spacing, as the planners move along it
      const double length = i > 0 ? (path.points[i] - path.points[i - 1]).norm() : 0.0;
      const int inside = static_cast<int>(std::ceil(length / settings.sample_spacing_mm)) - 1;
      for (int m = 1; m <= inside; ++m) {
        const double f = static_cast<double>(m) / (inside + 1);
        visit(Pose(path.points[i - 1] + f * (path.points[i] - path.points[i - 1]),
                   slerp_axis(path.tool_axis(i - 1), path.tool_axis(i), f),
                   path.rolls[i - 1] + f * (path.rolls[i] - path.rolls[i - 1])),
              static_cast<long>(p), i, false, true);
      }
      visit(Pose(path.points[i], path.tool_axis(i), path.rolls[i]), static_cast<long>(p), i,
            i == 0);
    }
    if (!dense_problems.empty()) break;
  }
  visit(Pose(out.end_mm, vertical_tool_axis(), out.end_roll_rad), -2, 0, true);
  if (!dense_problems.empty()) throw InputError(dense_problems);

  // the posture measures at the stations: the chosen rolls against roll 0 and the best fixed
  // roll (each on its own best branch), what the choice gains
  // (and how far the joints turn while printing: the price of a roll that keeps them comfortable)
  const auto joint_turn_deg = [](const Arm6Joints& a, const Arm6Joints& b) {
    double sum = 0.0;
    for (size_t j = 0; j < 6; ++j) sum += std::abs(j == 5 ? wrapped(a[j], b[j]) : a[j] - b[j]);
    return rad_to_deg(sum);
  };
  result.chosen = best_possible_posture();
  double chosen_cost = 0.0;
  Arm6Joints last{};
  for (size_t t = 0; t < n; ++t) {
    throw_if_interrupted();
    chosen_cost += cost[at(branch, t, chosen[t])];
    if (!arm.branch_solutions(rolled(stations[t], chosen[t] * step_rad), solved)) continue;
    keep_worst(result.chosen, posture_at(arm, part, to_vector(solved[branch])));
    if (t > 0 && !stations[t].after_travel)
      result.chosen_joint_travel_deg += joint_turn_deg(last, solved[branch]);
    last = solved[branch];
  }
  result.chosen_mean_cost = chosen_cost / static_cast<double>(n);
  for (FixedRollComparison* fixed : {&result.roll_zero, &result.best_fixed}) {
    fixed->stats = best_possible_posture();
    const int k = static_cast<int>(std::lround(fixed->roll_deg / settings.roll_step_deg)) % K;
    for (size_t t = 0; t < n; ++t) {
      throw_if_interrupted();
      if (!arm.branch_solutions(rolled(stations[t], k * step_rad), solved)) continue;
      keep_worst(fixed->stats, posture_at(arm, part, to_vector(solved[fixed->branch])));
      if (t > 0 && !stations[t].after_travel)
        fixed->joint_travel_deg += joint_turn_deg(last, solved[fixed->branch]);
      last = solved[fixed->branch];
    }
    if (fixed->feasible && fixed->stats.min_clearance_mm < settings.min_clearance_mm) {
      fixed->feasible = false;
      fixed->problem = "the " + fixed->stats.nearest_shape + " comes within " +
                       format("%.3g", fixed->stats.min_clearance_mm) + " mm of the part";
    }
  }
  return result;
}

}  // namespace depotwin
