#include "planners/motion/uniform/corner_choice.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <utility>

#include "core/error.hpp"
#include "deposition/thickness_field.hpp"

namespace depotwin {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// the prediction's steps: at most kStepS, and at most a quarter sigma of travel (the footprint
// is integrated exactly along each step's chord, the shutter's open fraction linear within
// it; at 4 ms the comparison scenarios' line_cv and times were the same to every digit shown)
constexpr double kStepS = 0.01;
constexpr double kStepSigmas = 0.25;
// a slowed aerosol blend's prediction takes up to this many steps at once (see evaluate_corner)
constexpr int kMaxMergedSteps = 4;
constexpr double kWindowSigmas = 6.0;  // window beyond what the candidates change
constexpr double kRollSigmas = 6.0;    // pre- and post-rolls (the footprint ends at 5 sigma)
// an extruder's flow settles within this many lags (exp(-6) = 0.25 %): the rolls and the window
// reach that far at print speed
constexpr double kLagSettlingLags = 6.0;
// the prediction's footprint ends here (the simulation's default: 5 sigma); the tail beyond
// holds exp(-8) = 3e-4 of the peak, renormalised onto the footprint's square, alike for every
// candidate
constexpr double kPredictionTruncationSigmas = 4.0;
// and its steps are batched over 2 sigma of path (the simulation's default: 1), 4 quadrature
// nodes a batch: at most 5.9e-8 2^8 = 1.5e-5 of a batch's peak on smooth motion
// (deposition/step_batch.hpp)
constexpr double kPredictionBatchSigmas = 2.0;
// error cells this far (arc length) from the window's ends
constexpr double kEndClearSigmas = 1.0;
// the prediction's cells: half a sigma (every cell's volume is exact at any size; the error
// sums compare candidates, which this resolves)
constexpr double kCellSigmas = 0.5;
// the corner's cell in its own frame: the middle of a scratch field's tile
constexpr double kFrameCornerCells = 0.5 * ThicknessField::Tiles::kSize;
constexpr double kMaxTrimShare = 0.3;  // a loop's trim leaves most of the edge printed
constexpr double kTrimFractions[] = {0.0, 0.25, 0.5, 0.75, 1.0};
constexpr double kTrimInFractions[] = {0.0, 0.25};
// slowed corners try the largest blend within the tolerance and smaller ones (slower, nearer
// the corner)
constexpr double kSlowBlendShares[] = {1.0, 0.7, 0.5, 0.35, 0.25};

// the steady line's cross-section area (mm^2) at print speed v
double line_area_mm2(const DepositionSettings& s, double speed_mm_s) {
  if (s.type == ProcessType::aerosol) return s.aerosol_flow_mm3_s() / speed_mm_s;
  if (s.flow_mm3_s > 0.0) return s.flow_mm3_s / speed_mm_s;
  return s.bead_width_mm * s.layer_height_mm;
}

// the length over which the two lines of a sharp corner overlap (2 sigma / sin(alpha) for an
// interior angle alpha below 90 deg, else 0): the loops' trims are fractions of it
double overlap_mm(const CornerGeometry& g, const DepositModel& model) {
  const double alpha = deg_to_rad(g.interior_deg);
  const double sigma = model.settings.footprint_sigma_mm();
  return alpha < 0.5 * kPi ? 2.0 * sigma / std::max(std::sin(alpha), 1e-3) : 0.0;
}

// the largest trim a loop candidate tries on an edge of this length, at these fractions of the
// overlap (kTrimInFractions before the corner, kTrimFractions after it)
template <size_t count>
double largest_trim_mm(const CornerGeometry& g, double edge_mm, const DepositModel& model,
                       const double (&fractions)[count]) {
  return std::min(*std::max_element(fractions, fractions + count) * overlap_mm(g, model),
                  kMaxTrimShare * edge_mm);
}

// the longer of the two edges' speed changes from print speed to rest, and the extruder's flow
// settling after it (as the post-roll allows for)
double speed_change_reach_mm(const PrintChain& chain, size_t corner, const TcpLimits& limits,
                             const PathMotionOptions& options) {
  double reach = 0.0;
  for (const size_t e : {corner - 1, corner}) {
    const Vec3& a = chain.points[e];
    const Vec3& b = chain.points[e + 1];
    const LineLimits line = line_limits((b - a).normalized(), limits.along(a, b),
                                        chain.edge_speed_mm_s[e], options.deceleration_lag_s());
    reach = std::max(reach, speed_change_distance(line.v_max_mm_s, 0.0, line) +
                                kLagSettlingLags * options.lag_s * line.v_max_mm_s);
  }
  return reach;
}

// how far on each side of the corner the window reaches: the slowest candidate's speed
// change (to rest) and the flow lag's settling after it, the largest blend or trim, and
// kWindowSigmas
double window_reach_mm(const PrintChain& chain, size_t corner, const CornerGeometry& g,
                       const TcpLimits& limits, const PathMotionOptions& options,
                       const DepositModel& model) {
  const double sigma = model.settings.footprint_sigma_mm();
  double reach = speed_change_reach_mm(chain, corner, limits, options);
  for (const size_t e : {corner - 1, corner}) {
    const double edge_mm = (chain.points[e + 1] - chain.points[e]).norm();
    reach = std::max(reach, std::max(largest_trim_mm(g, edge_mm, model, kTrimFractions),
                                     largest_trim_mm(g, edge_mm, model, kTrimInFractions)));
  }
  return reach + g.max_half_length_mm * g.tangent_per_length + kWindowSigmas * sigma;
}

// the time spans of a plan with the material off (a loop)
std::vector<std::pair<double, double>> closed_spans(const Trajectory& plan) {
  std::vector<std::pair<double, double>> spans;
  for (const TrajectoryPiece& piece : plan.pieces())
    if (!piece.depositing) spans.emplace_back(piece.t_begin_s, piece.t_end_s);
  return spans;
}

// the ideal blade's open fraction (sim/shutter.hpp for print intervals and gaps longer than its
// time): the share of [t, t + T] with the material on
double open_fraction(const std::vector<std::pair<double, double>>& closed, double t,
                     double time_s) {
  double blocked = 0.0;
  for (const auto& [a, b] : closed)
    blocked += std::max(0.0, std::min(b, t + time_s) - std::max(a, t));
  return std::clamp(1.0 - blocked / time_s, 0.0, 1.0);
}

// The polyline a - c - b in the plane, its two edges' starts, directions and lengths (the
// same arithmetic as taking them per point, once).
struct WindowPolyline {
  Eigen::Vector2d start[2], direction[2];
  double length[2] = {}, length_squared[2] = {};
  WindowPolyline(const Vec3& a, const Vec3& c, const Vec3& b) {
    const Vec3 ends[3] = {a, c, b};
    for (int e = 0; e < 2; ++e) {
      start[e] = ends[e].head<2>();
      direction[e] = ends[e + 1].head<2>() - start[e];
      length[e] = direction[e].norm();
      length_squared[e] = length[e] * length[e];
    }
  }
  // the nearest point to p: squared distance and arc length from a (the squares compared: no
  // root per edge)
  void nearest(const Eigen::Vector2d& p, double& distance_squared, double& arc, int& edge) const {
    distance_squared = kInf;
    double arc_start = 0.0;
    for (int e = 0; e < 2; ++e) {
      const Eigen::Vector2d& p0 = start[e];
      const Eigen::Vector2d& d = direction[e];
      const double f =
          length[e] > 0.0 ? std::clamp((p - p0).dot(d) / length_squared[e], 0.0, 1.0) : 0.0;
      const double squared = (p0 + f * d - p).squaredNorm();
      if (squared < distance_squared) {
        distance_squared = squared;
        arc = arc_start + f * length[e];
        edge = e;
      }
      arc_start += length[e];
    }
  }
};

// the cells [first, last] of row y (within [ix_lo, ix_hi]) that may lie within r of the segment
// p0-p1: its r-neighbourhood (a stadium: the band p0-p1 +- r along its normal and a disc at each
// end, convex) meets the row in one interval, widened by a cell (an empty range, first > last,
// when it misses the row)
std::pair<int, int> row_cells_near(const Vec3& p0, const Vec3& p1, double y, double r, double h,
                                   int ix_lo, int ix_hi) {
  double lo = kInf, hi = -kInf;
  const auto include = [&](double x) { lo = std::min(lo, x), hi = std::max(hi, x); };
  // the end discs
  for (const Vec3* end : {&p0, &p1}) {
    const double dy = y - end->y();
    if (std::abs(dy) <= r) {
      const double half = std::sqrt(r * r - dy * dy);
      include(end->x() - half);
      include(end->x() + half);
    }
  }
  // the band: the rectangle p0 +- r n, p1 +- r n, each side crossing the row
  const Eigen::Vector2d d = (p1 - p0).head<2>();
  const double length = d.norm();
  if (length > 0.0) {
    const Eigen::Vector2d n = Eigen::Vector2d(-d.y(), d.x()) * (r / length);
    const Eigen::Vector2d a = p0.head<2>(), b = p1.head<2>();
    const Eigen::Vector2d corners[4] = {a + n, b + n, b - n, a - n};
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2d& from = corners[k];
      const Eigen::Vector2d& to = corners[(k + 1) % 4];
      if ((y < from.y() && y < to.y()) || (y > from.y() && y > to.y())) continue;
      if (from.y() == to.y()) {
        include(from.x());
        include(to.x());
      } else {
        include(from.x() + (y - from.y()) / (to.y() - from.y()) * (to.x() - from.x()));
      }
    }
  }
  if (!(lo <= hi)) return {ix_hi + 1, ix_hi};
  const int first = static_cast<int>(std::floor(lo / h)) - 1;
  const int last = static_cast<int>(std::ceil(hi / h)) + 1;
  return {std::max(first, ix_lo), std::min(last, ix_hi)};
}

