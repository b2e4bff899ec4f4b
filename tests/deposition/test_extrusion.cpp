// Extrusion process: bead cross-section Q/v, first-order flow lag (thin start, ooze blob),
// and material conservation with nothing captured.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "deposition/deposition_metrics.hpp"
#include "deposition/layered_deposit.hpp"
#include "deposition/process.hpp"
#include "deposition_test_util.hpp"

namespace depotwin {
namespace {

using test::drive;

constexpr double kBeadWidth = 0.4;
constexpr double kLayerHeight = 0.2;
constexpr double kTau = 0.05;
constexpr double kSpeed = 20.0;
constexpr double kLength = 20.0;  // mm, printed in 1 s
const double kSqrt2Pi = std::sqrt(2.0 * kPi);

DepositionSettings extrusion_settings() {
  DepositionSettings settings;
  settings.type = ProcessType::extrusion;
  settings.bead_width_mm = kBeadWidth;
  settings.layer_height_mm = kLayerHeight;
  settings.tau_s = kTau;
  return settings;
}

// print one line along x at constant speed with the command on, then dwell at its end
// with the command off so the lagged flow oozes out
void print_line_then_dwell(Process& process, double dwell_s) {
  const double t_print = kLength / kSpeed;
  drive(
      process, 0.0, t_print + dwell_s, 1e-3,
      [&](double t) { return Vec3(kSpeed * std::min(t, t_print), 0.0, 0.0); },
      [](double) { return 0.0; }, [&](double t) { return t < t_print ? 1.0 : 0.0; },
      [&](double t) { return t < t_print ? kSpeed : 0.0; });
}

// cross-section area at column x: sum of the column's cells times the cell width (mm^2)
double cross_section_mm2(const ThicknessField& field, double x_mm) {
  const int ix = static_cast<int>(std::lround(x_mm / field.cell_mm()));
  double sum = 0.0;
  for (int iy = -40; iy <= 40; ++iy) sum += field.cell_thickness_mm(ix, iy);
  return sum * field.cell_mm();
}

TEST(Extrusion, DefaultsFollowTheBead) {
  const DepositionSettings settings = extrusion_settings();
  EXPECT_DOUBLE_EQ(settings.footprint_sigma_mm(), 0.1);      // w / 4
  EXPECT_DOUBLE_EQ(settings.resolved_line_width_mm(), 0.4);  // w
  EXPECT_DOUBLE_EQ(settings.default_cell_mm(), 0.05);        // w / 8
}

// steady bead: cross-section Q / v = w h, centreline peak w h / (sigma sqrt(2 pi))
TEST(Extrusion, SteadyBeadCrossSectionIsFlowOverSpeed) {
  ExtrusionProcess process(extrusion_settings(), 0.0);
  print_line_then_dwell(process, 0.0);
  const double area = kBeadWidth * kLayerHeight;
  EXPECT_NEAR(cross_section_mm2(process.field(), 12.0) / area, 1.0, 1e-4);
  EXPECT_NEAR(process.field().thickness_mm_at(12.0, 0.0) / (area / (0.1 * kSqrt2Pi)), 1.0, 1e-4);
}

// the lag: the start is thin (cross-section w h (1 - exp(-x / (v tau)))), the end blobs
TEST(Extrusion, LagGivesThinStartAndOozeBlob) {
  ExtrusionProcess process(extrusion_settings(), 0.0);
  const double t_print = kLength / kSpeed;
  print_line_then_dwell(process, 0.0);
  const double emitted_at_stop = process.account().emitted_mm3;
  const double flow_at_stop = process.nozzle_flow_mm3_s();
  drive(
      process, t_print, t_print + 2.0, 1e-3, [&](double) { return Vec3(kLength, 0.0, 0.0); },
      [](double) { return 0.0; }, [](double) { return 0.0; }, [](double) { return 0.0; });

  // ooze after the stop: the remaining flow integrates to Q tau, all of it at the end point
  const double nominal = kSpeed * kBeadWidth * kLayerHeight;
  EXPECT_NEAR(flow_at_stop, nominal * (1.0 - std::exp(-t_print / kTau)), 1e-9 * nominal);
  EXPECT_NEAR(process.account().emitted_mm3 - emitted_at_stop, flow_at_stop * kTau,
              1e-9 * nominal * kTau);
  EXPECT_EQ(process.nozzle_flow_mm3_s(), 0.0);

  // thin start: cross-section follows the lagged flow (smoothed by sigma << v tau)
  const double area = kBeadWidth * kLayerHeight;
  const double x_start = 1.0;  // = v tau
  EXPECT_NEAR(cross_section_mm2(process.field(), x_start) / (area * (1.0 - std::exp(-1.0))), 1.0,
              0.02);

  // the metric view: thickness near the start below the mean, at the end above it
  const Toolpath toolpath = test::straight_toolpath(0.0, 0.0, kLength, 0.0, kSpeed);
  const DepositionMetrics metrics =
      evaluate_deposition(process.field(), toolpath, process.line_width_mm(), process.account());
  const double line_mean_mm = process.field().thickness_mm_at(10.0, 0.0);
  EXPECT_LT(process.field().thickness_mm_at(0.3, 0.0), 0.5 * line_mean_mm);
  EXPECT_GT(process.field().thickness_mm_at(kLength - 0.1, 0.0), 2.0 * line_mean_mm);
  EXPECT_LT(metrics.thickness.min_rel, 0.5);
  EXPECT_GT(metrics.thickness.max_rel, 1.5);
}

// emitted = on_target + overspray (nothing captured); emitted = commanded volume once the
// ooze has run out, and ooze on a travel move is overspray
TEST(Extrusion, MaterialIsConservedAndOozeOnTravelIsOverspray) {
  ExtrusionProcess process(extrusion_settings(), 0.0);
  const double t_print = kLength / kSpeed;
  // print, then travel away sideways at 50 mm/s for 2 s with the command off
  drive(
      process, 0.0, t_print + 2.0, 1e-3,
      [&](double t) {
        return t < t_print ? Vec3(kSpeed * t, 0.0, 0.0) : Vec3(kLength, 50.0 * (t - t_print), 0.0);
      },
      [](double) { return 0.0; }, [&](double t) { return t < t_print ? 1.0 : 0.0; },
      [&](double t) { return t < t_print ? kSpeed : 0.0; });

  const Toolpath toolpath = test::straight_toolpath(0.0, 0.0, kLength, 0.0, kSpeed);
  const DepositionMetrics metrics =
      evaluate_deposition(process.field(), toolpath, process.line_width_mm(), process.account());
  const MaterialSplit& m = metrics.material;
  const double commanded = kSpeed * kBeadWidth * kLayerHeight * t_print;
  EXPECT_NEAR(m.emitted_mm3, commanded, 1e-9 * commanded);
  EXPECT_EQ(m.captured_mm3, 0.0);
  EXPECT_NEAR(m.on_target_mm3 + m.overspray_mm3, m.emitted_mm3, 1e-6 * m.emitted_mm3);
  // most of the ooze (~Q tau, 5% of the line) is strung along the travel: overspray
  EXPECT_GT(m.overspray_mm3, 0.5 * kSpeed * kBeadWidth * kLayerHeight * kTau);
}

TEST(Extrusion, ZeroTauFollowsTheCommandInstantly) {
  DepositionSettings settings = extrusion_settings();
  settings.tau_s = 0.0;
  ExtrusionProcess process(settings, 0.0);
  print_line_then_dwell(process, 0.5);
  const double commanded = kSpeed * kBeadWidth * kLayerHeight * (kLength / kSpeed);
  EXPECT_NEAR(process.account().emitted_mm3, commanded, 1e-12 * commanded);
  // no lag: the start cross-section is already the full bead half a sigma in
  EXPECT_NEAR(cross_section_mm2(process.field(), 0.5) / (kBeadWidth * kLayerHeight), 1.0, 1e-4);
}

// process.retract: a command below 0 draws the lagged flow down faster and stops it at 0.
// From Q0 = nominal, a command of -nominal held for 0.1 s (2 tau) crosses 0 at t* = tau ln 2
// and lays Qc t* + Q0 tau = Q0 tau (1 - ln 2); after that nothing flows, and the chord is
// deposited only up to where the flow stopped. Without retract the same command is 0: the
// flow decays as exp(-t / tau) and lays Q0 tau (1 - exp(-2)).
TEST(Extrusion, RetractingCommandStopsTheFlowAtZero) {
  for (const bool retract : {true, false}) {
    SCOPED_TRACE(retract ? "retract" : "no retract");
    DepositionSettings settings = extrusion_settings();
    settings.retract = retract;
    ExtrusionProcess process(settings, 0.0);
    const double nominal = kSpeed * kBeadWidth * kLayerHeight;
    DepositionStep step;
    step.flow_command = 1.0;
    step.desired_speed_mm_s = kSpeed;
    process.start_steady(step);
    ASSERT_DOUBLE_EQ(process.nozzle_flow_mm3_s(), nominal);
    // one 0.1 s step along x from 0 to 2 mm, commanding -1
    step.t0_s = 0.0;
    step.t1_s = 2.0 * kTau;
    step.p0_mm = Vec3(0, 0, 0);
    step.p1_mm = Vec3(2, 0, 0);
    step.flow_command = -1.0;
    process.advance(step);
    const double expected =
        retract ? nominal * kTau * (1.0 - std::log(2.0)) : nominal * kTau * -std::expm1(-2.0);
    EXPECT_NEAR(process.account().emitted_mm3, expected, 1e-12 * expected);
    EXPECT_NEAR(process.field().total_volume_mm3(), expected, 1e-9 * expected);
    if (retract) {
      EXPECT_EQ(process.nozzle_flow_mm3_s(), 0.0);
      // the flow stopped at u = ln 2 / 2 of the 2 mm chord, x = ln 2 mm: beyond the footprint's
      // reach past it (5 sigma = 0.5 mm) the field is empty, before it the bead lies
      const ThicknessField& field = process.field();
      const auto column = [&](double x_mm) { return cross_section_mm2(field, x_mm); };
      EXPECT_EQ(column(std::log(2.0) + 0.55), 0.0);
      EXPECT_GT(column(0.3), 0.0);
      // a later retracting step lays nothing and the flow stays at 0
      step.t0_s = step.t1_s;
      step.t1_s += 0.01;
      process.advance(step);
      EXPECT_NEAR(process.account().emitted_mm3, expected, 1e-12 * expected);
      EXPECT_EQ(process.nozzle_flow_mm3_s(), 0.0);
    } else {
      EXPECT_NEAR(process.nozzle_flow_mm3_s(), nominal * std::exp(-2.0), 1e-12 * nominal);
    }
  }
}

// start_steady: the lagged flow starts settled at the step's command, so a line printed from
// there lands exactly command x time (no thin start), and nothing lands before it
TEST(Extrusion, StartSteadySettlesTheLagWithoutDepositing) {
  ExtrusionProcess process(extrusion_settings(), 0.0);
  DepositionStep step;
  step.flow_command = 1.0;
  step.desired_speed_mm_s = kSpeed;
  process.start_steady(step);
  const double command = kSpeed * kBeadWidth * kLayerHeight;
  EXPECT_DOUBLE_EQ(process.nozzle_flow_mm3_s(), command);
  EXPECT_EQ(process.account().emitted_mm3, 0.0);
  EXPECT_EQ(process.field().total_volume_mm3(), 0.0);
  const double t_print = kLength / kSpeed;
  drive(
      process, 0.0, t_print, 1e-3, [&](double t) { return Vec3(kSpeed * t, 0.0, 0.0); },
      [](double) { return 0.0; }, [](double) { return 1.0; }, [](double) { return kSpeed; });
  EXPECT_NEAR(process.account().emitted_mm3, command * t_print, 1e-9 * command * t_print);
  // the same line from rest: the lag withholds about Q tau at its start
  ExtrusionProcess from_rest(extrusion_settings(), 0.0);
  drive(
      from_rest, 0.0, t_print, 1e-3, [&](double t) { return Vec3(kSpeed * t, 0.0, 0.0); },
      [](double) { return 0.0; }, [](double) { return 1.0; }, [](double) { return kSpeed; });
  EXPECT_NEAR(command * t_print - from_rest.account().emitted_mm3, command * kTau,
              1e-3 * command * kTau);
  // 2 mm in (two lag lengths v tau): the settled start lays the full bead, the one from rest
  // is still about exp(-2) = 14 % thin
  const double bead_mm2 = kBeadWidth * kLayerHeight;
  EXPECT_NEAR(cross_section_mm2(process.field(), 2.0) / bead_mm2, 1.0, 1e-3);
  EXPECT_NEAR(cross_section_mm2(from_rest.field(), 2.0) / bead_mm2, 1.0 - std::exp(-2.0), 0.01);
}

// restart: a process that printed something, restarted, then given a line lays exactly what a
// new process lays for it (field cell for cell, account, lag state), aerosol and extrusion,
// with a few tiles' memory kept (the first print near the second) or freed (a print spread over
// more tiles than restart keeps)
TEST(Process, RestartedProcessDepositsLikeANewOne) {
  for (const ProcessType type : {ProcessType::aerosol, ProcessType::extrusion}) {
    for (const double first_length_mm : {3.0, 400.0}) {
      SCOPED_TRACE(std::string(process_type_name(type)) + " " + std::to_string(first_length_mm));
      DepositionSettings settings = extrusion_settings();
      settings.type = type;
      const auto print_line = [&](Process& process, const Vec3& from, const Vec3& to,
                                  double pause_fraction) {
        const double duration = (to - from).norm() / kSpeed;
        drive(
            process, 0.0, duration, 1e-3,
            [&](double t) { return Vec3(from + (to - from) * (t / duration)); },
            [&](double t) { return t < pause_fraction * duration ? 1.0 : 0.0; },
            [&](double t) { return t < pause_fraction * duration ? 1.0 : 0.0; },
            [](double) { return kSpeed; });
      };
      std::unique_ptr<Process> reused = make_process(settings);
      // the first print ends with the material off (extrusion: an oozing lag state)
      print_line(*reused, Vec3(-1, -1, 0), Vec3(-1 + first_length_mm, 2, 0), 0.97);
      ASSERT_GT(reused->account().landed_mm3, 0.0);  // (some steps still batched, not yet put down)
      reused->restart();
      EXPECT_EQ(reused->field().total_volume_mm3(), 0.0);
      EXPECT_EQ(reused->account().emitted_mm3, 0.0);
      EXPECT_EQ(reused->nozzle_flow_mm3_s(), make_process(settings)->nozzle_flow_mm3_s());
      std::unique_ptr<Process> fresh = make_process(settings);
      for (Process* process : {reused.get(), fresh.get()})
        print_line(*process, Vec3(0, 0, 0), Vec3(4, 1, 0), 1.0);
      EXPECT_EQ(test::max_abs_difference(reused->field(), fresh->field()), 0.0);
      EXPECT_EQ(reused->account().emitted_mm3, fresh->account().emitted_mm3);
      EXPECT_EQ(reused->account().landed_mm3, fresh->account().landed_mm3);
      EXPECT_EQ(reused->field().total_volume_mm3(), fresh->field().total_volume_mm3());
    }
  }
}

// One nozzle over two layers: the flow still lagging out of it when the steps move on to the
// next layer (a layer change's travel shorter than the lag's tail) goes on into that layer.
// The whole job then emits what was commanded, w h v for each second printed, exactly as one
// process driven through the same steps does; before, the tail was dropped (4.9 % of a
// layer at tau 0.2 s and a 0.14 s layer change).
TEST(Extrusion, TheLagsTailCrossesALayerChange) {
  DepositionSettings settings = extrusion_settings();
  settings.tau_s = 0.2;
  LayeredDeposit layered(settings, 0.0, 2);
  ExtrusionProcess single(settings, 0.0);
  // layer 0: a line along x for 1 s; 0.1 s of travel up to layer 1 with the flow off; layer
  // 1: the line back for 1 s; then 8 s at rest for the ooze (40 tau)
  const double dt_s = 1e-3;
  const auto phase = [&](double t_s) { return t_s < 1.0 ? 0 : t_s < 1.1 ? 1 : t_s < 2.1 ? 2 : 3; };
  const auto position = [&](double t_s) {
    if (t_s <= 1.0) return Vec3(kSpeed * t_s, 0.0, 0.2);
    if (t_s <= 1.1) return Vec3(kLength, 0.0, 0.2 + 2.0 * (t_s - 1.0));
    return Vec3(kLength - kSpeed * std::min(t_s - 1.1, 1.0), 0.0, 0.4);
  };
  for (int k = 0; k < 10100; ++k) {
    DepositionStep step;
    step.t0_s = k * dt_s;
    step.t1_s = (k + 1) * dt_s;
    step.p0_mm = position(step.t0_s);
    step.p1_mm = position(step.t1_s);
    const int now = phase(0.5 * (step.t0_s + step.t1_s));
    step.flow_command = now == 0 || now == 2 ? 1.0 : 0.0;
    step.desired_speed_mm_s = step.flow_command * kSpeed;
    layered.advance(step, now == 0 ? 0 : 1);
    single.advance(step);
  }
  layered.finish();
  const double commanded_mm3 = 2.0 * kBeadWidth * kLayerHeight * kSpeed;  // 3.2
  EXPECT_NEAR(layered.account().emitted_mm3, commanded_mm3, 1e-9 * commanded_mm3);
  EXPECT_NEAR(layered.account().emitted_mm3, single.account().emitted_mm3, 1e-12 * commanded_mm3);
  EXPECT_NEAR(layered.field().total_volume_mm3(), single.field().total_volume_mm3(),
              1e-9 * commanded_mm3);
  // layer 0 holds what left the nozzle while its line was printed: w h v (1 s - tau (1 -
  // exp(-1 s / tau))) of the lagging flow; layer 1 the rest
  const double layer0_mm3 =
      kBeadWidth * kLayerHeight * kSpeed * (1.0 - settings.tau_s * -std::expm1(-1.0 / 0.2));
  EXPECT_NEAR(layered.layer(0).account().emitted_mm3, layer0_mm3, 1e-9 * commanded_mm3);
  EXPECT_NEAR(layered.layer(1).account().emitted_mm3, commanded_mm3 - layer0_mm3,
              1e-9 * commanded_mm3);
}

}  // namespace
}  // namespace depotwin
