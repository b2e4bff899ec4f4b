// The arm's posture along a toolpath (posture/arm_posture): a roll at every point and one branch
// that keep the arm off its joint limits, singularities and the part; every point solved on that
// branch, continuously; clear errors naming the point where no posture works.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/error.hpp"
#include "posture/arm_posture.hpp"
#include "toolpath/analytic_surfaces.hpp"
#include "toolpath/hatching.hpp"

namespace depotwin {
namespace {

std::string plain_name(size_t path, size_t point) {
  return "path " + std::to_string(path) + ", point " + std::to_string(point);
}

struct Hatched {
  TriangleMesh part;
  Toolpath toolpath;
};

Hatched beam(int layers, double alpha) {
  Hatched h;
  CurvedBeamParams params;
  params.mesh.cell_mm = 1.0;
  h.part = curved_beam(params);
  SurfaceHatchSpec spec;
  spec.angles_deg = {0.0};
  spec.layers = layers;
  spec.alpha = alpha;
  spec.speed_mm_s = 20.0;
  h.toolpath = hatch_surface(h.part, spec).toolpath;
  h.toolpath.start_mm = h.toolpath.end_mm = Vec3(0, 0, 30);
  return h;
}

TEST(ArmPosture, BeamEveryPointSolvedOnOneBranchContinuously) {
  const Arm6 arm;
  const Hatched h = beam(2, 0.5);
  const PartClearance clearance(h.part);
  const auto started = std::chrono::steady_clock::now();
  const ArmPosture posture =
      choose_arm_posture(arm, &clearance, h.toolpath, ArmPostureSettings{}, plain_name);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  RecordProperty("seconds", std::to_string(seconds));
  RecordProperty("stations", std::to_string(posture.stations));
  const Toolpath& out = posture.toolpath;
  ASSERT_EQ(out.paths.size(), h.toolpath.paths.size());
  const ArmPostureSettings defaults;
  // every point: a solution on the branch within the ranges, forward kinematics gives the pose,
  // neighbours close in joint space
  Arm6Solutions all;
  // the chain starts where the job does (joint 6 nearest 0), as the posture's own
  JointVector previous;
  ASSERT_TRUE(arm.inverse(Pose(out.start_mm, vertical_tool_axis(), out.start_roll_rad), previous));
  ASSERT_EQ(arm.branch_of(previous), posture.branch);
  for (const PrintPath& path : out.paths) {
    ASSERT_EQ(path.rolls.size(), path.points.size());
    for (size_t i = 0; i < path.points.size(); ++i) {
      const Pose pose(path.points[i], path.tool_axis(i), path.rolls[i]);
      const int count = arm.solutions(pose, all);
      JointVector best;
      double best_distance = 1e300;
      for (int s = 0; s < count; ++s) {
        if (all[s].branch != posture.branch) continue;
        double d = 0.0;
        for (int j = 0; j < 6; ++j)
          d += previous.empty() ? 0.0 : std::pow(all[s].q[j] - previous[j], 2);
        if (d < best_distance) {
          best_distance = d;
          best.assign(all[s].q.begin(), all[s].q.end());
        }
      }
      ASSERT_FALSE(best.empty()) << "no solution on the branch at " << i;
      const Pose back = arm.forward(best);
      EXPECT_LT((back.position_mm - pose.position_mm).norm(), 1e-9);
      EXPECT_GT(rad_to_deg(arm.joint_margin_rad(best)), 0.0);
      if (!previous.empty() && i > 0) {
        for (int j = 0; j < 6; ++j)
          EXPECT_LT(std::abs(best[j] - previous[j]), deg_to_rad(defaults.max_joint_step_deg));
      }
      previous = best;
    }
  }
  // the chosen postures keep their distances (at the stations)
  EXPECT_GE(posture.chosen.min_joint_margin_deg, defaults.min_joint_margin_deg);
  EXPECT_GE(posture.chosen.min_wrist_alignment, defaults.min_wrist_alignment);
  EXPECT_GE(posture.chosen.min_clearance_mm, defaults.min_clearance_mm);
}

// a single path with one point beyond the arm's reach, one past where the wrist can stay
// clear of singularity and one inside the part: each a problem naming the point and saying why
Toolpath single_path(const std::vector<Vec3>& points) {
  Toolpath toolpath;
  toolpath.start_mm = toolpath.end_mm = Vec3(0, 0, 40);
  PrintPath path;
  path.points = points;
  path.speed_mm_s = 10.0;
  toolpath.paths.push_back(path);
  return toolpath;
}

std::string problem_text(const Arm6& arm, const PartClearance* part, const Toolpath& toolpath,
                         const ArmPostureSettings& settings) {
  try {
    choose_arm_posture(arm, part, toolpath, settings, plain_name);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ArmPosture, UnreachablePointIsNamed) {
  const Arm6 arm;
  const std::string text =
      problem_text(arm, nullptr, single_path({Vec3(0, 0, 0), Vec3(5, 0, 0), Vec3(600, 0, 0)}), {});
  EXPECT_NE(text.find("path 0, point 2 (600.000, 0.000, 0.000) mm"), std::string::npos) << text;
  EXPECT_NE(text.find("out of the arm's reach for every roll and branch"), std::string::npos)
      << text;
  EXPECT_EQ(text.find("point 1"), std::string::npos) << text;  // only the bad point
  // then how many, why and where, and where the arm works
  EXPECT_NE(text.find("1 of 5 points checked along the toolpath cannot be posed (1 out of the "
                      "arm's reach), spanning x 600.0 to 600.0, y 0.0 to 0.0, z 0.0 to 0.0 mm; "
                      "arm6 works best on a part centred at the work frame's origin"),
            std::string::npos)
      << text;
}

TEST(ArmPosture, SingularPointIsNamed) {
  // the wrist centre at least 1 m from the joint-1 axis: no posture of this arm qualifies
  const Arm6 arm;
  ArmPostureSettings settings;
  settings.min_wrist_offset_mm = 1000.0;
  const std::string text =
      problem_text(arm, nullptr, single_path({Vec3(0, 0, 0), Vec3(5, 0, 0)}), settings);
  EXPECT_NE(text.find("at a singularity for every roll and branch"), std::string::npos) << text;
}

TEST(ArmPosture, CollidingPointIsNamed) {
  // a point 15 mm inside a solid block on the table: the nozzle (its last 3 mm excepted) is in
  // the part at every roll
  const Arm6 arm;
  TriangleMesh block;
  block.vertices = {Vec3(-20, -20, 0),  Vec3(20, -20, 0),  Vec3(20, 20, 0),  Vec3(-20, 20, 0),
                    Vec3(-20, -20, 40), Vec3(20, -20, 40), Vec3(20, 20, 40), Vec3(-20, 20, 40)};
  block.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                     {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  const PartClearance part(block);
  const std::string text =
      problem_text(arm, &part, single_path({Vec3(0, 0, 40), Vec3(0, 5, 25)}), {});
  EXPECT_NE(text.find("path 0, point 1"), std::string::npos) << text;
  EXPECT_NE(text.find("too close to the part"), std::string::npos) << text;
}

// a long print edge is checked along its length, not only at its two points: a 400 mm line in
// two points whose middle passes over the arm's base fails there and names the edge, and one
// beside the base (where the 51-point line of the same span works) is posed
TEST(ArmPosture, ALongEdgeIsCheckedBetweenItsPoints) {
  const Arm6 arm;
  const auto line = [](double x) {
    return single_path({Vec3(x, -205, 0), Vec3(x, -200, 0), Vec3(x, 200, 0), Vec3(x, 205, 0)});
  };
  const std::string text = problem_text(arm, nullptr, line(-360.0), {});
  EXPECT_NE(text.find("no roll sequence gets along the 400 mm edge from path 0, point 1 (-360.000, "
                      "-200.000, 0.000) mm to path 0, point 2 (-360.000, 200.000, 0.000) mm (a "
                      "pose on it is beyond"),
            std::string::npos)
      << text;
  // 110 mm in front of the base: joint 1 swings through about 130 deg along the line, in steps
  // of a few degrees between the poses in between (one 130 deg step between the two points)
  const ArmPosture posture =
      choose_arm_posture(arm, nullptr, line(-250.0), ArmPostureSettings{}, plain_name);
  EXPECT_GT(posture.chosen_joint_travel_deg, 100.0);
  EXPECT_EQ(posture.toolpath.paths[0].points.size(), 4u);  // the toolpath keeps its points
}

// a long print edge's poses in between are kept clear of the part, not only its two points: a
// 120 mm line through a block, its ends 50 mm clear of it, is refused naming the edge (it was
// posed, the nozzle through the block); with the block beside the line, it is posed
TEST(ArmPosture, ALongEdgeIsKeptClearOfThePartBetweenItsPoints) {
  const Arm6 arm;
  const auto block_at = [](double x0, double x1) {
    TriangleMesh block;
    block.vertices = {Vec3(x0, -20, 0),  Vec3(x1, -20, 0),  Vec3(x1, 20, 0),  Vec3(x0, 20, 0),
                      Vec3(x0, -20, 40), Vec3(x1, -20, 40), Vec3(x1, 20, 40), Vec3(x0, 20, 40)};
    block.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                       {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
    return block;
  };
  Toolpath line = single_path({Vec3(-65, 0, 5), Vec3(-60, 0, 5), Vec3(60, 0, 5), Vec3(65, 0, 5)});
  line.start_mm = line.end_mm = Vec3(0, 0, 120);
  const PartClearance through(block_at(-10.0, 10.0));
  const std::string text = problem_text(arm, &through, line, {});
  EXPECT_NE(text.find("no roll sequence gets along the 120 mm edge from path 0, point 1 (-60.000, "
                      "0.000, 5.000) mm to path 0, point 2 (60.000, 0.000, 5.000) mm (a pose on "
                      "it is beyond a joint's range or the reach, at a singularity, or within "
                      "arm.min_clearance_mm 1 mm of the part"),
            std::string::npos)
      << text;
  const PartClearance beside(block_at(100.0, 140.0));
  const ArmPosture posed = choose_arm_posture(arm, &beside, line, ArmPostureSettings{}, plain_name);
  EXPECT_EQ(posed.toolpath.paths[0].points.size(), 4u);
  EXPECT_GE(posed.chosen.min_clearance_mm, 1.0);
}

// where no branch has a roll sequence at all (a steep bowl, tool square to it: the travel to the
// second layer has no posture in between), the search still names where it breaks: never an
// empty reason, "(...)"
TEST(ArmPosture, ABranchlessJobNamesWhereItBreaks) {
  const Arm6 arm;
  // z = 10 + r^2 / 10 over 16 x 16 mm: 66 deg steep at the corners
  TriangleMesh bowl;
  const int cells = 40;
  for (int i = 0; i <= cells; ++i)
    for (int j = 0; j <= cells; ++j) {
      const double x = -8.0 + 16.0 * i / cells, y = -8.0 + 16.0 * j / cells;
      bowl.vertices.emplace_back(x, y, 10.0 + (x * x + y * y) / 10.0);
    }
  for (int i = 0; i < cells; ++i)
    for (int j = 0; j < cells; ++j) {
      const int a = i * (cells + 1) + j, b = a + cells + 1;
      bowl.triangles.push_back({a, b, b + 1});
      bowl.triangles.push_back({a, b + 1, a + 1});
    }
  SurfaceHatchSpec spec;
  spec.hatch_mm = 1.0;
  spec.angles_deg = {0.0, 90.0};
  spec.layers = 2;
  spec.layer_height_mm = 1.0;
  spec.alpha = 1.0;
  spec.speed_mm_s = 20.0;
  Toolpath toolpath = hatch_surface(bowl, spec).toolpath;
  toolpath.start_mm = toolpath.end_mm = Vec3(0, 0, 45);
  const std::string text = problem_text(arm, nullptr, toolpath, {});
  EXPECT_NE(text.find("(branch 0: no roll sequence gets over the travel from path 16, point 16 "
                      "(8.000, 8.000, 22.800) mm to path 17, point 0"),
            std::string::npos)
      << text;
  EXPECT_EQ(text.find("()"), std::string::npos) << text;
}

// the roll is a real choice: a fixed roll that the wrist cannot hold over the whole path fails
// where the optimised rolls succeed
TEST(ArmPosture, OptimisedRollsReachWhereOneFixedRollCannot) {
  const Arm6 arm;
  // a circle of tool axes tilted 30 deg outwards: the nozzle's lean swings all round
  Toolpath toolpath;
  toolpath.start_mm = toolpath.end_mm = Vec3(0, 0, 40);
  PrintPath path;
  path.speed_mm_s = 10.0;
  for (int i = 0; i <= 72; ++i) {
    const double a = 2 * kPi * i / 72.0;
    path.points.emplace_back(40 * std::cos(a), 40 * std::sin(a), 0);
    const double tilt = deg_to_rad(30.0);
    path.normals.emplace_back(std::sin(tilt) * std::cos(a), std::sin(tilt) * std::sin(a),
                              std::cos(tilt));
  }
  toolpath.paths.push_back(path);
  const ArmPosture posture =
      choose_arm_posture(arm, nullptr, toolpath, ArmPostureSettings{}, plain_name);
  EXPECT_GE(posture.chosen.min_joint_margin_deg, ArmPostureSettings{}.min_joint_margin_deg);
  // the rolls turn along the circle: not one value
  const std::vector<double>& rolls = posture.toolpath.paths[0].rolls;
  const auto [lo, hi] = std::minmax_element(rolls.begin(), rolls.end());
  EXPECT_GT(*hi - *lo, deg_to_rad(30.0));
  // and at least as far from trouble as the best single roll
  EXPECT_GE(posture.chosen.min_wrist_alignment,
            posture.best_fixed.stats.min_wrist_alignment - 1e-9);
  // no single roll keeps the wrist within its ranges and clear of its singularity all round (the
  // best fails at a point and says so)
  EXPECT_FALSE(posture.best_fixed.feasible);
  EXPECT_FALSE(posture.roll_zero.feasible);
  EXPECT_NE(posture.best_fixed.problem.find("stations fail on the best branch"), std::string::npos)
      << posture.best_fixed.problem;
}

}  // namespace
}  // namespace depotwin