// the process as predicted: the footprint ends at kPredictionTruncationSigmas at most, the
// steps batched over kPredictionBatchSigmas
DepositionSettings prediction_settings(DepositionSettings settings) {
  settings.truncation_sigmas = std::min(settings.truncation_sigmas, kPredictionTruncationSigmas);
  settings.batch_length_sigmas = kPredictionBatchSigmas;
  return settings;
}

// the prediction's step: at most kStepS, and at most kStepSigmas of travel at the speed
double prediction_step_s(double sigma_mm, double speed_mm_s) {
  return std::min(kStepS, kStepSigmas * sigma_mm / speed_mm_s);
}

// a step of the steady line at print speed (its command: the whole flow, shutter open)
DepositionStep steady_step(double speed_mm_s) {
  DepositionStep step;
  step.open0 = step.open1 = 1.0;
  step.flow_command = 1.0;
  step.desired_speed_mm_s = speed_mm_s;
  return step;
}

// Reads a field's cells in runs (rows of cells): the tile of the last read is kept, so most
// reads skip the tile lookup. The values of ThicknessField::cell_thickness_mm and
// thickness_mm_at.
class CellReader {
 public:
  explicit CellReader(const ThicknessField& field) : field_(field) {}
  double at(int ix, int iy) {
    const int tx = ThicknessField::Tiles::tile_of(ix), ty = ThicknessField::Tiles::tile_of(iy);
    if (tx != tx_ || ty != ty_) {
      tx_ = tx, ty_ = ty;
      tile_ = field_.tiles().find(tx, ty);
    }
    return tile_ ? tile_[ThicknessField::Tiles::local_index(ix, iy)] : 0.0;
  }
  // the field's thickness_mm_at where the point lies (bilinear_point on the same cells)
  double interpolated(const BilinearPoint& point) {
    return bilinear_between_cells(point, [this](int ix, int iy) { return at(ix, iy); });
  }

 private:
  const ThicknessField& field_;
  int tx_ = std::numeric_limits<int>::min(), ty_ = std::numeric_limits<int>::min();
  const double* tile_ = nullptr;
};

// Reads the cells of one tile of a field (a window whose targets all lie in it): no tile lookup
// per read. The values of CellReader.
class TileReader {
 public:
  TileReader(const ThicknessField& field, int tile_x, int tile_y)
      : tile_(field.tiles().find(tile_x, tile_y)) {}
  double at(int ix, int iy) const {
    return tile_ ? tile_[ThicknessField::Tiles::local_index(ix, iy)] : 0.0;
  }
  double interpolated(const BilinearPoint& point) const {
    return bilinear_between_cells(point, [this](int ix, int iy) { return at(ix, iy); });
  }

 private:
  const double* tile_;
};

// What every candidate at one corner shares: the window of the path around it (planned alone,
// entering and leaving at print speed), and the even deposit it is compared with.
struct CornerWindow {
  PrintChain chain;  // a - c - b
  // the limits it is planned under: the machine's, with every box clamped into the corner's
  // edges' box on the path (an edge taken on past its end keeps the limits at its end)
  TcpLimits limits;
  std::vector<CornerGeometry> geometry;
  Vec3 a, c, b;
  Vec3 d_in, d_out;
  double v_in = 0.0, v_out = 0.0;
  double lag_s = 0.0;  // the extruder's flow lag (0: aerosol)
  double cell_mm = 0.0;
  // the corner's own frame, where the predictions run: the corner at cell (kFrameCornerCells,
  // kFrameCornerCells), so every corner's prediction reuses the same few tiles of the scratch
  // fields (a small window: one), and equal corners predict alike wherever they are (a point
  // is first taken relative to the corner, then shifted: points on a line through the corner
  // keep their exact offsets from it)
  Vec3 frame_corner = Vec3::Zero();
  Vec3 in_frame(const Vec3& p) const { return (p - c) + frame_corner; }
  // the target cells (within half a line width of the centreline, clear of the window's ends)
  // and the centreline's samples, in the order their errors are summed; each holds what the
  // window's own deposit should add to the rolls' (the target less the rolls' deposit there)
  // Each error is weighted into a length of line: a cell's thickness error times its area over
  // the line's cross section (the length that volume would print), a centreline sample's error
  // over the line's peak times a cell of arc length.
  struct TargetCell {
    int ix = 0, iy = 0;
    double missing_mm = 0.0;
    double weight = 0.0;               // cell area / line cross section
    double missing_shared_mm[2] = {};  // less the shared ends' deposit too (per SharedEnds)
  };
  struct CentreSample {
    BilinearPoint point;  // (on the field's cell lattice)
    double missing_mm = 0.0;
    double weight = 0.0;  // cell / line peak
    double missing_shared_mm[2] = {};
  };
  std::vector<TargetCell> cells;
  std::vector<CentreSample> centre;
  // whether every target cell and every cell a centreline sample reads lies in one tile (most
  // windows: the corner is mid-tile), and which
  bool one_tile = false;
  int tile_x = 0, tile_y = 0;
  // calls read(reader) with a reader of the field's cells: a TileReader where one tile holds
  // them all, else a CellReader
  template <class ReadFn>
  auto with_reader(const ThicknessField& field, ReadFn&& read) const {
    if (one_tile) return read(TileReader(field, tile_x, tile_y));
    return read(CellReader(field));
  }
  // the window's shared ends: its first shared_in_mm (from a) and last shared_out_mm (to b),
  // beyond where the candidates of a kind are expected to change anything: every candidate
  // (kBlendEnds: blends, slowed corners and stops), or the loops alone (kLoopEnds: the line at
  // print speed up to the trims, so longer ends). Their deposit, at print speed, is predicted
  // once with the rolls (missing_shared_mm); a candidate found steady on its kind's ends has
  // only the rest of its window predicted, any other the whole window
  enum SharedEnds { kBlendEnds = 0, kLoopEnds = 1 };
  double shared_in_mm[2] = {}, shared_out_mm[2] = {};
  // the process each candidate's window deposit is predicted with, restarted for each
  Process* scratch = nullptr;
};

