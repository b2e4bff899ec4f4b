// The linear delta end to end (issue 5): Giberti et al.'s scenarios planned, simulated on the
// delta's carriages (six rods closed on a free platform in MuJoCo), extruded and scored
// through the run pipeline (prepare_job / simulate_job / write_run / compare_runs).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "kinematics/linear_delta.hpp"
#include "pipeline/compare.hpp"
#include "pipeline/pipeline_test_util.hpp"
#include "pipeline/quiet_settings.hpp"
#include "pipeline/run.hpp"
#include "planners/motion/bezier/bezier_checks.hpp"
#include "plots/png_check.hpp"
#include "plots/style.hpp"
#include "scenario/scenario.hpp"
#include "sim/mujoco_access.hpp"

namespace depotwin {
namespace {

using testing_support::fresh_directory;
using testing_support::scenario_path;
using testing_support::write_text;

using testing_support::quiet;

// a scenario planned and simulated with its first planner (or the one named)
struct DeltaRun {
  PreparedJob job;
  SimulatedRun run;
};

DeltaRun simulate(const std::string& scenario_file, const std::string& planner_name = "") {
  DeltaRun result;
  result.job = prepare_job(load_scenario(scenario_file));
  PlannerSpec spec = result.job.scenario.planners.front();
  for (const PlannerSpec& candidate : result.job.scenario.planners)
    if (candidate.name == planner_name) spec = candidate;
  result.run = simulate_job(result.job, spec, quiet());
  return result;
}

// the depositing pieces of one print path
std::vector<const TrajectoryPiece*> printing_pieces(const Trajectory& trajectory, int path) {
  std::vector<const TrajectoryPiece*> pieces;
  for (const TrajectoryPiece& piece : trajectory.pieces())
    if (piece.path_index == path && piece.depositing) pieces.push_back(&piece);
  return pieces;
}

// The paper's speed-variation measure (bezier_checks.hpp) on the simulated nozzle, as on the
// plan: over the plan's central part [first, last] (the samples whose planned speed is v_c),
// the spacing of the nozzle's positions one plan period T_s apart over T_s, against v_c. The
// record holds every physics step; T_s is a whole number of them (1 with the default 1 ms).
struct CentralPart {
  double t_first_s = 0.0, t_last_s = 0.0;
  double period_s = 0.0;  // the plan's T_s
};

CentralPart central_part(const TrajectoryPiece& piece, double v_c) {
  const SampledMotion& motion = std::get<SampledMotion>(piece.motion);
  size_t first = motion.position_mm.size(), last = 0;
  for (size_t k = 0; k < motion.position_mm.size(); ++k) {
    if (std::abs(motion.velocity_mm_s[k].norm() - v_c) <= 1e-9 * v_c) {
      first = std::min(first, k);
      last = k;
    }
  }
  return {piece.t_begin_s + first * motion.period_s, piece.t_begin_s + last * motion.period_s,
          motion.period_s};
}

double simulated_speed_variation(const RecordedRun& record, const CentralPart& part, double v_c) {
  const double steps_per_sample = part.period_s / record.timestep_s;
  const size_t stride = static_cast<size_t>(std::lround(steps_per_sample));
  EXPECT_NEAR(steps_per_sample, static_cast<double>(stride), 1e-9);
  double largest = 0.0;
  for (size_t k = 0; k + stride < record.size(); ++k) {
    if (record.t_s[k] < part.t_first_s || record.t_s[k + stride] > part.t_last_s) continue;
    const double dt = record.t_s[k + stride] - record.t_s[k];
    const double v = (record.nozzle_mm[k + stride] - record.nozzle_mm[k]).norm() / dt;
    largest = std::max(largest, std::abs(v - v_c) / v_c);
  }
  return largest;
}

// ---------------------------------------------------------------------------------------
// closed chains

// The largest gap between the two ends of the delta's <connect> closures at the present state,
// measured from MuJoCo's body poses alone: each rod tip (the anchor in the rod's frame) against
// its ball joint on the platform (the compiler's anchor in the platform's frame), in world
// coordinates; the largest component (mm), as a residual row of the constraint gives it.
double closure_gap_mm(const mjModel& m, const mjData& d) {
  double largest_m = 0.0;
  for (int eq = 0; eq < m.neq; ++eq) {
    if (m.eq_type[eq] != mjEQ_CONNECT) continue;
    const mjtNum* anchors = m.eq_data + mjNEQDATA * eq;  // body 1's frame, then body 2's
    const int body[2] = {m.eq_obj1id[eq], m.eq_obj2id[eq]};
    Eigen::Vector3d end[2];
    for (int side = 0; side < 2; ++side) {
      const Eigen::Map<const Eigen::Matrix<mjtNum, 3, 3, Eigen::RowMajor>> rotation(d.xmat +
                                                                                    9 * body[side]);
      const Eigen::Map<const Eigen::Vector3d> origin(d.xpos + 3 * body[side]);
      const Eigen::Map<const Eigen::Vector3d> anchor(anchors + 3 * side);
      end[side] = origin + rotation * anchor;
    }
    largest_m = std::max(largest_m, (end[0] - end[1]).cwiseAbs().maxCoeff());
  }
  return 1e3 * largest_m;
}

// The six rods stay on the platform (MuJoCo <connect> residual) on every delta scenario and
// planner, including starts away from the delta's home: the chain is assembled around the
// start pose before the first step, so the nozzle starts exactly at the toolpath's start.
// (At the end the carriages rest within their Coulomb-friction dead band, 0.3 N / kp = 0.01
// mm each, so the end is not checked this tightly.) The reported violation is checked against
// the rod ends' gap measured from the body poses at every control update of the same run
// (simulated again, with the pipeline's feed-forward), not against the figure it copies.
TEST(DeltaPipeline, ClosedChainsStayClosed) {
  struct Case {
    const char* file;
    const char* planner;
  };
  for (const Case& c : {Case{"giberti_fig3.yaml", ""}, Case{"giberti_circle.yaml", ""},
                        Case{"thompson_fig7_delta.yaml", "lspb_mtt"},
                        Case{"thompson_fig7_delta.yaml", "stop_and_go"},
                        Case{"thompson_fig7_delta.yaml", "bezier"}}) {
    const DeltaRun delta = simulate(scenario_path(c.file), c.planner);
    const RecordedRun& record = delta.run.record;
    const double violation_mm = delta.run.report.sim->max_constraint_violation_mm;
    EXPECT_LT(violation_mm, 0.01) << c.file << " " << c.planner;
    EXPECT_LT((record.nozzle_mm.front() - delta.job.toolpath.start_mm).norm(), 0.01)
        << c.file << " " << c.planner;

    // the same run again, the gap measured at every control update (every step: 1 kHz)
    Simulation& simulation = *delta.run.simulation;
    const SimSettings settings = sim_settings(delta.job.scenario);
    ASSERT_EQ(settings.control_stride(), 1);
    const Simulation::FeedForwardHook feedforward =
        closure_feedforward_hook(*delta.job.machine, delta.run.plan.trajectory, settings);
    const mjModel& model = SimulationAccess::model(simulation);
    const mjData& data = SimulationAccess::data(simulation);
    double measured_mm = 0.0;
    long measurements = 0;
    simulation.set_feedforward_hook([&](const JointReference& reference, double* force) {
      feedforward(reference, force);
      measured_mm = std::max(measured_mm, closure_gap_mm(model, data));
      ++measurements;
    });
    const RecordedRun again = simulation.run(delta.run.plan.trajectory);
    simulation.set_feedforward_hook({});
    EXPECT_EQ(measurements, again.steps + 1);
    EXPECT_EQ(again.nozzle_mm.back(), record.nozzle_mm.back());  // the same run
    EXPECT_GT(measured_mm, 0.0);
    EXPECT_NEAR(violation_mm, measured_mm, 1e-9 * measured_mm + 1e-12)
        << c.file << " " << c.planner;
    std::printf("[ closure ] %-26s %-12s max violation %.2e mm (rod ends measured %.2e mm)\n",
                c.file, c.planner, violation_mm, measured_mm);
  }
}

// The controller's load model is the closed chain's rigid-body dynamics: at a pose off the
// axis (where giberti_fig3 ends, assembled by the simulation), the simulator's tree terms for
// each carriage subtree, m_sub (q'' + g), plus LinearDelta::closure_feedforward equal
// MuJoCo's own inverse dynamics projected on the carriages by virtual work, G^T (M qacc +
// qfrc_bias), G the map from carriage to all joint velocities (from the closures' Jacobian),
// within 1 mN per m/s^2 of TCP acceleration (the rods' tube radius, which the thin-rod model
// leaves out).
TEST(DeltaPipeline, ClosureFeedForwardIsTheChainsRigidBodyDynamics) {
  const DeltaRun fig3 = simulate(scenario_path("giberti_fig3.yaml"));
  const mjModel* m = &SimulationAccess::model(*fig3.run.simulation);
  mjData* d = mj_makeData(m);
  mj_copyData(d, m, &SimulationAccess::data(*fig3.run.simulation));
  mju_zero(d->qvel, m->nv);
  mj_forward(m, d);
  const LinearDelta& delta = dynamic_cast<const LinearDelta&>(*fig3.job.machine);
  const Vec3 tcp_mm = fig3.run.record.nozzle_mm.back();
  ASSERT_GT(tcp_mm.head<2>().norm(), 50.0);

  // G: held (carriage) columns identity, the others -J_free^+ J_held
  int held[3];
  double subtree_kg[3];
  for (int j = 0; j < 3; ++j) {
    const int joint = mj_name2id(m, mjOBJ_JOINT, ("carriage" + std::to_string(j + 1)).c_str());
    held[j] = m->jnt_dofadr[joint];
    subtree_kg[j] = m->body_subtreemass[m->jnt_bodyid[joint]];
  }
  std::vector<int> rows, free_dofs;
  for (int r = 0; r < d->nefc; ++r)
    if (d->efc_type[r] == mjCNSTR_EQUALITY) rows.push_back(r);
  for (int c = 0; c < m->nv; ++c)
    if (c != held[0] && c != held[1] && c != held[2]) free_dofs.push_back(c);
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(rows.size(), m->nv);
  for (size_t i = 0; i < rows.size(); ++i) {
    const int r = rows[i];
    if (mj_isSparse(m)) {
      for (int k = 0; k < d->efc_J_rownnz[r]; ++k)
        jacobian(i, d->efc_J_colind[d->efc_J_rowadr[r] + k]) = d->efc_J[d->efc_J_rowadr[r] + k];
    } else {
      for (int c = 0; c < m->nv; ++c) jacobian(i, c) = d->efc_J[r * m->nv + c];
    }
  }
  Eigen::MatrixXd jacobian_free(rows.size(), free_dofs.size()), jacobian_held(rows.size(), 3);
  for (size_t c = 0; c < free_dofs.size(); ++c) jacobian_free.col(c) = jacobian.col(free_dofs[c]);
  for (int c = 0; c < 3; ++c) jacobian_held.col(c) = jacobian.col(held[c]);
  const Eigen::MatrixXd free_map =
      -jacobian_free.completeOrthogonalDecomposition().solve(jacobian_held);
  Eigen::MatrixXd velocity_map = Eigen::MatrixXd::Zero(m->nv, 3);
  for (int c = 0; c < 3; ++c) velocity_map(held[c], c) = 1.0;
  for (size_t c = 0; c < free_dofs.size(); ++c) velocity_map.row(free_dofs[c]) = free_map.row(c);

  JointVector joints;
  ASSERT_TRUE(delta.inverse(tcp_mm, joints));
  for (const Vec3& acceleration_mm_s2 :
       {Vec3(0, 0, 0), Vec3(1000, 0, 0), Vec3(0, 1000, 0), Vec3(0, 0, 1000)}) {
    // at rest, so J qacc = 0 is the whole acceleration constraint
    const JointVector carriage_mm_s2 =
        delta.joint_acceleration(joints, Vec3::Zero(), acceleration_mm_s2);
    const Eigen::Vector3d carriage_m_s2(mm_to_m(carriage_mm_s2[0]), mm_to_m(carriage_mm_s2[1]),
                                        mm_to_m(carriage_mm_s2[2]));
    const Eigen::VectorXd qacc = velocity_map * carriage_m_s2;
    std::vector<mjtNum> inertia_n(m->nv);
    mj_mulM(m, d, inertia_n.data(), qacc.data());
    Eigen::VectorXd generalized_n(m->nv);
    for (int c = 0; c < m->nv; ++c) generalized_n[c] = inertia_n[c] + d->qfrc_bias[c];
    const Eigen::Vector3d mujoco_n = velocity_map.transpose() * generalized_n;

    double closure_n[3] = {0, 0, 0};
    delta.closure_feedforward(tcp_mm, Vec3::Zero(), acceleration_mm_s2, closure_n);
    for (int j = 0; j < 3; ++j) {
      const double controller_n =
          subtree_kg[j] * (carriage_m_s2[j] + delta.geometry().gravity_m_s2) + closure_n[j];
      EXPECT_NEAR(controller_n, mujoco_n[j], 1e-3)
          << "carriage " << j + 1 << " at a = " << acceleration_mm_s2.transpose();
    }
  }
  mj_deleteData(d);
}

// ---------------------------------------------------------------------------------------
// the circle (Fig. 11)

// Fig. 11b: the platform follows the circle's polygon closely. The nozzle (read from MuJoCo
// in the plate's frame) stays within 0.1 mm of the print path; the blends alone cut the
// 25-degree corners by delta sin(12.5) cos(12.5) / 2 = 0.048 mm.
TEST(DeltaPipeline, CircleNozzleStaysWithinATenthOfAMillimetre) {
  const DeltaRun circle = simulate(scenario_path("giberti_circle.yaml"));
  const MetricsReport& r = circle.run.report;
  EXPECT_LT(r.path_error->max_mm, 0.1);
  const double corner_cut_mm = 0.45 * std::sin(deg_to_rad(12.5)) * std::cos(deg_to_rad(12.5)) / 2.0;
  EXPECT_GT(r.path_error->max_mm, corner_cut_mm - 0.005);  // the blends are really there
  // the servos add little to the plan's own deviation
  ASSERT_TRUE(r.path_error.has_value());
  EXPECT_LT(r.path_error->max_mm - r.planned_path_error.max_mm, 0.02);
  // the speed-error headline: the whole printed length counts each path's start and end ramps
  // (from rest: near 100 %); outside them (the papers' figure) the plan holds the speed and
  // the simulated nozzle stays within 1 %
  EXPECT_GT(r.planned_velocity_error.max_rel, 0.9);
  EXPECT_LT(r.planned_velocity_error_steady.max_rel, 1e-3);
  ASSERT_TRUE(r.velocity_error_steady.has_value());
  EXPECT_LT(r.velocity_error_steady->max_rel, 0.01);
  EXPECT_LE(r.velocity_error_steady->rms_rel, r.velocity_error->rms_rel);
  EXPECT_GT(r.speed_ramps.size(), 0u);
  std::printf("[ circle ] path error max %.4f mm (planned %.4f), rms %.4f mm\n",
              r.path_error->max_mm, r.planned_path_error.max_mm, r.path_error->rms_mm);
}

// The print part of a delta run at constant speed (depositing, 0.1 s clear of the start and
// stop ramps): each carriage's largest |acceleration| and when, the plan's own carriage
// acceleration peak over the same instants (J a + (dJ/dt) v of the planned TCP motion), and
// the instants each carriage reverses (its velocity changes sign).
struct CarriagePeaks {
  double acceleration_mm_s2[3] = {0, 0, 0};
  double at_s[3] = {0, 0, 0};
  double planned_mm_s2[3] = {0, 0, 0};
  std::vector<double> reversals_s[3];

