#include "toolpath/random_segments.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace depotwin {

namespace {

// a uniform double in [0, 1) from the top 53 bits of one mt19937_64 draw (explicit
// arithmetic, so the instances are the same with every standard library)
double uniform01(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

double uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * uniform01(rng);
}

struct Segment2 {
  double x0, y0, x1, y1;
};

// sign of the turn a -> b -> c (cross product)
double orient(double ax, double ay, double bx, double by, double cx, double cy) {
  return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
}

bool on_box(double ax, double ay, double bx, double by, double px, double py) {
  return std::min(ax, bx) <= px && px <= std::max(ax, bx) && std::min(ay, by) <= py &&
         py <= std::max(ay, by);
}

// closed segments intersect (touching counts): the standard orientation test
bool intersect(const Segment2& s, const Segment2& t) {
  const double d1 = orient(t.x0, t.y0, t.x1, t.y1, s.x0, s.y0);
  const double d2 = orient(t.x0, t.y0, t.x1, t.y1, s.x1, s.y1);
  const double d3 = orient(s.x0, s.y0, s.x1, s.y1, t.x0, t.y0);
  const double d4 = orient(s.x0, s.y0, s.x1, s.y1, t.x1, t.y1);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
    return true;
  if (d1 == 0 && on_box(t.x0, t.y0, t.x1, t.y1, s.x0, s.y0)) return true;
  if (d2 == 0 && on_box(t.x0, t.y0, t.x1, t.y1, s.x1, s.y1)) return true;
  if (d3 == 0 && on_box(s.x0, s.y0, s.x1, s.y1, t.x0, t.y0)) return true;
  if (d4 == 0 && on_box(s.x0, s.y0, s.x1, s.y1, t.x1, t.y1)) return true;
  return false;
}

// placed segments bucketed by the grid cells their bounding boxes touch, so a
// candidate is tested only against segments nearby (N = 10^5 stays fast)
class SegmentGrid {
 public:
  SegmentGrid(double width_mm, double height_mm, double cell_mm)
      : cell_mm_(cell_mm),
        columns_(std::max(1, static_cast<int>(std::ceil(width_mm / cell_mm)))),
        rows_(std::max(1, static_cast<int>(std::ceil(height_mm / cell_mm)))),
        cells_(static_cast<size_t>(columns_) * rows_) {}

  bool intersects_any(const Segment2& s) {
    ++stamp_;
    bool hit = false;
    for_cells(s, [&](std::vector<int>& cell) {
      for (int index : cell) {
        if (hit || checked_[index] == stamp_) continue;
        checked_[index] = stamp_;
        hit = intersect(s, placed_[index]);
      }
    });
    return hit;
  }

  void add(const Segment2& s) {
    const int index = static_cast<int>(placed_.size());
    placed_.push_back(s);
    checked_.push_back(0);
    for_cells(s, [&](std::vector<int>& cell) { cell.push_back(index); });
  }

 private:
  template <class Visit>
  void for_cells(const Segment2& s, Visit visit) {
    const int c0 = column(std::min(s.x0, s.x1)), c1 = column(std::max(s.x0, s.x1));
    const int r0 = row(std::min(s.y0, s.y1)), r1 = row(std::max(s.y0, s.y1));
    for (int r = r0; r <= r1; ++r)
      for (int c = c0; c <= c1; ++c) visit(cells_[static_cast<size_t>(r) * columns_ + c]);
  }
  int column(double x) const {
    return std::clamp(static_cast<int>(std::floor(x / cell_mm_)), 0, columns_ - 1);
  }
  int row(double y) const {
    return std::clamp(static_cast<int>(std::floor(y / cell_mm_)), 0, rows_ - 1);
  }

  double cell_mm_;
  int columns_, rows_;
  std::vector<std::vector<int>> cells_;
  std::vector<Segment2> placed_;
  std::vector<unsigned> checked_;  // stamp of the last query that tested each segment
  unsigned stamp_ = 0;
};

void check_spec(const RandomSegmentsSpec& spec) {
  const std::string key = "toolpath.random_segments";
  std::vector<Problem> problems;
  auto fail = [&](const std::string& field, const std::string& message) {
    problems.push_back(Problem{"", 0, key + "." + field, message});
  };
  if (spec.count < 0) fail("n", "must be >= 0");
  if (!(spec.bed_x_mm > 0.0) || !(spec.bed_y_mm > 0.0) || !std::isfinite(spec.bed_x_mm) ||
      !std::isfinite(spec.bed_y_mm))
    fail("bed", "both sides must be positive finite numbers (mm)");
  if (!(spec.length_min_mm > 0.0) || !(spec.length_max_mm >= spec.length_min_mm) ||
      !std::isfinite(spec.length_max_mm))
    fail("length", "must be [min, max] with 0 < min <= max (mm)");
  else if (spec.length_max_mm > std::min(spec.bed_x_mm, spec.bed_y_mm))
    fail("length", "the longest segment (" + std::to_string(spec.length_max_mm) +
                       " mm) must fit the shorter bed side in every direction");
  if (!(spec.speed_mm_s > 0.0) || !std::isfinite(spec.speed_mm_s))
    fail("speed", "must be a positive number (mm/s)");
  if (!problems.empty()) throw InputError(std::move(problems));
}

}  // namespace

