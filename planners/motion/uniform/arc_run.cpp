#include "planners/motion/uniform/arc_run.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "core/error.hpp"
#include "core/segment_distance.hpp"

namespace depotwin {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// a run's corners turn about parallel normals (cosine) and its points lie this close to its plane
constexpr double kParallelNormals = 1.0 - 1e-9;
constexpr double kPlanarTolerance_mm = 1e-6;
// at most this many corners are fitted as one run (a longer curve is cut into such pieces)
constexpr size_t kMaxArcRunCorners = 128;
// a transition turns at most this much (the clothoid's power series and the shift's rise with
// its length hold far beyond it)
constexpr double kMaxTransitionTurnRad = 0.25 * kPi;
// the transition is sized for the speed with this much more shift than it needs (the radius
// and the shift are solved together by a few fixed-point steps)
constexpr double kShiftMargin = 1.001;
constexpr int kRadiusIterations = 12;
// a run slower than the print speed (where the flow follows the speed) is sized for this share
// of the speed its arc alone allows (the rest leaves its transitions a finite length)
constexpr double kSlowRunShare = 0.9;
// the speed shares a run whose transitions do not fit its end edges at the print speed is
// tried at (shorter transitions)
constexpr double kShortTransitionSpeedShares[] = {0.9, 0.75, 0.6};
constexpr int kBisections = 60;
// a run from rest to rest tries transitions sized for these shares of the print speed
constexpr double kRestTransitionSpeedShares[] = {1.0, 0.5, 0.25, 0.125};
// the tolerance check's samples are this share of the tolerance apart (each sample's distance
// from the polyline plus half the spacing bounds the curve's between them), at most this many
constexpr double kSampleShareOfTolerance = 0.1;
constexpr size_t kMaxSamples = 200000;
// each sample's nearest edge is looked for among this many after the last sample's
constexpr size_t kEdgesAhead = 8;

// shift p and start offset k of a transition of length Lc up to curvature 1 / R (header)
void transition_offsets(double length_mm, double radius_mm, double& shift_mm, double& start_mm) {
  const double tau = length_mm / (2.0 * radius_mm);
  double x = 0.0, y = 0.0;
  clothoid_integrals(tau, 1.0, x, y);
  shift_mm = length_mm * y - radius_mm * (1.0 - std::cos(tau));
  start_mm = length_mm * x - radius_mm * std::sin(tau);
}

double transition_shift(double length_mm, double radius_mm) {
  double shift = 0.0, start = 0.0;
  transition_offsets(length_mm, radius_mm, shift, start);
  return shift;
}

// At a free end (the chain's own end, entered or left at speed) the transition runs from the
// end point itself: that point lies sqrt((R + p)^2 + k^2) from the centre, this much beyond R.
double free_end_shift(double length_mm, double radius_mm) {
  double shift = 0.0, start = 0.0;
  transition_offsets(length_mm, radius_mm, shift, start);
  return std::hypot(radius_mm + shift, start) - radius_mm;
}

// the transition length whose shift (`shift_of`: an edge's or a free end's, each rising with
// the length up to the largest turn) is `shift_mm`; infinity beyond that turn's
template <class Shift>
double transition_for_shift(double shift_mm, double radius_mm, const Shift& shift_of) {
  const double longest = 2.0 * radius_mm * kMaxTransitionTurnRad;
  if (!(shift_mm >= 0.0)) return kInf;
  if (shift_of(longest, radius_mm) < shift_mm) return kInf;
  double lo = 0.0, hi = longest;
  for (int k = 0; k < kBisections; ++k) {
    const double mid = 0.5 * (lo + hi);
    (shift_of(mid, radius_mm) < shift_mm ? lo : hi) = mid;
  }
  return hi;
}

// The per-axis bounds of a constant-speed traversal of the run's curve (header): `reach` per
// axis the plane's extent on it, `limits` blend_limits over the run's box.
struct RunBounds {
  Vec3 reach = Vec3::Zero();
  MachineLimits limits;