  // the time from carriage j's peak to the nearest of its reversals (1e9 without any)
  double peak_to_reversal_s(int j) const {
    double nearest_s = 1e9;
    for (double t : reversals_s[j]) nearest_s = std::min(nearest_s, std::abs(t - at_s[j]));
    return nearest_s;
  }
};

CarriagePeaks carriage_peaks(const DeltaRun& delta) {
  const RecordedRun& r = delta.run.record;
  double first_s = -1.0, last_s = -1.0;
  for (size_t k = 0; k < r.size(); ++k) {
    if (!r.deposit_command[k]) continue;
    if (first_s < 0) first_s = r.t_s[k];
    last_s = r.t_s[k];
  }
  const LinearDelta& machine = dynamic_cast<const LinearDelta&>(*delta.job.machine);
  CarriagePeaks peaks;
  JointVector joints;
  for (size_t k = 1; k < r.size(); ++k) {
    if (!r.deposit_command[k] || r.t_s[k] < first_s + 0.1 || r.t_s[k] > last_s - 0.1) continue;
    const TrajectorySample sample = delta.run.plan.trajectory.at(r.t_s[k]);
    EXPECT_TRUE(machine.inverse(sample.position_mm, joints));
    const JointVector planned =
        machine.joint_acceleration(joints, sample.velocity_mm_s, sample.acceleration_mm_s2);
    for (int j = 0; j < 3; ++j) {
      const double a = std::abs(r.joint(r.joint_acceleration, k, j));
      if (a > peaks.acceleration_mm_s2[j]) {
        peaks.acceleration_mm_s2[j] = a;
        peaks.at_s[j] = r.t_s[k];
      }
      peaks.planned_mm_s2[j] = std::max(peaks.planned_mm_s2[j], std::abs(planned[j]));
      if (r.joint(r.joint_velocity, k - 1, j) * r.joint(r.joint_velocity, k, j) < 0.0)
        peaks.reversals_s[j].push_back(r.t_s[k]);
    }
  }
  return peaks;
}

// Fig. 11a: constant TCP speed, yet the carriages see acceleration peaks where they reverse.
//
// Why: carriage i moves with the component of the platform's motion along its rod, which lies
// in the vertical plane through its column. On a circle about the axis the carriage reverses
// where the path runs across that plane (the nozzle at +-20 mm along u_i), and there a corner's
// centripetal acceleration, which points at the centre, lies in that plane: the carriage takes
// the corner's acceleration whole, where elsewhere it takes only a projection of it. Among
// equal corners, then, each carriage's peak is at a corner where it reverses.
//
// 1. A circle of equal corners: a regular 12-gon of radius 20 mm (30-degree corners) with
//    vertices at 0, 30, ..., 330 degrees, so through all six reversal points (u_i at 90, 210
//    and 330 degrees, and their opposites). Every carriage's print peak lies at one of its
//    reversals (within 0.1 s, half a 0.45 mm blend at 5 mm/s is 0.05 s), the next-largest
//    corners, 30 degrees on, giving about 12 % less (180 / 300 against 159 / 302 of the rod's
//    horizontal over vertical extent).
// 2. The paper's circle (giberti_circle.yaml: slicing lines across u3, so its corners are not
//    equal: 25 degrees next to +-u3, 5.8 degrees at the steep crossings). Carriage 3 reverses at
//    the sharpest corners, so, as in the paper, its peak is the largest and lies where it
//    reverses. Carriages 1 and 2 reverse at 6.6-degree corners and take a 25-degree corner's
//    projection (cos 60 degrees of four times the acceleration) for more: their largest peaks
//    are at the 25-degree corners, 2.7 s from their reversals, in the plan too. On both
//    circles every carriage's peak is far above what a constant-speed straight line gives
//    (where the carriages only see the kinematics' gentle curvature) and is the plan's own
//    (within 10 %): the servos add no peaks of their own. No carriage exceeds its limits (the
//    planners get LinearDelta::cartesian_limits).
TEST(DeltaPipeline, CarriagesSeeAccelerationPeaksWhereTheyReverseOnTheCircle) {
  const std::string dir = fresh_directory("delta_reversal_peaks");
  const char* head = R"(machine: linear_delta
limits: {v_max: 100, a_max: 500, joint: {v_max: 200, a_max: 3000}}
process: {type: extrusion, bead_width_mm: 0.45, layer_height_mm: 0.2, tau_s: 0.05}
planners: [{name: bezier, delta: 0.45}]
toolpath:
  speed: 5
)";
  // the 12-gon, closed, from the vertex at 0 degrees, counter-clockwise
  std::string polygon = std::string("name: delta_12gon\n") + head +
                        "  start: [0, 0]\n  end: [0, 0]\n  polylines:\n    - [";
  for (int k = 0; k <= 12; ++k) {
    const double angle = deg_to_rad(30.0 * (k % 12));
    char point[64];
    std::snprintf(point, sizeof point, "%s[%.6f, %.6f]", k > 0 ? ", " : "", 20.0 * std::cos(angle),
                  20.0 * std::sin(angle));
    polygon += point;
  }
  polygon += "]\n";
  const DeltaRun equal_corners = simulate(write_text(dir, "polygon.yaml", polygon));
  const DeltaRun circle = simulate(scenario_path("giberti_circle.yaml"));
  // a 30 mm line at the same speed and limits through the same region, along x (it reverses
  // carriage 1 at x = 0, slowly: no corner there)
  const DeltaRun line = simulate(write_text(dir, "line.yaml",
                                            std::string("name: delta_line\n") + head +
                                                "  start: [-15, 0]\n  end: [15, 0]\n"
                                                "  segments:\n    - [[-15, 0], [15, 0]]\n"));
  const CarriagePeaks on_polygon = carriage_peaks(equal_corners);
  const CarriagePeaks on_circle = carriage_peaks(circle);
  const CarriagePeaks on_line = carriage_peaks(line);