CornerWindow corner_window(const PrintChain& chain, size_t corner, const CornerGeometry& geometry,
                           const TcpLimits& limits, const PathMotionOptions& options,
                           const DepositModel& model) {
  const double reach = window_reach_mm(chain, corner, geometry, limits, options, model);

  // the window: the two edges around the corner, cut at `reach`. An edge too short to hold a
  // target of its own (within the end clearance and a cell: the next corner a hair away, where
  // the points could not be merged) is taken on straight to `reach` instead: cut at its end,
  // the window would hold no targets near the corner (every candidate's error 0, the crawl
  // chosen) and no room for the speed change (its time a fraction of the plan's)
  CornerWindow w;
  const Vec3& c = chain.points[corner];
  const double edge_in = (c - chain.points[corner - 1]).norm();
  const double edge_out = (chain.points[corner + 1] - c).norm();
  const double sigma = model.settings.footprint_sigma_mm();
  const double short_edge_mm = (kEndClearSigmas + kCellSigmas) * sigma;
  const auto window_end = [&](double edge_mm, const Vec3& end, const Vec3& along) {
    return edge_mm <= reach && edge_mm >= short_edge_mm ? end : Vec3(c + reach * along);
  };
  const Vec3 a = window_end(edge_in, chain.points[corner - 1], -geometry.d_in);
  const Vec3 b = window_end(edge_out, chain.points[corner + 1], geometry.d_out);
  w.a = a, w.b = b, w.c = c;
  // the limits where the corner is: every box the window asks about is clamped into its edges'
  // box on the path, since an edge taken on straight past its end runs out of the path's
  // region, where a delta's limits fall (a short edge at 99 mm/s on x, taken on 39 mm, needed
  // more than its 94 there and refused the whole plan); each edge keeps its own box within it
  // (the limits over both edges' box would hold a line at 100 mm/s to the other's 99.6)
  const Vec3 path_a = edge_in <= reach ? chain.points[corner - 1] : a;
  const Vec3 path_b = edge_out <= reach ? chain.points[corner + 1] : b;
  const Vec3 region_lo = path_a.cwiseMin(c).cwiseMin(path_b);
  const Vec3 region_hi = path_a.cwiseMax(c).cwiseMax(path_b);
  w.limits = limits.same_everywhere()
                 ? limits
                 : TcpLimits(
                       limits.requested(),
                       [limits, region_lo, region_hi](const Vec3& lo, const Vec3& hi) {
                         return limits.over(lo.cwiseMax(region_lo).cwiseMin(region_hi),
                                            hi.cwiseMax(region_lo).cwiseMin(region_hi));
                       },
                       limits.shared_joint_map());
  w.cell_mm = kCellSigmas * sigma;
  w.frame_corner = Vec3(kFrameCornerCells * w.cell_mm, kFrameCornerCells * w.cell_mm, 0.0);
  w.d_in = geometry.d_in, w.d_out = geometry.d_out;
  PrintChain& window = w.chain;
  window.points = {a, c, b};
  window.orientations.assign(3, ToolOrientation{});
  window.edge_speed_mm_s = {chain.edge_speed_mm_s[corner - 1], chain.edge_speed_mm_s[corner]};
  window.edge_path = {0, 0};
  window.edge_source = {chain.edge_source[corner - 1], chain.edge_source[corner]};
  window.point_path = {0, 0, 0};
  window.point_index = {0, 1, 2};
  // the corner's own geometry (its blend shape is the costly part), its blends bounded by the
  // window's edges alone (corner_geometry with no tolerance)
  w.geometry.resize(3);
  for (int i = 0; i < 3; ++i) w.geometry[i].point = window.points[i];
  w.geometry[1] = geometry;
  w.geometry[1].max_half_length_mm = max_blend_half_length(
      geometry, std::min((c - a).norm(), edge_in), std::min((b - c).norm(), edge_out), kInf);
  w.v_in = window.edge_speed_mm_s[0], w.v_out = window.edge_speed_mm_s[1];
  w.lag_s = options.lag_s;
  // the shared ends: the window less what a kind's candidates change and the shutter's lead
  // before a change (less a hundredth of sigma, so a ramp starts clear of them, not on them to
  // rounding). Blends and slowed corners change the lines from their speed change on (to rest
  // at the most) and the largest blend; loops from their largest trims on. Aerosol only: an
  // extruder's flow still settles at the exit, and its command is held over each step, so a
  // window stepped from another start moves its prediction by a per cent or two (enough to
  // flip a near tie: thompson_fig7_delta's 117 deg slowed blend took another size)
  if (model.aerosol() && model.share_window_ends) {
    const double lead_mm = model.shutter_time_s * std::max(w.v_in, w.v_out) +
                           0.01 * model.settings.footprint_sigma_mm();
    const double blend_change_mm = speed_change_reach_mm(chain, corner, limits, options) +
                                   geometry.max_half_length_mm * geometry.tangent_per_length;
    w.shared_in_mm[CornerWindow::kBlendEnds] =
        std::max(0.0, (c - a).norm() - blend_change_mm - lead_mm);
    w.shared_out_mm[CornerWindow::kBlendEnds] =
        std::max(0.0, (b - c).norm() - blend_change_mm - lead_mm);
    const double loop_in_mm = largest_trim_mm(geometry, edge_in, model, kTrimInFractions);
    const double loop_out_mm = largest_trim_mm(geometry, edge_out, model, kTrimFractions);
    w.shared_in_mm[CornerWindow::kLoopEnds] = std::max(0.0, (c - a).norm() - loop_in_mm - lead_mm);
    w.shared_out_mm[CornerWindow::kLoopEnds] =
        std::max(0.0, (b - c).norm() - loop_out_mm - lead_mm);
  }
  return w;
}