Toolpath make_random_segments(const RandomSegmentsSpec& spec) {
  check_spec(spec);
  std::mt19937_64 rng(spec.seed);
  SegmentGrid grid(spec.bed_x_mm, spec.bed_y_mm, spec.length_max_mm);
  // a generous budget: at the paper's densest case (N = 100 on 100 x 100 mm) a 40 mm
  // segment is accepted about once in a few hundred tries (2 000 to 4 000 for the instance,
  // 31 a segment for 10^5 segments at that density). A bed filled to its last segments would
  // take each of them up to the first budget and the instance minutes (2 000 segments on
  // 90 x 90 mm: a minute, then an error), so the tries are bounded in all too
  constexpr long kAttemptsPerSegment = 1000000;
  const long attempts_budget = kAttemptsPerSegment + 100L * spec.count;
  long attempts_in_all = 0;

  Toolpath toolpath;
  toolpath.paths.reserve(spec.count);
  for (int i = 0; i < spec.count; ++i) {
    // the length is drawn once (uniform on [min, max]); only the placement is retried,
    // so rejections do not bias the lengths towards short segments (unless asked to)
    double length_mm = uniform(rng, spec.length_min_mm, spec.length_max_mm);
    bool placed = false;
    long attempt = 0;
    for (; attempt < kAttemptsPerSegment && attempts_in_all < attempts_budget && !placed;
         ++attempt, ++attempts_in_all) {
      Segment2 s;
      if (spec.redraw_length_on_reject) {
        // start point, direction and length uniform; redrawn together when rejected
        if (attempt > 0) length_mm = uniform(rng, spec.length_min_mm, spec.length_max_mm);
        const double angle_rad = uniform(rng, 0.0, 2.0 * kPi);
        s.x0 = uniform(rng, 0.0, spec.bed_x_mm), s.y0 = uniform(rng, 0.0, spec.bed_y_mm);
        s.x1 = s.x0 + length_mm * std::cos(angle_rad),
        s.y1 = s.y0 + length_mm * std::sin(angle_rad);
        if (s.x1 < 0.0 || s.x1 > spec.bed_x_mm || s.y1 < 0.0 || s.y1 > spec.bed_y_mm) continue;
      } else {
        // uniform direction, then a midpoint uniform over the positions that keep the
        // whole segment on the bed
        const double angle_rad = uniform(rng, 0.0, 2.0 * kPi);
        const double half_dx = 0.5 * length_mm * std::cos(angle_rad);
        const double half_dy = 0.5 * length_mm * std::sin(angle_rad);
        const double mid_x = uniform(rng, std::abs(half_dx), spec.bed_x_mm - std::abs(half_dx));
        const double mid_y = uniform(rng, std::abs(half_dy), spec.bed_y_mm - std::abs(half_dy));
        s = {mid_x - half_dx, mid_y - half_dy, mid_x + half_dx, mid_y + half_dy};
      }
      if (grid.intersects_any(s)) continue;
      grid.add(s);
      PrintPath path;
      path.points = {Vec3(s.x0, s.y0, 0.0), Vec3(s.x1, s.y1, 0.0)};
      path.speed_mm_s = spec.speed_mm_s;
      path.source_index = i;
      toolpath.paths.push_back(std::move(path));
      placed = true;
    }
    if (!placed)
      throw InputError("toolpath.random_segments",
                       "could not place segment " + std::to_string(i + 1) + " of " +
                           std::to_string(spec.count) + " without crossing the others after " +
                           std::to_string(attempt) + " tries (" + std::to_string(attempts_in_all) +
                           " for all): use a larger bed, fewer or shorter segments");
  }
  // start and end of the job, uniform on the bed
  toolpath.start_mm = Vec3(uniform(rng, 0.0, spec.bed_x_mm), uniform(rng, 0.0, spec.bed_y_mm), 0.0);
  toolpath.end_mm = Vec3(uniform(rng, 0.0, spec.bed_x_mm), uniform(rng, 0.0, spec.bed_y_mm), 0.0);
  return toolpath;
}

}  // namespace depotwin
