#include "deposition/gaussian_footprint.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"

namespace depotwin {

namespace {

using Tiles = ThicknessField::Tiles;
constexpr int kTile = Tiles::kSize;
constexpr int kMaxNodes = 4;
// the longest sub-chord deposit_chord hands over, in sigmas (3-point sub-chords)
constexpr double kMaxSubChordSigmas = 0.3;
// the footprint fades to zero over this width centred on the truncation radius (quintic
// smoothstep 1 - s^3 (10 - 15 s + 6 s^2), twice differentiable, w(s) + w(1 - s) = 1):
// continuous in the node position, with the hard cut's mass to first order
constexpr double kTaperSigmas = 0.5;

// floor and ceil of x as int, |x| < 2^31 (std::floor and std::ceil exactly, without their
// library code where the target has no rounding instruction)
int floor_int(double x) {
  const int i = static_cast<int>(x);
  return x < i ? i - 1 : i;
}
int ceil_int(double x) {
  const int i = static_cast<int>(x);
  return x > i ? i + 1 : i;
}

// count Gaussian recurrences side by side: g_k[i] = value_k, value_k *= ratio_k,
// ratio_k *= step_factor, sum_k += value_k (independent chains, so the multiplies overlap)
template <int count>
void fill_chains(const double* first, const double* first_ratio, double step_factor, int n,
                 double* g, int stride, double* sum) {
  // locals, so the chains stay in registers while g is written
  double value[count], ratio[count], total[count];
  for (int k = 0; k < count; ++k) {
    value[k] = first[k];
    ratio[k] = first_ratio[k];
    total[k] = 0.0;
  }
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < count; ++k) {
      g[k * stride + i] = value[k];
      total[k] += value[k];
      value[k] *= ratio[k];
      ratio[k] *= step_factor;
    }
  }
  for (int k = 0; k < count; ++k) sum[k] = total[k];
}

}  // namespace

GaussianFootprint::GaussianFootprint(double sigma_mm, double cell_mm, double truncation_sigmas,
                                     double max_span_sigmas)
    : sigma_mm_(sigma_mm),
      cell_mm_(cell_mm),
      reach_mm_((truncation_sigmas + 0.5 * kTaperSigmas) * sigma_mm),
      taper_start_mm_((truncation_sigmas - 0.5 * kTaperSigmas) * sigma_mm),
      step_factor_(std::exp(-(cell_mm * cell_mm) / (sigma_mm * sigma_mm))),
      inv_two_var_(0.5 / (sigma_mm * sigma_mm)) {
  if (!(sigma_mm > 0.0) || !(cell_mm > 0.0) || !(truncation_sigmas >= 2.0) ||
      !(max_span_sigmas >= 0.0) || !std::isfinite(max_span_sigmas))
    throw InternalError(
        "GaussianFootprint: sigma, cell must be > 0, truncation >= 2 sigma, span >= 0");
  // box side: node spread + two reaches, plus the rounding of both ends
  const double span_sigmas = std::max(kMaxSubChordSigmas, max_span_sigmas);
  capacity_ =
      static_cast<int>(std::ceil(2.0 * reach_mm_ / cell_mm + span_sigmas * sigma_mm / cell_mm)) + 3;
  x_factors_.assign(static_cast<size_t>(kMaxNodes) * capacity_, 0.0);
  y_factors_.assign(static_cast<size_t>(kMaxNodes) * capacity_, 0.0);
}