  double line_peak = 0.0;
  for (int j = 0; j < 3; ++j) line_peak = std::max(line_peak, on_line.acceleration_mm_s2[j]);
  EXPECT_LT(line_peak, 1.0);  // ~ |v|^2 / rod height = 25 / 300 mm/s^2, plus servo noise

  for (const auto& [name, peaks] :
       {std::pair<const char*, const CarriagePeaks*>{"12-gon", &on_polygon},
        {"circle", &on_circle}}) {
    for (int j = 0; j < 3; ++j) {
      EXPECT_GT(peaks->acceleration_mm_s2[j], 10.0 * line_peak) << name << " carriage " << j + 1;
      EXPECT_NEAR(peaks->acceleration_mm_s2[j], peaks->planned_mm_s2[j],
                  0.1 * peaks->planned_mm_s2[j])
          << name << " carriage " << j + 1;
      EXPECT_GE(peaks->reversals_s[j].size(), 2u) << name << " carriage " << j + 1;
      std::printf(
          "[ %s, carriage %d ] print peak %.2f mm/s^2 (plan %.2f) at %.3f s, %.3f s from a "
          "reversal; line %.3f\n",
          name, j + 1, peaks->acceleration_mm_s2[j], peaks->planned_mm_s2[j], peaks->at_s[j],
          peaks->peak_to_reversal_s(j), on_line.acceleration_mm_s2[j]);
    }
  }
  // equal corners: every carriage peaks where it reverses
  for (int j = 0; j < 3; ++j)
    EXPECT_LT(on_polygon.peak_to_reversal_s(j), 0.1) << "12-gon carriage " << j + 1;
  // the paper's circle: carriage 3 peaks where it reverses, at the sharpest corners, highest
  EXPECT_LT(on_circle.peak_to_reversal_s(2), 0.1);
  EXPECT_GT(on_circle.acceleration_mm_s2[2], on_circle.acceleration_mm_s2[0]);
  EXPECT_GT(on_circle.acceleration_mm_s2[2], on_circle.acceleration_mm_s2[1]);
  // carriages 1 and 2 take more from the 25-degree corners than from their own 6.6-degree
  // ones: their peaks are far from their reversals (the reason lies in the corners, not in
  // the carriages: the 12-gon's equal corners put them at their reversals)
  for (int j = 0; j < 2; ++j)
    EXPECT_GT(on_circle.peak_to_reversal_s(j), 1.0) << "circle carriage " << j + 1;

