// The deposition kernel: a 2-D isotropic Gaussian footprint swept along one step's chord.
//
// Within a step the nozzle moves on the straight chord p0 -> p1 at uniform speed, and the
// deposition rate varies smoothly with the step fraction u in [0, 1] (linear shutter
// opening, exponential flow lag). The deposit is
//   D(x) = V * int_0^1 rate(u) G_sigma(x - p0 - u (p1 - p0)) du / int_0^1 rate(u) du.
// The u-integral is done by Gauss-Legendre quadrature on sub-chords (not by sampling the
// step once), so the map does not depend on the timestep:
//   chord L <= 1e-4 sigma: one node (midpoint), error <= (L/sigma)^2/24 < 5e-10 of the peak;
//   L <= 0.05 sigma: 2 nodes, error <= 6.9e-4 (L/sigma)^4 < 5e-9;
//   otherwise sub-chords of <= 0.3 sigma with 3 nodes each, error <= 7.4e-6 (0.3)^6 < 6e-9
// (Gauss-Legendre remainder (n!)^4 / ((2n+1) ((2n)!)^3) f^(2n), with
// max |He_2n(x) exp(-x^2/2)| = 3 and 15 for 2n = 4, 6). Each node's footprint is
// separable, G(x, y) = g(x) g(y), so a node costs two short factor vectors and the cells
// take one multiply-add per node.
//
// Truncation: each node's factors fade to zero across truncation_sigmas +- 0.25 sigma from
// the node (a quintic smoothstep; with a hard cut, cells at the edge would pop in and out
// by exp(-12.5) = 4e-6 of the peak factor as the node moves, visible whenever two
// quadratures of the same path are compared). The truncation is per node, so a node's
// footprint does not depend on which other nodes share its box: batched and unbatched
// deposits truncate alike.
// Conservation: each node's factors are normalised to sum to one over its own truncated
// square, and node volumes are scaled to add up to the step's exact volume V. The cells
// therefore receive exactly V (to rounding), whatever the truncation radius and cell size.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "deposition/thickness_field.hpp"

namespace depotwin {

// One quadrature node: footprint centre (mm) and the volume it deposits (mm^3).
struct FootprintNode {
  double x_mm = 0.0;
  double y_mm = 0.0;
  double volume_mm3 = 0.0;
};

class GaussianFootprint {
 public:
  // sigma and cell in mm; cells farther than truncation_sigmas * sigma from a node (along
  // x or y) receive nothing from it (that tail is renormalised onto its square).
  // max_span_sigmas: the widest node group deposit_nodes must take (at least the 0.3 sigma
  // sub-chords of deposit_chord); it sizes the reusable factor vectors.
  GaussianFootprint(double sigma_mm, double cell_mm, double truncation_sigmas,
                    double max_span_sigmas = 0.3);

  double sigma_mm() const { return sigma_mm_; }

  // deposit volume_mm3 along the chord (x0, y0) -> (x1, y1); rate(u) >= 0 is the relative
  // deposition rate at step fraction u (its scale does not matter)
  template <class RateFn>
  void deposit_chord(ThicknessField& field, double x0_mm, double y0_mm, double x1_mm, double y1_mm,
                     double volume_mm3, const RateFn& rate);

  // deposit 1..4 nodes over their common box (the separable rank-n update); the nodes
  // must lie within max_span_sigmas of each other
  void deposit_nodes(ThicknessField& field, const FootprintNode* nodes, int count);

 private:
  // for each of `count` centres c_k: g_k[0..n) = exp(-(x_i - c_k)^2 / 2 sigma^2),
  // x_i = (i0 + i) h, within reach of c_k (tapered, 0 beyond), normalised to sum scale_k;
  // g_k starts at g + k * capacity_. The recurrences of all centres run side by side
  // (independent chains pipeline well).
  void fill_factors(const double* centres_mm, const double* scales, int count, int i0, int n,
                    double* g) const;

  double sigma_mm_;
  double cell_mm_;
  double reach_mm_;                // outer truncation radius (end of the taper)
  double taper_start_mm_;          // the footprint fades from here to reach_mm_
  double step_factor_;             // exp(-h^2 / sigma^2), ratio of successive ratios
  double inv_two_var_;             // 1 / (2 sigma^2)
  int capacity_ = 0;               // longest factor vector one sub-chord can need
  std::vector<double> x_factors_;  // 4 x capacity_, reused every step
  std::vector<double> y_factors_;
};

template <class RateFn>
void GaussianFootprint::deposit_chord(ThicknessField& field, double x0_mm, double y0_mm,
                                      double x1_mm, double y1_mm, double volume_mm3,
                                      const RateFn& rate) {
  if (!(volume_mm3 > 0.0)) return;
  const double dx = x1_mm - x0_mm;
  const double dy = y1_mm - y0_mm;
  const double chord_sigmas = std::sqrt(dx * dx + dy * dy) / sigma_mm_;

  // a (nearly) standing nozzle: one node at the chord's midpoint
  if (chord_sigmas <= 1e-4) {
    const FootprintNode node{x0_mm + 0.5 * dx, y0_mm + 0.5 * dy, volume_mm3};
    deposit_nodes(field, &node, 1);
    return;
  }

  // Gauss-Legendre nodes on [-1, 1] and weights: 2-point for short chords, else 3-point
  static constexpr double kNodes2[2] = {-0.57735026918962576451, 0.57735026918962576451};
  static constexpr double kWeights2[2] = {1.0, 1.0};
  static constexpr double kNodes3[3] = {-0.77459666924148337704, 0.0, 0.77459666924148337704};
  static constexpr double kWeights3[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  const bool short_chord = chord_sigmas <= 0.05;
  const int per_sub = short_chord ? 2 : 3;
  const double* xi = short_chord ? kNodes2 : kNodes3;
  const double* wi = short_chord ? kWeights2 : kWeights3;
  const int sub_chords = short_chord ? 1 : static_cast<int>(std::ceil(chord_sigmas / 0.3));

  // first pass: the quadrature sum of the rate, so node volumes add up to exactly V
  double rate_sum = 0.0;
  for (int j = 0; j < sub_chords; ++j)
    for (int k = 0; k < per_sub; ++k)
      rate_sum += wi[k] * rate((j + 0.5 * (1.0 + xi[k])) / sub_chords);
  const bool uniform = !(rate_sum > 0.0);
  if (uniform) rate_sum = 2.0 * sub_chords;  // sum of the weights
  const double volume_per_weight = volume_mm3 / rate_sum;

  // second pass: deposit each sub-chord's nodes
  FootprintNode nodes[3];
  for (int j = 0; j < sub_chords; ++j) {
    for (int k = 0; k < per_sub; ++k) {
      const double u = (j + 0.5 * (1.0 + xi[k])) / sub_chords;
      const double weight = wi[k] * (uniform ? 1.0 : rate(u));
      nodes[k] = FootprintNode{x0_mm + u * dx, y0_mm + u * dy, weight * volume_per_weight};
    }
    deposit_nodes(field, nodes, per_sub);
  }
}

}  // namespace depotwin