void GaussianFootprint::fill_factors(const double* centres_mm, const double* scales, int count,
                                     int i0, int n, double* g) const {
  // Gaussian by recurrence: g_{i+1} = g_i r_i, r_{i+1} = r_i exp(-h^2/sigma^2) (2 exp per
  // vector); each centre's chain is the same arithmetic whether filled alone or side by side
  const double h = cell_mm_;
  double value[kMaxNodes] = {}, ratio[kMaxNodes] = {}, sum[kMaxNodes] = {};
  for (int k = 0; k < count; ++k) {
    const double d0 = i0 * h - centres_mm[k];
    value[k] = std::exp(-d0 * d0 * inv_two_var_);
    ratio[k] = std::exp(-(2.0 * d0 * h + h * h) * inv_two_var_);
  }
  switch (count) {
    case 4:
      fill_chains<4>(value, ratio, step_factor_, n, g, capacity_, sum);
      break;
    case 3:
      fill_chains<3>(value, ratio, step_factor_, n, g, capacity_, sum);
      break;
    case 2:
      fill_chains<2>(value, ratio, step_factor_, n, g, capacity_, sum);
      break;
    default:
      fill_chains<1>(value, ratio, step_factor_, n, g, capacity_, sum);
      break;
  }
  // each centre's own truncation (cells within reach of it, whatever box the group
  // needs), faded out over the taper so a cell's share changes continuously as the centre
  // moves: only the few cells at the ends change, and the sum with them; then the
  // discrete normalisation: its cells receive exactly its volume (times its scale)
  const double inv_taper = 1.0 / (kTaperSigmas * sigma_mm_);
  const double inv_h = 1.0 / h;
  for (int k = 0; k < count; ++k) {
    double* gk = g + static_cast<size_t>(k) * capacity_;
    const double centre = centres_mm[k];
    // (by 1 / h: a rounding that moves an index by one moves a cell the taper gives nothing,
    // or leaves whole, from one loop to the other)
    const int first = std::max(0, ceil_int((centre - reach_mm_) * inv_h) - i0);
    const int last = std::min(n - 1, floor_int((centre + reach_mm_) * inv_h) - i0);
    // cells where the taper has begun, on either side of the centre
    const int inner_first = floor_int((centre - taper_start_mm_) * inv_h) - i0;
    const int inner_last = ceil_int((centre + taper_start_mm_) * inv_h) - i0;
    double removed = 0.0;
    auto cut = [&](int i) {
      removed += gk[i];
      gk[i] = 0.0;
    };
    // (without branches: clamped, s = 0 keeps the cell exactly (weight 1) and s = 1 takes all
    // of it (weight 0))
    auto fade = [&](int i) {
      const double s =
          std::clamp((std::abs((i0 + i) * h - centre) - taper_start_mm_) * inv_taper, 0.0, 1.0);
      const double kept = gk[i] * (1.0 - s * s * s * (10.0 + s * (-15.0 + 6.0 * s)));
      removed += gk[i] - kept;
      gk[i] = kept;
    };
    for (int i = 0; i < std::min(first, n); ++i) cut(i);
    for (int i = std::max(last + 1, 0); i < n; ++i) cut(i);
    for (int i = first; i <= std::min(last, inner_first); ++i) fade(i);
    for (int i = std::max(first, std::max(inner_last, inner_first + 1)); i <= last; ++i) fade(i);
    // (the cells beyond reach are 0 already)
    const double factor = scales[k] / (sum[k] - removed);
    for (int i = first; i <= last; ++i) gk[i] *= factor;
  }
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
  const int ix_lo = ceil_int((x_min - reach_mm_) / cell_mm_);
  const int ix_hi = floor_int((x_max + reach_mm_) / cell_mm_);
  const int iy_lo = ceil_int((y_min - reach_mm_) / cell_mm_);
  const int iy_hi = floor_int((y_max + reach_mm_) / cell_mm_);
  const int nx = ix_hi - ix_lo + 1;
  const int ny = iy_hi - iy_lo + 1;
  if (nx > capacity_ || ny > capacity_ || count < 1 || count > kMaxNodes)
    throw InternalError("GaussianFootprint: box of " + std::to_string(nx) + " x " +
                        std::to_string(ny) + " cells exceeds capacity " +
                        std::to_string(capacity_));

  // the rows to write: the box's, within the field's write region if it has one (nothing to
  // write there: nothing to compute)
  const ThicknessField::WriteRegion* region = field.write_region();
  int row_first = iy_lo, row_last = iy_hi;
  if (region != nullptr) {
    row_first = std::max(row_first, region->iy_lo);
    row_last = std::min(row_last, region->iy_hi());
    const auto row_overlaps = [&](int iy) {
      const std::pair<int, int>& span = region->spans[iy - region->iy_lo];
      return std::max(span.first, ix_lo) <= std::min(span.second, ix_hi);
    };
    while (row_first <= row_last && !row_overlaps(row_first)) ++row_first;
    while (row_last >= row_first && !row_overlaps(row_last)) --row_last;
    if (row_first > row_last) return;
  }

  // per-node column factors, and row factors scaled to thickness (volume / cell area)
  const double inv_area = 1.0 / (cell_mm_ * cell_mm_);
  double centres_x[kMaxNodes] = {}, centres_y[kMaxNodes] = {};
  for (int k = 0; k < count; ++k) {
    centres_x[k] = nodes[k].x_mm;
    centres_y[k] = nodes[k].y_mm;
  }
  double ones[kMaxNodes] = {}, amplitudes[kMaxNodes] = {};
  for (int k = 0; k < count; ++k) {
    ones[k] = 1.0;
    amplitudes[k] = nodes[k].volume_mm3 * inv_area;
  }
  fill_factors(centres_x, ones, count, ix_lo, nx, x_factors_.data());
  fill_factors(centres_y, amplitudes, count, iy_lo, ny, y_factors_.data());
  const double* gx0 = x_factors_.data();
  const double* gx1 = gx0 + capacity_;
  const double* gx2 = gx1 + capacity_;
  const double* gx3 = gx2 + capacity_;
  const double* gy0 = y_factors_.data();
  const double* gy1 = gy0 + capacity_;
  const double* gy2 = gy1 + capacity_;
  const double* gy3 = gy2 + capacity_;

  // rank-count update of every tile the box overlaps: cell += sum_k gy_k[row] gx_k[col] (in a
  // write region, each row's cells within its span)
  ThicknessField::Tiles& tiles = field.tiles_for_writing(ix_lo, ix_hi, row_first, row_last);
  for (int ty = Tiles::tile_of(row_first); ty <= Tiles::tile_of(row_last); ++ty) {
    const int row_lo = std::max(row_first, ty * kTile);
    const int row_hi = std::min(row_last, ty * kTile + kTile - 1);
    for (int tx = Tiles::tile_of(ix_lo); tx <= Tiles::tile_of(ix_hi); ++tx) {
      const int tile_col_lo = std::max(ix_lo, tx * kTile);
      const int tile_col_hi = std::min(ix_hi, tx * kTile + kTile - 1);
      double* tile = nullptr;
      for (int iy = row_lo; iy <= row_hi; ++iy) {
        int col_lo = tile_col_lo, col_hi = tile_col_hi;
        if (region != nullptr) {
          const std::pair<int, int>& span = region->spans[iy - region->iy_lo];
          col_lo = std::max(col_lo, span.first);
          col_hi = std::min(col_hi, span.second);
          if (col_lo > col_hi) continue;
        }
        if (tile == nullptr) tile = tiles.get_or_create(tx, ty);
        const int cols = col_hi - col_lo + 1;
        const int c0 = col_lo - ix_lo;
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
        } else if (count == 3) {
          const double a1 = gy1[r];
          const double a2 = gy2[r];
          const double* __restrict x1 = gx1 + c0;
          const double* __restrict x2 = gx2 + c0;
          for (int c = 0; c < cols; ++c) dst[c] += a0 * x0[c] + a1 * x1[c] + a2 * x2[c];
        } else {
          const double a1 = gy1[r];
          const double a2 = gy2[r];
          const double a3 = gy3[r];
          const double* __restrict x1 = gx1 + c0;
          const double* __restrict x2 = gx2 + c0;
          const double* __restrict x3 = gx3 + c0;
          for (int c = 0; c < cols; ++c)
            dst[c] += (a0 * x0[c] + a1 * x1[c]) + (a2 * x2[c] + a3 * x3[c]);
        }
      }
    }
  }
}

}  // namespace depotwin
