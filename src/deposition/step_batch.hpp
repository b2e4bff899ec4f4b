// Batched deposition: consecutive short steps put down together.
//
// At 1 ms steps a nozzle at a few mm/s moves ~0.03 sigma per step, yet each step's
// footprint touches a (2 x 5 sigma)^2 box of cells. StepBatch holds consecutive steps
// until their path would exceed batch_length (default 1 sigma) and then deposits them as
// one 4-point Gauss-Legendre quadrature in time over the whole batch:
//   D(x) = int rate(t) G(x - p(t)) dt  ~  sum_i w_i (T/2) rate(t_i) G(x - p(t_i)),
// with p(t) and rate(t) exactly what the steps describe (each step's straight chord at
// uniform speed and its own rate shape), node volumes scaled so the batch lands exactly
// its steps' volume. For smooth uniform motion the 4-point error is <= 5.9e-8 (L/sigma)^8
// of the batch's own peak, L its path length (Gauss-Legendre remainder
// (n!)^4 / ((2n+1) ((2n)!)^3) f^(2n) with max |He_8(x) exp(-x^2/2)| = 105; 3 points would
// give 7.4e-6 (L/sigma)^6): 4 nodes per sigma of path instead of 2 nodes per 1 ms step.
//
// Kinks break that smoothness. A rate kink (a shutter ramp starting or ending, a flow
// command change) splits the batch there first when its size (kink_size) exceeds
// kKinkTolerance. Any other (a corner) is caught a posteriori: the nodes' centroid, and
// their second moments about the steps' exact centroid c, must match the steps' exact
// sum V E[q] and sum V E[(q - c)(q - c)^T] to kMomentTolerance sigma (sigma^2) per unit
// volume. Expanding G around c, the deposit then differs from the steps' own by at most
// about (e^-1/2 + 1/2) kMomentTolerance of the batch's peak, plus third-order terms that
// are smaller still for L <= sigma. A batch that fails is split in two halves, each tried
// again. A single step is deposited on its own by GaussianFootprint::deposit_chord (the
// exact unbatched path), and so are steps longer than batch_length and steps of zero
// duration.
//
// Paired steps (pair_short_steps, for predictions that trade a little accuracy for speed): where
// a halved batch comes down to two steps, each no longer than kPairChordSigmas, that still
// fail (their moments, or a rate kink between them), both are deposited in one 4-node call, 2
// Gauss-Legendre nodes along each chord (its own volume and rate shape), instead of one
// deposit_chord each (3 nodes, one call each): an error of at most 6.9e-4 (L/sigma)^4 <= 5.6e-6 of
// the step's peak (gaussian_footprint.hpp) for half the calls, most of the work on curves (a
// blend's chords keep the moments apart).
//
// A batch also ends at a gap in time or position between steps, after kMaxSteps steps,
// and on flush(). Batch boundaries depend only on the steps (and on when flush() is
// called), so the same steps give the same field.
#pragma once

#include <cmath>
#include <vector>

#include "deposition/gaussian_footprint.hpp"
#include "deposition/thickness_field.hpp"

namespace depotwin {

// Relative deposition rate within one step, u in [0, 1] the step fraction:
//   rate(u) = constant + slope u + decaying exp(-decay u)
// (aerosol: the shutter's linear opening; extrusion: the flow lag's exponential).
struct StepRate {
  double constant = 1.0;
  double slope = 0.0;
  double decaying = 0.0;
  double decay = 0.0;
  double at(double u) const {
    double rate = constant + slope * u;
    if (decaying != 0.0) rate += decaying * std::exp(-decay * u);
    return rate;
  }
  // d rate / du
  double derivative(double u) const {
    double derivative = slope;
    if (decaying != 0.0) derivative -= decaying * decay * std::exp(-decay * u);
    return derivative;
  }
};

// One step handed to StepBatch (substrate frame, mm; z ignored).
struct BatchStep {
  double t0_s = 0.0;
  double t1_s = 0.0;
  double x0_mm = 0.0;
  double y0_mm = 0.0;
  double x1_mm = 0.0;
  double y1_mm = 0.0;
  double volume_mm3 = 0.0;  // exactly what lands during the step
  StepRate rate;            // its shape within the step (scale does not matter)
};

class StepBatch {
 public:
  static constexpr int kMaxSteps = 128;
  // centroid and second moments about it must match to this many sigma (sigma^2) per
  // unit volume
  static constexpr double kMomentTolerance = 3e-5;
  // steps join a batch across gaps in time (per step duration) and position (per sigma)
  // up to this
  static constexpr double kJoinTolerance = 1e-6;
  // a batch is split at its worst kink when that kink's size exceeds this (see kink_size)
  static constexpr double kKinkTolerance = 1e-3;