  // the largest constant speed on an arc of radius R alone (no transitions: jerk v^3 / R^2)
  double arc_speed_bound(double radius_mm) const {
    double bound = kInf;
    for (int axis = 0; axis < 3; ++axis) {
      const double m = reach[axis];
      if (!(m > 1e-12)) continue;
      const AxisLimits& limit = limits.axes[axis];
      bound = std::min({bound, limit.v_max_mm_s / m, std::sqrt(limit.a_max_mm_s2 * radius_mm / m)});
      if (limit.j_max_mm_s3 > 0.0)
        bound = std::min(bound, std::cbrt(limit.j_max_mm_s3 * radius_mm * radius_mm / m));
    }
    return bound;
  }
  // the largest constant speed at radius R with transitions of at least length Lc
  double speed_bound(double radius_mm, double transition_mm) const {
    double bound = kInf;
    const double third =
        std::sqrt(1.0 / std::pow(radius_mm * transition_mm, 2) + 1.0 / std::pow(radius_mm, 4));
    for (int axis = 0; axis < 3; ++axis) {
      const double m = reach[axis];
      if (!(m > 1e-12)) continue;
      const AxisLimits& limit = limits.axes[axis];
      bound = std::min(bound, limit.v_max_mm_s / m);
      bound = std::min(bound, std::sqrt(limit.a_max_mm_s2 * radius_mm / m));
      if (limit.j_max_mm_s3 > 0.0)
        bound = std::min(bound, std::cbrt(limit.j_max_mm_s3 / (m * third)));
    }
    return bound;
  }
  // the least transition length at radius R for speed v; infinity where the arc alone
  // exceeds a limit at v
  double transition_for_speed(double radius_mm, double speed_mm_s) const {
    double length = 0.0;
    for (int axis = 0; axis < 3; ++axis) {
      const double m = reach[axis];
      if (!(m > 1e-12)) continue;
      const AxisLimits& limit = limits.axes[axis];
      if (speed_mm_s * m > limit.v_max_mm_s * (1 + 1e-12)) return kInf;
      if (speed_mm_s * speed_mm_s * m / radius_mm > limit.a_max_mm_s2) return kInf;
      if (!(limit.j_max_mm_s3 > 0.0)) continue;
      // v^3 m sqrt(1 / (R Lc)^2 + 1 / R^4) <= j
      const double room = std::pow(limit.j_max_mm_s3 / (std::pow(speed_mm_s, 3) * m), 2) -
                          1.0 / std::pow(radius_mm, 4);
      if (!(room > 0.0)) return kInf;
      length = std::max(length, 1.0 / (radius_mm * std::sqrt(room)));
    }
    return length;
  }
};

// Fits corners a..b of the chain (a run candidate: one plane, one sense, one path and speed) as
// one curve, or null (see find_arc_runs). A run from rest to rest (both ends free, the chain
// entered and left at rest) has its transitions sized for transition_speed_share of the print
// speed and keeps the arc's own bound: it passes them at its ramps' speeds, which its law
// checks (plan_chain).
std::shared_ptr<const ArcRun> fit_arc_run(const MergedChain& merged, const PrintChain& given,
                                          const std::vector<CornerGeometry>& geometry, size_t a,
                                          size_t b, double tolerance, const TcpLimits& limits,
                                          const PathMotionOptions& options, bool free_start,
                                          bool free_end, double transition_speed_share = 1.0,
                                          double run_speed_share = 1.0,
                                          bool* ends_too_long = nullptr) {
  const bool from_rest_to_rest =
      free_start && free_end && !options.enter_at_speed && !options.leave_at_speed;
  const PrintChain& chain = merged.chain;
  const std::vector<Vec3>& points = chain.points;
  const size_t n = points.size();
  // the plane: turning left about e3, e1 the entry direction
  const Vec3 d_in = geometry[a].d_in, d_out = geometry[b].d_out;
  const Vec3 e3 = d_in.cross(geometry[a].d_out).normalized();
  const Vec3 e1 = d_in, e2 = e3.cross(e1);
  for (size_t k = a - 1; k <= b + 1; ++k)
    if (std::abs((points[k] - points[a]).dot(e3)) > kPlanarTolerance_mm) return nullptr;

  // the vertices' least-squares circle (Kasa: x^2 + y^2 + D x + E y + F = 0), in the plane
  // about the vertices' mean (from rest to rest, the chain's ends too: the curve starts and
  // ends at them, and a transition from an end off the circle is long)
  const size_t fit_first = from_rest_to_rest ? a - 1 : a;
  const size_t fit_last = from_rest_to_rest ? b + 1 : b;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (size_t k = fit_first; k <= fit_last; ++k)
    mean += Eigen::Vector2d((points[k] - points[a]).dot(e1), (points[k] - points[a]).dot(e2));
  mean /= static_cast<double>(fit_last - fit_first + 1);
  Eigen::Matrix3d normal_matrix = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (size_t k = fit_first; k <= fit_last; ++k) {
    const Eigen::Vector2d q =
        Eigen::Vector2d((points[k] - points[a]).dot(e1), (points[k] - points[a]).dot(e2)) - mean;
    const Eigen::Vector3d row(q.x(), q.y(), 1.0);
    normal_matrix += row * row.transpose();
    rhs -= q.squaredNorm() * row;
  }
  const Eigen::Vector3d def = normal_matrix.ldlt().solve(rhs);
  const Eigen::Vector2d centre_2d = mean - 0.5 * def.head<2>();
  const double fit_radius_sq = 0.25 * def.head<2>().squaredNorm() - def.z();
  if (!def.allFinite() || !(fit_radius_sq > 0.0)) return nullptr;
  const double fit_radius = std::sqrt(fit_radius_sq);
  const Vec3 centre = points[a] + centre_2d.x() * e1 + centre_2d.y() * e2;
  // (cheap first) every vertex within the tolerance of that circle
  for (size_t k = fit_first; k <= fit_last; ++k)
    if (std::abs((points[k] - centre).norm() - fit_radius) > tolerance) return nullptr;
  const Vec3 n_in = e3.cross(d_in), n_out = e3.cross(d_out);

  // each end's distance from the centre: its line's (on its left, the turning side), or at a
  // free end, the chain end's
  const double h_in = free_start ? (points[a - 1] - centre).norm() : (centre - points[a]).dot(n_in);
  const double h_out = free_end ? (points[b + 1] - centre).norm() : (centre - points[b]).dot(n_out);
  if (!(h_in > 0.0 && h_out > 0.0)) return nullptr;
  const auto shift_in = [&](double length, double radius) {
    return free_start ? free_end_shift(length, radius) : transition_shift(length, radius);
  };
  const auto shift_out = [&](double length, double radius) {
    return free_end ? free_end_shift(length, radius) : transition_shift(length, radius);
  };
  double total_turn = 0.0;
  for (size_t k = a; k <= b; ++k) total_turn += geometry[k].turn_rad;

  // the bounds over the run's box (the polyline's, padded by the tolerance)
  Vec3 lo = points[a - 1], hi = points[a - 1];
  for (size_t k = a; k <= b + 1; ++k) {
    lo = lo.cwiseMin(points[k]);
    hi = hi.cwiseMax(points[k]);
  }
  RunBounds bounds;
  const Vec3 pad = Vec3::Constant(tolerance);
  bounds.limits = blend_limits(limits.over(lo - pad, hi + pad));
  for (int axis = 0; axis < 3; ++axis) bounds.reach[axis] = std::hypot(e1[axis], e2[axis]);

  // the radius: the nearer end's distance less the shift of the transition the speed needs
  // there (a fixed point: the shift grows as the radius shrinks), at the print speed; where
  // that fails, at a share of what the arc alone allows (the planner weighs a slower run
  // against the corners' own choices)
  const auto radius_for = [&](double speed) {
    double radius = std::min(h_in, h_out);
    for (int k = 0; k < kRadiusIterations; ++k) {
      const double needed = bounds.transition_for_speed(radius, speed);
      if (!std::isfinite(needed) || needed > 2.0 * radius * kMaxTransitionTurnRad) return -1.0;
      radius = std::min(h_in - kShiftMargin * shift_in(needed, radius),
                        h_out - kShiftMargin * shift_out(needed, radius));
      if (!(radius > 0.0)) return -1.0;
    }
    return radius;
  };
  const double share = from_rest_to_rest ? transition_speed_share : 1.0;
  double speed = run_speed_share * chain.edge_speed_mm_s[a];
  double radius = radius_for(share * speed);
  if (!(radius > 0.0)) {
    speed = std::min(speed, kSlowRunShare * bounds.arc_speed_bound(std::min(h_in, h_out)));
    radius = radius_for(share * speed);
  }
  if (!(radius > 0.0)) return nullptr;
  const double transition_in = transition_for_shift(h_in - radius, radius, shift_in);
  const double transition_out = transition_for_shift(h_out - radius, radius, shift_out);
  if (!std::isfinite(transition_in) || !std::isfinite(transition_out)) return nullptr;
  // the curve's ends, each on its edge (see below) or at a free end, the chain's end itself,
  // the transition's line turned to pass through it: there the end lies k along the line
  // from the centre's foot and R + p to its right, so the line's direction is the end's
  // direction from the centre turned by the angle of (-k, R + p) at the start, (k, R + p) at the
  // end
  double shift = 0.0, start_in = 0.0, start_out = 0.0;
  transition_offsets(transition_in, radius, shift, start_in);
  const double shift_at_start = shift;
  transition_offsets(transition_out, radius, shift, start_out);
  const double shift_at_end = shift;
  const auto turned = [&](const Vec3& from_centre, double along, double across_mm) {
    const Vec3 u = from_centre.normalized();
    const double norm = std::hypot(along, across_mm);
    return Vec3((along * u + across_mm * e3.cross(u)) / norm);
  };
  const Vec3 start_direction =
      free_start ? turned(points[a - 1] - centre, -start_in, radius + shift_at_start) : d_in;
  const Vec3 end_direction =
      free_end ? turned(points[b + 1] - centre, start_out, radius + shift_at_end) : d_out;
  // the turn from the start's direction to the end's: the corners' and the free ends' own
  const auto signed_turn = [&](const Vec3& from, const Vec3& to) {
    return std::atan2(e3.dot(from.cross(to)), from.dot(to));
  };
  total_turn += signed_turn(start_direction, d_in) + signed_turn(d_out, end_direction);
  const double tau_sum = (transition_in + transition_out) / (2.0 * radius);
  if (!(tau_sum <= total_turn)) return nullptr;
  // (from rest to rest: the print speed where the arc allows it, else a share of what it allows)
  const double arc_bound = bounds.arc_speed_bound(radius);
  const double speed_bound =
      !from_rest_to_rest   ? bounds.speed_bound(radius, std::min(transition_in, transition_out))
      : arc_bound >= speed ? speed
                           : kSlowRunShare * arc_bound;
  if (!(speed_bound >= (from_rest_to_rest ? 0.5 : 1.0 - 1e-9) * speed)) return nullptr;

  // On an edge, the curve's end leaves half the edge for its other end (the whole edge at an
  // end of the chain the path enters or leaves at speed); a free end takes it whole.
  const double edge_in = (points[a] - points[a - 1]).norm();
  const double edge_out = (points[b + 1] - points[b]).norm();
  const Vec3 start =
      free_start ? points[a - 1]
                 : Vec3(points[a] + (centre - points[a]).dot(d_in) * d_in - start_in * d_in);
  const Vec3 end =
      free_end ? points[b + 1]
               : Vec3(points[b] + (centre - points[b]).dot(d_out) * d_out + start_out * d_out);
  const double entry_trim = free_start ? edge_in : (points[a] - start).dot(d_in);
  const double exit_trim = free_end ? edge_out : (end - points[b]).dot(d_out);
  const double room_in =
      (a == 1 && (options.enter_at_speed || free_start)) ? edge_in : 0.5 * edge_in;
  const double room_out =
      (b + 2 == n && (options.leave_at_speed || free_end)) ? edge_out : 0.5 * edge_out;
  if (!(entry_trim >= 0.0 && entry_trim <= room_in && exit_trim >= 0.0 && exit_trim <= room_out)) {
    if (ends_too_long != nullptr) *ends_too_long = true;
    return nullptr;
  }

  // (cheap first) every vertex within the tolerance of the curve's radial range about the
  // centre: from R on the arc out to the farther end's distance
  const double outermost = std::max((start - centre).norm(), (end - centre).norm());
  for (size_t k = a; k <= b; ++k) {
    const double from_centre = (points[k] - centre).norm();
    if (from_centre < radius - tolerance || from_centre > outermost + tolerance) return nullptr;
  }

  auto run = std::make_shared<ArcRun>(a, b, centre, radius, start_direction, end_direction, e3,
                                      total_turn, transition_in, transition_out, start, end);
  run->entry_trim_mm = entry_trim;
  run->exit_trim_mm = exit_trim;
  run->speed_bound_mm_s = speed_bound;
  run->from_rest_to_rest = from_rest_to_rest;

  // within the tolerance of the polyline as given (before merge_fine_edges) both ways, on
  // samples: each sample's distance from it (the nearest of the next few edges: the curve
  // follows them in order; an overestimate at worst) plus half their spacing; each kept vertex's
  // distance from the nearest sample
  const std::vector<Vec3>& polyline = given.points;
  const size_t first_edge = merged.source_point[a - 1], last_edge = merged.source_point[b + 1] - 1;
  const double length = run->length_mm();
  const double spacing_goal = kSampleShareOfTolerance * tolerance;
  if (length / spacing_goal > static_cast<double>(kMaxSamples)) return nullptr;
  const size_t intervals =
      std::max<size_t>(1, static_cast<size_t>(std::ceil(length / spacing_goal)));
  const double spacing = length / static_cast<double>(intervals);
  std::vector<Vec3> samples(intervals + 1);
  double deviation = 0.0;
  size_t edge = first_edge;  // the nearest edge so far
  for (size_t m = 0; m <= intervals; ++m) {
    samples[m] = run->position(m == intervals ? length : spacing * static_cast<double>(m));
    double nearest = kInf;
    size_t nearest_edge = edge;
    for (size_t e = edge; e <= std::min(last_edge, edge + kEdgesAhead); ++e) {
      const double d = point_segment_distance(samples[m], polyline[e], polyline[e + 1]);
      if (d < nearest) {
        nearest = d;
        nearest_edge = e;
      }
    }
    edge = nearest_edge;
    deviation = std::max(deviation, nearest);
    if (deviation + 0.5 * spacing > tolerance) return nullptr;
  }
  // (the nearest sample to each vertex follows the last one's; the scan stops two of the
  // run's longest edges past the nearest so far)
  double longest_edge = 0.0;
  for (size_t k = a - 1; k <= b; ++k)
    longest_edge = std::max(longest_edge, (points[k + 1] - points[k]).norm());
  const size_t beyond = static_cast<size_t>(std::ceil(2.0 * longest_edge / spacing)) + 1;
  size_t from = 0;
  for (size_t k = a; k <= b; ++k) {
    double nearest = kInf;
    size_t at = from;
    for (size_t m = from; m < samples.size() && m <= at + beyond; ++m) {
      const double d = (samples[m] - points[k]).norm();
      if (d < nearest) {
        nearest = d;
        at = m;
      }
    }
    if (nearest > tolerance) return nullptr;
    from = at;
  }
  run->deviation_mm = deviation + 0.5 * spacing;
  return run;
}

}  // namespace

