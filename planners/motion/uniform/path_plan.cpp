#include "planners/motion/uniform/path_plan.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/error.hpp"
#include "planners/motion/fine_edges.hpp"
#include "planners/motion/path_check.hpp"
#include "planners/motion/transition.hpp"
#include "planners/motion/uniform/arc_run.hpp"

namespace depotwin {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// turns below this are straight on (no blend); above pi minus it, a reversal (no blend fits)
constexpr double kStraightTurnRad = 1e-10;
constexpr double kReversalMarginRad = 1e-6;
// blends keep this share of the acceleration and jerk limits: the slack the cubic Hermite
// interpolation of their samples needs (its acceleration error is of order T^2 snap / 12)
constexpr double kBlendLimitShare = 0.99;
constexpr const char* kAxisName[3] = {"x", "y", "z"};
// each half of a blend has at least this many sample periods (shorter than period_s when the
// blend is short), so its motion is resolved by its own samples
constexpr int kMinBlendHalfPeriods = 4;
// merge_fine_edges looks at most this many points ahead for one edge (its cost per point)
constexpr size_t kMaxMergedPoints = 256;

// a straight line's piece of the path from `from` in direction u, timed by the 1-D profile
PhaseMotion line_motion(const AxisProfile& along, const Vec3& from, const Vec3& u) {
  PhaseMotion motion;
  for (int axis = 0; axis < 3; ++axis) {
    AxisProfile scaled(from[axis], u[axis] * along.v_start(), u[axis] * along.a_start());
    for (const Phase& phase : along.phases()) {
      if (phase.jerk == 0.0)
        scaled.append(phase.duration_s, u[axis] * phase.a0);
      else
        scaled.append_jerk(phase.duration_s, u[axis] * phase.jerk);
    }
    motion.axes[axis] = std::move(scaled);
  }
  return motion;
}

// the box of a blend: it lies in the triangle of its ends and the corner
void blend_box(const ClothoidBlend& blend, Vec3& lo, Vec3& hi) {
  lo = blend.start_mm().cwiseMin(blend.end_mm()).cwiseMin(blend.corner_mm());
  hi = blend.start_mm().cwiseMax(blend.end_mm()).cwiseMax(blend.corner_mm());
}

// a depositing piece of the chain's edge `edge` over [t, t + duration] (its motion unset)
TrajectoryPiece depositing_piece(const PrintChain& chain, size_t edge,
                                 const PathMotionOptions& options, double t_s, double duration_s) {
  TrajectoryPiece piece;
  piece.t_begin_s = t_s;
  piece.t_end_s = t_s + duration_s;
  piece.path_index = chain.edge_path[edge];
  piece.depositing = true;
  piece.desired_speed_mm_s = chain.edge_speed_mm_s[edge];
  piece.flow_lead_s = options.flow_follows_speed ? options.lag_s : -1.0;
  piece.flow_may_retract = options.flow_follows_speed && options.flow_may_retract;
  return piece;
}

// a depositing piece of edge `edge` from t_s made of the samples begin..end (one period apart)
TrajectoryPiece sampled_piece(const PrintChain& chain, size_t edge,
                              const PathMotionOptions& options, double t_s, double period_s,
                              const std::vector<Vec3>& position, const std::vector<Vec3>& velocity,
                              size_t begin, size_t end) {
  TrajectoryPiece piece =
      depositing_piece(chain, edge, options, t_s, static_cast<double>(end - begin) * period_s);
  SampledMotion motion;
  motion.period_s = period_s;
  motion.position_mm.assign(position.begin() + begin, position.begin() + end + 1);
  motion.velocity_mm_s.assign(velocity.begin() + begin, velocity.begin() + end + 1);
  piece.motion = std::move(motion);
  return piece;
}

// The worst per-axis acceleration and jerk against their limits of a speed law along a curve:
// per axis k, a_k = p'_k sddot + p''_k sdot^2, j_k = p'_k sdddot + 3 p''_k sdot sddot +
// p'''_k sdot^3 (plan_run_from_rest, plan_curved_ramp)
struct CurveLimitRatios {
  double accel = 0.0, jerk = 0.0;
  bool jerk_by_cross_term = false;  // at the worst jerk, the cross term is the larger
  void add(const Vec3& d1, const Vec3& d2, const Vec3& d3, double v, double a, double law_jerk,
           const MachineLimits& axes) {
    for (int axis = 0; axis < 3; ++axis) {
      const double axis_accel = d1[axis] * a + d2[axis] * v * v;
      const double cross = 3.0 * d2[axis] * v * a;
      const double axis_jerk = d1[axis] * law_jerk + cross + d3[axis] * v * v * v;
      accel = std::max(accel, std::abs(axis_accel) / axes.axes[axis].a_max_mm_s2);
      const double ratio = std::abs(axis_jerk) / axes.axes[axis].j_max_mm_s3;
      if (ratio > jerk) {
        jerk = ratio;
        jerk_by_cross_term = std::abs(cross) > std::abs(d1[axis] * law_jerk);
      }
    }
  }
  bool within() const { return accel <= 1.0 + 1e-9 && jerk <= 1.0 + 1e-9; }
  // lowers the law where exceeded: an exceeded acceleration, or a jerk the cross term sets,
  // lowers its acceleration; a jerk p' sdddot sets, its jerk
  void lower(LineLimits& law, double scale) const {
    if (accel > 1.0 + 1e-9 || (jerk > 1.0 + 1e-9 && jerk_by_cross_term)) law.a_max_mm_s2 *= scale;
    if (jerk > 1.0 + 1e-9 && !jerk_by_cross_term) law.j_max_mm_s3 *= scale;
  }
};

// A chain that is one arc run from rest to rest (ArcRun::from_rest_to_rest: an extrusion path
// along one chorded circle, a slicer's hole), its speed changing on the curve itself. The speed
// along it is line_profile's jerk-limited law in arc length (decelerations under the flow
// lag's rule) up to the run's speed; per axis k the curve adds its own terms,
//   a_k = p'_k sddot + p''_k sdot^2,   j_k = p'_k sdddot + 3 p''_k sdot sddot + p'''_k sdot^3,
// so the law's acceleration and jerk start at the least of the axes' limits over their reach
// in the run's plane and are lowered (kRampLimitScale a round) until every axis keeps
// blend_limits over the run's box at every quarter period: where an axis' acceleration is
// exceeded, the law's acceleration; where its jerk is, the law's jerk if p'_k sdddot is the
// larger of the two terms the law sets there, else its acceleration (the cross term, which on
// a tight circle binds first). Sampled at the period, a piece per section (its edge's path).
constexpr double kRampLimitScale = 0.9;
constexpr double kRampCruiseScale = 0.99;
constexpr int kRampRounds = 80;
constexpr int kRampBoxSamples = 64;
PlannedPath plan_run_from_rest(const PrintChain& chain, const ArcRun& run, const TcpLimits& limits,
                               const PathMotionOptions& options, double t_begin_s) {
  const double length = run.length_mm();
  // the run's box: its curve's samples, padded by the most the curve bulges between them
  Vec3 lo = run.start_mm(), hi = run.start_mm();
  for (int m = 1; m <= kRampBoxSamples; ++m) {
    const Vec3 p = run.position(length * m / kRampBoxSamples);
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double step = length / kRampBoxSamples;
  const Vec3 pad = Vec3::Constant(step * step / (8.0 * run.radius_mm()));
  const MachineLimits axes = blend_limits(limits.over(lo - pad, hi + pad));
  const double print_speed = chain.edge_speed_mm_s[run.first_corner()];
  LineLimits law;
  law.v_max_mm_s = std::min(run.speed_bound_mm_s, print_speed);
  // (an axis takes at most its reach, sqrt(1 - normal_k^2), of the law's)
  law.a_max_mm_s2 = law.j_max_mm_s3 = kInf;
  const Vec3 normal = run.normal();
  for (int axis = 0; axis < 3; ++axis) {
    const double reach = std::sqrt(std::max(0.0, 1.0 - normal[axis] * normal[axis]));
    if (!(reach > 0.0)) continue;
    law.a_max_mm_s2 = std::min(law.a_max_mm_s2, axes.axes[axis].a_max_mm_s2 / reach);
    law.j_max_mm_s3 = std::min(law.j_max_mm_s3, axes.axes[axis].j_max_mm_s3 / reach);
  }
  law.lag_s = options.deceleration_lag_s();
  AxisProfile profile;
  for (int round = 0;; ++round) {
    profile = line_profile(length, 0.0, 0.0, law);
    const double duration = profile.duration_s();
    const size_t checks =
        std::max<size_t>(8, static_cast<size_t>(std::ceil(4.0 * duration / options.period_s)));
    CurveLimitRatios ratios;
    size_t phase = 0;
    for (size_t m = 0; m <= checks; ++m) {
      const double t = duration * static_cast<double>(m) / static_cast<double>(checks);
      const AxisState state = profile.at(t, phase);
      Vec3 p, d1, d2, d3;
      run.at(std::clamp(state.q, 0.0, length), p, d1, d2, d3);
      ratios.add(d1, d2, d3, state.v, state.a, profile.jerk_at(t), axes);
    }
    if (ratios.within()) break;
    if (round == kRampRounds)
      throw InternalError("uniform: an arc run from rest does not keep its limits");
    ratios.lower(law, kRampLimitScale);
    // (past half the rounds, the jerk and the cruise too: a cruise at its arc's bound leaves a
    // ramp's end no room unless the jerk is at most about 2 a^2 / v)
    if (2 * round >= kRampRounds) {
      law.j_max_mm_s3 *= kRampLimitScale;
      law.v_max_mm_s *= kRampCruiseScale;
    }
  }

  // the samples
  const double duration = profile.duration_s();
  const size_t periods =
      std::max<size_t>(2, static_cast<size_t>(std::ceil(duration / options.period_s)));
  const double period = duration / static_cast<double>(periods);
  std::vector<double> s(periods + 1);
  std::vector<Vec3> position(periods + 1), velocity(periods + 1);
  size_t phase = 0;
  for (size_t m = 0; m <= periods; ++m) {
    const AxisState state = profile.at(period * static_cast<double>(m), phase);
    s[m] = m == periods ? length : std::clamp(state.q, 0.0, length);
    Vec3 d1, d2, d3;
    run.at(s[m], position[m], d1, d2, d3);
    velocity[m] = m == periods || m == 0 ? Vec3::Zero() : Vec3(d1 * state.v);
  }
  // a piece per section, split at the first sample on or past its start (the transitions belong
  // to the end edges' paths, the arc to the inner edges')
  PlannedPath planned;
  double t = t_begin_s;
  size_t begin = 0;
  double section_end = 0.0;
  for (int section = 0; section < 3; ++section) {
    section_end += run.section_length_mm(section);
    size_t end = begin;
    while (end < periods && (section == 2 || s[end] < section_end)) ++end;
    if (end == begin) continue;
    planned.pieces.push_back(sampled_piece(chain, run.section_edge(section), options, t, period,
                                           position, velocity, begin, end));
    t = planned.pieces.back().t_end_s;
    begin = end;
  }
  planned.t_end_s = t;
  planned.corner_speed_mm_s.assign(chain.points.size(), 0.0);
  for (size_t i = run.first_corner(); i <= run.last_corner(); ++i)
    planned.corner_speed_mm_s[i] = std::min(law.v_max_mm_s, profile.peak_speed());
  planned.run_speed_deficit_mm = std::max(0.0, print_speed * duration - length);
  planned.lookahead_corner_speed_mm_s = planned.corner_speed_mm_s;
  return planned;
}

}  // namespace

MachineLimits blend_limits(MachineLimits limits) {
  for (AxisLimits& axis : limits.axes) {
    axis.a_max_mm_s2 *= kBlendLimitShare;
    axis.j_max_mm_s3 *= kBlendLimitShare;
  }
  return limits;
}

MachineLimits corner_blend_limits(const CornerGeometry& g, double half_length_mm,
                                  const TcpLimits& limits) {
  const double tangent = half_length_mm * g.tangent_per_length;
  const Vec3 p0 = g.point - tangent * g.d_in, p1 = g.point + tangent * g.d_out;
  return blend_limits(
      limits.over(p0.cwiseMin(p1).cwiseMin(g.point), p0.cwiseMax(p1).cwiseMax(g.point)));
}

ToolOrientation PrintChain::edge_orientation(size_t e, double fraction) const {
  const ToolOrientation& a = orientations[e];
  const ToolOrientation& b = orientations[e + 1];
  if (fraction <= 0.0) return a;
  if (fraction >= 1.0) return b;
  return {slerp_axis(a.axis, b.axis, fraction), a.roll_rad + fraction * (b.roll_rad - a.roll_rad)};
}

ToolOrientation PrintChain::orientation_near_corner(size_t corner, const Vec3& p) const {
  // the nearer of the two edges meeting at the corner, at the projection's fraction
  double best = kInf;
  ToolOrientation result = orientations[corner];
  for (const size_t e : {corner - 1, corner}) {
    const Vec3 edge = points[e + 1] - points[e];
    const double f = std::clamp((p - points[e]).dot(edge) / edge.squaredNorm(), 0.0, 1.0);
    const double d = (points[e] + f * edge - p).squaredNorm();
    if (d < best) {
      best = d;
      result = edge_orientation(e, f);
    }
  }
  return result;
}

std::vector<PrintChain> print_chains(const Toolpath& toolpath) {
  std::vector<PrintChain> chains;
  for (size_t index = 0; index < toolpath.paths.size(); ++index) {
    const PrintPath& path = toolpath.paths[index];
    const std::string name = "toolpath path " + std::to_string(path.source_index);
    validate_print_path(path, name, kJoinTolerance_mm);
    // a path whose start is the previous one's end goes on printing through the joint
    const bool joined =
        !chains.empty() &&
        (chains.back().points.back() - path.points.front()).norm() <= kJoinTolerance_mm;
    if (!joined) {
      chains.emplace_back();
      PrintChain& chain = chains.back();
      chain.points.push_back(path.points.front());
      chain.orientations.push_back(path.orientation(0));
      chain.point_path.push_back(static_cast<int>(index));
      chain.point_index.push_back(0);
    }
    PrintChain& chain = chains.back();
    chain.oriented = chain.oriented || !path.normals.empty() || !path.rolls.empty();
    for (size_t i = 1; i < path.points.size(); ++i) {
      chain.points.push_back(path.points[i]);
      chain.orientations.push_back(path.orientation(i));
      chain.edge_speed_mm_s.push_back(path.speed_mm_s);
      chain.edge_path.push_back(static_cast<int>(index));
      chain.edge_source.push_back(path.source_index);
      chain.point_path.push_back(static_cast<int>(index));
      chain.point_index.push_back(static_cast<int>(i));
    }
  }
  return chains;
}

const char* corner_treatment_name(CornerTreatment treatment) {
  switch (treatment) {
    case CornerTreatment::straight:
      return "straight";
    case CornerTreatment::blend:
      return "blend";
    case CornerTreatment::loop:
      return "loop";
    case CornerTreatment::stop:
      return "stop";
    case CornerTreatment::arc:
      return "arc";
  }
  return "?";
}

LineLimits line_limits(const Vec3& u, const MachineLimits& limits, double speed_cap, double lag_s) {
  LineLimits line;
  line.v_max_mm_s = speed_cap;
  line.a_max_mm_s2 = kInf;
  line.j_max_mm_s3 = kInf;
  line.lag_s = lag_s;
  for (int axis = 0; axis < 3; ++axis) {
    const double c = std::abs(u[axis]);
    if (c < 1e-15) continue;
    const AxisLimits& limit = limits.axes[axis];
    line.v_max_mm_s = std::min(line.v_max_mm_s, limit.v_max_mm_s / c);
    line.a_max_mm_s2 = std::min(line.a_max_mm_s2, limit.a_max_mm_s2 / c);
    line.j_max_mm_s3 = std::min(line.j_max_mm_s3, limit.j_max_mm_s3 / c);
  }
  return line;
}

TcpLimits with_jerk_limits(const TcpLimits& limits, double jerk_ramp_s) {
  const auto fill = [jerk_ramp_s](MachineLimits m) {
    for (AxisLimits& axis : m.axes)
      if (!(axis.j_max_mm_s3 > 0.0)) axis.j_max_mm_s3 = axis.a_max_mm_s2 / jerk_ramp_s;
    return m;
  };
  if (limits.uniform())
    return TcpLimits(fill(limits.requested()), nullptr, limits.shared_joint_map());
  TcpLimits filled(
      fill(limits.requested()),
      [limits, fill](const Vec3& lo, const Vec3& hi) { return fill(limits.over(lo, hi)); },
      limits.shared_joint_map());
  filled.set_box_independent(limits.same_everywhere());
  return filled;
}

MergedChain merge_fine_edges(const PrintChain& chain, double max_error_mm,
                             const TcpLimits* limits) {
  MergedChain merged;
  const size_t n = chain.points.size();
  if (n < 3 || !(max_error_mm > 0.0)) {
    merged.chain = chain;
    merged.edge_error_mm.assign(chain.edges(), 0.0);
    merged.source_point.resize(n);
    for (size_t i = 0; i < n; ++i) merged.source_point[i] = i;
    return merged;
  }
  // the points kept: edges of the same path and speed merged within max_error_mm; on a chain
  // that turns the tool, only where the tool keeps one orientation (the arm's planar jobs: one
  // roll everywhere), so the orientation between the kept points is the one given
  const auto same_orientation = [&](size_t i, size_t j) {
    const ToolOrientation& p = chain.orientations[i];
    const ToolOrientation& q = chain.orientations[j];
    return p.axis == q.axis && p.roll_rad == q.roll_rad;
  };
  // the merged edge's print speed within every axis's limit along it: its direction is none
  // of the edges' it replaces (chords zig-zagging 0.1 off x, each slowed to v_max / cos 5.7
  // deg, merged into one along x needed 1.005 v_max)
  const auto speed_fits = [&](size_t anchor, size_t edge) {
    if (limits == nullptr) return true;
    const Vec3& from = chain.points[anchor];
    const Vec3& to = chain.points[edge + 1];
    const Vec3 step = to - from;
    const double length = step.norm();
    if (!(length > 0.0)) return true;
    const MachineLimits along = limits->along(from, to);
    for (int axis = 0; axis < 3; ++axis)
      if (chain.edge_speed_mm_s[anchor] * std::abs(step[axis]) / length >
          along.axes[axis].v_max_mm_s * (1 + 1e-12))
        return false;
    return true;
  };
  const FineEdgeMerge kept = merge_polyline_edges(
      chain.points, max_error_mm, kMaxMergedPoints, [&](size_t anchor, size_t edge) {
        return chain.edge_path[edge] == chain.edge_path[anchor] &&
               chain.edge_speed_mm_s[edge] == chain.edge_speed_mm_s[anchor] &&
               (!chain.oriented || same_orientation(anchor, edge + 1)) && speed_fits(anchor, edge);
      });
  PrintChain& out = merged.chain;
  out.oriented = chain.oriented;
  for (size_t k = 0; k < kept.kept.size(); ++k) {
    const size_t i = kept.kept[k];
    out.points.push_back(chain.points[i]);
    out.orientations.push_back(chain.orientations[i]);
    out.point_path.push_back(chain.point_path[i]);
    out.point_index.push_back(chain.point_index[i]);
    merged.source_point.push_back(i);
    if (k == 0) continue;
    // the merged edge takes the path, speed and source of the first edge it replaces
    const size_t anchor = kept.kept[k - 1];
    out.edge_speed_mm_s.push_back(chain.edge_speed_mm_s[anchor]);
    out.edge_path.push_back(chain.edge_path[anchor]);
    out.edge_source.push_back(chain.edge_source[anchor]);
  }
  merged.edge_error_mm = kept.edge_error_mm;
  return merged;
}

std::vector<CornerGeometry> corner_geometry(const std::vector<Vec3>& points, double tolerance_mm,
                                            const std::vector<double>& edge_error_mm) {
  const size_t n = points.size();
  std::vector<CornerGeometry> corners(n);
  for (size_t i = 0; i < n; ++i) corners[i].point = points[i];
  for (size_t i = 1; i + 1 < n; ++i) {
    CornerGeometry& c = corners[i];
    const Vec3 in = points[i] - points[i - 1], out = points[i + 1] - points[i];
    c.d_in = in.normalized();
    c.d_out = out.normalized();
    c.turn_rad = ClothoidBlend::turn_angle(c.d_in, c.d_out);
    c.interior_deg = 180.0 - rad_to_deg(c.turn_rad);
    if (c.turn_rad <= kStraightTurnRad || c.turn_rad >= kPi - kReversalMarginRad) continue;
    c.tangent_per_length = ClothoidBlend::tangent_per_length(c.turn_rad);
    c.deviation_per_length = ClothoidBlend::deviation_per_length(c.turn_rad);
    c.shape = ClothoidBlend::unit_shape(c.d_in, c.d_out);
    c.max_half_length_mm = max_blend_half_length(
        c, in.norm(), out.norm(), corner_tolerance_mm(tolerance_mm, edge_error_mm, i));
  }
  return corners;
}

double corner_tolerance_mm(double tolerance_mm, const std::vector<double>& edge_error_mm,
                           size_t corner) {
  if (edge_error_mm.empty()) return tolerance_mm;
  return tolerance_mm - std::max(edge_error_mm[corner - 1], edge_error_mm[corner]);
}

double max_blend_half_length(const CornerGeometry& g, double edge_in_mm, double edge_out_mm,
                             double tolerance_mm) {
  if (!(g.tangent_per_length > 0.0)) return 0.0;
  // within the tolerance, and leaving each adjacent edge at least half for its other end
  const double room = 0.5 * std::min(edge_in_mm, edge_out_mm);
  return std::min(tolerance_mm / g.deviation_per_length, room / g.tangent_per_length);
}

namespace {

// an edge less the blends' (or loops') trims at its ends, with its limits along it
struct TrimmedLine {
  Vec3 from, to, u;
  double length = 0.0;
  LineLimits limits;
};

// A stretch of a chain from or to rest (or a corner held at its cap) across blended (or
// straight) corners: lines first_line to last_line with the blends between them, planned as one
// curve in arc length. The look-ahead changes speed on the lines only (each line's profile
// starts and ends with zero acceleration, the blends are taken at constant speed), so a ramp
// over short chords crawls up chord by chord. Here it is line_profile's law over the whole stretch,
// held to every axis' limits by the same check as a run from rest (plan_run_from_rest): per axis k
// the curve adds a_k = p'_k sddot + p''_k sdot^2 and j_k = p'_k sdddot + 3 p''_k sdot sddot +
// p'''_k sdot^3, checked on the blends at every quarter period (and twice per emitted sample)
// against blend_limits over each blend's box, and each blend's speed against its corner's cap.
struct CurvedRamp {
  struct Section {
    double s_begin = 0.0, length = 0.0;
    const TrimmedLine* line = nullptr;     // a line, or
    const ClothoidBlend* blend = nullptr;  // a blend's half (the second: from its apex)
    bool second_half = false;
    size_t edge = 0;  // the edge whose path it prints
    MachineLimits axes;
    double speed_cap_mm_s = 0.0;  // a line's cruise cap, a blend's corner cap
  };
  size_t first_line = 0, last_line = 0;
  std::vector<Section> sections;
  double length = 0.0;
  AxisProfile profile;