  // paired steps are each at most this long (in sigmas)
  static constexpr double kPairChordSigmas = 0.3;

  // batch_length_mm <= 0: every step is deposited on its own
  StepBatch(double sigma_mm, double batch_length_mm);

  // deposit the last two steps of a failed batch as a pair (see above); off by default
  void pair_short_steps(bool on) { pair_short_steps_ = on; }

  // take one step (time order); deposits whatever is due into `field`
  void add(GaussianFootprint& footprint, ThicknessField& field, const BatchStep& step);
  // deposit the steps held so far
  void flush(GaussianFootprint& footprint, ThicknessField& field);
  // forget the steps held so far (nothing is deposited)
  void discard() {
    count_ = 0;
    length_mm_ = duration_s_ = 0.0;
  }

  int pending_steps() const { return count_; }
  double batch_length_mm() const { return batch_length_mm_; }

  // what happened so far (for benchmarks and tests)
  struct Stats {
    long steps = 0;         // steps taken with material
    long quadratures = 0;   // batches (or halves) deposited as one 4-node quadrature
    long single_steps = 0;  // steps deposited on their own
    long paired_steps = 0;  // steps deposited in pairs (pair_short_steps)
    long splits = 0;        // batches split at a rate kink or halved (moments disagreed)
  };
  const Stats& stats() const { return stats_; }

 private:
  struct Pending {
    BatchStep step;
    double t_begin_s = 0.0;  // start, relative to the batch's first step
    double duration_s = 0.0;
    double rate_integral = 0.0;  // int_0^1 rate(u) du (<= 0: treated as uniform)
    double mean_u = 0.5;         // E[u] and E[u^2] under the rate
    double mean_u2 = 1.0 / 3.0;
    // volume rate (mm^3/s) and its time derivative (mm^3/s^2) at the step's start and end
    double flow_begin = 0.0, flow_end = 0.0;
    double flow_slope_begin = 0.0, flow_slope_end = 0.0;
  };

  // the size of the rate kink at boundary k (between steps k-1 and k) of [begin, end):
  // the jump in volume rate times T, plus the jump in its slope beyond what the
  // neighbouring boundaries show (a smooth rate's steady change is no kink) times T^2,
  // both per mean rate, T the range's duration
  double kink_size(int begin, int end, int k, double duration_s, double mean_flow) const;

  // deposit pending steps [begin, end): one quadrature if the moments agree, else halves
  void deposit_range(GaussianFootprint& footprint, ThicknessField& field, int begin, int end);
  static void deposit_single(GaussianFootprint& footprint, ThicknessField& field,
                             const BatchStep& step);
  // pending steps [begin, begin + 2) as a pair, when both are short enough (else false)
  bool deposit_pair(GaussianFootprint& footprint, ThicknessField& field, int begin);

  double sigma_mm_;
  double batch_length_mm_;
  bool pair_short_steps_ = false;
  std::vector<Pending> pending_;  // kMaxSteps, allocated once
  int count_ = 0;
  double length_mm_ = 0.0;   // path length of the pending steps
  double duration_s_ = 0.0;  // their total duration
  Stats stats_;
};

}  // namespace depotwin