// The window's target cells and centreline samples (needed once a candidate's deposit is
// predicted), less the deposit of the pre- and post-roll at print speed before a and after b
// (the lines continuing beyond the window).
void add_targets(CornerWindow& w, const DepositModel& model, PredictionScratch& scratch) {
  const DepositionSettings& settings = model.settings;
  const double sigma = settings.footprint_sigma_mm();
  // (in the corner's own frame)
  const Vec3 a = w.in_frame(w.a), b = w.in_frame(w.b), c = w.in_frame(w.c);

  // the rolls: from the extruder's settled state, long enough for the footprint and the lag
  if (!scratch.rolls) {
    scratch.rolls = make_process(prediction_settings(settings), w.cell_mm);
    scratch.window = make_process(prediction_settings(settings), w.cell_mm);
    // (curves: a halved batch's last two steps in one footprint call, step_batch.hpp)
    scratch.rolls->pair_short_steps(true);
    scratch.window->pair_short_steps(true);
  }
  Process& rolls_process = *scratch.rolls;
  w.scratch = scratch.window.get();
  rolls_process.restart();
  const double roll_mm =
      std::max(kRollSigmas * sigma, kLagSettlingLags * w.lag_s * std::max(w.v_in, w.v_out));
  const double step_s = prediction_step_s(sigma, std::max(w.v_in, w.v_out));
  const auto steady = [&](const Vec3& from, const Vec3& to, double speed, double t0) {
    const double length = (to - from).norm();
    const int steps = std::max(1, static_cast<int>(std::ceil(length / (speed * step_s))));
    const double dt = length / speed / steps;
    rolls_process.start_steady(steady_step(speed));
    for (int k = 0; k < steps; ++k) {
      DepositionStep step = steady_step(speed);
      step.t0_s = t0 + k * dt;
      step.t1_s = t0 + (k + 1) * dt;
      step.p0_mm = from + (to - from) * (static_cast<double>(k) / steps);
      step.p1_mm = from + (to - from) * (static_cast<double>(k + 1) / steps);
      rolls_process.advance(step);
    }
  };

  // the even deposit over the window's target cells: the steady line's cross section at the
  // cell's distance from the nearest centreline point (the rolls' deposit taken off below)
  const double h = w.cell_mm;
  const double r = 0.5 * settings.resolved_line_width_mm();
  const double total_arc = (c - a).norm() + (b - c).norm();
  const double peak_per_area = 1.0 / (sigma * std::sqrt(2.0 * kPi));
  const double areas[2] = {line_area_mm2(settings, w.v_in), line_area_mm2(settings, w.v_out)};
  const Vec3 lo = a.cwiseMin(b).cwiseMin(c) - Vec3::Constant(r + h);
  const Vec3 hi = a.cwiseMax(b).cwiseMax(c) + Vec3::Constant(r + h);
  const int ix_lo = static_cast<int>(std::floor(lo.x() / h));
  const int ix_hi = static_cast<int>(std::ceil(hi.x() / h));
  const WindowPolyline polyline(a, c, b);
  // (room for the band's cells: its length by its width, and the ends' caps)
  w.cells.reserve(static_cast<size_t>((total_arc / h + 2.0 * r / h + 2.0) * (2.0 * r / h + 2.0)));
  w.centre.reserve(static_cast<size_t>(total_arc / h) + 1);
  for (int iy = static_cast<int>(std::floor(lo.y() / h));
       iy <= static_cast<int>(std::ceil(hi.y() / h)); ++iy) {
    // only the row's cells near either edge (in the same order as a scan of the whole row):
    // most of the window's bounding box is far from its two lines
    std::pair<int, int> spans[2];
    for (int e = 0; e < 2; ++e)
      spans[e] = row_cells_near(e == 0 ? a : c, e == 0 ? c : b, iy * h, r, h, ix_lo, ix_hi);
    if (spans[1].first < spans[0].first) std::swap(spans[0], spans[1]);
    for (int e = 0; e < 2; ++e) {
      const int first = e == 1 ? std::max(spans[1].first, spans[0].second + 1) : spans[0].first;
      for (int ix = first; ix <= spans[e].second; ++ix) {
        double distance_squared = 0.0, arc = 0.0;
        int edge = 0;
        polyline.nearest(Eigen::Vector2d(ix * h, iy * h), distance_squared, arc, edge);
        if (distance_squared > r * r * (1.0 + 1e-9) || arc < kEndClearSigmas * sigma ||
            arc > total_arc - kEndClearSigmas * sigma)
          continue;
        // (the root only near the line, and the band's edge decided on it)
        const double distance = std::sqrt(distance_squared);
        if (distance > r) continue;
        CornerWindow::TargetCell cell;
        cell.ix = ix, cell.iy = iy;
        cell.missing_mm =
            areas[edge] * peak_per_area * std::exp(-0.5 * distance * distance / (sigma * sigma));
        cell.weight = h * h / areas[edge];
        w.cells.push_back(cell);
      }
    }
  }
  // and along the centreline itself (where a line's thickness is measured), every cell
  const double leg[2] = {(c - a).norm(), (b - c).norm()};
  for (double arc = kEndClearSigmas * sigma; arc <= total_arc - kEndClearSigmas * sigma; arc += h) {
    const int edge = arc < leg[0] ? 0 : 1;
    const Vec3 p = edge == 0 ? Vec3(a + arc * w.d_in) : Vec3(c + (arc - leg[0]) * w.d_out);
    const double peak = areas[edge] * peak_per_area;
    w.centre.push_back({bilinear_point(p.x(), p.y(), h), peak, h / peak});
  }

  // every deposit of this corner is read at those cells alone: the scratch fields write no
  // other (in each row, from its first such cell to its last); and the one tile they all fall
  // in, if one does (their bounding box's corners do)
  {
    // the cells read: each target, and the four around each centreline sample (two passes:
    // their rows' range, then each row's span)
    const auto for_each_read_cell = [&w](auto&& visit) {
      for (const CornerWindow::TargetCell& cell : w.cells) visit(cell.ix, cell.iy);
      for (const CornerWindow::CentreSample& sample : w.centre)
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx) visit(sample.point.ix0 + dx, sample.point.iy0 + dy);
    };
    ThicknessField::WriteRegion region;
    if (!w.cells.empty() || !w.centre.empty()) {
      int iy_low = std::numeric_limits<int>::max(), iy_high = std::numeric_limits<int>::min();
      for_each_read_cell(
          [&](int, int iy) { iy_low = std::min(iy_low, iy), iy_high = std::max(iy_high, iy); });
      region.iy_lo = iy_low;
      region.spans.assign(static_cast<size_t>(iy_high - iy_low + 1),
                          {std::numeric_limits<int>::max(), std::numeric_limits<int>::min()});
      int ix_first = std::numeric_limits<int>::max(), ix_last = std::numeric_limits<int>::min();
      for_each_read_cell([&](int ix, int iy) {
        std::pair<int, int>& span = region.spans[static_cast<size_t>(iy - region.iy_lo)];
        span.first = std::min(span.first, ix), span.second = std::max(span.second, ix);
        ix_first = std::min(ix_first, ix), ix_last = std::max(ix_last, ix);
      });
      using Tiles = ThicknessField::Tiles;
      w.tile_x = Tiles::tile_of(ix_first), w.tile_y = Tiles::tile_of(iy_low);
      w.one_tile = Tiles::tile_of(ix_last) == w.tile_x && Tiles::tile_of(iy_high) == w.tile_y;
    }
    rolls_process.limit_writes(region);
    w.scratch->limit_writes(std::move(region));
  }

  // the rolls' deposit, taken off the targets
  steady(a - roll_mm * w.d_in, a, w.v_in, -roll_mm / w.v_in);
  steady(b, b + roll_mm * w.d_out, w.v_out, 0.0);

  // the targets' readings of the rolls' field: the rolls alone, then as the shared ends are
  // deposited with them (after them in time)
  // (in the scratch's buffers, kept from corner to corner)
  using Reading = PredictionScratch::FieldReading;
  std::vector<Reading>& readings = scratch.readings;
  scratch.readings_used = 0;
  const auto read = [&w, &rolls_process, &scratch]() {
    if (scratch.readings_used == scratch.readings.size()) scratch.readings.emplace_back();
    Reading& reading = scratch.readings[scratch.readings_used++];
    w.with_reader(rolls_process.field(), [&](auto&& reader) {
      reading.cells.resize(w.cells.size());
      for (size_t k = 0; k < w.cells.size(); ++k)
        reading.cells[k] = reader.at(w.cells[k].ix, w.cells[k].iy);
      reading.centre.resize(w.centre.size());
      for (size_t k = 0; k < w.centre.size(); ++k)
        reading.centre[k] = reader.interpolated(w.centre[k].point);
    });
    return static_cast<int>(scratch.readings_used) - 1;
  };
  // what the window's own deposit should add: the target less the rolls'
  const int rolls_only = read();
  for (size_t k = 0; k < w.cells.size(); ++k)
    w.cells[k].missing_mm -= readings[rolls_only].cells[k];
  for (size_t k = 0; k < w.centre.size(); ++k)
    w.centre[k].missing_mm -= readings[rolls_only].centre[k];

  // the shared ends: on each side the kinds' ends in order of length, each piece from where the
  // last ended, the targets read after each (a kind whose end adds nothing shares the last
  // reading). A kind's ends add to the targets what its pieces did (the deposit is linear)
  constexpr int kKinds = 2;
  double t_s = roll_mm / w.v_out;  // (aerosol: the times only order the steps)
  // side 0: from a along d_in; side 1: back from b along -d_out
  int side_start[2] = {rolls_only, rolls_only}, after_kind[2][kKinds] = {};
  int last = rolls_only;
  for (int side = 0; side < 2; ++side) {
    const double* shared_mm = side == 0 ? w.shared_in_mm : w.shared_out_mm;
    const Vec3 from = side == 0 ? a : b;
    const Vec3 along = side == 0 ? w.d_in : Vec3(-w.d_out);
    const double speed = side == 0 ? w.v_in : w.v_out;
    side_start[side] = last;
    int order[kKinds] = {CornerWindow::kBlendEnds, CornerWindow::kLoopEnds};
    if (shared_mm[order[1]] < shared_mm[order[0]]) std::swap(order[0], order[1]);
    double deposited_mm = 0.0;
    for (const int kind : order) {
      if (shared_mm[kind] > deposited_mm) {
        // (the outgoing side printed towards b, as the window does)
        const Vec3 p0 = from + deposited_mm * along, p1 = from + shared_mm[kind] * along;
        if (side == 0)
          steady(p0, p1, speed, t_s);
        else
          steady(p1, p0, speed, t_s);
        t_s += (shared_mm[kind] - deposited_mm) / speed + 1.0;
        deposited_mm = shared_mm[kind];
        last = read();
      }
      after_kind[side][kind] = last;
    }
  }
  for (int kind = 0; kind < kKinds; ++kind) {
    // what the kind's two ends added: (after its in-end less before it) + (the same out)
    const Reading &in_before = readings[side_start[0]], &in_after = readings[after_kind[0][kind]];
    const Reading &out_before = readings[side_start[1]], &out_after = readings[after_kind[1][kind]];
    for (size_t k = 0; k < w.cells.size(); ++k)
      w.cells[k].missing_shared_mm[kind] =
          w.cells[k].missing_mm -
          ((in_after.cells[k] - in_before.cells[k]) + (out_after.cells[k] - out_before.cells[k]));
    for (size_t k = 0; k < w.centre.size(); ++k)
      w.centre[k].missing_shared_mm[kind] =
          w.centre[k].missing_mm - ((in_after.centre[k] - in_before.centre[k]) +
                                    (out_after.centre[k] - out_before.centre[k]));
  }
}

