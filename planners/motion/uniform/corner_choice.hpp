// How `uniform` takes each corner, chosen by predicting the deposit with the project's own
// deposition model (deposition/process.hpp: the Gaussian footprint integrated along the
// nozzle's chords, the aerosol shutter's open fraction, the extruder's flow lag).
//
// Candidates at a corner of interior angle alpha (the joint angle, 180 deg straight on):
//   blend   the least clothoid blend that keeps the print speed (constant-speed blend), when it
//           fits the tolerance and the room on the edges;
//   slow    the largest blend within the tolerance, at the lower constant speed its curvature
//           allows (a slowed corner: the lines slow down to it and speed up after it);
//   loop    printing stops trim_in before the corner and resumes trim_out past it, where that
//           evens the overlap of the two lines at a sharp corner (the trims are searched over
//           fractions of 2 sigma / sin(alpha), the length over which the lines overlap).
//           Aerosol: the shutter closes, the nozzle loops with the shutter closed and the next
//           line resumes at print speed. Extrusion, at joints sharper than 90 deg and with a
//           trim: the line ends at rest, the nozzle travels with the flow off and the next line
//           starts from rest (the flow follows the speed at both);
//   stop    extrusion only: the path comes to rest at the corner (the flow follows the speed).
// A corner of 90 deg or more that the least blend takes at print speed has that one candidate:
// its deposit is not predicted. At a sharper one the two lines overlap next to the corner even
// at print speed: that blend is predicted and weighed against the loops. Otherwise, for each
// candidate, a window of the path around the corner (the two edges, as far as the slowest
// candidate's speed change and the flow lag's settling after it, the largest blend and the largest
// trim its loops try, plus 6 sigma) is planned as the planner will plan it (entering and leaving at
// print speed), its deposit predicted step by step (at most 10 ms and a quarter sigma of travel;
// the footprint cut at 4 sigma) from the extruder's settled state, plus pre- and post-rolls at
// print speed so the window's ends deposit as a continuing line would (the rolls' deposit is the
// same for every candidate: predicted once), and compared with the even deposit the process
// engineer asks for: on every cell within half a line width of the window's centreline (1 sigma
// clear of its ends), the steady line's cross section at the cell's distance from the nearest
// centreline point (the union of the lines: where two lines meet at a sharp corner the target is
// not their doubled sum). The predicted thickness error is
//   E = sum |T - T*| cell^2 / A_line   (mm: the length of line whose material is misplaced;
//                                        A_line the steady line's cross-section area)
// and the cost E + time_weight * (window time - window length / print speed): time_weight is
// in mm/s, the length of misplaced line one second of extra time is worth. The cheapest
// candidate is taken.
// Order and shortcuts: a candidate whose extra time alone costs more than the best so far is
// not predicted (pruned). Aerosol: the loops first, then the slowed blends only while they still
// beat the best so far (the stream cannot follow the speed: a slowed corner thickens as 1 / v;
// a search rule, which changed no choice on bench_uniform's 462 predicted corners nor on the
// comparison scenarios); a slowed blend whose deposit partway already exceeds its targets by
// more than the best's cost is abandoned (the deposit only grows: it cannot win). Extrusion:
// the slowed blends' whole series, the stop, then the loops.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/limits.hpp"
#include "deposition/process.hpp"
#include "planners/motion/uniform/path_plan.hpp"

