// Aerosol process: closed-form line thickness, exact along-chord integration (timestep
// independence), shutter capture and material conservation.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"
#include "deposition/deposition_metrics.hpp"
#include "deposition/process.hpp"
#include "deposition_test_util.hpp"

namespace depotwin {
namespace {

using test::drive;

constexpr double kSigma = 0.1;
constexpr double kCell = 0.025;  // sigma / 4
const double kSqrt2Pi = std::sqrt(2.0 * kPi);

DepositionSettings aerosol_settings() {
  DepositionSettings settings;
  settings.type = ProcessType::aerosol;
  settings.sigma_mm = kSigma;
  return settings;
}

double normal_cdf(double z) {
  return 0.5 * std::erfc(-z / std::sqrt(2.0));
}

auto always_open = [](double) { return 1.0; };
auto no_command = [](double) { return 0.0; };

// the default flow makes a 3 mm/s line peak at 2 um: Q = peak v sigma sqrt(2 pi)
TEST(Aerosol, DefaultFlowGivesTwoMicronPeakAtThreeMmPerSecond) {
  const DepositionSettings settings = aerosol_settings();
  EXPECT_NEAR(settings.aerosol_flow_mm3_s(), 0.002 * 3.0 * 0.1 * kSqrt2Pi, 1e-15);
  EXPECT_DOUBLE_EQ(settings.resolved_line_width_mm(), 0.4);
  EXPECT_DOUBLE_EQ(settings.default_cell_mm(), 0.025);
}

// steady line: peak = Q / (v sigma sqrt(2 pi)), profile along the line = Phi(s) - Phi(s - l)
TEST(Aerosol, StraightLinePeakAndProfileMatchClosedForm) {
  const double speed = 3.0, length = 9.0;  // 3 s: a whole number of steps
  AerosolProcess process(aerosol_settings(), kCell);
  const double flow = process.nozzle_flow_mm3_s();
  drive(
      process, 0.0, length / speed, 1e-3, [&](double t) { return Vec3(speed * t, 0.0, 0.0); },
      always_open, no_command, no_command);

  const double peak_mm = flow / (speed * kSigma * kSqrt2Pi);
  EXPECT_NEAR(peak_mm, 0.002, 1e-12);
  // on-lattice centreline: cell values are samples of the continuous profile
  EXPECT_NEAR(process.field().thickness_mm_at(4.5, 0.0) / peak_mm, 1.0, 1e-5);
  // the cross-section is Gaussian: one sigma off the centreline
  EXPECT_NEAR(process.field().thickness_mm_at(4.5, kSigma) / peak_mm, std::exp(-0.5), 1e-5);

  // line_cv against the closed-form profile sampled at the same points
  const Toolpath toolpath = test::straight_toolpath(0.0, 0.0, length, 0.0, speed);
  const DepositionMetrics metrics =
      evaluate_deposition(process.field(), toolpath, process.line_width_mm(), process.account());
  const double r = 0.2;
  double sum = 0.0, squares = 0.0;
  int n = 0;
  for (int k = 0; r + k * kCell <= length - r + 1e-12; ++k, ++n) {
    const double s = r + k * kCell;
    const double v = normal_cdf(s / kSigma) - normal_cdf((s - length) / kSigma);
    sum += v;
    squares += v * v;
  }
  const double mean = sum / n;
  const double expected_line_cv = std::sqrt(squares / n - mean * mean) / mean;
  EXPECT_EQ(metrics.thickness.line_samples, static_cast<size_t>(n));
  EXPECT_LT(metrics.thickness.line_cv, 0.01);
  EXPECT_NEAR(metrics.thickness.line_cv, expected_line_cv, 1e-5);
  // max over the stats region is the centreline peak
  EXPECT_NEAR(metrics.thickness.max_rel * metrics.thickness.mean_um / 1000.0 / peak_mm, 1.0, 1e-4);
}

// an off-lattice line: bilinear sampling on the centreline is within 1% of the peak
TEST(Aerosol, OffLatticeLinePeakWithinOnePercent) {
  const double speed = 3.0, y_line = 0.3 * kCell + 0.0123;
  AerosolProcess process(aerosol_settings(), kCell);
  drive(
      process, 0.0, 2.0, 1e-3, [&](double t) { return Vec3(0.37 + speed * t, y_line, 0.0); },
      always_open, no_command, no_command);
  const double peak_mm = process.nozzle_flow_mm3_s() / (speed * kSigma * kSqrt2Pi);
  EXPECT_NEAR(process.field().thickness_mm_at(3.37, y_line) / peak_mm, 1.0, 0.01);
}

// one long step against the closed form D = V phi(b) [Phi(a/s) - Phi((a-L)/s)] / L
TEST(Aerosol, SingleStepMatchesErfClosedForm) {
  AerosolProcess process(aerosol_settings(), kCell);
  DepositionStep step;
  step.t0_s = 0.0;
  step.t1_s = 0.02;
  step.p0_mm = Vec3(0.013, -0.021, 0.0);
  step.p1_mm = Vec3(0.013 + 0.16, -0.021 + 0.12, 0.0);  // L = 0.2 mm = 2 sigma, diagonal
  step.open0 = step.open1 = 1.0;
  process.advance(step);

  const double volume = process.nozzle_flow_mm3_s() * 0.02;
  const double length = 0.2, ex = 0.8, ey = 0.6;
  double worst = 0.0, peak = 0.0;
  for (int iy = -12; iy <= 16; ++iy) {
    for (int ix = -12; ix <= 20; ++ix) {
      const double x = ix * kCell - step.p0_mm.x(), y = iy * kCell - step.p0_mm.y();
      const double a = x * ex + y * ey, b = -x * ey + y * ex;
      const double expected = volume * std::exp(-b * b / (2 * kSigma * kSigma)) /
                              (kSigma * kSqrt2Pi) *
                              (normal_cdf(a / kSigma) - normal_cdf((a - length) / kSigma)) / length;
      worst = std::max(worst, std::abs(process.field().cell_thickness_mm(ix, iy) - expected));
      peak = std::max(peak, expected);
    }
  }
  RecordProperty("max_rel_error_vs_erf", std::to_string(worst / peak));
  EXPECT_LT(worst / peak, 1e-5) << "worst " << worst << " peak " << peak;
}

// the same curved, accelerating motion with shutter moves at 1 ms and 0.1 ms steps
TEST(Aerosol, MapIndependentOfTimestepOnCurvedMotion) {
  auto position = [](double t) {
    const double angle = 0.5 * t + 0.4 * t * t;  // accelerating along a 3 mm circle
    return Vec3(3.0 * std::cos(angle), 3.0 * std::sin(angle), 0.0);
  };
  auto open = [](double t) {  // opens over 20 ms at 0.1003 s, closes over 20 ms at 0.9007 s
    const double opening = std::min(1.0, std::max(0.0, (t - 0.1003) / 0.02));
    const double closing = std::min(1.0, std::max(0.0, (t - 0.9007) / 0.02));
    return opening - closing;
  };
  AerosolProcess coarse(aerosol_settings(), kCell);
  AerosolProcess fine(aerosol_settings(), kCell);
  drive(coarse, 0.0, 1.2, 1e-3, position, open, no_command, no_command);
  drive(fine, 0.0, 1.2, 1e-4, position, open, no_command, no_command);
  const double relative =
      test::max_abs_difference(coarse.field(), fine.field()) / test::max_value(fine.field());
  RecordProperty("max_rel_diff_1ms_vs_0.1ms", std::to_string(relative));
  EXPECT_LT(relative, 1e-3);
  EXPECT_NEAR(coarse.account().landed_mm3, fine.account().landed_mm3,
              1e-4 * fine.account().landed_mm3);
}

// straight motion and a shutter ramp that both steppings represent exactly: 10 ms steps
// must reproduce 0.1 ms steps to quadrature accuracy (a per-step mean open fraction or a
// single sample per step would not)
TEST(Aerosol, LongStepsAreExactAlongTheChord) {
  auto position = [](double t) { return Vec3(0.6 * 3.0 * t, 0.8 * 3.0 * t, 0.0); };
  auto open = [](double t) {
    const double opening = std::min(1.0, std::max(0.0, (t - 0.1) / 0.02));
    const double closing = std::min(1.0, std::max(0.0, (t - 0.3) / 0.02));
    return opening - closing;
  };
  AerosolProcess coarse(aerosol_settings(), kCell);
  AerosolProcess fine(aerosol_settings(), kCell);
  drive(coarse, 0.0, 0.4, 1e-2, position, open, no_command, no_command);
  drive(fine, 0.0, 0.4, 1e-4, position, open, no_command, no_command);
  const double relative =
      test::max_abs_difference(coarse.field(), fine.field()) / test::max_value(fine.field());
  RecordProperty("max_rel_diff_10ms_vs_0.1ms", std::to_string(relative * 1e9) + "e-9");
  EXPECT_LT(relative, 1e-6);
}

// a closed shutter captures Q dt exactly and lands nothing
TEST(Aerosol, ClosedShutterCapturesEverything) {
  AerosolProcess process(aerosol_settings(), kCell);
  auto closed = [](double) { return 0.0; };
  drive(
      process, 0.0, 0.5, 1e-3, [](double t) { return Vec3(3.0 * t, 0.0, 0.0); }, closed, no_command,
      no_command);
  const double q = process.nozzle_flow_mm3_s();
  EXPECT_NEAR(process.account().captured_mm3, q * 0.5, 1e-12 * q);
  EXPECT_NEAR(process.account().emitted_mm3, q * 0.5, 1e-12 * q);
  EXPECT_EQ(process.account().landed_mm3, 0.0);
  EXPECT_NEAR(process.account().closed_time_s, 0.5, 1e-12);
  EXPECT_EQ(process.field().allocated_tiles(), 0u);
}

// emitted = on_target + overspray + captured, with the captured part in closed form
TEST(Aerosol, MaterialIsConservedThroughShutterTransitions) {
  const double speed = 3.0;
  // two print paths along x at y = 0 and y = 1, joined by a closed-shutter move
  auto position = [&](double t) {
    if (t < 2.0) return Vec3(speed * t, 0.0, 0.0);
    if (t < 2.5) return Vec3(6.0, 2.0 * (t - 2.0), 0.0);
    return Vec3(6.0 - speed * (t - 2.5), 1.0, 0.0);
  };
  // flap: opens 0.00-0.02, closes 1.98-2.00, opens 2.50-2.52, closes 4.48-4.50 (step-aligned)
  auto open = [](double t) {
    auto ramp = [t](double t0) { return std::min(1.0, std::max(0.0, (t - t0) / 0.02)); };
    return ramp(0.0) - ramp(1.98) + ramp(2.5) - ramp(4.48);
  };
  AerosolProcess process(aerosol_settings(), kCell);
  drive(process, 0.0, 5.0, 1e-3, position, open, no_command, no_command);

  Toolpath toolpath = test::straight_toolpath(0.0, 0.0, 6.0, 0.0, speed);
  toolpath.paths.push_back(test::straight_toolpath(6.0, 1.0, 0.0, 1.0, speed).paths[0]);
  const DepositionMetrics metrics =
      evaluate_deposition(process.field(), toolpath, process.line_width_mm(), process.account());

  const double q = process.nozzle_flow_mm3_s();
  const double emitted = q * 5.0;
  // open time: two 2 s windows, each losing half of its two 20 ms ramps
  const double closed_time = 5.0 - 2.0 * (2.0 - 0.02);
  const MaterialSplit& m = metrics.material;
  EXPECT_NEAR(m.emitted_mm3, emitted, 1e-12 * emitted);
  EXPECT_NEAR(m.captured_mm3, q * closed_time, 1e-9 * emitted);
  EXPECT_NEAR(m.closed_time_s, closed_time, 1e-9);
  EXPECT_NEAR(m.on_target_mm3 + m.overspray_mm3 + m.captured_mm3, emitted, 1e-6 * emitted);
  EXPECT_NEAR(process.field().total_volume_mm3(), process.account().landed_mm3, 1e-12 * emitted);
  EXPECT_GT(m.overspray_mm3, 0.0);  // the Gaussian tail beyond +-2 sigma

  // the waste, from an account of its own: the material that landed farther than half a line
  // width from both centrelines (a cell the band's edge crosses by the share of the field read
  // at its 8 x 8 sub-points that lies beyond),
  // summed over the deposit's cells themselves, plus Q x the closed time above, over Q x 5 s
  const double r = 0.5 * process.line_width_mm();
  const double area = kCell * kCell;
  const FieldBounds bounds = process.field().bounds();
  ASSERT_FALSE(bounds.empty);
  double outside_mm3 = 0.0, landed_mm3 = 0.0;
  for (long iy = std::lround(bounds.y_lo_mm / kCell); iy <= std::lround(bounds.y_hi_mm / kCell);
       ++iy)
    for (long ix = std::lround(bounds.x_lo_mm / kCell); ix <= std::lround(bounds.x_hi_mm / kCell);
         ++ix) {
      const double volume = process.field().cell_thickness_mm(ix, iy) * area;
      // its sub-points, each by the field read there; the share of what they read outside
      int outside = 0;
      double read_outside = 0.0, read_all = 0.0;
      for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i) {
          const double x = (ix + (i - 3.5) / 8.0) * kCell, y = (iy + (j - 3.5) / 8.0) * kCell;
          // distance to the segments (0, 0)-(6, 0) and (0, 1)-(6, 1)
          const double along = std::max(0.0, std::max(x - 6.0, -x));
          const double d = std::min(std::hypot(along, y), std::hypot(along, y - 1.0));
          const double t = process.field().thickness_mm_at(x, y);
          read_all += t;
          if (d > r * (1.0 + 1e-9)) {
            ++outside;
            read_outside += t;
          }
        }
      landed_mm3 += volume;
      if (outside == 64)
        outside_mm3 += volume;
      else if (outside > 0 && volume != 0.0)
        outside_mm3 += volume * (read_all > 0.0 ? read_outside / read_all : outside / 64.0);
    }
  EXPECT_NEAR(landed_mm3, emitted - q * closed_time, 1e-6 * emitted);
  // the Gaussian tails on both sides of 12 mm of line beyond r = 2 sigma, erfc(r / (sigma
  // sqrt 2)) = 4.6 % (the line's ends add little). Before each cell was counted by its
  // centre alone, the rows exactly r away whole: the band ended half a cell beyond r (3.4 %)
  EXPECT_NEAR(outside_mm3 / landed_mm3, std::erfc(r / (kSigma * std::sqrt(2.0))), 0.002);
  EXPECT_NEAR(m.fraction, (outside_mm3 + q * closed_time) / emitted, 1e-9);
  EXPECT_NEAR(m.overspray_mm3, outside_mm3, 1e-9 * emitted);
}

TEST(Aerosol, BadSettingsAreInputErrors) {
  DepositionSettings settings = aerosol_settings();
  settings.sigma_mm = -1.0;
  EXPECT_THROW(make_process(settings), InputError);
  settings = aerosol_settings();
  EXPECT_THROW(make_process(settings, 0.5), InputError);  // cell coarser than sigma
  EXPECT_THROW(process_type_from_name("spray"), InputError);
}

TEST(Aerosol, NonFiniteStepIsInternalError) {
  AerosolProcess process(aerosol_settings(), kCell);
  DepositionStep step;
  step.t1_s = 1e-3;
  step.p1_mm = Vec3(std::nan(""), 0.0, 0.0);
  EXPECT_THROW(process.advance(step), InternalError);
}

}  // namespace
}  // namespace depotwin