  // no carriage beyond its velocity, acceleration or force limit, on any run
  for (const DeltaRun* delta : {&equal_corners, &circle, &line}) {
    const ActuatorStats& actuators = *delta->run.report.actuators;
    EXPECT_EQ(actuators.limit_violations, 0) << delta->job.scenario.name;
    for (int j = 0; j < 3; ++j) {
      EXPECT_LE(actuators.peak_vel[j], actuators.limit_vel[j]);
      EXPECT_LE(actuators.peak_acc[j], actuators.limit_acc[j]);
    }
  }
}

// ---------------------------------------------------------------------------------------
// speed variation (Figs. 3-4)

// Sec. 4.1: in the plan, the speed variation over the central part stays within the paper's
// 0.14 / 0.27 / 0.22 % at 5 / 10 / 20 mm/s on the delta too (its Cartesian limits slow no
// corner, so the central part is nearly the whole 80 mm path).
TEST(DeltaPipeline, Fig3PlannedSpeedVariationIsWithinThePapers) {
  const DeltaRun fig3 = simulate(scenario_path("giberti_fig3.yaml"));
  EXPECT_TRUE(fig3.run.plan.trajectory.warnings().empty());
  const double paper[3] = {0.0014, 0.0027, 0.0022};
  ASSERT_EQ(fig3.job.toolpath.paths.size(), 3u);
  for (int path = 0; path < 3; ++path) {
    const double v_c = fig3.job.toolpath.paths[path].speed_mm_s;
    const auto pieces = printing_pieces(fig3.run.plan.trajectory, path);
    ASSERT_EQ(pieces.size(), 1u);
    const SampledMotion& motion = std::get<SampledMotion>(pieces[0]->motion);
    const bezier_test::SpeedVariation planned = bezier_test::speed_variation(motion, v_c);
    EXPECT_GT(planned.central_samples, 0.98 * 80.0 / v_c / motion.period_s);
    EXPECT_LT(planned.max_rel, paper[path]) << v_c << " mm/s";
    const double simulated =
        simulated_speed_variation(fig3.run.record, central_part(*pieces[0], v_c), v_c);
    std::printf("[ speed variation ] %4.0f mm/s: plan %.4f %%, simulated %.4f %% (paper %.2f %%)\n",
                v_c, 100 * planned.max_rel, 100 * simulated, 100 * paper[path]);
  }
}

// The issue's target for the simulated nozzle: within 0.5 % over the same central part,
// measured the same way (sample spacing over T_s). Measured 0.378 / 0.096 / 0.046 % at
// 5 / 10 / 20 mm/s (before the controller and friction changes: 4.85 / 12.4 / 5.51 %).
// What it took (the report of issue 5 has the figures):
// - the guide friction is Coulomb (models/linear_delta.xml): MuJoCo's default regularisation
//   made it a damper below 1.1 mm/s, so its force followed the carriage speed wherever a
//   carriage slowed or reversed (every corner, every path start), which no direction-based
//   compensation could match: 4.6 / 2.0 / 1.8 % at the corners;
// - the servo's feed-forward comes from its sampled setpoints (velocity and acceleration as
//   differences, Simulation), held as the plant's Euler steps see them: the analytic
//   references were half a step late at every acceleration step, so each path's start (right
//   after a transition's 1300 mm/s^2 stop) rang by 4 % at 5 mm/s, and kv a h / 2 lagged the
//   carriages by ~5 um in every acceleration;
// - the closed chain's rigid-body load is exact (the rods as rods, not riding on the carriages).
// - the friction feed-forward is the plant's friction law at the reference's velocity and
//   acceleration (Simulation: MuJoCo's friction leads the velocity by 1 / B).
// The largest figure is each path's first millisecond at 5 mm/s (0.38 %): the print path
// starts where the transition stops, all three carriages pass zero speed at once there. With
// 0.5 ms (0.25 ms) steps and servo updates it measures 0.071 / 0.020 / 0.047 %
// (0.084 / 0.038 / 0.050 %). Not met with a servo period longer than the physics step (0.5 ms
// steps, 1 ms servo: 2.7 / 2.7 / 1.3 %): the plant moves between updates and the held
// references match it only on average.
TEST(DeltaPipeline, Fig3SimulatedSpeedVariationIsWithinHalfAPercent) {
  const DeltaRun fig3 = simulate(scenario_path("giberti_fig3.yaml"));
  for (int path = 0; path < 3; ++path) {
    const double v_c = fig3.job.toolpath.paths[path].speed_mm_s;
    const auto pieces = printing_pieces(fig3.run.plan.trajectory, path);
    ASSERT_EQ(pieces.size(), 1u);
    EXPECT_LT(simulated_speed_variation(fig3.run.record, central_part(*pieces[0], v_c), v_c), 0.005)
        << v_c << " mm/s";
  }
}

// ---------------------------------------------------------------------------------------
// extrusion

// one 30 mm line along x at 5 mm/s, entered at speed (lspb_mtt) and stopped right at its end
std::string straight_line_scenario(const std::string& dir, const std::string& name, double tau_s) {
  char text[1024];
  std::snprintf(text, sizeof text, R"(name: %s
machine: linear_delta
limits: {v_max: 100, a_max: 500, joint: {v_max: 200, a_max: 3000}}
process: {type: extrusion, bead_width_mm: 0.45, layer_height_mm: 0.2, tau_s: %g}
toolpath:
  speed: 5
  start: [-20, 0]
  end: [15, 0]
  segments:
    - [[-15, 0], [15, 0]]
planners: [lspb_mtt]
)",
                name.c_str(), tau_s);
  return write_text(dir, name + ".yaml", text);
}