// Whether a window's plan prints its shared ends as the rolls' prediction of them does: on the
// incoming line at print speed from a, and (when there is a shared exit) on the outgoing one at
// print speed up to b, the material fully on throughout. A phase-timed piece (a line's profile)
// is checked exactly: where no phase overlapping the span accelerates or jerks, the motion is
// linear, and its two ends decide; any other piece is sampled every step_s and at its ends.
bool steady_on_shared_ends(const CornerWindow& w, int kind, const Trajectory& motion,
                           const std::vector<std::pair<double, double>>& closed,
                           const DepositModel& model, double step_s) {
  constexpr double kTolerance = 1e-9;
  const double duration = motion.duration_s();
  TrajectoryCursor cursor(motion);
  // the plan's position and velocity at time t against the steady line through `from` along d
  // at speed v, there at t0
  const auto on_line = [&](double t, const Vec3& position, const Vec3& velocity, const Vec3& from,
                           const Vec3& d, double v, double t0) {
    return (position - (from + (t - t0) * v * d)).norm() <= kTolerance * (1.0 + v) &&
           (velocity - v * d).norm() <= kTolerance * v;
  };
  const auto steady_over = [&](double t_first, double t_last, const Vec3& from, const Vec3& d,
                               double v, double t0) {
    // the shutter fully open: no closed span overlaps [t, t + its time] for t in the span
    for (const auto& [close, open] : closed)
      if (open > close && close < t_last + model.shutter_time_s && open > t_first) return false;
    for (int index = 0; index < static_cast<int>(motion.pieces().size()); ++index) {
      const TrajectoryPiece& piece = motion.pieces()[index];
      if (piece.t_begin_s > t_last || piece.t_end_s < t_first) continue;
      const double t_a = std::max(t_first, piece.t_begin_s), t_b = std::min(t_last, piece.t_end_s);
      const auto* phases = std::get_if<PhaseMotion>(&piece.motion);
      if (phases == nullptr) {
        const int samples = std::max(1, static_cast<int>(std::ceil((t_b - t_a) / step_s)));
        for (int k = 0; k <= samples; ++k) {
          const double t = k == samples ? t_b : t_a + k * (t_b - t_a) / samples;
          const TrajectorySample sample = cursor.at(t);
          if (!sample.depositing || std::abs(sample.flow_fraction - 1.0) > kTolerance ||
              !on_line(t, sample.position_mm, sample.velocity_mm_s, from, d, v, t0))
            return false;
        }
        continue;
      }
      // (the flow at constant velocity: the piece's fraction, or the speed over the desired one
      // when it follows the speed)
      if (!piece.depositing) return false;
      const double flow =
          piece.flow_lead_s >= 0.0
              ? (piece.desired_speed_mm_s > 0.0 ? v / piece.desired_speed_mm_s : 0.0)
              : piece.flow_fraction;
      if (std::abs(flow - 1.0) > kTolerance) return false;
      const double tau_a = t_a - piece.t_begin_s, tau_b = t_b - piece.t_begin_s;
      Vec3 position_a, velocity_a, position_b, velocity_b;
      for (int axis = 0; axis < 3; ++axis) {
        const AxisProfile& profile = phases->axes[axis];
        for (const Phase& phase : profile.phases())
          if (phase.t_begin_s < tau_b && phase.t_begin_s + phase.duration_s > tau_a &&
              (phase.a0 != 0.0 || phase.jerk != 0.0))
            return false;
        const AxisState state_a = profile.at(tau_a), state_b = profile.at(tau_b);
        position_a[axis] = state_a.q, velocity_a[axis] = state_a.v;
        position_b[axis] = state_b.q, velocity_b[axis] = state_b.v;
      }
      if (!on_line(t_a, position_a, velocity_a, from, d, v, t0) ||
          !on_line(t_b, position_b, velocity_b, from, d, v, t0))
        return false;
    }
    return true;
  };
  const double in_mm = w.shared_in_mm[kind], out_mm = w.shared_out_mm[kind];
  if (in_mm > 0.0 && !steady_over(0.0, in_mm / w.v_in, w.a, w.d_in, w.v_in, 0.0)) return false;
  if (out_mm > 0.0 &&
      !steady_over(duration - out_mm / w.v_out, duration, w.b, w.d_out, w.v_out, duration))
    return false;
  return true;
}