namespace depotwin {

// the process as the planner predicts it
struct DepositModel {
  DepositionSettings settings;
  double shutter_time_s = 0.02;
  // aerosol: a candidate steady on its window's ends takes their deposit from the rolls' (see
  // corner_choice.cpp, CornerWindow); off, every candidate's whole window is predicted (the
  // tests compare the two)
  bool share_window_ends = true;
  // a slowed corner whose deposit partway already costs more than the best candidate so far is
  // predicted no further (CornerCandidate::abandoned); off, it is predicted to its end (the
  // tests compare the two)
  bool abandon_costly_predictions = true;
  bool aerosol() const { return settings.type == ProcessType::aerosol; }
};

struct CornerCandidate {
  std::string name;  // blend, slow, loop, stop
  CornerPlan plan;
  double error_mm = 0.0;      // predicted thickness error over the window
  double extra_time_s = 0.0;  // the window's time beyond its length at print speed
  double cost = 0.0;
  double speed_mm_s = 0.0;  // the speed the corner is printed at (loop: the lines' speed)
  // its time alone costs more than a candidate already evaluated: the deposit was not
  // predicted (error_mm 0, cost its time's share only)
  bool pruned = false;
  // its deposit partway already cost more than a candidate already evaluated: predicted no
  // further (error_mm and cost are lower bounds: the excess over the targets so far)
  bool abandoned = false;
};

// The processes the corner predictions reuse, restarted for each corner and candidate (one per
// planning: not to be shared between threads).
struct PredictionScratch {
  std::unique_ptr<Process> rolls, window;
  // a corner's readings of the rolls' field at its target cells and centreline samples (the
  // first `readings_used` are this corner's; each keeps its capacity from corner to corner)
  struct FieldReading {
    std::vector<double> cells, centre;
  };
  std::vector<FieldReading> readings;
  size_t readings_used = 0;
};

struct CornerDecision {
  CornerCandidate chosen;
  std::vector<CornerCandidate> candidates;  // every one evaluated, the chosen among them
};

// The treatment of interior point `corner` of the chain (geometry: corner_geometry of its
// points), its candidates evaluated as above. `limits` must carry jerk limits.
CornerDecision choose_corner(const PrintChain& chain, size_t corner,
                             const std::vector<CornerGeometry>& geometry, const TcpLimits& limits,
                             const PathMotionOptions& options, const DepositModel& model,
                             double time_weight_mm_s, PredictionScratch& scratch);

// Aerosol: the whole chain printed at one constant speed, every corner a blend at it (the
// scale-down Shembekar et al. apply to a path and `conformal` does on the joints). A stream
// that cannot follow the speed then lays an even line everywhere, thicker by print speed /
// that speed, where a corner taken alone (slowed or looped) leaves a bump or a seam: on a
// small circle of fine chords no corner keeps the print speed (4 mm at 50 mm/s: 27 loops in
// 31 corners, 6.25 s against lspb_mtt's 0.74 s). The speed is the largest every corner's
// largest blend within the tolerance takes (blend_speed_bound; a corner next to an end of the
// chain may take that end's whole edge), the print speed at the most; its thickness error is
// the even line's against the target, summed as a corner's is (the band's cells and the
// centreline's samples, E = (print speed / speed - 1) (1 + erf(w / (2 sqrt 2 sigma))) x the
// chain's length, w the line width). speed_mm_s 0: no such plan (an extrusion chain, one of
// several print speeds or carrying the tool's orientation, a corner with no blend or sharper
// than 90 deg, where the two lines overlap next to it whatever the speed, or one the
// look-ahead would slow further). The pieces keep the print speed as their desired speed: the
// slow-down shows as a speed error.
struct ConstantSpeedChain {
  double speed_mm_s = 0.0;
  std::vector<CornerPlan> corners;  // per point (ends and straights: straight)
  PlannedPath planned;
  double error_mm = 0.0;
};
// the misplaced line per mm of path where an even line is laid thicker than the target by its
// whole cross section (summed as a corner's error is: the band's cells, the share
// erf(w / (2 sqrt 2 sigma)) of the line's cross section, and the centreline's samples)
double even_line_error_per_mm(const DepositModel& model);
// (geometry: corner_geometry(chain.points, tolerance_mm, edge_error_mm); not planned, speed
// 0, when its error alone is worth_below_mm or more: it cannot beat what costs that)
ConstantSpeedChain constant_speed_chain(const PrintChain& chain,
                                        const std::vector<CornerGeometry>& geometry,
                                        double tolerance_mm,
                                        const std::vector<double>& edge_error_mm,
                                        const TcpLimits& limits, const PathMotionOptions& options,
                                        const DepositModel& model, double worth_below_mm);

// The decisions of one planning's corners, kept so that a corner equal to one already decided
// takes its decision instead of predicting it again (a slicer's layers repeat their perimeters
// and infill: the same corners at another height). Equal means equal to the bit in everything
// choose_corner reads of the corner: its point and its two neighbours, its two edges' print
// speeds and its geometry (the planning's limits, options, deposit model and time weight are
// the same for every corner). The height is left out of the key where the corner is planar
// (its three points at one z): the window is then planned and predicted in the corner's own
// frame, every z the same, with limits that hold everywhere; its decision does not depend on
// that z (tests/planners/motion/test_uniform_planner.cpp checks it to the bit). Only when the
// limits are the same everywhere (a Cartesian machine): where they depend on the position (a
// delta), nothing is kept.
class CornerDecisionCache {
 public:
  CornerDecisionCache(const TcpLimits& limits, bool enabled)
      : enabled_(enabled && limits.same_everywhere()) {}
  // the decision of interior point `corner` of the chain: an equal corner's, or decide()'s
  // (stored for the next equal one)
  template <class Decide>
  CornerDecision decision(const PrintChain& chain, size_t corner,
                          const std::vector<CornerGeometry>& geometry, Decide&& decide) {
    if (!enabled_) return decide();
    std::vector<uint64_t> key = corner_key(chain, corner, geometry);
    if (const auto found = decisions_.find(key); found != decisions_.end()) {
      ++reused_;
      return found->second;
    }
    CornerDecision decided = decide();
    // (bounded: when full, the kept decisions start over from this one; a slicer's layers
    // repeat the layer before)
    if (decisions_.size() >= kMaxKept) decisions_.clear();
    decisions_.emplace(std::move(key), decided);
    return decided;
  }
  // how many decisions were taken from an equal corner's
  size_t reused() const { return reused_; }
  // at most this many decisions are kept (about 1.2 kB each)
  static constexpr size_t kMaxKept = size_t{1} << 15;

 private:
  struct KeyHash {
    size_t operator()(const std::vector<uint64_t>& key) const;
  };
  static std::vector<uint64_t> corner_key(const PrintChain& chain, size_t corner,
                                          const std::vector<CornerGeometry>& geometry);
  bool enabled_;
  size_t reused_ = 0;
  std::unordered_map<std::vector<uint64_t>, CornerDecision, KeyHash> decisions_;
};

}  // namespace depotwin