ArcRun::ArcRun(size_t first_corner, size_t last_corner, const Vec3& centre, double radius_mm,
               const Vec3& d_in, const Vec3& d_out, const Vec3& normal, double total_turn_rad,
               double transition_in_mm, double transition_out_mm, const Vec3& start_mm,
               const Vec3& end_mm)
    : first_corner_(first_corner),
      last_corner_(last_corner),
      centre_(centre),
      radius_(radius_mm),
      d_in_(d_in),
      n_in_(normal.cross(d_in)),
      d_out_(d_out),
      n_out_(normal.cross(d_out)),
      transition_in_(transition_in_mm),
      transition_out_(transition_out_mm),
      tau_in_(transition_in_mm / (2.0 * radius_mm)),
      tau_out_(transition_out_mm / (2.0 * radius_mm)),
      start_(start_mm),
      end_(end_mm) {
  const double arc_turn = total_turn_rad - tau_in_ - tau_out_;
  if (!(radius_mm > 0.0 && transition_in_mm > 0.0 && transition_out_mm > 0.0 && arc_turn >= 0.0))
    throw InternalError("an arc run needs a positive radius, transitions and turn");
  arc_length_ = radius_mm * arc_turn;
}

double ArcRun::section_length_mm(int section) const {
  return section == 0 ? transition_in_ : section == 1 ? arc_length_ : transition_out_;
}