// The predicted error and extra time of one corner plan in its window (see the header). A plan
// whose extra time alone costs at least prune_above_mm is not deposited (pruned); one whose
// deposit so far already costs more than abandon_above_mm is deposited no further (abandoned:
// its error and cost are then lower bounds).
CornerCandidate evaluate_corner(CornerWindow& w, const CornerPlan& plan,
                                const PathMotionOptions& options, const DepositModel& model,
                                double time_weight_mm_s, double prune_above_mm,
                                double abandon_above_mm = kInf) {
  const DepositionSettings& settings = model.settings;
  const double sigma = settings.footprint_sigma_mm();
  const Vec3 &a = w.a, &b = w.b, &c = w.c;
  std::vector<CornerPlan> plans(3);
  plans[1] = plan;
  PathMotionOptions window_options = options;
  window_options.enter_at_speed = window_options.leave_at_speed = true;
  // its blend sampled twice a prediction step at the finest (the samples are interpolated by
  // their velocities; the chosen plan is sampled at options.period_s)
  window_options.period_s =
      std::max(options.period_s, 0.5 * prediction_step_s(sigma, std::max(w.v_in, w.v_out)));
  PlannedPath planned = plan_chain(w.chain, w.geometry, plans, w.limits, window_options, 0.0);
  const Trajectory motion("uniform", std::move(planned.pieces));
  const double duration = motion.duration_s();
  const double v_in = w.v_in, v_out = w.v_out;
  CornerCandidate candidate;
  candidate.plan = plan;
  candidate.extra_time_s = duration - ((c - a).norm() / v_in + (b - c).norm() / v_out);
  candidate.speed_mm_s = planned.corner_speed_mm_s[1];
  // its time alone costs more than the best so far: no need to predict its deposit
  if (time_weight_mm_s * candidate.extra_time_s >= prune_above_mm) {
    candidate.pruned = true;
    candidate.cost = time_weight_mm_s * candidate.extra_time_s;
    return candidate;
  }

  // the deposit of the window's plan, the extruder settled at print speed as the pre-roll
  // leaves it (the rolls' deposit, shared by every candidate, is taken off the targets); on
  // [t_begin, t_end], the window less its shared ends when the plan is steady on them
  Process* process = w.scratch;
  process->restart();
  process->start_steady(steady_step(v_in));
  const double step_s = prediction_step_s(sigma, std::max(v_in, v_out));
  const auto closed = closed_spans(motion);
  const int kind =
      plan.treatment == CornerTreatment::loop ? CornerWindow::kLoopEnds : CornerWindow::kBlendEnds;
  const double shared_in_s = w.shared_in_mm[kind] / v_in;
  const double shared_out_s = w.shared_out_mm[kind] / v_out;
  const bool shared = shared_in_s + shared_out_s < duration &&
                      steady_on_shared_ends(w, kind, motion, closed, model, step_s);
  const double t_begin = shared ? shared_in_s : 0.0;
  const double t_end = shared ? duration - shared_out_s : duration;
  const int steps = std::max(1, static_cast<int>(std::ceil((t_end - t_begin) / step_s)));
  const double dt = (t_end - t_begin) / steps;
  TrajectoryCursor cursor(motion);
  TrajectorySample before = cursor.at(t_begin);
  bool shut_before = false, before_stale = false;
  // an aerosol plan with the shutter open throughout (a blend) takes as many grid steps at once,
  // up to kMaxMergedSteps, as keep its chord within kStepSigmas: a slowed corner's chords are
  // then as long as the print speed's (the stream is constant, the chord integrated exactly)
  const bool merge_slow_steps = model.aerosol() && closed.empty();
  const double longest_chord_mm = kStepSigmas * sigma;
  // the time of grid point k (the last one exactly t_end)
  const auto grid_time = [&](int k) { return k == steps ? t_end : t_begin + k * dt; };

  // the error of the field's deposit against the even deposit over the window's target cells,
  // then along its centreline (the rolls' deposit is in the targets' missing_mm). Partway
  // (excess_only), only where the deposit already exceeds its target: the rest of the window
  // adds material and never takes any away, so that much error remains (a lower bound)
  const ThicknessField& field = process->field();
  const auto error_so_far = [&](bool excess_only) {
    return w.with_reader(field, [&](auto&& cells) {
      const auto part = [excess_only](double deposit, double target) {
        return excess_only ? std::max(0.0, deposit - target) : std::abs(deposit - target);
      };
      double error_mm = 0.0;
      for (const CornerWindow::TargetCell& cell : w.cells)
        error_mm += part(cells.at(cell.ix, cell.iy),
                         shared ? cell.missing_shared_mm[kind] : cell.missing_mm) *
                    cell.weight;
      for (const CornerWindow::CentreSample& sample : w.centre)
        error_mm += part(cells.interpolated(sample.point),
                         shared ? sample.missing_shared_mm[kind] : sample.missing_mm) *
                    sample.weight;
      return error_mm;
    });
  };
  const double time_cost_mm = time_weight_mm_s * candidate.extra_time_s;
  // the abandon checks: at three quarters of the steps and at seven eighths (a slowed corner's
  // excess comes as it passes the corner and after; earlier checks cost more than they saved)
  int next_check = std::isfinite(abandon_above_mm) ? 3 * steps / 4 : steps;
  for (int k = 0; k < steps;) {
    if (k >= next_check) {
      next_check += std::max(1, steps / 8);
      const double excess_mm = error_so_far(true);
      if (excess_mm + time_cost_mm > abandon_above_mm) {
        candidate.abandoned = true;
        candidate.error_mm = excess_mm;
        candidate.cost = excess_mm + time_cost_mm;
        return candidate;
      }
    }
    const double t0 = grid_time(k);
    int taken = 1;
    TrajectorySample after;
    if (merge_slow_steps) {
      // (clamped as a double: at rest the ratio is infinite)
      const double fit = longest_chord_mm / (before.velocity_mm_s.norm() * dt);
      taken = static_cast<int>(std::clamp(fit, 1.0, static_cast<double>(kMaxMergedSteps)));
      taken = std::min(taken, steps - k);
      after = cursor.at(grid_time(k + taken));
      // (an accelerating plan may have run further: one grid step then)
      if (taken > 1 && (after.position_mm - before.position_mm).norm() > longest_chord_mm) {
        taken = 1;
        after = cursor.at(grid_time(k + 1));
      }
    }
    k += taken;
    const double t1 = grid_time(k);
    const double open0 = open_fraction(closed, t0, model.shutter_time_s);
    const double open1 = open_fraction(closed, t1, model.shutter_time_s);
    // an aerosol's shut shutter lets nothing through: after the first such step (which ends
    // the run of batched steps), the rest of the loop need not be followed
    const bool shut = model.aerosol() && open0 == 0.0 && open1 == 0.0;
    const bool skip = shut && shut_before;
    shut_before = shut;
    if (skip) {
      before_stale = true;
      continue;
    }
    if (before_stale) before = cursor.at(t0);
    before_stale = false;
    if (!merge_slow_steps) after = cursor.at(t1);
    DepositionStep step;
    step.t0_s = t0;
    step.t1_s = t1;
    step.p0_mm = w.in_frame(before.position_mm);  // the corner's frame (add_targets)
    step.p1_mm = w.in_frame(after.position_mm);
    step.open0 = open0;
    step.open1 = open1;
    step.flow_command = before.depositing ? before.flow_fraction : 0.0;
    step.desired_speed_mm_s = before.desired_speed_mm_s;
    process->advance(step);
    before = after;
  }
  process->flush();
  candidate.error_mm = error_so_far(false);
  candidate.cost = candidate.error_mm + time_cost_mm;
  return candidate;
}

}  // namespace