// centreline thickness (mm) at arc length s along the line from (-15, 0) to (15, 0)
double centreline_mm(const ThicknessField& field, double s_mm) {
  return field.thickness_mm_at(-15.0 + s_mm, 0.0);
}

struct LineProfile {
  double mid_mean_mm = 0.0;
  double central_cv = 0.0;    // over 2 mm .. 28 mm
  double start_rel = 0.0;     // at 3 sigma past the start, / mid
  double end_peak_rel = 0.0;  // largest within 0.5 mm of the end, / mid
  double metrics_line_cv = 0.0;
};

LineProfile line_profile(const DeltaRun& line) {
  const ThicknessField& field = line.run.deposit->field();
  const double sigma_mm = line.run.deposit->footprint_sigma_mm();
  LineProfile profile;
  std::vector<double> central;
  for (double s = 2.0; s <= 28.0 + 1e-9; s += field.cell_mm())
    central.push_back(centreline_mm(field, s));
  double sum = 0.0, squares = 0.0;
  for (double v : central) sum += v;
  const double mean = sum / central.size();
  for (double v : central) squares += (v - mean) * (v - mean);
  profile.central_cv = std::sqrt(squares / central.size()) / mean;
  double mid = 0.0;
  int count = 0;
  for (double s = 10.0; s <= 20.0 + 1e-9; s += field.cell_mm(), ++count)
    mid += centreline_mm(field, s);
  profile.mid_mean_mm = mid / count;
  profile.start_rel = centreline_mm(field, 3.0 * sigma_mm) / profile.mid_mean_mm;
  double end_peak = 0.0;
  for (double s = 29.5; s <= 30.5 + 1e-9; s += 0.25 * field.cell_mm())
    end_peak = std::max(end_peak, centreline_mm(field, s));
  profile.end_peak_rel = end_peak / profile.mid_mean_mm;
  profile.metrics_line_cv = line.run.report.thickness->line_cv;
  return profile;
}