void ArcRun::at(double s, Vec3& position, Vec3& d1, Vec3& d2, Vec3& d3) const {
  const double length = length_mm();
  s = std::clamp(s, 0.0, length);
  // the tangent angle psi from `d` towards `n`; t = cos psi d + sin psi n, N = t turned +90 deg
  const auto frame = [&](const Vec3& d, const Vec3& n, double psi, double kappa, double rate) {
    const Vec3 t = std::cos(psi) * d + std::sin(psi) * n;
    const Vec3 normal = -std::sin(psi) * d + std::cos(psi) * n;
    d1 = t;
    d2 = kappa * normal;
    d3 = rate * normal - kappa * kappa * t;
    return normal;
  };
  double x = 0.0, y = 0.0;
  if (s < transition_in_) {
    // from the start: psi = tau_in u^2, kappa = u / R
    const double u = s / transition_in_;
    clothoid_integrals(tau_in_, u, x, y);
    position = start_ + transition_in_ * (x * d_in_ + y * n_in_);
    frame(d_in_, n_in_, tau_in_ * u * u, u / radius_, 1.0 / (radius_ * transition_in_));
  } else if (s <= transition_in_ + arc_length_) {
    // on the circle: the centre is R along the normal
    const double psi = tau_in_ + (s - transition_in_) / radius_;
    const Vec3 normal = frame(d_in_, n_in_, psi, 1.0 / radius_, 0.0);
    position = centre_ - radius_ * normal;
  } else {
    // from the end backwards: psi = -tau_out u^2 from d_out, kappa = u / R falling
    const double u = (length - s) / transition_out_;
    clothoid_integrals(tau_out_, u, x, y);
    position = end_ - transition_out_ * (x * d_out_ - y * n_out_);
    frame(d_out_, n_out_, -tau_out_ * u * u, u / radius_, -1.0 / (radius_ * transition_out_));
  }
  if (s == 0.0) position = start_;
  if (s == length) position = end_;
}

