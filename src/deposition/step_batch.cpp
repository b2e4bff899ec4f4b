#include "deposition/step_batch.hpp"

#include <algorithm>
#include <cmath>

namespace depotwin {

namespace {

// 3-point Gauss-Legendre nodes on [-1, 1] and weights (a step's rate moments)
constexpr double kNodes3[3] = {-0.77459666924148337704, 0.0, 0.77459666924148337704};
constexpr double kWeights3[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
// 4-point Gauss-Legendre nodes and weights (a batch's quadrature)
constexpr int kBatchNodes = 4;
constexpr double kNodes4[kBatchNodes] = {-0.86113631159405257522, -0.33998104358485626480,
                                         0.33998104358485626480, 0.86113631159405257522};
constexpr double kWeights4[kBatchNodes] = {0.34785484513745385737, 0.65214515486254614263,
                                           0.65214515486254614263, 0.34785484513745385737};

}  // namespace

StepBatch::StepBatch(double sigma_mm, double batch_length_mm)
    : sigma_mm_(sigma_mm),
      batch_length_mm_(std::max(0.0, batch_length_mm)),
      pending_(batch_length_mm > 0.0 ? kMaxSteps : 0) {}

void StepBatch::deposit_single(GaussianFootprint& footprint, ThicknessField& field,
                               const BatchStep& step) {
  const StepRate& rate = step.rate;
  footprint.deposit_chord(field, step.x0_mm, step.y0_mm, step.x1_mm, step.y1_mm, step.volume_mm3,
                          [&rate](double u) { return rate.at(u); });
}

bool StepBatch::deposit_pair(GaussianFootprint& footprint, ThicknessField& field, int begin) {
  // 2-point Gauss-Legendre nodes on [0, 1] (weights equal)
  constexpr double kPairNodes[2] = {0.5 - 0.28867513459481288225, 0.5 + 0.28867513459481288225};
  const double longest_mm = kPairChordSigmas * sigma_mm_;
  FootprintNode nodes[4];
  for (int j = 0; j < 2; ++j) {
    const BatchStep& step = pending_[begin + j].step;
    const double dx = step.x1_mm - step.x0_mm, dy = step.y1_mm - step.y0_mm;
    if (dx * dx + dy * dy > longest_mm * longest_mm) return false;
    // the step's volume split by its rate at the two nodes (uniform when it has no shape)
    double rates[2] = {step.rate.at(kPairNodes[0]), step.rate.at(kPairNodes[1])};
    if (!(rates[0] + rates[1] > 0.0)) rates[0] = rates[1] = 1.0;
    const double volume_per_rate = step.volume_mm3 / (rates[0] + rates[1]);
    for (int k = 0; k < 2; ++k)
      nodes[2 * j + k] = FootprintNode{step.x0_mm + kPairNodes[k] * dx,
                                       step.y0_mm + kPairNodes[k] * dy, rates[k] * volume_per_rate};
  }
  footprint.deposit_nodes(field, nodes, 4);
  stats_.paired_steps += 2;
  return true;
}

void StepBatch::add(GaussianFootprint& footprint, ThicknessField& field, const BatchStep& step) {
  // nothing lands: the run of steps with material ends here
  if (!(step.volume_mm3 > 0.0)) {
    flush(footprint, field);
    return;
  }
  ++stats_.steps;
  // (sqrt, not hypot: millimetre chords cannot overflow, and hypot costs ~20 ns)
  const double chord_x = step.x1_mm - step.x0_mm, chord_y = step.y1_mm - step.y0_mm;
  const double chord_mm = std::sqrt(chord_x * chord_x + chord_y * chord_y);
  const double duration_s = step.t1_s - step.t0_s;

  // unbatched, long or instantaneous steps: on their own, exactly as deposit_chord does
  if (batch_length_mm_ <= 0.0 || !(duration_s > 0.0) || chord_mm > batch_length_mm_) {
    flush(footprint, field);
    deposit_single(footprint, field, step);
    ++stats_.single_steps;
    return;
  }

  // a batch is a gap-free run of steps no longer than batch_length (gaps below 1e-6 of the
  // step or of sigma are rounding: t0 = k dt against t1 = (k - 1) dt + dt)
  if (count_ > 0) {
    const BatchStep& last = pending_[count_ - 1].step;
    const double gap_x = step.x0_mm - last.x1_mm, gap_y = step.y0_mm - last.y1_mm;
    const double join_mm = kJoinTolerance * sigma_mm_;
    const bool joined = std::abs(step.t0_s - last.t1_s) <= kJoinTolerance * duration_s &&
                        gap_x * gap_x + gap_y * gap_y <= join_mm * join_mm;
    if (!joined || count_ == kMaxSteps || length_mm_ + chord_mm > batch_length_mm_)
      flush(footprint, field);
  }

  // the rate's integral and its first two moments in u (3-point rule: exact for a linear rate)
  Pending& p = pending_[count_++];
  p.step = step;
  p.t_begin_s = duration_s_;
  p.duration_s = duration_s;
  double integral = 0.0, first = 0.0, second = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double u = 0.5 * (1.0 + kNodes3[i]);
    const double weighted = 0.5 * kWeights3[i] * step.rate.at(u);
    integral += weighted;
    first += weighted * u;
    second += weighted * u * u;
  }
  if (integral > 0.0) {
    p.rate_integral = integral;
    p.mean_u = first / integral;
    p.mean_u2 = second / integral;
  } else {  // no shape: uniform, as deposit_chord treats it
    p.rate_integral = 0.0;
    p.mean_u = 0.5;
    p.mean_u2 = 1.0 / 3.0;
  }
  // the volume rate V rate(u) / (int rate du * duration) and its time derivative at both ends
  const double flow_scale =
      step.volume_mm3 / ((p.rate_integral > 0.0 ? p.rate_integral : 1.0) * duration_s);
  const bool shaped = p.rate_integral > 0.0;
  p.flow_begin = flow_scale * (shaped ? step.rate.at(0.0) : 1.0);
  p.flow_end = flow_scale * (shaped ? step.rate.at(1.0) : 1.0);
  p.flow_slope_begin = shaped ? flow_scale * step.rate.derivative(0.0) / duration_s : 0.0;
  p.flow_slope_end = shaped ? flow_scale * step.rate.derivative(1.0) / duration_s : 0.0;
  length_mm_ += chord_mm;
  duration_s_ += duration_s;
}

double StepBatch::kink_size(int begin, int end, int k, double duration_s, double mean_flow) const {
  auto slope_jump = [this](int boundary) {
    return pending_[boundary].flow_slope_begin - pending_[boundary - 1].flow_slope_end;
  };
  // the slope's jump against the mean of the neighbouring boundaries' (one-sided at the ends)
  const double jump = slope_jump(k);
  double expected = 0.0;
  const bool has_before = k - 1 > begin, has_after = k + 1 < end;
  if (has_before && has_after)
    expected = 0.5 * (slope_jump(k - 1) + slope_jump(k + 1));
  else if (has_before)
    expected = slope_jump(k - 1);
  else if (has_after)
    expected = slope_jump(k + 1);
  const double value_jump = std::abs(pending_[k].flow_begin - pending_[k - 1].flow_end);
  return (value_jump * duration_s + std::abs(jump - expected) * duration_s * duration_s) /
         mean_flow;
}

void StepBatch::flush(GaussianFootprint& footprint, ThicknessField& field) {
  if (count_ == 0) return;
  deposit_range(footprint, field, 0, count_);
  count_ = 0;
  length_mm_ = 0.0;
  duration_s_ = 0.0;
}

void StepBatch::deposit_range(GaussianFootprint& footprint, ThicknessField& field, int begin,
                              int end) {
  if (end - begin == 1) {
    deposit_single(footprint, field, pending_[begin].step);
    ++stats_.single_steps;
    return;
  }
  // a rate kink: split there, so each side is smooth for the quadrature (the range's volume
  // first: the kinks are sized by its mean flow)
  double volume = 0.0;
  for (int k = begin; k < end; ++k) volume += pending_[k].step.volume_mm3;
  const double t_lo = pending_[begin].t_begin_s;
  const double t_hi = pending_[end - 1].t_begin_s + pending_[end - 1].duration_s;
  int worst_kink = -1;
  double worst_size = kKinkTolerance;
  for (int boundary = begin + 1; boundary < end; ++boundary) {
    const double size = kink_size(begin, end, boundary, t_hi - t_lo, volume / (t_hi - t_lo));
    if (size > worst_size) {
      worst_size = size;
      worst_kink = boundary;
    }
  }
  if (worst_kink > 0) {
    ++stats_.splits;
    if (pair_short_steps_ && end - begin == 2 && deposit_pair(footprint, field, begin)) return;
    deposit_range(footprint, field, begin, worst_kink);
    deposit_range(footprint, field, worst_kink, end);
    return;
  }

  // the steps' exact first and second moments about the range's start (uniform motion along
  // each chord: q = a + u d, with E[u], E[u^2] under its rate)
  const double origin_x = pending_[begin].step.x0_mm;
  const double origin_y = pending_[begin].step.y0_mm;
  double m1x = 0.0, m1y = 0.0, mxx = 0.0, mxy = 0.0, myy = 0.0;
  for (int k = begin; k < end; ++k) {
    const Pending& p = pending_[k];
    const double v = p.step.volume_mm3;
    const double ax = p.step.x0_mm - origin_x, ay = p.step.y0_mm - origin_y;
    const double dx = p.step.x1_mm - p.step.x0_mm, dy = p.step.y1_mm - p.step.y0_mm;
    m1x += v * (ax + dx * p.mean_u);
    m1y += v * (ay + dy * p.mean_u);
    mxx += v * (ax * ax + 2.0 * ax * dx * p.mean_u + dx * dx * p.mean_u2);
    mxy += v * (ax * ay + (ax * dy + dx * ay) * p.mean_u + dx * dy * p.mean_u2);
    myy += v * (ay * ay + 2.0 * ay * dy * p.mean_u + dy * dy * p.mean_u2);
  }
  // centroid, and the second moments about it
  const double cx = m1x / volume, cy = m1y / volume;
  const double cxx = mxx - volume * cx * cx;
  const double cxy = mxy - volume * cx * cy;
  const double cyy = myy - volume * cy * cy;

  // 4 Gauss-Legendre nodes in time over the range, on the steps' chords, weighted by the
  // volume rate there (each step: V rate(u) / (int rate du * duration))
  const double half_s = 0.5 * (t_hi - t_lo);
  FootprintNode nodes[kBatchNodes];
  double node_sum = 0.0;
  int k = begin;
  for (int i = 0; i < kBatchNodes; ++i) {
    const double t = t_lo + half_s * (1.0 + kNodes4[i]);
    while (k < end - 1 && t >= pending_[k].t_begin_s + pending_[k].duration_s) ++k;
    const Pending& p = pending_[k];
    const double u = std::min(1.0, std::max(0.0, (t - p.t_begin_s) / p.duration_s));
    const double shape = p.rate_integral > 0.0 ? p.step.rate.at(u) / p.rate_integral : 1.0;
    const double volume_rate = p.step.volume_mm3 * std::max(0.0, shape) / p.duration_s;
    nodes[i].x_mm = p.step.x0_mm + u * (p.step.x1_mm - p.step.x0_mm);
    nodes[i].y_mm = p.step.y0_mm + u * (p.step.y1_mm - p.step.y0_mm);
    nodes[i].volume_mm3 = kWeights4[i] * half_s * volume_rate;
    node_sum += nodes[i].volume_mm3;
  }

  // node volumes add up to exactly the steps' volume; then their centroid and their
  // spread about the steps' centroid must match the steps'
  bool agree = node_sum > 0.0;
  if (agree) {
    const double scale = volume / node_sum;
    double n1x = 0.0, n1y = 0.0, nxx = 0.0, nxy = 0.0, nyy = 0.0;
    for (FootprintNode& node : nodes) {
      node.volume_mm3 *= scale;
      const double qx = node.x_mm - origin_x, qy = node.y_mm - origin_y;
      const double ex = qx - cx, ey = qy - cy;
      n1x += node.volume_mm3 * qx;
      n1y += node.volume_mm3 * qy;
      nxx += node.volume_mm3 * ex * ex;
      nxy += node.volume_mm3 * ex * ey;
      nyy += node.volume_mm3 * ey * ey;
    }
    const double centroid_tol = kMomentTolerance * sigma_mm_ * volume;
    const double spread_tol = kMomentTolerance * sigma_mm_ * sigma_mm_ * volume;
    agree = std::abs(n1x - m1x) <= centroid_tol && std::abs(n1y - m1y) <= centroid_tol &&
            std::abs(nxx - cxx) <= spread_tol && std::abs(nxy - cxy) <= spread_tol &&
            std::abs(nyy - cyy) <= spread_tol;
  }
  if (agree) {
    footprint.deposit_nodes(field, nodes, kBatchNodes);
    ++stats_.quadratures;
    return;
  }
  ++stats_.splits;
  if (pair_short_steps_ && end - begin == 2 && deposit_pair(footprint, field, begin)) return;
  const int middle = begin + (end - begin) / 2;
  deposit_range(footprint, field, begin, middle);
  deposit_range(footprint, field, middle, end);
}

}  // namespace depotwin