// A straight line at constant speed lays an even bead: away from its ends the centreline
// varies by under 1 %, at the steady bead's peak w h / (sigma sqrt(2 pi)) = 1.6 h = 0.319 mm.
TEST(DeltaPipeline, ExtrudedLineIsEvenAwayFromItsEnds) {
  const std::string dir = fresh_directory("delta_line_even");
  const DeltaRun line = simulate(straight_line_scenario(dir, "line", 0.05));
  const LineProfile profile = line_profile(line);
  EXPECT_LT(profile.central_cv, 0.01);
  const double steady_peak_mm = 0.45 * 0.2 / ((0.45 / 4) * std::sqrt(2.0 * kPi));
  EXPECT_NEAR(profile.mid_mean_mm, steady_peak_mm, 0.01 * steady_peak_mm);
  std::printf(
      "[ extrusion ] line centre cv %.4f %% (metrics line_cv over the whole line %.4f %%), "
      "mid %.1f um (steady bead %.1f um)\n",
      100 * profile.central_cv, 100 * profile.metrics_line_cv, 1000 * profile.mid_mean_mm,
      1000 * steady_peak_mm);
}

// The flow lag, seen in the simulated field: with tau = 50 ms the flow builds up after the
// start (v tau = 0.25 mm) and oozes on where the nozzle stops at the end, so the line starts
// thin and ends in a blob. The same line with a negligible lag (0.1 ms) has neither: the
// effect is the lag's, not the line's geometry.
TEST(DeltaPipeline, FlowLagGivesAThinStartAndABlobAtTheEnd) {
  const std::string dir = fresh_directory("delta_line_lag");
  const LineProfile lagging = line_profile(simulate(straight_line_scenario(dir, "lag", 0.05)));
  const LineProfile prompt = line_profile(simulate(straight_line_scenario(dir, "prompt", 0.0001)));
  EXPECT_LT(lagging.start_rel, 0.8);
  EXPECT_GT(lagging.end_peak_rel, 1.2);
  EXPECT_GT(prompt.start_rel, 0.95);
  EXPECT_LT(prompt.end_peak_rel, 1.1);
  // the metrics see it too: line_cv (which leaves out only a footprint radius at each end)
  // is under 1 % without the lag and several times that with it
  EXPECT_LT(prompt.metrics_line_cv, 0.01);
  EXPECT_GT(lagging.metrics_line_cv, 5.0 * prompt.metrics_line_cv);
  std::printf(
      "[ flow lag ] tau 50 ms: start %.3f, end %.3f of mid; tau 0.1 ms: start %.3f, "
      "end %.3f; metrics line_cv %.4f vs %.4f\n",
      lagging.start_rel, lagging.end_peak_rel, prompt.start_rel, prompt.end_peak_rel,
      lagging.metrics_line_cv, prompt.metrics_line_cv);
}