CornerDecision choose_corner(const PrintChain& chain, size_t corner,
                             const std::vector<CornerGeometry>& geometry, const TcpLimits& limits,
                             const PathMotionOptions& options, const DepositModel& model,
                             double time_weight_mm_s, PredictionScratch& scratch) {
  const CornerGeometry& g = geometry[corner];
  const double speed = chain.corner_print_speed_mm_s(corner);
  CornerWindow window = corner_window(chain, corner, g, limits, options, model);
  std::vector<CornerCandidate> candidates;
  double best = std::numeric_limits<double>::infinity();
  // evaluates a candidate (its deposit only when its time alone does not already cost more
  // than the best so far; with `may_abandon`, only until its deposit does) and returns it
  const auto add = [&](const std::string& name, const CornerPlan& plan, bool may_abandon) {
    const bool abandon = may_abandon && model.abandon_costly_predictions;
    CornerCandidate candidate = evaluate_corner(window, plan, options, model, time_weight_mm_s,
                                                best, abandon ? best : kInf);
    candidate.name = name;
    candidates.push_back(candidate);
    if (!candidate.pruned && !candidate.abandoned) best = std::min(best, candidate.cost);
    return candidate;
  };

  // the least blend that keeps the print speed, when it fits the tolerance
  CornerPlan full_speed;
  bool full_speed_fits = false;
  if (g.max_half_length_mm > 0.0) {
    const MachineLimits box = corner_blend_limits(g, g.max_half_length_mm, limits);
    const double needed = blend_half_length_for_speed(g.shape, speed, box);
    if (needed <= g.max_half_length_mm) {
      full_speed.treatment = CornerTreatment::blend;
      full_speed.half_length_mm = std::max(needed, 1e-9 * g.max_half_length_mm);
      full_speed_fits = true;
    }
  }
  if (full_speed_fits && overlap_mm(g, model) <= 0.0) {
    // at 90 deg or more the lines do not overlap: the only candidate, the print speed kept
    // within the tolerance, nothing to weigh it against (its deposit is not predicted; its
    // time is)
    CornerCandidate candidate =
        evaluate_corner(window, full_speed, options, model, time_weight_mm_s, -kInf);
    candidate.name = "blend";
    candidates.push_back(candidate);
  } else {
    add_targets(window, model, scratch);
    // loops, printing resuming past the overlap of the two lines at a sharp corner (aerosol:
    // at print speed, the shutter closed; extrusion: the line ends at rest, the nozzle travels
    // with the flow off and the next line starts from rest, where the overlap calls for a trim)
    const auto add_loops = [&]() {
      if (!options.loops_allowed) return;
      const double overlap = overlap_mm(g, model);
      if (!model.aerosol() && overlap <= 0.0) return;
      const double edge_in = (chain.points[corner] - chain.points[corner - 1]).norm();
      const double edge_out = (chain.points[corner + 1] - chain.points[corner]).norm();
      double last_in = -1.0;
      for (const double in_fraction : kTrimInFractions) {
        const double trim_in = std::min(in_fraction * overlap, kMaxTrimShare * edge_in);
        if (trim_in <= last_in) continue;
        last_in = trim_in;
        double last_out = -1.0, previous = std::numeric_limits<double>::infinity();
        for (const double fraction : kTrimFractions) {
          CornerPlan plan;
          plan.treatment = CornerTreatment::loop;
          plan.trim_in_mm = trim_in;
          plan.trim_out_mm = std::min(fraction * overlap, kMaxTrimShare * edge_out);
          if (plan.trim_out_mm <= last_out) continue;
          last_out = plan.trim_out_mm;
          // (an extruder's loop without trims is the stop)
          if (!model.aerosol() && plan.trim_in_mm + plan.trim_out_mm <= 0.0) continue;
          const double cost = add("loop", plan, false).cost;
          if (cost > previous) break;
          previous = cost;
        }
      }
    };
    // slowed corners: smaller blends while they pay (the cost is unimodal in the size here);
    // with `still_competing`, also only while they beat the best candidate so far, and one whose
    // deposit partway already costs more than that is abandoned
    const auto add_slowed = [&](bool still_competing) {
      if (g.max_half_length_mm <= 0.0) return;
      CornerPlan plan;
      plan.treatment = CornerTreatment::blend;
      double previous = std::numeric_limits<double>::infinity();
      for (const double share : kSlowBlendShares) {
        plan.half_length_mm = share * g.max_half_length_mm;
        const double best_before = best;
        const CornerCandidate slow = add("slow", plan, still_competing);
        if (slow.abandoned || slow.cost > previous || (still_competing && slow.cost > best_before))
          break;
        previous = slow.cost;
      }
    };
    if (full_speed_fits) {
      // a sharper joint taken at print speed: its lines still overlap next to the corner, so
      // the blend is weighed against the loops, which trim the overlap
      add("blend", full_speed, false);
      add_loops();
    } else if (model.aerosol()) {
      // the stream cannot follow the speed: a slowed corner thickens the line as 1 / v, and
      // beats a loop seldom (on bench_uniform's 462 such corners, never where its largest blend
      // did not). The loops first, so the slowed corners can stop as soon as they cannot win
      add_loops();
      add_slowed(true);
      // no loop allowed and no blend to slow: the corner taken at rest
      if (candidates.empty()) {
        CornerPlan plan;
        plan.treatment = CornerTreatment::stop;
        add("stop", plan, false);
      }
    } else {
      // an extruder's flow follows the speed: slowed corners compete, and smaller blends may
      // win after a larger one lost (at 60 deg: the third), so their series runs in full
      add_slowed(false);
      CornerPlan plan;
      plan.treatment = CornerTreatment::stop;
      add("stop", plan, false);
      add_loops();
    }
  }
  if (candidates.empty()) throw InternalError("uniform: a corner without candidates");
  CornerDecision decision;
  decision.chosen = candidates.front();
  for (const CornerCandidate& candidate : candidates)
    if (!candidate.pruned && !candidate.abandoned &&
        (decision.chosen.pruned || decision.chosen.abandoned ||
         candidate.cost < decision.chosen.cost))
      decision.chosen = candidate;
  decision.candidates = std::move(candidates);
  return decision;
}

