#include "deposition/gaussian_footprint.hpp"

#include <string>

#include "core/error.hpp"

namespace depotwin {

namespace {

using Tiles = ThicknessField::Tiles;
constexpr int kTile = Tiles::kSize;
constexpr int kMaxNodes = 3;
// the longest sub-chord deposit_chord hands over, in sigmas (3-point sub-chords)
constexpr double kMaxSubChordSigmas = 0.3;

}  // namespace

GaussianFootprint::GaussianFootprint(double sigma_mm, double cell_mm, double truncation_sigmas)
    : sigma_mm_(sigma_mm),
      cell_mm_(cell_mm),
      reach_mm_(truncation_sigmas * sigma_mm),
      step_factor_(std::exp(-(cell_mm * cell_mm) / (sigma_mm * sigma_mm))),
      inv_two_var_(0.5 / (sigma_mm * sigma_mm)) {
  if (!(sigma_mm > 0.0) || !(cell_mm > 0.0) || !(truncation_sigmas >= 2.0))
    throw InternalError("GaussianFootprint: sigma, cell must be > 0 and truncation >= 2 sigma");
  // box side: chord extent + two reaches, plus the rounding of both ends
  capacity_ = static_cast<int>(
                  std::ceil((2.0 * truncation_sigmas + kMaxSubChordSigmas) * sigma_mm / cell_mm)) +
              3;
  x_factors_.assign(static_cast<size_t>(kMaxNodes) * capacity_, 0.0);
  y_factors_.assign(static_cast<size_t>(kMaxNodes) * capacity_, 0.0);
}

void GaussianFootprint::fill_factors(double centre_mm, int i0, int n, double* g) const {
  // Gaussian by recurrence: g_{i+1} = g_i r_i, r_{i+1} = r_i exp(-h^2/sigma^2) (2 exp per vector)
  const double h = cell_mm_;
  const double d0 = i0 * h - centre_mm;
  double value = std::exp(-d0 * d0 * inv_two_var_);
  double ratio = std::exp(-(2.0 * d0 * h + h * h) * inv_two_var_);
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    g[i] = value;
    sum += value;
    value *= ratio;
    ratio *= step_factor_;
  }
  // discrete normalisation: the box receives exactly the node's volume
  const double inv_sum = 1.0 / sum;
  for (int i = 0; i < n; ++i) g[i] *= inv_sum;
}

void GaussianFootprint::deposit_nodes(ThicknessField& field, const FootprintNode* nodes,
                                      int count) {
  // common box: every cell within reach of at least the nodes' bounding box
  double x_min = nodes[0].x_mm, x_max = x_min, y_min = nodes[0].y_mm, y_max = y_min;
  for (int k = 1; k < count; ++k) {
    x_min = std::min(x_min, nodes[k].x_mm);
    x_max = std::max(x_max, nodes[k].x_mm);
    y_min = std::min(y_min, nodes[k].y_mm);
    y_max = std::max(y_max, nodes[k].y_mm);
  }
  const int ix_lo = static_cast<int>(std::ceil((x_min - reach_mm_) / cell_mm_));
  const int ix_hi = static_cast<int>(std::floor((x_max + reach_mm_) / cell_mm_));
  const int iy_lo = static_cast<int>(std::ceil((y_min - reach_mm_) / cell_mm_));
  const int iy_hi = static_cast<int>(std::floor((y_max + reach_mm_) / cell_mm_));
  const int nx = ix_hi - ix_lo + 1;
  const int ny = iy_hi - iy_lo + 1;
  if (nx > capacity_ || ny > capacity_ || count > kMaxNodes)
    throw InternalError("GaussianFootprint: box of " + std::to_string(nx) + " x " +
                        std::to_string(ny) + " cells exceeds capacity " +
                        std::to_string(capacity_));

  // per-node column factors, and row factors scaled to thickness (volume / cell area)
  const double inv_area = 1.0 / (cell_mm_ * cell_mm_);
  for (int k = 0; k < count; ++k) {
    double* gx = x_factors_.data() + static_cast<size_t>(k) * capacity_;
    double* gy = y_factors_.data() + static_cast<size_t>(k) * capacity_;
    fill_factors(nodes[k].x_mm, ix_lo, nx, gx);
    fill_factors(nodes[k].y_mm, iy_lo, ny, gy);
    const double amplitude = nodes[k].volume_mm3 * inv_area;
    for (int j = 0; j < ny; ++j) gy[j] *= amplitude;
  }
  const double* gx0 = x_factors_.data();
  const double* gx1 = gx0 + capacity_;
  const double* gx2 = gx1 + capacity_;
  const double* gy0 = y_factors_.data();
  const double* gy1 = gy0 + capacity_;
  const double* gy2 = gy1 + capacity_;

  // rank-count update of every tile the box overlaps: cell += sum_k gy_k[row] gx_k[col]
  for (int ty = Tiles::tile_of(iy_lo); ty <= Tiles::tile_of(iy_hi); ++ty) {
    const int row_lo = std::max(iy_lo, ty * kTile);
    const int row_hi = std::min(iy_hi, ty * kTile + kTile - 1);
    for (int tx = Tiles::tile_of(ix_lo); tx <= Tiles::tile_of(ix_hi); ++tx) {
      const int col_lo = std::max(ix_lo, tx * kTile);
      const int col_hi = std::min(ix_hi, tx * kTile + kTile - 1);
      const int cols = col_hi - col_lo + 1;
      const int c0 = col_lo - ix_lo;
      double* tile = field.tiles().get_or_create(tx, ty);
      for (int iy = row_lo; iy <= row_hi; ++iy) {
        const int r = iy - iy_lo;
        double* __restrict dst = tile + Tiles::local_of(iy) * kTile + Tiles::local_of(col_lo);
        const double a0 = gy0[r];
        const double* __restrict x0 = gx0 + c0;
        if (count == 1) {
          for (int c = 0; c < cols; ++c) dst[c] += a0 * x0[c];
        } else if (count == 2) {
          const double a1 = gy1[r];
          const double* __restrict x1 = gx1 + c0;
          for (int c = 0; c < cols; ++c) dst[c] += a0 * x0[c] + a1 * x1[c];
        } else {
          const double a1 = gy1[r];
          const double a2 = gy2[r];
          const double* __restrict x1 = gx1 + c0;
          const double* __restrict x2 = gx2 + c0;
          for (int c = 0; c < cols; ++c) dst[c] += a0 * x0[c] + a1 * x1[c] + a2 * x2[c];
        }
      }
    }
  }
}

}  // namespace depotwin