// ---------------------------------------------------------------------------------------
// compare

// `compare` on the delta: all three planners through the whole pipeline, one row each, and
// the side-by-side sheet (one 460 px column per planner, not blank).
TEST(DeltaPipeline, CompareRunsAllThreePlanners) {
  const std::string dir = fresh_directory("delta_compare");
  const Scenario scenario = load_scenario(scenario_path("thompson_fig7_delta.yaml"));
  ASSERT_EQ(scenario.planners.size(), 3u);
  const std::vector<ComparisonRow> rows =
      compare_runs(scenario, scenario.planners, {}, dir, quiet(true));
  ASSERT_EQ(rows.size(), 3u);
  const char* names[3] = {"lspb_mtt", "stop_and_go", "bezier"};
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(rows[i].label, names[i]);
    EXPECT_EQ(rows[i].report.machine, "linear_delta");
    EXPECT_TRUE(std::filesystem::exists(dir + "/" + names[i] + "/metrics.json")) << names[i];
    EXPECT_TRUE(std::filesystem::exists(dir + "/" + names[i] + "/scene.png")) << names[i];
  }
  for (const char* file : {"comparison.json", "comparison.csv", "comparison.md", "comparison.png"})
    EXPECT_TRUE(std::filesystem::exists(dir + "/" + file)) << file;

  // three rows in each table
  const std::string csv = testing_support::read_bytes(dir + "/comparison.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 4);
  const std::string md = testing_support::read_bytes(dir + "/comparison.md");
  for (const char* name : names)
    EXPECT_NE(md.find(std::string("| ") + name + " | " + name + " |"), std::string::npos) << name;
  // comparison.json: the same table (columns and one row per run), then each run's metrics
  const nlohmann::ordered_json json =
      nlohmann::ordered_json::parse(testing_support::read_bytes(dir + "/comparison.json"));
  ASSERT_EQ(json["rows"].size(), 3u);
  ASSERT_EQ(json["runs"].size(), 3u);
  EXPECT_EQ(json["columns"][0], "run");
  EXPECT_EQ(csv.substr(0, csv.find(',')), "run");
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(json["rows"][i]["run"], names[i]);
    EXPECT_EQ(json["runs"][i]["run"], names[i]);
  }

  // the sheet: three columns wide, not blank
  const std::string png = testing_support::read_bytes(dir + "/comparison.png");
  const auto header = testing_support::png_header(png);
  ASSERT_TRUE(header.valid);
  EXPECT_EQ(header.width, 3u * plots::style::kComparisonColumnWidth_px);
  EXPECT_EQ(header.height, static_cast<unsigned>(plots::style::kComparisonHeight_px));
  EXPECT_GT(testing_support::pixel_variance(png), 100.0);

  // the planners differ as they should: stop-and-go stops at every joint (100 % speed
  // error), Thompson & Yoon's averaging keeps the joint speed error near 60 %
  EXPECT_GT(rows[1].report.velocity_error->max_rel, 0.9);
  EXPECT_LT(rows[0].report.velocity_error->max_rel, 0.7);
  for (const ComparisonRow& row : rows) {
    EXPECT_LT(row.report.sim->max_constraint_violation_mm, 0.01) << row.label;
    EXPECT_EQ(row.report.actuators->limit_violations, 0) << row.label;
  }
}

}  // namespace
}  // namespace depotwin
