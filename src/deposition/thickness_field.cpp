#include "deposition/thickness_field.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.hpp"

namespace depotwin {

namespace {

constexpr int kTile = ThicknessField::Tiles::kSize;
constexpr double kUmPerMm = 1000.0;
constexpr size_t kMaxHeightMapCells = size_t{1} << 28;

}  // namespace

ThicknessField::ThicknessField(double cell_mm) : cell_mm_(cell_mm) {
  if (!(cell_mm > 0.0) || !std::isfinite(cell_mm))
    throw InputError("sim.cell_mm",
                     "must be a positive number of mm, got " + std::to_string(cell_mm));
}

double ThicknessField::cell_thickness_mm(int ix, int iy) const {
  const double* tile = tiles_.find(Tiles::tile_of(ix), Tiles::tile_of(iy));
  return tile ? tile[Tiles::local_index(ix, iy)] : 0.0;
}

double ThicknessField::thickness_mm_at(double x_mm, double y_mm) const {
  return bilinear_between_cells(x_mm, y_mm, cell_mm_,
                                [this](int ix, int iy) { return cell_thickness_mm(ix, iy); });
}

double ThicknessField::total_volume_mm3() const {
  // rows, then tiles, then a compensated (Neumaier) sum over tiles: a long line's million
  // cells add up to the deposited volume to ~1e-15, not ~1e-12
  double sum_mm = 0.0, compensation_mm = 0.0;
  for (const auto& [tx, ty] : tiles_.sorted_tiles()) {
    const double* tile = tiles_.find(tx, ty);
    double tile_mm = 0.0;
    for (int row = 0; row < kTile; ++row) {
      double row_mm = 0.0;
      for (int col = 0; col < kTile; ++col) row_mm += tile[row * kTile + col];
      tile_mm += row_mm;
    }
    const double next = sum_mm + tile_mm;
    compensation_mm += std::abs(sum_mm) >= std::abs(tile_mm) ? (sum_mm - next) + tile_mm
                                                             : (tile_mm - next) + sum_mm;
    sum_mm = next;
  }
  return (sum_mm + compensation_mm) * cell_mm_ * cell_mm_;
}

FieldBounds ThicknessField::bounds() const {
  int ix_lo = std::numeric_limits<int>::max(), iy_lo = ix_lo;
  int ix_hi = std::numeric_limits<int>::min(), iy_hi = ix_hi;
  for (const auto& [tx, ty] : tiles_.sorted_tiles()) {
    const double* tile = tiles_.find(tx, ty);
    for (int ly = 0; ly < kTile; ++ly) {
      for (int lx = 0; lx < kTile; ++lx) {
        if (tile[ly * kTile + lx] <= 0.0) continue;
        const int ix = tx * kTile + lx;
        const int iy = ty * kTile + ly;
        ix_lo = std::min(ix_lo, ix);
        ix_hi = std::max(ix_hi, ix);
        iy_lo = std::min(iy_lo, iy);
        iy_hi = std::max(iy_hi, iy);
      }
    }
  }
  FieldBounds b;
  if (ix_lo > ix_hi) return b;
  b.empty = false;
  b.x_lo_mm = ix_lo * cell_mm_;
  b.y_lo_mm = iy_lo * cell_mm_;
  b.x_hi_mm = ix_hi * cell_mm_;
  b.y_hi_mm = iy_hi * cell_mm_;
  return b;
}

HeightMap ThicknessField::to_heightmap(double x_lo_mm, double y_lo_mm, double x_hi_mm,
                                       double y_hi_mm, int stride) const {
  if (stride < 1) throw InternalError("ThicknessField::to_heightmap: stride must be >= 1");
  HeightMap map;
  map.cell_mm = cell_mm_ * stride;
  // field cells whose centres lie inside the region (a tolerance absorbs rounding of lo/hi)
  const double tol = 1e-9;
  const int ix_begin = static_cast<int>(std::ceil(x_lo_mm / cell_mm_ - tol));
  const int iy_begin = static_cast<int>(std::ceil(y_lo_mm / cell_mm_ - tol));
  const int ix_last = static_cast<int>(std::floor(x_hi_mm / cell_mm_ + tol));
  const int iy_last = static_cast<int>(std::floor(y_hi_mm / cell_mm_ + tol));
  map.origin_x_mm = (ix_begin + 0.5 * (stride - 1)) * cell_mm_;
  map.origin_y_mm = (iy_begin + 0.5 * (stride - 1)) * cell_mm_;
  if (ix_last < ix_begin || iy_last < iy_begin) return map;

  // output size: partial blocks at the high edges still average a full stride x stride block
  const long long native_nx = static_cast<long long>(ix_last) - ix_begin + 1;
  const long long native_ny = static_cast<long long>(iy_last) - iy_begin + 1;
  const long long nx = (native_nx + stride - 1) / stride;
  const long long ny = (native_ny + stride - 1) / stride;
  if (static_cast<unsigned long long>(nx) * static_cast<unsigned long long>(ny) >
      kMaxHeightMapCells)
    throw InternalError("ThicknessField::to_heightmap: " + std::to_string(nx) + " x " +
                        std::to_string(ny) + " cells is too large; use a larger stride");
  map.nx = static_cast<int>(nx);
  map.ny = static_cast<int>(ny);
  map.thickness_um.assign(static_cast<size_t>(nx) * static_cast<size_t>(ny), 0.0f);

  // visit only allocated tiles that overlap the (block-extended) region
  const int ix_end = ix_begin + map.nx * stride;  // exclusive
  const int iy_end = iy_begin + map.ny * stride;
  const double scale_um = kUmPerMm / (static_cast<double>(stride) * stride);
  for (int ty = Tiles::tile_of(iy_begin); ty <= Tiles::tile_of(iy_end - 1); ++ty) {
    for (int tx = Tiles::tile_of(ix_begin); tx <= Tiles::tile_of(ix_end - 1); ++tx) {
      const double* tile = tiles_.find(tx, ty);
      if (!tile) continue;
      const int row_lo = std::max(iy_begin, ty * kTile);
      const int row_hi = std::min(iy_end, (ty + 1) * kTile);
      const int col_lo = std::max(ix_begin, tx * kTile);
      const int col_hi = std::min(ix_end, (tx + 1) * kTile);
      for (int iy = row_lo; iy < row_hi; ++iy) {
        const double* row = tile + Tiles::local_of(iy) * kTile;
        float* out_row = map.thickness_um.data() + static_cast<size_t>((iy - iy_begin) / stride) *
                                                       static_cast<size_t>(map.nx);
        for (int ix = col_lo; ix < col_hi; ++ix)
          out_row[(ix - ix_begin) / stride] +=
              static_cast<float>(row[Tiles::local_of(ix)] * scale_um);
      }
    }
  }
  return map;
}

HeightMap ThicknessField::to_heightmap(int stride) const {
  const FieldBounds b = bounds();
  if (b.empty) {
    HeightMap map;
    map.cell_mm = cell_mm_ * stride;
    return map;
  }
  return to_heightmap(b.x_lo_mm, b.y_lo_mm, b.x_hi_mm, b.y_hi_mm, stride);
}

int ThicknessField::stride_for_max_cells(double x_lo_mm, double y_lo_mm, double x_hi_mm,
                                         double y_hi_mm, size_t max_cells) const {
  const double native_nx = std::max(1.0, std::floor((x_hi_mm - x_lo_mm) / cell_mm_) + 1.0);
  const double native_ny = std::max(1.0, std::floor((y_hi_mm - y_lo_mm) / cell_mm_) + 1.0);
  const double budget = static_cast<double>(std::max<size_t>(1, max_cells));
  // start from the area ratio, then step up until the rounded-up block counts fit
  int stride = std::max(1, static_cast<int>(std::floor(std::sqrt(native_nx * native_ny / budget))));
  while (std::ceil(native_nx / stride) * std::ceil(native_ny / stride) > budget) ++stride;
  return stride;
}

void ThicknessField::zero() {
  if (written_.everything) {
    tiles_.zero();
  } else if (written_.ix_lo <= written_.ix_hi) {
    // each tile's rows and columns within the written box
    tiles_.for_each_tile([this](int tx, int ty, double* cells) {
      const int row_lo = std::max(written_.iy_lo, ty * Tiles::kSize);
      const int row_hi = std::min(written_.iy_hi, ty * Tiles::kSize + Tiles::kSize - 1);
      const int col_lo = std::max(written_.ix_lo, tx * Tiles::kSize);
      const int col_hi = std::min(written_.ix_hi, tx * Tiles::kSize + Tiles::kSize - 1);
      if (row_lo > row_hi || col_lo > col_hi) return;
      for (int iy = row_lo; iy <= row_hi; ++iy)
        std::fill(cells + Tiles::local_index(col_lo, iy),
                  cells + Tiles::local_index(col_hi, iy) + 1, 0.0);
    });
  }
  written_ = CellBox{};
}

void ThicknessField::add(const ThicknessField& other) {
  if (other.cell_mm_ != cell_mm_)
    throw InternalError("ThicknessField::add: fields with different cells");
  written_.everything = true;
  for (const auto& [tx, ty] : other.tiles_.sorted_tiles()) {
    const double* from = other.tiles_.find(tx, ty);
    double* to = tiles_.get_or_create(tx, ty);
    for (int k = 0; k < Tiles::kCells; ++k) to[k] += from[k];
  }
}

void ThicknessField::scale_cells(const std::function<double(double x_mm, double y_mm)>& factor) {
  for (const auto& [tx, ty] : tiles_.sorted_tiles()) {
    double* cells = tiles_.find(tx, ty);
    for (int k = 0; k < Tiles::kCells; ++k) {
      if (cells[k] == 0.0) continue;
      const int ix = tx * Tiles::kSize + k % Tiles::kSize;
      const int iy = ty * Tiles::kSize + k / Tiles::kSize;
      cells[k] *= factor(ix * cell_mm_, iy * cell_mm_);
    }
  }
}

void ThicknessField::add_to_cell(int ix, int iy, double thickness_mm) {
  written_.include(ix, ix, iy, iy);
  tiles_.get_or_create(Tiles::tile_of(ix), Tiles::tile_of(iy))[Tiles::local_index(ix, iy)] +=
      thickness_mm;
}

}  // namespace depotwin