size_t ArcRun::section_edge(int section) const {
  return section == 0 ? first_corner_ - 1 : section == 1 ? first_corner_ : last_corner_;
}

Vec3 ArcRun::normal() const {
  return d_in_.cross(n_in_);
}

Vec3 ArcRun::position(double s) const {
  Vec3 p, d1, d2, d3;
  at(s, p, d1, d2, d3);
  return p;
}

std::vector<std::shared_ptr<const ArcRun>> find_arc_runs(
    const MergedChain& merged, const PrintChain& given, const std::vector<CornerGeometry>& geometry,
    double tolerance_mm, const TcpLimits& limits, const PathMotionOptions& options) {
  const PrintChain& chain = merged.chain;
  std::vector<std::shared_ptr<const ArcRun>> runs;
  const size_t n = chain.points.size();
  if (chain.oriented || n < kMinArcRunCorners + 2) return runs;
  // a corner a run may hold: it turns, by less than 90 deg, between edges of one print speed
  // (a run's inner edges are of one path, its end edges may be of the paths joined to it: a
  // G-code arc between its lines)
  const auto turning = [&](size_t i) {
    const CornerGeometry& g = geometry[i];
    return !taken_straight_on(g) && g.turn_rad < 0.5 * kPi && g.max_half_length_mm > 0.0 &&
           chain.edge_speed_mm_s[i - 1] == chain.edge_speed_mm_s[i];
  };
  const auto turn_normal = [&](size_t i) {
    return geometry[i].d_in.cross(geometry[i].d_out).normalized();
  };
  // a corner whose own largest blend cannot keep the print speed (what a run is for)
  const auto slow_alone = [&](size_t i) {
    const CornerGeometry& g = geometry[i];
    const double bound = blend_speed_bound(g.shape, g.max_half_length_mm,
                                           corner_blend_limits(g, g.max_half_length_mm, limits));
    return bound < chain.corner_print_speed_mm_s(i) * (1.0 - 1e-9);
  };
  size_t i = 1;
  while (i + 1 < n) {
    if (!turning(i)) {
      ++i;
      continue;
    }
    // the sequence first..last of corners that continue one another (one plane and sense)
    const size_t first = i;
    const Vec3 normal = turn_normal(first);
    size_t last = first;
    while (last + 2 < n && last + 1 - first < kMaxArcRunCorners && turning(last + 1) &&
           turn_normal(last + 1).dot(normal) >= kParallelNormals &&
           chain.edge_path[last] == chain.edge_path[first])
      ++last;
    i = last + 1;
    if (last + 1 - first < kMinArcRunCorners) continue;
    // slow[k]: how many of first..first+k-1 are slow alone
    std::vector<size_t> slow(last - first + 2, 0);
    for (size_t k = first; k <= last; ++k)
      slow[k - first + 1] = slow[k - first] + (slow_alone(k) ? 1 : 0);
    // from each corner, the longest run that fits and holds a slow corner
    size_t a = first;
    while (a + kMinArcRunCorners - 1 <= last) {
      std::shared_ptr<const ArcRun> found;
      for (size_t b = last; b >= a + kMinArcRunCorners - 1 && !found; --b) {
        const bool whole_at_rest =
            a == 1 && b + 2 == n && !options.enter_at_speed && !options.leave_at_speed;
        // no slow corner left in a..b (a whole chain from rest to rest needs none: its lines
        // ramp one at a time between blends at constant speeds, where the run ramps on the
        // curve)
        if (!whole_at_rest && slow[b - first + 1] == slow[a - first]) break;
        // (a run that is the whole chain, entered and left at rest, its speed changing on the
        // curve, is tried first there, as lines at its ends would have to reach the run's one
        // speed from rest within half an edge: its transitions sized for the print speed, else
        // for less: shorter, they leave the arc nearer the circle)
        for (const double share : kRestTransitionSpeedShares) {
          if (!whole_at_rest || found) break;
          found = fit_arc_run(merged, given, geometry, a, b, tolerance_mm, limits, options, true,
                              true, share);
        }
        bool ends_too_long = false;
        if (!found)
          found = fit_arc_run(merged, given, geometry, a, b, tolerance_mm, limits, options, false,
                              false, 1.0, 1.0, &ends_too_long);
        // (its transitions too long for its end edges at the print speed: sized for less, the
        // run below the print speed, weighed against its corners by the planner)
        for (const double share : kShortTransitionSpeedShares) {
          if (found || !ends_too_long || whole_at_rest) break;
          ends_too_long = false;
          found = fit_arc_run(merged, given, geometry, a, b, tolerance_mm, limits, options, false,
                              false, 1.0, share, &ends_too_long);
        }
        // (at an end of the chain entered or left at speed, the curve may run to the end
        // itself: a chorded circle's closing chords are seldom the length its transitions
        // need)
        const bool free_start = a == 1 && options.enter_at_speed;
        const bool free_end = b + 2 == n && options.leave_at_speed;
        if (!found && (free_start || free_end))
          found = fit_arc_run(merged, given, geometry, a, b, tolerance_mm, limits, options,
                              free_start, free_end);
      }
      if (found) {
        a = found->last_corner() + 1;
        runs.push_back(std::move(found));
      } else {
        ++a;
      }
    }
  }
  return runs;
}

}  // namespace depotwin