double even_line_error_per_mm(const DepositModel& model) {
  const double sigma = model.settings.footprint_sigma_mm();
  return 1.0 + std::erf(0.5 * model.settings.resolved_line_width_mm() / (std::sqrt(2.0) * sigma));
}

ConstantSpeedChain constant_speed_chain(const PrintChain& chain,
                                        const std::vector<CornerGeometry>& geometry,
                                        double tolerance_mm,
                                        const std::vector<double>& edge_error_mm,
                                        const TcpLimits& limits, const PathMotionOptions& options,
                                        const DepositModel& model, double worth_below_mm) {
  ConstantSpeedChain none;
  if (!model.aerosol() || chain.oriented || chain.edges() == 0) return none;
  const double print_speed = chain.edge_speed_mm_s.front();
  for (const double speed : chain.edge_speed_mm_s)
    if (speed != print_speed) return none;

  // each corner's largest blend: geometry's, except that a corner next to an end of the chain
  // may take that end's whole edge (no blend at the end shares it; the chain enters and
  // leaves at the speed)
  const size_t n = chain.points.size();
  std::vector<double> largest(n, 0.0);
  for (size_t i = 1; i + 1 < n; ++i) {
    const CornerGeometry& g = geometry[i];
    largest[i] = g.max_half_length_mm;
    if ((i == 1 || i + 2 == n) && largest[i] > 0.0) {
      const double edge_in = (chain.points[i] - chain.points[i - 1]).norm();
      const double edge_out = (chain.points[i + 1] - chain.points[i]).norm();
      // (max_blend_half_length leaves half of each edge: an end edge counted twice is whole)
      largest[i] = max_blend_half_length(g, i == 1 ? 2.0 * edge_in : edge_in,
                                         i + 2 == n ? 2.0 * edge_out : edge_out,
                                         corner_tolerance_mm(tolerance_mm, edge_error_mm, i));
    }
  }
  // the speed: what every corner's largest blend within the tolerance takes
  double speed = print_speed;
  for (size_t i = 1; i + 1 < n; ++i) {
    const CornerGeometry& g = geometry[i];
    if (taken_straight_on(g)) continue;
    if (!(largest[i] > 0.0)) return none;  // a reversal: no blend
    // (a joint sharper than 90 deg: its two lines overlap next to it, an error of the corner's
    // own that the even line's does not count)
    if (overlap_mm(g, model) > 0.0) return none;
    speed = std::min(
        speed, blend_speed_bound(g.shape, largest[i], corner_blend_limits(g, largest[i], limits)));
  }
  if (!(speed > 0.0)) return none;

  // the even line's error against the target
  ConstantSpeedChain constant;
  double length_mm = 0.0;
  for (size_t e = 0; e < chain.edges(); ++e)
    length_mm += (chain.points[e + 1] - chain.points[e]).norm();
  constant.error_mm = (print_speed / speed - 1.0) * even_line_error_per_mm(model) * length_mm;
  if (!(constant.error_mm < worth_below_mm)) return none;  // (not planned: it cannot win)

  // the chain planned at it: each corner the least blend that takes it
  constant.speed_mm_s = speed;
  constant.corners.assign(n, CornerPlan{});
  for (size_t i = 1; i + 1 < n; ++i) {
    const CornerGeometry& g = geometry[i];
    if (taken_straight_on(g)) continue;
    const MachineLimits box = corner_blend_limits(g, largest[i], limits);
    constant.corners[i].treatment = CornerTreatment::blend;
    constant.corners[i].half_length_mm =
        std::clamp(blend_half_length_for_speed(g.shape, speed, box), 1e-9 * largest[i], largest[i]);
  }
  PrintChain slowed = chain;
  slowed.edge_speed_mm_s.assign(chain.edges(), speed);
  constant.planned = plan_chain(slowed, geometry, constant.corners, limits, options, 0.0);
  // (the look-ahead slows no node below it: the line is even throughout)
  for (size_t i = 1; i + 1 < n; ++i)
    if (constant.corners[i].treatment == CornerTreatment::blend &&
        !(constant.planned.corner_speed_mm_s[i] >= speed * (1.0 - 1e-9)))
      return none;
  for (TrajectoryPiece& piece : constant.planned.pieces)
    if (piece.depositing) piece.desired_speed_mm_s = print_speed;
  return constant;
}

std::vector<uint64_t> CornerDecisionCache::corner_key(const PrintChain& chain, size_t corner,
                                                      const std::vector<CornerGeometry>& geometry) {
  std::vector<uint64_t> key;
  key.reserve(40);
  const auto add = [&key](double value) {
    uint64_t bits = 0;
    std::memcpy(&bits, &value, sizeof bits);
    key.push_back(bits);
  };
  const auto add_vector = [&add](const Vec3& v) {
    for (int axis = 0; axis < 3; ++axis) add(v[axis]);
  };
  // the three points: (x, y), and the heights unless the corner is planar (then a marker)
  const Vec3& a = chain.points[corner - 1];
  const Vec3& c = chain.points[corner];
  const Vec3& b = chain.points[corner + 1];
  const CornerGeometry& g = geometry[corner];
  for (const Vec3* p : {&a, &c, &b, &g.point}) {
    add(p->x());
    add(p->y());
  }
  const bool planar = a.z() == c.z() && b.z() == c.z() && g.point.z() == c.z();
  key.push_back(planar ? 1 : 0);
  if (!planar)
    for (const Vec3* p : {&a, &c, &b, &g.point}) add(p->z());
  // the edges' speeds and the corner's geometry
  add(chain.edge_speed_mm_s[corner - 1]);
  add(chain.edge_speed_mm_s[corner]);
  add_vector(g.d_in);
  add_vector(g.d_out);
  add(g.turn_rad);
  add(g.interior_deg);
  add(g.tangent_per_length);
  add(g.deviation_per_length);
  add_vector(g.shape.tangent);
  add_vector(g.shape.curvature);
  add_vector(g.shape.third);
  add(g.max_half_length_mm);
  return key;
}

size_t CornerDecisionCache::KeyHash::operator()(const std::vector<uint64_t>& key) const {
  // each word mixed by splitmix64's finaliser into the running hash
  uint64_t hash = key.size();
  for (const uint64_t word : key) {
    uint64_t z = word + 0x9e3779b97f4a7c15ull + hash;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    hash = z ^ (z >> 31);
  }
  return static_cast<size_t>(hash);
}

}  // namespace depotwin