  // the least time any blend half takes at speeds up to `speed` (each half also under its
  // corner's cap, which the ramp's check holds); infinite without blends
  double shortest_blend_half_s(double speed) const {
    double shortest = kInf;
    for (const Section& section : sections)
      if (section.blend != nullptr)
        shortest = std::min(shortest, section.length / std::min(speed, section.speed_cap_mm_s));
    return shortest;
  }

  // the longest sample period for the law: period_s, shorter where a blend's half would have
  // fewer than kMinBlendHalfPeriods samples at the law's peak speed (as a blend on its own)
  double sample_period_s(double period_s) const {
    const double peak = profile.peak_speed();
    return peak > 0.0 ? std::min(period_s, shortest_blend_half_s(peak) / kMinBlendHalfPeriods)
                      : period_s;
  }

  // the time in [lo_s, hi_s] at which the law reaches arc length s (bisection: s grows with
  // time), to 1e-12 s
  double time_at(double s, double lo_s, double hi_s) const {
    for (int step = 0; step < 60 && hi_s - lo_s > 1e-12; ++step) {
      const double mid = 0.5 * (lo_s + hi_s);
      (profile.at(mid).q < s ? lo_s : hi_s) = mid;
    }
    return hi_s;
  }

  // the curve at arc length s (section: a hint, advanced to the section that holds s)
  void at(double s, size_t& section, Vec3& p, Vec3& d1, Vec3& d2, Vec3& d3) const {
    while (section + 1 < sections.size() &&
           s > sections[section].s_begin + sections[section].length)
      ++section;
    const Section& sec = sections[section];
    const double local = std::clamp(s - sec.s_begin, 0.0, sec.length);
    if (sec.line != nullptr) {
      p = sec.line->from + local * sec.line->u;
      d1 = sec.line->u;
      d2 = d3 = Vec3::Zero();
      return;
    }
    sec.blend->at(local + (sec.second_half ? sec.length : 0.0), p, d1, d2, d3);
  }
};

constexpr int kCurvedRampRounds = 40;
// a ramp is sampled at most this much finer than period_s (its blends' halves keep
// kMinBlendHalfPeriods samples at the law's peak speed, or their caps where lower): a ramp over
// blends shorter than that allows is not tried (the look-ahead samples each blend on its own)
constexpr double kMaxRampRefinement = 16.0;

// Plans lines first..last (and the blends between them) from v0 to v1 as one CurvedRamp; false
// where the law cannot join the speeds in the stretch or is not faster than standard_s, the
// look-ahead's time over the stretch. node_cap: each node's speed cap (its blend's bound).
bool plan_curved_ramp(const std::vector<TrimmedLine>& lines,
                      const std::vector<ClothoidBlend>& blends,
                      const std::vector<CornerPlan>& corners, const std::vector<double>& node_cap,
                      size_t first, size_t last, double v0, double v1, double standard_s,
                      const TcpLimits& limits, const PathMotionOptions& options, CurvedRamp& ramp) {
  ramp.first_line = first;
  ramp.last_line = last;
  ramp.sections.clear();
  ramp.length = 0.0;
  LineLimits law;
  law.v_max_mm_s = law.a_max_mm_s2 = law.j_max_mm_s3 = kInf;
  law.lag_s = options.deceleration_lag_s();
  const auto add = [&](CurvedRamp::Section section, const Vec3& lo, const Vec3& hi,
                       double speed_cap) {
    if (!(section.length > 0.0)) return;
    section.speed_cap_mm_s = speed_cap;
    section.s_begin = ramp.length;
    section.axes = blend_limits(limits.over(lo, hi));
    ramp.length += section.length;
    ramp.sections.push_back(section);
  };
  for (size_t k = first; k <= last; ++k) {
    // the line; its limits (with the blends' share: it is sampled) are the law's first bound
    const TrimmedLine& line = lines[k];
    law.v_max_mm_s = std::min(law.v_max_mm_s, line.limits.v_max_mm_s);
    law.a_max_mm_s2 = std::min(law.a_max_mm_s2, kBlendLimitShare * line.limits.a_max_mm_s2);
    law.j_max_mm_s3 = std::min(law.j_max_mm_s3, kBlendLimitShare * line.limits.j_max_mm_s3);
    CurvedRamp::Section section;
    section.line = &line;
    section.length = line.length;
    section.edge = k;
    add(section, line.from.cwiseMin(line.to), line.from.cwiseMax(line.to), line.limits.v_max_mm_s);
    if (k == last || corners[k + 1].treatment != CornerTreatment::blend) continue;
    // the blend after it, in halves (its apex splits the two edges' paths)
    const ClothoidBlend& blend = blends[k + 1];
    Vec3 lo, hi;
    blend_box(blend, lo, hi);
    section = CurvedRamp::Section();
    section.blend = &blend;
    section.length = blend.half_length_mm();
    section.edge = k;
    add(section, lo, hi, node_cap[k + 1]);
    section.second_half = true;
    section.edge = k + 1;
    add(section, lo, hi, node_cap[k + 1]);
  }
  const double lowest = std::max(v0, v1);
  if (ramp.sections.empty() || lowest > law.v_max_mm_s) return false;
  if (ramp.shortest_blend_half_s(law.v_max_mm_s) / kMinBlendHalfPeriods <
      options.period_s / kMaxRampRefinement)
    return false;
  // (checked once a period while the law is lowered, then at every quarter period and at least
  // twice per emitted sample, so each half blend is checked kMinBlendHalfPeriods * 2 times or
  // more however short it is)
  bool fine = false;
  for (int round = 0;; ++round) {
    if (speed_change_distance(v0, lowest, law) + speed_change_distance(lowest, v1, law) >
        ramp.length)
      return false;
    ramp.profile = line_profile(ramp.length, v0, v1, law);
    const double duration = ramp.profile.duration_s();
    if (!(duration < standard_s)) return false;
    // every axis on the blends, against their boxes' limits (on the lines the law keeps the
    // lines' own limits), once a period (fine: as above)
    const double check_step_s =
        fine ? std::min(options.period_s / 4.0, ramp.sample_period_s(options.period_s) / 2.0)
             : options.period_s;
    const size_t checks =
        std::max<size_t>(8, static_cast<size_t>(std::ceil(duration / check_step_s)));
    double speed_ratio = 0.0;
    CurveLimitRatios ratios;
    // one check: the state at t, in section `hint` or past it (updated)
    const auto check = [&](double t, const AxisState& state, size_t& hint) {
      Vec3 p, d1, d2, d3;
      ramp.at(std::clamp(state.q, 0.0, ramp.length), hint, p, d1, d2, d3);
      if (ramp.sections[hint].line != nullptr) return;
      const MachineLimits& axes = ramp.sections[hint].axes;
      const double v = state.v;
      speed_ratio = std::max(speed_ratio, v / ramp.sections[hint].speed_cap_mm_s);
      for (int axis = 0; axis < 3; ++axis)
        speed_ratio = std::max(speed_ratio, std::abs(d1[axis] * v) / axes.axes[axis].v_max_mm_s);
      ratios.add(d1, d2, d3, v, state.a, ramp.profile.jerk_at(t), axes);
    };
    size_t phase = 0, section = 0;
    double t_before = 0.0;
    for (size_t m = 0; m <= checks; ++m) {
      const double t = duration * static_cast<double>(m) / static_cast<double>(checks);
      const AxisState state = ramp.profile.at(t, phase);
      const size_t section_before = section;
      check(t, state, section);
      // a blend half passed between two checks (faster than its cap allows, or the grid
      // still coarse): checked at its middle, found by bisection in time
      for (size_t skipped = section_before + 1; skipped < section; ++skipped) {
        const CurvedRamp::Section& half = ramp.sections[skipped];
        if (half.blend == nullptr) continue;
        const double middle = ramp.time_at(half.s_begin + 0.5 * half.length, t_before, t);
        size_t hint = skipped;
        check(middle, ramp.profile.at(middle), hint);
      }
      t_before = t;
    }
    if (speed_ratio <= 1.0 + 1e-9 && ratios.within()) {
      if (fine) return true;
      fine = true;
      continue;
    }
    if (round >= kCurvedRampRounds) return false;
    // lower what was exceeded (as plan_run_from_rest does); past half the rounds the jerk and
    // the cruise too
    if (speed_ratio > 1.0 + 1e-9) law.v_max_mm_s /= speed_ratio;
    ratios.lower(law, kRampLimitScale);
    if (2 * round >= kCurvedRampRounds) {
      law.j_max_mm_s3 *= kRampLimitScale;
      law.v_max_mm_s *= kRampCruiseScale;
    }
    if (lowest > law.v_max_mm_s) return false;
  }
}

// The ramp's pieces from t_begin_s, a piece per section from the time the law reaches its
// start to the time it reaches its end (so each sample lies on its own edge, and a chain's
// joined paths meet exactly), each sampled at most the ramp's sample period apart; each inner
// corner's speed at its apex into planned.corner_speed_mm_s; the speed deficit of its lines
// that meet an arc run (next_to_run(edge)) into planned.run_speed_deficit_mm, as for such a
// line on its own. Returns the time the ramp ends.
template <typename NextToRun>
double emit_curved_ramp(const CurvedRamp& ramp, const PrintChain& chain,
                        const PathMotionOptions& options, double t_begin_s, PlannedPath& planned,
                        NextToRun next_to_run) {
  const double duration = ramp.profile.duration_s();
  const double sample_period = ramp.sample_period_s(options.period_s);
  double t = t_begin_s, section_begin = 0.0;  // (section_begin: in the ramp's own time)
  std::vector<Vec3> position, velocity;
  for (size_t k = 0; k < ramp.sections.size(); ++k) {
    const CurvedRamp::Section& sec = ramp.sections[k];
    const bool last_section = k + 1 == ramp.sections.size();
    const double section_end =
        last_section ? duration : ramp.time_at(sec.s_begin + sec.length, section_begin, duration);
    const double span = section_end - section_begin;
    if (!(span > 0.0)) continue;
    const size_t periods =
        std::max<size_t>(1, static_cast<size_t>(std::ceil(span / sample_period)));
    const double period = span / static_cast<double>(periods);
    position.resize(periods + 1);
    velocity.resize(periods + 1);
    double first_speed = 0.0;
    size_t phase = 0, hint = k;
    for (size_t m = 0; m <= periods; ++m) {
      const bool ramp_end = last_section && m == periods;
      const AxisState state =
          ramp.profile.at(section_begin + period * static_cast<double>(m), phase);
      const double speed = ramp_end ? ramp.profile.v_end() : state.v;
      Vec3 d1, d2, d3;
      ramp.at(ramp_end ? ramp.length : std::clamp(state.q, 0.0, ramp.length), hint, position[m], d1,
              d2, d3);
      velocity[m] = d1 * speed;
      if (m == 0) first_speed = speed;
    }
    if (sec.second_half) planned.corner_speed_mm_s[sec.edge] = first_speed;
    planned.pieces.push_back(
        sampled_piece(chain, sec.edge, options, t, period, position, velocity, 0, periods));
    if (sec.line != nullptr && next_to_run(sec.edge))
      planned.run_speed_deficit_mm +=
          std::max(0.0, chain.edge_speed_mm_s[sec.edge] * span - sec.length);
    t = planned.pieces.back().t_end_s;
    section_begin = section_end;
  }
  return t;
}

}  // namespace

PlannedPath plan_chain(const PrintChain& chain, const std::vector<CornerGeometry>& geometry,
                       const std::vector<CornerPlan>& corners, const TcpLimits& limits,
                       const PathMotionOptions& options, double t_begin_s) {
  const size_t n = chain.points.size();
  const size_t edges = n - 1;
  // the print speed must be possible along every whole edge
  for (size_t e = 0; e < edges; ++e) {
    const Vec3& p0 = chain.points[e];
    const Vec3& p1 = chain.points[e + 1];
    const double speed = chain.edge_speed_mm_s[e];
    const Vec3 u = (p1 - p0) / (p1 - p0).norm();
    const MachineLimits edge_limits = limits.along(p0, p1);
    for (int axis = 0; axis < 3; ++axis) {
      if (std::abs(speed * u[axis]) > edge_limits.axes[axis].v_max_mm_s * (1 + 1e-12)) {
        std::ostringstream msg;
        msg << "segment " << e << " needs " << std::abs(speed * u[axis]) << " mm/s on axis "
            << kAxisName[axis] << " at print speed " << speed << " mm/s, above v_max "
            << edge_limits.axes[axis].v_max_mm_s;
        throw InputError("toolpath path " + std::to_string(chain.edge_source[e]), msg.str());
      }
    }
  }
  if (edges >= 2 && corners[1].treatment == CornerTreatment::arc &&
      corners[1].arc->from_rest_to_rest)
    return plan_run_from_rest(chain, *corners[1].arc, limits, options, t_begin_s);

  // the trimmed lines: each edge loses the blend's tangent (or the loop's trim) at its ends
  std::vector<TrimmedLine> lines(edges);
  std::vector<ClothoidBlend> blends(n);
  for (size_t e = 0; e < edges; ++e) {
    const Vec3& p0 = chain.points[e];
    const Vec3& p1 = chain.points[e + 1];
    const double speed = chain.edge_speed_mm_s[e];
    TrimmedLine& line = lines[e];
    const double edge_length = (p1 - p0).norm();
    line.u = (p1 - p0) / edge_length;
    double trim0 = 0.0, trim1 = 0.0;
    if (e > 0) {
      const CornerPlan& c = corners[e];
      if (c.treatment == CornerTreatment::blend)
        trim0 = c.half_length_mm * geometry[e].tangent_per_length;
      if (c.treatment == CornerTreatment::loop) trim0 = c.trim_out_mm;
      // (an arc run's inner edge is taken whole by its curve)
      if (c.treatment == CornerTreatment::arc)
        trim0 = c.arc->last_corner() == e ? c.arc->exit_trim_mm : edge_length;
    }
    if (e + 1 < edges) {
      const CornerPlan& c = corners[e + 1];
      if (c.treatment == CornerTreatment::blend)
        trim1 = c.half_length_mm * geometry[e + 1].tangent_per_length;
      if (c.treatment == CornerTreatment::loop) trim1 = c.trim_in_mm;
      if (c.treatment == CornerTreatment::arc)
        trim1 = c.arc->first_corner() == e + 1 ? c.arc->entry_trim_mm : edge_length;
    }
    line.length = std::max(0.0, edge_length - trim0 - trim1);
    line.from = p0 + trim0 * line.u;
    line.to = p1 - trim1 * line.u;
    if (trim0 + trim1 >= edge_length) line.to = line.from;
    const MachineLimits box =
        line.length > 0.0 ? limits.along(line.from, line.to) : limits.along(p0, p1);
    line.limits = line_limits(line.u, box, speed, options.deceleration_lag_s());
  }
  for (size_t i = 1; i + 1 < n; ++i)
    if (corners[i].treatment == CornerTreatment::blend)
      blends[i] = ClothoidBlend(chain.points[i], geometry[i].d_in, geometry[i].d_out,
                                corners[i].half_length_mm);

  // node caps: node k sits before line k (k = edges: after the last line); a loop splits the
  // node into the end of one run and the start of the next
  std::vector<double> cap_before(edges + 1, 0.0), cap_after(edges + 1, 0.0);
  std::vector<char> split(edges + 1, 0);
  cap_before[0] = options.enter_at_speed ? lines[0].limits.v_max_mm_s : 0.0;
  cap_after[edges] = options.leave_at_speed ? lines[edges - 1].limits.v_max_mm_s : 0.0;
  PlannedPath planned;
  planned.corner_speed_mm_s.assign(n, 0.0);
  for (size_t k = 1; k < edges; ++k) {
    const CornerPlan& c = corners[k];
    const double both = std::min(lines[k - 1].limits.v_max_mm_s, lines[k].limits.v_max_mm_s);
    double cap = both;
    if (c.treatment == CornerTreatment::blend) {
      Vec3 lo, hi;
      blend_box(blends[k], lo, hi);
      cap = std::min(cap, blend_speed_bound(geometry[k].shape, c.half_length_mm,
                                            blend_limits(limits.over(lo, hi))));
    }
    if (c.treatment == CornerTreatment::arc) cap = std::min(cap, c.arc->speed_bound_mm_s);
    if (c.treatment == CornerTreatment::stop) cap = 0.0;
    if (c.treatment == CornerTreatment::loop) {
      split[k] = 1;
      cap_after[k] = options.loops_at_rest ? 0.0 : lines[k - 1].limits.v_max_mm_s;
      cap_before[k] = options.loops_at_rest ? 0.0 : lines[k].limits.v_max_mm_s;
    } else {
      cap_after[k] = cap_before[k] = cap;
    }
  }

  // look-ahead: backward then forward over the lines (speed[k]: line k's start, end[k]: end)
  std::vector<double> v_start(edges), v_end(edges);
  for (size_t k = 0; k < edges; ++k) {
    v_start[k] = cap_before[k];
    v_end[k] = cap_after[k + 1];
  }
  for (size_t k = edges; k-- > 0;) {
    // the node after line k joins v_end[k] and v_start[k + 1] unless split
    if (k + 1 < edges && !split[k + 1]) v_end[k] = std::min(v_end[k], v_start[k + 1]);
    v_start[k] = std::min(
        v_start[k], reachable_speed(v_end[k], lines[k].length, v_start[k], lines[k].limits, true));
  }
  const std::vector<double> backward_bound = v_start;  // what the rests ahead allow at each node
  for (size_t k = 0; k < edges; ++k) {
    if (k > 0 && !split[k]) v_start[k] = std::min(v_start[k], v_end[k - 1]);
    v_end[k] = std::min(
        v_end[k], reachable_speed(v_start[k], lines[k].length, v_end[k], lines[k].limits, false));
  }
  // one speed per joined node (the forward pass may have lowered an end below its next start)
  for (size_t k = 0; k + 1 < edges; ++k)
    if (!split[k + 1]) v_start[k + 1] = v_end[k] = std::min(v_end[k], v_start[k + 1]);

  // ramps from and to rest (or a corner held at its cap) across blended corners, where the
  // look-ahead leaves corners below their caps (speeds the lines between them and that node
  // could not reach): each such stretch, from the node to the first corner it does not hold,
  // as one CurvedRamp where that is faster (the look-ahead's corner speeds kept for
  // resize_held_blends)
  std::vector<CurvedRamp> ramps;
  std::vector<int> ramp_of_line(edges, -1);
  planned.lookahead_corner_speed_mm_s.assign(n, 0.0);
  for (size_t k = 1; k < edges; ++k)
    planned.lookahead_corner_speed_mm_s[k] = std::min(v_end[k - 1], v_start[k]);
  if (options.curved_ramps && !chain.oriented) {
    const auto line_time = [&](size_t k) {
      return lines[k].length > 0.0
                 ? line_profile(lines[k].length, v_start[k], v_end[k], lines[k].limits).duration_s()
                 : 0.0;
    };
    // node i (0 < i < edges) a ramp may pass or start at: a blend or a straight, not split
    const auto ramp_corner = [&](size_t i) {
      return !split[i] && (corners[i].treatment == CornerTreatment::blend ||
                           corners[i].treatment == CornerTreatment::straight);
    };
    // node i inside a ramp: a ramp corner taken below its cap; held by a rest behind it (the
    // forward pass: inside a ramp out of that rest) or by one ahead (the backward pass: inside
    // a ramp into that rest)
    const auto inner = [&](size_t i, bool held_from_behind) {
      const double speed = v_end[i - 1];
      if (!ramp_corner(i) || !(speed > 0.0) || !(speed < cap_before[i] * (1.0 - 1e-9)))
        return false;
      return held_from_behind == (speed < backward_bound[i] * (1.0 - 1e-9));
    };
    // a ramp over lines first..last, if one fits and is quicker: its gain over the look-ahead
    const auto ramp_gain = [&](size_t first, size_t last, CurvedRamp& ramp) {
      if (last <= first) return 0.0;  // (no inner corner)
      double standard_s = 0.0;
      for (size_t k = first; k <= last; ++k) {
        standard_s += line_time(k);
        if (k < last && corners[k + 1].treatment == CornerTreatment::blend)
          standard_s += blends[k + 1].length_mm() / v_end[k];
      }
      return plan_curved_ramp(lines, blends, corners, cap_before, first, last, v_start[first],
                              v_end[last], standard_s, limits, options, ramp)
                 ? standard_s - ramp.profile.duration_s()
                 : 0.0;
    };
    // the stretch first..last, or without its line farthest from the rest (which may change
    // speed quicker on its own, under its own limits), whichever gains more
    const auto try_ramp = [&](size_t first, size_t last, bool rest_at_first) {
      if (last <= first) return;  // (no inner corner)
      for (size_t k = first; k <= last; ++k)
        if (ramp_of_line[k] >= 0) return;
      CurvedRamp whole, shorter;
      const double whole_gain = ramp_gain(first, last, whole);
      const double shorter_gain =
          rest_at_first ? ramp_gain(first, last - 1, shorter) : ramp_gain(first + 1, last, shorter);
      if (!(std::max(whole_gain, shorter_gain) > 0.0)) return;
      CurvedRamp& ramp = whole_gain >= shorter_gain ? whole : shorter;
      for (size_t k = ramp.first_line; k <= ramp.last_line; ++k)
        ramp_of_line[k] = static_cast<int>(ramps.size());
      ramps.push_back(std::move(ramp));
    };
    // the rests' ramps first (near rest the lines' crawl costs most, under the lag rule), then
    // the held corners' on the lines left: each ramp keeps its ends' speeds, so the rests'
    // ramps are those they would be alone
    for (const bool rests : {true, false}) {
      for (size_t r = 0; r <= edges; ++r) {
        // node r at rest (the chain's ends, stops, loops at rest) or held at its own cap (a
        // blend or straight the look-ahead takes at its bound: a sharp corner's slow blend)
        const bool at_rest = (r == edges || v_start[r] == 0.0) && (r == 0 || v_end[r - 1] == 0.0);
        const bool at_cap =
            r > 0 && r < edges && ramp_corner(r) && v_start[r] >= cap_before[r] * (1.0 - 1e-9);
        if (rests ? !at_rest : at_rest || !at_cap) continue;
        // into it (lines first..r-1), then out of it (lines r..last)
        if (r > 0) {
          size_t first = r - 1;
          while (first > 0 && inner(first, false)) --first;
          try_ramp(first, r - 1, false);
        }
        if (r < edges) {
          size_t last = r;
          while (last + 1 < edges && inner(last + 1, true)) ++last;
          try_ramp(r, last, true);
        }
      }
    }
  }

  // the pieces
  double t = t_begin_s;
  const auto base_piece = [&](double duration, size_t edge) {
    return depositing_piece(chain, edge, options, t, duration);
  };
  // line k starts or ends at an arc run (a slow line there is the run's deficit)
  const auto next_to_run = [&](size_t k) {
    return (k > 0 && corners[k].treatment == CornerTreatment::arc) ||
           (k + 1 < edges && corners[k + 1].treatment == CornerTreatment::arc);
  };
  for (size_t k = 0; k < edges; ++k) {
    const TrimmedLine& line = lines[k];
    if (ramp_of_line[k] >= 0) {
      // a ramp: its curve once, at its first line; its inner corners add nothing
      const CurvedRamp& ramp = ramps[static_cast<size_t>(ramp_of_line[k])];
      if (k == ramp.first_line) t = emit_curved_ramp(ramp, chain, options, t, planned, next_to_run);
      if (k + 1 == edges) break;
      if (k < ramp.last_line) continue;
    }
    // the line
    if (ramp_of_line[k] < 0 && line.length > 0.0) {
      const AxisProfile along = line_profile(line.length, v_start[k], v_end[k], line.limits);
      const double duration = along.duration_s();
      if (next_to_run(k))
        planned.run_speed_deficit_mm +=
            std::max(0.0, chain.edge_speed_mm_s[k] * duration - line.length);
      if (duration > 0.0) {
        TrajectoryPiece piece = base_piece(duration, k);
        piece.motion = line_motion(along, line.from, line.u);
        piece.tool_axis = segment_tool_axis(chain.points[k], chain.orientations[k],
                                            chain.points[k + 1], chain.orientations[k + 1]);
        planned.pieces.push_back(std::move(piece));
        t += duration;
      }
    }
    if (k + 1 == edges) break;
    // the corner after it
    const size_t i = k + 1;
    const CornerPlan& c = corners[i];
    planned.corner_speed_mm_s[i] = std::min(v_end[k], v_start[k + 1]);
    if (c.treatment == CornerTreatment::blend) {
      const ClothoidBlend& blend = blends[i];
      const double w = v_end[k];
      if (!(w > 0.0)) throw InternalError("uniform: a blend planned at rest");
      const double length = blend.length_mm(), duration = length / w;
      const size_t half_periods = static_cast<size_t>(
          std::max(double(kMinBlendHalfPeriods), std::ceil(duration / (2.0 * options.period_s))));
      const size_t periods = 2 * half_periods;
      const double period = duration / static_cast<double>(periods);
      // two pieces split at the apex: the first half belongs to the incoming edge's path, the
      // second to the outgoing one's (they differ where two paths join at the corner)
      for (int half = 0; half < 2; ++half) {
        SampledMotion motion;
        motion.period_s = period;
        for (size_t m = half * half_periods; m <= (half + 1) * half_periods; ++m) {
          const double s = m == periods ? length : length * static_cast<double>(m) / periods;
          Vec3 p, d1, d2, d3;
          blend.at(s, p, d1, d2, d3);
          motion.position_mm.push_back(p);
          motion.velocity_mm_s.push_back(w * d1);
          if (chain.oriented) {
            const ToolOrientation o = chain.orientation_near_corner(i, p);
            motion.tool_axis.push_back(o.axis);
            motion.roll_rad.push_back(o.roll_rad);
          }
        }
        TrajectoryPiece piece = base_piece(static_cast<double>(half_periods) * period, k + half);
        if (chain.oriented) {
          piece.tool_axis.begin = motion.tool_axis.front();
          piece.tool_axis.end = motion.tool_axis.back();
          piece.tool_axis.roll_begin = motion.roll_rad.front();
          piece.tool_axis.roll_end = motion.roll_rad.back();
        }
        piece.motion = std::move(motion);
        planned.pieces.push_back(std::move(piece));
        t = planned.pieces.back().t_end_s;
      }
    } else if (c.treatment == CornerTreatment::arc && c.arc->first_corner() == i) {
      // the run's curve, once, at its first corner (its inner lines are empty, its other
      // corners add nothing): a piece per section, each of equal periods, so the joints of
      // the transitions and the arc, where the curvature rate jumps, fall on samples
      const ArcRun& run = *c.arc;
      const double w = v_end[k];
      if (!(w > 0.0)) throw InternalError("uniform: an arc run planned at rest");
      double s_begin = 0.0;
      for (int section = 0; section < 3; ++section) {
        const double length = run.section_length_mm(section);
        if (!(length > 0.0)) continue;
        const double duration = length / w;
        const size_t periods = static_cast<size_t>(
            std::max(double(kMinBlendHalfPeriods), std::ceil(duration / options.period_s)));
        const double period = duration / static_cast<double>(periods);
        SampledMotion motion;
        motion.period_s = period;
        for (size_t m = 0; m <= periods; ++m) {
          const double s =
              s_begin + (m == periods ? length : length * static_cast<double>(m) / periods);
          Vec3 p, d1, d2, d3;
          run.at(s, p, d1, d2, d3);
          motion.position_mm.push_back(p);
          motion.velocity_mm_s.push_back(w * d1);
        }
        TrajectoryPiece piece =
            base_piece(static_cast<double>(periods) * period, run.section_edge(section));
        planned.run_speed_deficit_mm +=
            std::max(0.0, length * (piece.desired_speed_mm_s / w - 1.0));
        piece.motion = std::move(motion);
        planned.pieces.push_back(std::move(piece));
        t = planned.pieces.back().t_end_s;
        s_begin += length;
      }
    } else if (c.treatment == CornerTreatment::loop) {
      // shutter closed: from the end of this line to the start of the next, at their speeds
      const TrimmedLine& next = lines[k + 1];
      const double edge_in = (chain.points[i] - chain.points[i - 1]).norm();
      const double edge_out = (chain.points[i + 1] - chain.points[i]).norm();
      TrajectoryPiece loop =
          transition_piece(t, line.to, v_end[k] * line.u, next.from, v_start[k + 1] * next.u,
                           limits, chain.edge_orientation(k, 1.0 - c.trim_in_mm / edge_in),
                           chain.edge_orientation(k + 1, c.trim_out_mm / edge_out));
      t = loop.t_end_s;
      planned.pieces.push_back(std::move(loop));
    }
  }
  // (an arc run that takes a chain's end edge whole leaves or enters it along its own end)
  const CornerPlan& first_corner = corners[1];
  const CornerPlan& last_corner = corners[edges - 1];
  const bool starts_on_run =
      edges > 1 && first_corner.treatment == CornerTreatment::arc && lines.front().length <= 0.0;
  const bool ends_on_run =
      edges > 1 && last_corner.treatment == CornerTreatment::arc && lines.back().length <= 0.0;
  planned.start_velocity =
      v_start.front() * (starts_on_run ? first_corner.arc->start_direction() : lines.front().u);
  planned.end_velocity =
      v_end.back() * (ends_on_run ? last_corner.arc->end_direction() : lines.back().u);
  planned.t_end_s = t;
  return planned;
}

}  // namespace depotwin
