// A sparse 2-D grid stored as square tiles of 64 x 64 cells, created on first write.
// Memory grows with the area actually touched, not with the substrate. Cell (ix, iy)
// belongs to tile (floor(ix / 64), floor(iy / 64)); indices may be negative.
// Iteration for outputs goes through sorted_tiles(), so results never depend on
// hash-map order.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <utility>
#include <vector>

namespace depotwin {

template <class Cell>
class SparseTiles {
 public:
  static constexpr int kShift = 6;
  static constexpr int kSize = 1 << kShift;  // cells per tile side
  static constexpr int kCells = kSize * kSize;

  // tile index of a cell index (floor division, also for negative indices)
  static int tile_of(int i) { return i >= 0 ? (i >> kShift) : -((-i - 1) >> kShift) - 1; }
  // position of a cell inside its tile, 0..63 (two's complement masking is floor-mod)
  static int local_of(int i) { return i & (kSize - 1); }
  static int local_index(int ix, int iy) { return local_of(iy) * kSize + local_of(ix); }

  // the tile's cells (row-major, 64 per row), value-initialised on first use
  Cell* get_or_create(int tx, int ty) {
    std::unique_ptr<Cell[]>& slot = tiles_[key(tx, ty)];
    if (!slot) slot.reset(new Cell[kCells]());
    return slot.get();
  }
  const Cell* find(int tx, int ty) const {
    auto it = tiles_.find(key(tx, ty));
    return it == tiles_.end() ? nullptr : it->second.get();
  }
  Cell* find(int tx, int ty) {
    auto it = tiles_.find(key(tx, ty));
    return it == tiles_.end() ? nullptr : it->second.get();
  }

  size_t tile_count() const { return tiles_.size(); }
  size_t allocated_cells() const { return tiles_.size() * static_cast<size_t>(kCells); }
  void clear() { tiles_.clear(); }
  // f(tx, ty, cells) for every tile, in no particular order (for order-free updates)
  template <class F>
  void for_each_tile(F f) {
    for (auto& [key, cells] : tiles_) f(tile_x(key), tile_y(key), cells.get());
  }
  // every cell back to its initial value, the tiles kept for reuse (no allocation)
  void zero() {
    for (auto& [key, cells] : tiles_) std::fill(cells.get(), cells.get() + kCells, Cell{});
  }

  // (tx, ty) of every tile, ordered by ty then tx: the deterministic output order
  std::vector<std::pair<int, int>> sorted_tiles() const {
    std::vector<std::pair<int, int>> order;
    order.reserve(tiles_.size());
    for (const auto& entry : tiles_) order.emplace_back(tile_x(entry.first), tile_y(entry.first));
    std::sort(order.begin(), order.end(), [](const auto& a, const auto& b) {
      return a.second != b.second ? a.second < b.second : a.first < b.first;
    });
    return order;
  }

 private:
  static uint64_t key(int tx, int ty) {
    return (static_cast<uint64_t>(static_cast<uint32_t>(ty)) << 32) | static_cast<uint32_t>(tx);
  }
  static int tile_x(uint64_t k) { return static_cast<int32_t>(static_cast<uint32_t>(k)); }
  static int tile_y(uint64_t k) { return static_cast<int32_t>(static_cast<uint32_t>(k >> 32)); }

  std::unordered_map<uint64_t, std::unique_ptr<Cell[]>> tiles_;
};

}  // namespace depotwin
