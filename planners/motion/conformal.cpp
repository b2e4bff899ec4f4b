#include "planners/motion/conformal.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/number_text.hpp"
#include "planners/motion/jerk_time_law.hpp"
#include "planners/motion/path_check.hpp"
#include "planners/motion/path_parametrization.hpp"

namespace depotwin {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMaxBlendTurnRad = 170.0 * kPi / 180.0;  // sharper turns stop (fine point)
constexpr double kMinBlendMm = 1e-3;                      // smaller blends stop instead
constexpr double kChunkMm = 2.0;                          // TCP limits asked per chunk
constexpr int kBlendMinIntervals = 8;                     // grid intervals per blend, at least
constexpr int kLineMinIntervals = 3;                      // per line (4-point differences)
constexpr int kRestGrading = 12;     // grid steps halve this many times towards a rest
constexpr double kMinLineMm = 1e-4;  // the shortest line left between two blends
constexpr double kTurnInPlaceLiftMm = 1.0;
constexpr double kSamePoint = 1e-9;  // mm
// flow_lag_s: the rounds of lowered speed bounds, and the speed they stop at (below it the law
// brakes to rest as the limits allow: the flow left is at most this share of the nominal)
constexpr int kLagRounds = 4;
constexpr double kLagFloorShare = 0.02;
// detailed warnings per plan; the rest are counted
constexpr size_t kMaxDetailedWarnings = 20;

// ---------------------------------------------------------------------------------------
// geometry

// A symmetric quadratic Bezier blend from corner - delta d_in through the corner (control
// point) to corner + delta d_out, by arc length. |B'(u)| = 2 delta sqrt(2 (1 - c)) sqrt(w^2 + k^2)
// with c = d_in . d_out, w = u - 1/2, k^2 = (1 + c) / (4 (1 - c)): the arc length is closed
// form (asinh), inverted by safeguarded Newton.
//
// Under a jerk limit (curvature_continuous) the blend is the quartic with control points
// corner - delta d_in, corner - delta/2 d_in, corner, corner + delta/2 d_out, corner + delta
// d_out (bezier_curve.hpp's degree-4 blend with weight 1): the same ends and tangents, zero
// curvature at both ends, so the curvature, and with it the acceleration at any speed, is
// continuous along the path. It passes the corner at (3 delta / 8) sin(theta / 2), within the
// quadratic's bound. Its arc length is integrated (Gauss-Legendre on 64 panels) and inverted
// by the same Newton iteration.
class Blend {
 public:
  Blend(const Vec3& corner, const Vec3& d_in, const Vec3& d_out, double delta,
        bool curvature_continuous = false)
      : corner_(corner), e0_(delta * d_in), e1_(delta * d_out), delta_(delta) {
    start_ = corner - e0_;
    end_ = corner + e1_;
    const double c = std::clamp(d_in.dot(d_out), -1.0, 1.0);
    straight_ = 1.0 - c < 1e-10;
    quartic_ = curvature_continuous && !straight_;
    if (quartic_) {
      // the quartic's first and second derivative control points (forward differences)
      const Vec3 q[5] = {start_, corner - 0.5 * e0_, corner, corner + 0.5 * e1_, end_};
      for (int i = 0; i < 4; ++i) first_[i] = 4.0 * (q[i + 1] - q[i]);
      for (int i = 0; i < 3; ++i) second_[i] = 3.0 * (first_[i + 1] - first_[i]);
      for (int i = 0; i < 5; ++i) points_[i] = q[i];
      panel_length_[0] = 0.0;
      for (int p = 0; p < kPanels; ++p)
        panel_length_[p + 1] =
            panel_length_[p] + gauss_length(double(p) / kPanels, double(p + 1) / kPanels);
      length_ = panel_length_[kPanels];
      return;
    }
    if (!straight_) {
      scale_ = 2.0 * delta * std::sqrt(2.0 * (1.0 - c));
      k2_ = (1.0 + c) / (4.0 * (1.0 - c));
      k_ = std::sqrt(k2_);
      g0_ = g(-0.5);
    }
    length_ = arc(1.0);
  }

  double length() const { return length_; }
  const Vec3& start() const { return start_; }
  const Vec3& end() const { return end_; }
  const Vec3& corner() const { return corner_; }

  // the parameter at arc length s (guess: a parameter near it, e.g. the previous query's)
  double u_at(double s, double guess = -1.0) const {
    if (s <= 0.0) return 0.0;
    if (s >= length_) return 1.0;
    if (straight_) return s / length_;
    double lo = 0.0, hi = 1.0, u = guess > 0.0 && guess < 1.0 ? guess : s / length_;
    for (int iteration = 0; iteration < 100; ++iteration) {
      const double f = arc(u) - s;
      if (std::abs(f) <= 1e-14 * length_) break;
      (f > 0.0 ? hi : lo) = u;
      double next = u - f / speed(u);
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      u = next;
    }
    return u;
  }

  Vec3 point(double u) const {
    if (quartic_) return bernstein(points_, 4, u);
    return (1 - u) * (1 - u) * start_ + 2 * u * (1 - u) * corner_ + u * u * end_;
  }

  // position and arc-length derivatives at parameter u
  void at(double u, Vec3& p, Vec3& d1, Vec3& d2) const {
    p = point(u);
    const Vec3 du = quartic_ ? bernstein(first_, 3, u) : Vec3(2.0 * ((1 - u) * e0_ + u * e1_));
    const Vec3 duu = quartic_ ? bernstein(second_, 2, u) : Vec3(2.0 * (e1_ - e0_));
    const double speed_u = du.norm();
    d1 = du / speed_u;
    d2 = (duu - duu.dot(d1) * d1) / (speed_u * speed_u);
  }

 private:
  static constexpr int kPanels = 64;

  // sum of control points c_0..c_m times the Bernstein polynomials of degree m at u
  static Vec3 bernstein(const Vec3* c, int m, double u) {
    Vec3 b[5];
    for (int i = 0; i <= m; ++i) b[i] = c[i];
    for (int level = 1; level <= m; ++level)
      for (int i = 0; i <= m - level; ++i) b[i] = (1.0 - u) * b[i] + u * b[i + 1];
    return b[0];
  }
  // the quartic's arc length over [u0, u1] (4-point Gauss-Legendre)
  double gauss_length(double u0, double u1) const {
    static constexpr double kNode[2] = {0.3399810435848563, 0.8611363115940526};
    static constexpr double kWeight[2] = {0.6521451548625461, 0.3478548451374538};
    const double mid = 0.5 * (u0 + u1), half = 0.5 * (u1 - u0);
    double length = 0.0;
    for (int k = 0; k < 2; ++k)
      for (const double sign : {-1.0, 1.0})
        length += kWeight[k] * half * speed(mid + sign * half * kNode[k]);
    return length;
  }
  double g(double w) const { return w * std::sqrt(w * w + k2_) + k2_ * std::asinh(w / k_); }
  double arc(double u) const {
    if (straight_) return 2.0 * delta_ * u;
    if (quartic_) {
      const int panel = std::clamp(static_cast<int>(u * kPanels), 0, kPanels - 1);
      return panel_length_[panel] + gauss_length(double(panel) / kPanels, u);
    }
    return 0.5 * scale_ * (g(u - 0.5) - g0_);
  }
  double speed(double u) const {
    if (straight_) return 2.0 * delta_;
    if (quartic_) return bernstein(first_, 3, u).norm();
    const double w = u - 0.5;
    return scale_ * std::sqrt(w * w + k2_);
  }

  Vec3 corner_, e0_, e1_, start_, end_;
  double delta_ = 0.0, scale_ = 0.0, k2_ = 0.0, k_ = 0.0, g0_ = 0.0, length_ = 0.0;
  bool straight_ = false;
  bool quartic_ = false;
  Vec3 points_[5], first_[4], second_[3];
  double panel_length_[kPanels + 1] = {};
};

// The orientation over a blend: a spherical quadratic Bezier of the axis (de Casteljau with
// slerps) and a quadratic Bezier of the roll, through the corner's orientation.
struct OrientationBlend {
  ToolOrientation begin, corner, end;

  bool constant() const {
    return begin.axis == corner.axis && corner.axis == end.axis &&
           begin.roll_rad == corner.roll_rad && corner.roll_rad == end.roll_rad;
  }
  void at(double u, Vec3& axis, double& roll) const {
    axis = begin.axis == corner.axis && corner.axis == end.axis
               ? corner.axis
               : slerp_axis(slerp_axis(begin.axis, corner.axis, u),
                            slerp_axis(corner.axis, end.axis, u), u);
    roll = (1 - u) * (1 - u) * begin.roll_rad + 2 * u * (1 - u) * corner.roll_rad +
           u * u * end.roll_rad;
  }
};

ToolOrientation slerp_orientation(const ToolOrientation& a, const ToolOrientation& b, double f) {
  return {slerp_axis(a.axis, b.axis, f), a.roll_rad + f * (b.roll_rad - a.roll_rad)};
}

// A line or a blend of a flown-by polyline.
struct Piece {
  bool is_blend = false;
  Vec3 from = Vec3::Zero(), to = Vec3::Zero();  // a line
  Blend blend{Vec3::Zero(), Vec3::UnitX(), Vec3::UnitX(), 0.0};
  OrientationBlend orientation_blend;
  ToolOrientation o_from, o_to;  // a line's orientation at its ends (slerped in between)
  double length = 0.0;
  bool stop_after = false;  // the path stops where this piece ends
};

// A polyline with its orientation per point and the blend size at each interior point
// (0: a fine point, the path stops there).
struct Polyline {
  std::vector<Vec3> points;
  std::vector<ToolOrientation> orientations;
  std::vector<double> delta;  // per point; 0 at both ends
};

std::vector<Piece> fly_by_pieces(const Polyline& polyline, bool curvature_continuous = false) {
  std::vector<Piece> pieces;
  const size_t n = polyline.points.size();
  // a line left between two blends is either none (they touch) or at least kMinLineMm: a
  // sliver (edges equal to rounding) would make grid steps too small for finite differences
  Polyline line = polyline;
  for (size_t e = 0; e + 1 < n; ++e) {
    const double length = (line.points[e + 1] - line.points[e]).norm();
    const double rest = length - line.delta[e] - line.delta[e + 1];
    if (rest <= 0.0 || rest >= kMinLineMm) continue;
    const double cut = 0.5 * (kMinLineMm - rest);
    for (const size_t k : {e, e + 1})
      if (line.delta[k] > 0.0) line.delta[k] = std::max(0.0, line.delta[k] - cut);
  }
  for (size_t e = 0; e + 1 < n; ++e) {
    const Vec3& p0 = line.points[e];
    const Vec3& p1 = line.points[e + 1];
    const double length = (p1 - p0).norm();
    const Vec3 dir = (p1 - p0) / length;
    const double d0 = line.delta[e], d1 = line.delta[e + 1];
    Piece piece;
    piece.from = p0 + d0 * dir;
    piece.to = p1 - d1 * dir;
    piece.length = length - d0 - d1;
    piece.o_from = slerp_orientation(line.orientations[e], line.orientations[e + 1], d0 / length);
    piece.o_to =
        slerp_orientation(line.orientations[e], line.orientations[e + 1], 1.0 - d1 / length);
    if (d0 == 0.0) piece.o_from = line.orientations[e];
    if (d1 == 0.0) piece.o_to = line.orientations[e + 1];
    piece.stop_after = d1 == 0.0 && e + 2 < n;
    if (piece.length > 1e-12 * length) {
      pieces.push_back(piece);
    } else if (d1 == 0.0 && e + 2 < n && !pieces.empty()) {
      pieces.back().stop_after = true;
    }
    if (e + 2 < n && d1 > 0.0) {
      const Vec3& p2 = line.points[e + 2];
      const double next_length = (p2 - p1).norm();
      Piece blend;
      blend.is_blend = true;
      blend.blend = Blend(p1, dir, (p2 - p1) / next_length, d1, curvature_continuous);
      blend.length = blend.blend.length();
      blend.orientation_blend = {
          slerp_orientation(line.orientations[e], line.orientations[e + 1], 1.0 - d1 / length),
          line.orientations[e + 1],
          slerp_orientation(line.orientations[e + 1], line.orientations[e + 2], d1 / next_length)};
      pieces.push_back(blend);
    }
  }
  return pieces;
}

// the orientation on a piece at arc length sigma from its start (u_guess: a blend parameter
// near sigma's, in/out)
void piece_orientation(const Piece& piece, double sigma, Vec3& axis, double& roll,
                       double* u_guess = nullptr) {
  if (piece.is_blend) {
    if (piece.orientation_blend.constant()) {
      axis = piece.orientation_blend.corner.axis;
      roll = piece.orientation_blend.corner.roll_rad;
      return;
    }
    const double u = piece.blend.u_at(sigma, u_guess ? *u_guess : -1.0);
    if (u_guess) *u_guess = u;
    piece.orientation_blend.at(u, axis, roll);
    return;
  }
  const ToolOrientation o =
      slerp_orientation(piece.o_from, piece.o_to, std::clamp(sigma / piece.length, 0.0, 1.0));
  axis = o.axis;
  roll = o.roll_rad;
}

// the pieces' orientation at any s along them (PathGrid::orientation_at); queries that move
// forwards along the path (resampling) start from the previous one's piece and parameter
std::function<void(double, Vec3&, double&)> pieces_orientation(std::vector<Piece> pieces) {
  struct State {
    std::vector<Piece> pieces;
    std::vector<double> starts;
    size_t piece = 0;
    double u = -1.0;
  };
  auto state = std::make_shared<State>();
  state->pieces = std::move(pieces);
  double s0 = 0.0;
  for (const Piece& piece : state->pieces) {
    state->starts.push_back(s0);
    s0 += piece.length;
  }
  return [state](double s, Vec3& axis, double& roll) {
    const std::vector<double>& starts = state->starts;
    size_t i = state->piece;
    if (i >= starts.size() || s < starts[i]) {
      i = static_cast<size_t>(std::max<std::ptrdiff_t>(
          0, std::upper_bound(starts.begin(), starts.end(), s) - starts.begin() - 1));
    } else {
      while (i + 1 < starts.size() && starts[i + 1] <= s) ++i;
    }
    if (i != state->piece) state->u = -1.0;
    state->piece = i;
    piece_orientation(state->pieces[i], s - starts[i], axis, roll, &state->u);
  };
}

// The grid of a flown-by polyline: each piece cut into equal arc-length steps of at most ds
// (at least 8 per blend, 3 per line); piece junctions are breaks (the curvature steps there).
// Next to a point where the path is at rest (its ends, fine points) the steps halve down to
// ds / 2^12: a law on a grid reaches a speed only at grid points, so a ramp shorter than a
// step would otherwise be stretched over the whole first step.
PathGrid polyline_grid(const std::vector<Piece>& pieces, double ds, double speed_mm_s,
                       const std::string& name) {
  PathGrid grid;
  grid.name = name;
  double s0 = 0.0;
  std::vector<double> sigmas;
  for (size_t index = 0; index < pieces.size(); ++index) {
    const Piece& piece = pieces[index];
    const int minimum = piece.is_blend ? kBlendMinIntervals : kLineMinIntervals;
    const double intervals = std::ceil(piece.length / ds - 1e-9);
    if (!(intervals <= 1e8))
      throw InputError("planners",
                       "conformal: a piece of " + message_number(piece.length) +
                           " mm would need more than 1e8 grid steps of ds_mm; raise ds_mm");
    const int steps = std::max(minimum, static_cast<int>(intervals));
    const double step = piece.length / steps;
    sigmas.clear();
    for (int j = 0; j < steps; ++j) sigmas.push_back(piece.length * j / steps);
    sigmas.push_back(piece.length);
    const bool rest_before = index == 0 || pieces[index - 1].stop_after;
    const bool rest_after = index + 1 == pieces.size() || piece.stop_after;
    for (int k = 1; k <= kRestGrading && !piece.is_blend; ++k) {
      const double near = step * std::ldexp(1.0, -k);
      if (rest_before) sigmas.push_back(near);
      if (rest_after) sigmas.push_back(piece.length - near);
    }
    std::sort(sigmas.begin(), sigmas.end());
    const Vec3 dir =
        piece.is_blend ? Vec3(Vec3::Zero()) : Vec3((piece.to - piece.from) / piece.length);
    for (size_t j = 0; j < sigmas.size(); ++j) {
      const double sigma = sigmas[j];
      const bool last = j + 1 == sigmas.size();
      PathPoint point;
      point.s_mm = s0 + sigma;
      point.speed_mm_s = speed_mm_s;
      if (piece.is_blend) {
        const double u = piece.blend.u_at(sigma);
        piece.blend.at(u, point.position_mm, point.d1_after, point.d2_after);
        if (j == 0) point.position_mm = piece.blend.start();
        if (last) point.position_mm = piece.blend.end();
      } else {
        point.position_mm = last ? piece.to : piece.from + sigma * dir;
        point.d1_after = dir;
        point.d2_after = Vec3::Zero();
      }
      piece_orientation(piece, sigma, point.tool_axis, point.roll_rad);
      point.d1_before = point.d1_after;
      point.d2_before = point.d2_after;
      if (j == 0 && !grid.points.empty()) {
        // the junction with the previous piece: its right-hand derivatives are this piece's
        PathPoint& joint = grid.points.back();
        joint.d1_after = point.d1_after;
        joint.d2_after = point.d2_after;
        joint.is_break = true;
        continue;
      }
      grid.points.push_back(point);
    }
    if (piece.stop_after) grid.points.back().speed_mm_s = 0.0;
    s0 += piece.length;
  }
  grid.points.front().speed_mm_s = 0.0;
  grid.points.back().speed_mm_s = 0.0;
  grid.orientation_at = pieces_orientation(pieces);
  return grid;
}

// ---------------------------------------------------------------------------------------
// print paths

std::string path_name(const PrintPath& path, size_t index) {
  return "toolpath path " + std::to_string(path.source_index) +
         (static_cast<int>(index) != path.source_index
              ? " (print path " + std::to_string(index) + ")"
              : std::string());
}

// how far the blended axis over corner i (blend size delta) strays from the axis the polyline
// asks at the nearest point of its two edges
double orientation_deviation(const PrintPath& path, size_t i, double delta) {
  const Vec3& a = path.points[i - 1];
  const Vec3& c = path.points[i];
  const Vec3& b = path.points[i + 1];
  const double l_in = (c - a).norm(), l_out = (b - c).norm();
  const Blend blend(c, (c - a) / l_in, (b - c) / l_out, delta);
  const OrientationBlend orientation{
      slerp_orientation(path.orientation(i - 1), path.orientation(i), 1.0 - delta / l_in),
      path.orientation(i),
      slerp_orientation(path.orientation(i), path.orientation(i + 1), delta / l_out)};
  double worst = 0.0;
  for (int k = 1; k < 16; k += 2) {
    for (const double u : {k / 16.0, 0.5}) {
      const Vec3 p = blend.point(u);
      Vec3 axis;
      double roll = 0.0;
      orientation.at(u, axis, roll);
      const double f_in = std::clamp((p - a).dot(c - a) / (l_in * l_in), 0.0, 1.0);
      const double f_out = std::clamp((p - c).dot(b - c) / (l_out * l_out), 0.0, 1.0);
      const double dist_in = (a + f_in * (c - a) - p).squaredNorm();
      const double dist_out = (c + f_out * (b - c) - p).squaredNorm();
      const Vec3 reference = dist_in <= dist_out
                                 ? slerp_axis(path.tool_axis(i - 1), path.tool_axis(i), f_in)
                                 : slerp_axis(path.tool_axis(i), path.tool_axis(i + 1), f_out);
      worst = std::max(worst, axis_angle_rad(axis, reference));
    }
  }
  return worst;
}

struct PathGeometry {
  Polyline polyline;
  std::vector<size_t> sharp_stops;  // interior points stopped at for their turn
  std::vector<size_t> tiny_stops;   // stopped at because the orientation zone left no blend
  double max_deviation_mm = 0.0;    // of the blended path from the polyline's points
};

PathGeometry print_geometry(const PrintPath& path, const ConformalSettings& settings,
                            bool curvature_continuous = false) {
  PathGeometry out;
  Polyline& line = out.polyline;
  const size_t n = path.points.size();
  line.points = path.points;
  line.delta.assign(n, 0.0);
  for (size_t i = 0; i < n; ++i) line.orientations.push_back(path.orientation(i));
  const double ori_tolerance = deg_to_rad(settings.zone_ori_deg);
  for (size_t i = 1; i + 1 < n; ++i) {
    const Vec3 d_in = (path.points[i] - path.points[i - 1]).normalized();
    const Vec3 d_out = (path.points[i + 1] - path.points[i]).normalized();
    const double turn = axis_angle_rad(d_in, d_out);
    if (settings.zone_mm <= 0.0) continue;
    if (turn > kMaxBlendTurnRad) {
      out.sharp_stops.push_back(i);
      continue;
    }
    const double shorter = std::min((path.points[i] - path.points[i - 1]).norm(),
                                    (path.points[i + 1] - path.points[i]).norm());
    // (the apex (delta / 2) sin(turn / 2) from P_i: within zone_mm / 2 up to zone_mm / sin)
    const double zone = settings.zone_bounds_deviation_only
                            ? settings.zone_mm / std::max(std::sin(0.5 * turn), 1e-12)
                            : settings.zone_mm;
    double delta = std::min(zone, 0.5 * shorter);
    const bool turning = !path.normals.empty() && (path.normals[i - 1] != path.normals[i] ||
                                                   path.normals[i] != path.normals[i + 1]);
    for (int round = 0; turning && round < 40 && delta >= kMinBlendMm; ++round) {
      const double deviation = orientation_deviation(path, i, delta);
      if (deviation <= ori_tolerance) break;
      delta *= std::clamp(0.9 * ori_tolerance / deviation, 0.05, 0.9);
    }
    if (delta < kMinBlendMm) {
      out.tiny_stops.push_back(i);
      continue;
    }
    line.delta[i] = delta;
    // the blend passes P_i at its apex, (delta / 2) sin(turn / 2) away, or nearer (the quartic
    // at 3/8 of it)
    const Blend blend(path.points[i], d_in, d_out, delta, curvature_continuous);
    double nearest = (blend.point(0.5) - path.points[i]).norm();
    for (int k = 0; k <= 64; ++k)
      nearest = std::min(nearest, (blend.point(k / 64.0) - path.points[i]).norm());
    out.max_deviation_mm = std::max(out.max_deviation_mm, nearest);
  }
  return out;
}

// ---------------------------------------------------------------------------------------
// joints

// the machine's joints along the grid, their limits with the headroom above
void attach_joints_with_headroom(PathGrid& grid, const JointMap& joints) {
  attach_joints(grid, joints);
  for (JointLimit& limit : grid.joint_limits) {
    limit.v_max *= kJointLimitHeadroom;
    limit.a_max *= kJointLimitHeadroom;
  }
}

// ---------------------------------------------------------------------------------------
// transitions

// The toolpath's highest point per square cell of (x, y): the paths lie on the part's surface,
// so a travel that would pass lower than them over its corridor must rise above them first (a
// straight move between two points of a convex part cuts through it).
class PathHeights {
 public:
  static constexpr double kCell_mm = 2.0;

  explicit PathHeights(const Toolpath& toolpath) {
    for (const PrintPath& path : toolpath.paths)
      for (const Vec3& p : path.points) {
        const auto key = cell_of(p.x(), p.y());
        auto [it, inserted] = highest_.emplace(key, p.z());
        if (!inserted) it->second = std::max(it->second, p.z());
      }
  }
  // the highest path point within `radius` (in x, y, cells rounded outwards) of the segment
  // a -> b; -infinity where there is none
  double highest_along(const Vec3& a, const Vec3& b, double radius) const {
    double top = -kInf;
    const double length = (b - a).head<2>().norm();
    const int steps = 1 + static_cast<int>(std::ceil(length / (0.5 * kCell_mm)));
    const int reach = 1 + static_cast<int>(std::ceil(radius / kCell_mm));
    for (int k = 0; k <= steps; ++k) {
      const Vec3 p = a + (b - a) * (static_cast<double>(k) / steps);
      const auto [cx, cy] = cell_of(p.x(), p.y());
      for (int dx = -reach; dx <= reach; ++dx)
        for (int dy = -reach; dy <= reach; ++dy) {
          const auto it = highest_.find({cx + dx, cy + dy});
          if (it != highest_.end()) top = std::max(top, it->second);
        }
    }
    return top;
  }

 private:
  static std::pair<long, long> cell_of(double x, double y) {
    return {static_cast<long>(std::floor(x / kCell_mm)),
            static_cast<long>(std::floor(y / kCell_mm))};
  }
  std::map<std::pair<long, long>, double> highest_;
};

// a travel heading more than this far from the tool axis (back towards the surface) does not
// lift first
constexpr double kNoLiftAngleRad = 2.0 * kPi / 3.0;
// a travel keeps the nozzle tip this far around it (mm, in x and y: its thin end is 1.5 mm
// wide) clear of the paths' heights
constexpr double kTravelCorridor_mm = 2.0;

// The lift-move-lower polyline from (p0, o0) to (p1, o1) and its grid; the orientation turns
// with a smoothstep in arc length between the end of the lift and the start of the lowering.
// Empty when there is nothing to do.
PathGrid transition_grid(const Vec3& p0, const ToolOrientation& o0, const Vec3& p1,
                         const ToolOrientation& o1, double lift_mm, double ds,
                         const std::string& name, const PathHeights* heights = nullptr,
                         bool curvature_continuous = false) {
  const bool same_orientation = o0.axis == o1.axis && o0.roll_rad == o1.roll_rad;
  if ((p1 - p0).norm() <= kSamePoint && same_orientation) return {};
  if ((p1 - p0).norm() <= kSamePoint && lift_mm <= 0.0) lift_mm = kTurnInPlaceLiftMm;
  Polyline line;
  // lift, then, where the paths between stand higher, rise above them; across and lower
  Vec3 up0 = p0 + lift_mm * o0.axis, up1 = p1 + lift_mm * o1.axis;
  // no lift where the move heads back against it (the job's start high above the paths: a
  // lift there would only add a hairpin), nor a lowering where it arrives from below
  if (lift_mm > 0.0 && axis_angle_rad(o0.axis, up1 - p0) > kNoLiftAngleRad) up0 = p0;
  if (lift_mm > 0.0 && axis_angle_rad(o1.axis, up0 - p1) > kNoLiftAngleRad) up1 = p1;
  Vec3 over0 = up0, over1 = up1;
  if (heights && lift_mm > 0.0) {
    // (half the lift above them: the lifted ends themselves stand that high over their own
    // points for tool axes up to 60 deg from vertical)
    const double clear_z = heights->highest_along(up0, up1, kTravelCorridor_mm) + 0.5 * lift_mm;
    if (clear_z > std::min(up0.z(), up1.z())) {
      over0.z() = std::max(over0.z(), clear_z);
      over1.z() = std::max(over1.z(), clear_z);
    }
  }
  std::vector<Vec3> candidates{p0, up0, over0, over1, up1, p1};
  const int count = static_cast<int>(candidates.size());
  for (int k = 0; k < count; ++k) {
    if (!line.points.empty() && (candidates[k] - line.points.back()).norm() <= kSamePoint) {
      if (k == count - 1) line.points.back() = p1;  // end exactly at p1
      continue;
    }
    line.points.push_back(candidates[k]);
  }
  const size_t n = line.points.size();
  line.orientations.assign(n, o0);
  line.delta.assign(n, 0.0);
  for (size_t i = 1; i + 1 < n; ++i) {
    const Vec3 in = line.points[i] - line.points[i - 1], out = line.points[i + 1] - line.points[i];
    if (axis_angle_rad(in, out) > kMaxBlendTurnRad) continue;  // reverse: stop there
    line.delta[i] = 0.5 * std::min(in.norm(), out.norm());
  }
  PathGrid grid = polyline_grid(fly_by_pieces(line, curvature_continuous), ds, kInf, name);
  // the turn: from where the lift leg's straight part ends to where the lowering's begins
  const double total = grid.length_mm();
  double s1 = 0.0, s2 = total;
  if (n >= 4 && (line.points[1] - up0).norm() <= kSamePoint &&
      (line.points[n - 2] - up1).norm() <= kSamePoint) {
    s1 = (line.points[1] - line.points[0]).norm() - line.delta[1];
    s2 = total - ((line.points[n - 1] - line.points[n - 2]).norm() - line.delta[n - 2]);
  }
  if (!(s2 > s1 + 1e-9)) {
    s1 = 0.0;
    s2 = total;
  }
  grid.orientation_at = [o0, o1, s1, s2](double s, Vec3& axis, double& roll) {
    const double x = std::clamp((s - s1) / (s2 - s1), 0.0, 1.0);
    const double f = x * x * (3.0 - 2.0 * x);
    axis = slerp_axis(o0.axis, o1.axis, f);
    roll = o0.roll_rad + f * (o1.roll_rad - o0.roll_rad);
  };
  for (PathPoint& point : grid.points)
    grid.orientation_at(point.s_mm, point.tool_axis, point.roll_rad);
  grid.points.front().tool_axis = o0.axis;
  grid.points.front().roll_rad = o0.roll_rad;
  grid.points.back().tool_axis = o1.axis;
  grid.points.back().roll_rad = o1.roll_rad;
  return grid;
}

// ---------------------------------------------------------------------------------------
// pieces

TrajectoryPiece sampled_piece(const PathSamples& samples, double t_begin) {
  TrajectoryPiece piece;
  piece.t_begin_s = t_begin;
  piece.t_end_s = t_begin + samples.duration_s();
  SampledMotion motion;
  motion.period_s = samples.period_s;
  motion.position_mm = samples.position_mm;
  motion.velocity_mm_s = samples.velocity_mm_s;
  motion.tool_axis = samples.tool_axis;
  if (std::any_of(samples.roll_rad.begin(), samples.roll_rad.end(),
                  [](double r) { return r != 0.0; }))
    motion.roll_rad = samples.roll_rad;
  piece.tool_axis.begin = samples.tool_axis.front();
  piece.tool_axis.end = samples.tool_axis.back();
  piece.tool_axis.roll_begin = samples.roll_rad.front();
  piece.tool_axis.roll_end = samples.roll_rad.back();
  piece.motion = std::move(motion);
  return piece;
}

void set_cruise_speed(PathGrid& grid, double speed_mm_s) {
  for (PathPoint& point : grid.points)
    if (point.speed_mm_s > 0.0) point.speed_mm_s = speed_mm_s;
}

// Lowers the grid's speed bounds ahead of every slow-down of the law (its samples) so that the
// speed falls by at most 1 / lag_s per mm: dv/dt = v dv/ds >= -v / lag_s, the deceleration a
// flow lagging by lag_s can follow when its command leads the speed ((v + lag_s dv/dt) stays
// >= 0). The bound at s is min over the later samples k of (sdot_k + (s_k - s) / lag_s), never
// below floor_mm_s (an exponential approach to rest would never arrive). True when some bound
// was lowered.
bool cap_decelerations(PathGrid& grid, const PathSamples& samples, double lag_s,
                       double floor_mm_s) {
  const size_t n = samples.s_mm.size();
  std::vector<double> later_min(n);  // min over samples k' >= k of sdot + s / lag_s
  double running = kInf;
  for (size_t k = n; k-- > 0;) {
    running = std::min(running, samples.sdot[k] + samples.s_mm[k] / lag_s);
    later_min[k] = running;
  }
  bool lowered = false;
  size_t k = 0;
  for (PathPoint& point : grid.points) {
    while (k < n && samples.s_mm[k] < point.s_mm) ++k;
    if (k == n) break;
    if (!(point.speed_mm_s > 0.0)) continue;  // a stop stays one
    const double bound = std::max(later_min[k] - point.s_mm / lag_s, floor_mm_s);
    if (bound < point.speed_mm_s * (1 - 1e-9)) {
      point.speed_mm_s = bound;
      lowered = true;
    }
  }
  return lowered;
}

// One print path planned: its flown-by geometry, the constant speed no limit slows (NaN where
// it was not asked), the cruise speed and the time law.
struct PlannedPath {
  PathGeometry geometry;
  double bound = 0.0;
  double line_speed = 0.0;
  TimedPath timed;
  // lead_in: the law as one piece (empty: no leads), and when it passes the path's first and
  // last point
  std::optional<TrajectoryPiece> whole;
  double print_from_s = 0.0, print_to_s = 0.0;
};

// The orientation a lead of length_mm ahead of point `end` of the path (0 or the last) takes
// at its far end: the path's own turn over as long a stretch from that end, continued the
// other way (the axis and the roll by at most kLeadTurnRad each), so that the tool turns at about
// the same rate per mm through the end point: at cruise speed a lead that held the axis still would
// step the joints' speeds there.
constexpr double kLeadTurnRad = 15.0 * kPi / 180.0;
ToolOrientation lead_orientation(const PrintPath& path, size_t end, double length_mm) {
  const size_t n = path.points.size();
  const int step = end == 0 ? 1 : -1;
  // the first point at least length_mm along the path from the end (or the other end)
  double along = 0.0;
  size_t k = end;
  while (along < length_mm && k != (end == 0 ? n - 1 : 0)) {
    along += (path.points[k + step] - path.points[k]).norm();
    k += step;
  }
  const ToolOrientation at_end = path.orientation(end), there = path.orientation(k);
  const double angle = axis_angle_rad(at_end.axis, there.axis);
  const double roll_turn = std::abs(there.roll_rad - at_end.roll_rad);
  double share = length_mm / along;  // of the stretch's turn, continued beyond the end
  if (angle * share > kLeadTurnRad) share = kLeadTurnRad / angle;
  if (roll_turn * share > kLeadTurnRad) share = kLeadTurnRad / roll_turn;
  return ToolOrientation{slerp_axis(at_end.axis, there.axis, -share),
                         at_end.roll_rad - share * (there.roll_rad - at_end.roll_rad)};
}

// The path extended by straight lines along its end edges, in_mm before its first point and
// out_mm after its last (a lead-in and a lead-out), the tool turning on them as the path does
// next to them (lead_orientation).
PrintPath with_leads(const PrintPath& path, double in_mm, double out_mm) {
  const size_t n = path.points.size();
  const Vec3 u_in = (path.points[1] - path.points[0]).normalized();
  const Vec3 u_out = (path.points[n - 1] - path.points[n - 2]).normalized();
  const ToolOrientation o_in = lead_orientation(path, 0, in_mm);
  const ToolOrientation o_out = lead_orientation(path, n - 1, out_mm);
  PrintPath out = path;
  out.points.insert(out.points.begin(), path.points.front() - in_mm * u_in);
  out.points.push_back(path.points.back() + out_mm * u_out);
  if (!path.normals.empty()) {
    out.normals.insert(out.normals.begin(), o_in.axis);
    out.normals.push_back(o_out.axis);
  }
  if (!path.rolls.empty()) {
    out.rolls.insert(out.rolls.begin(), o_in.roll_rad);
    out.rolls.push_back(o_out.roll_rad);
  }
  return out;
}

// How far a law from rest to rest runs before it first reaches its cruise (within 0.1 % of the
// cruise speed, or of the highest speed it reaches where the joints keep it below), and how
// far after it last leaves it.
struct RampLengths {
  double in_mm = 0.0, out_mm = 0.0;
};
RampLengths ramp_lengths(const PathSamples& samples, double cruise_mm_s) {
  const double top = *std::max_element(samples.sdot.begin(), samples.sdot.end());
  const double reached = (1 - 1e-3) * std::min(top, cruise_mm_s);
  size_t first = 0, last = samples.sdot.size() - 1;
  while (first < last && samples.sdot[first] < reached) ++first;
  while (last > first && samples.sdot[last] < reached) --last;
  return {samples.s_mm[first], samples.s_mm.back() - samples.s_mm[last]};
}

// The time in a law's piece (`whole`, from rest) at which its position crosses the plane
// through `point` normal to u: the first crossing from below, or (from_end) the last; by
// bisection in the sample interval where the signed distance (p - point) . u turns >= 0. NaN
// where it never does.
double crossing_time(const TrajectoryPiece& whole, const Vec3& point, const Vec3& u,
                     bool from_end) {
  const auto& sampled = std::get<SampledMotion>(whole.motion);
  const std::vector<Vec3>& p = sampled.position_mm;
  const auto side = [&](const Vec3& q) { return (q - point).dot(u); };
  size_t k = 0;
  bool found = false;
  if (!from_end) {
    for (; k + 1 < p.size() && !found; ++k) found = side(p[k]) < 0.0 && side(p[k + 1]) >= 0.0;
  } else {
    for (k = p.size() - 1; k > 0 && !found; --k) found = side(p[k - 1]) <= 0.0 && side(p[k]) > 0.0;
  }
  if (!found) return std::numeric_limits<double>::quiet_NaN();
  // (the loops stepped once past the interval [k - 1, k] or [k, k + 1] resp.)
  const size_t first = from_end ? k : k - 1;
  double lo = static_cast<double>(first) * sampled.period_s, hi = lo + sampled.period_s;
  for (int step = 0; step < 60; ++step) {
    const double mid = 0.5 * (lo + hi);
    Vec3 q, v, a;
    evaluate_motion(whole, mid, q, v, a);
    (side(q) < 0.0 ? lo : hi) = mid;
  }
  return hi;
}

// The law's piece `whole` from t0 to t1 as a piece of its own starting at t_begin: its
// interpolation sampled again at the period that divides the span into whole periods no
// longer than max_period_s, so that the piece starts and ends exactly at t0 and t1.
TrajectoryPiece resampled_piece(const TrajectoryPiece& whole, double t0, double t1, double t_begin,
                                double max_period_s) {
  const int intervals = std::max(1, static_cast<int>(std::ceil((t1 - t0) / max_period_s - 1e-9)));
  PathSamples samples;
  samples.period_s = (t1 - t0) / intervals;
  for (int j = 0; j <= intervals; ++j) {
    const double tau = j == intervals ? t1 : t0 + j * samples.period_s;
    Vec3 position, velocity, acceleration, axis, angular;
    double roll = 0.0;
    evaluate_motion(whole, tau, position, velocity, acceleration);
    evaluate_tool_axis(whole, tau, position, velocity, axis, angular, roll);
    samples.position_mm.push_back(position);
    samples.velocity_mm_s.push_back(velocity);
    samples.tool_axis.push_back(axis);
    samples.roll_rad.push_back(roll);
  }
  return sampled_piece(samples, t_begin);
}

}  // namespace

// ---------------------------------------------------------------------------------------

GapReport conformal_report(const Toolpath& toolpath, double gap_offset_mm) {
  GapReport report;
  report.offset_mm = gap_offset_mm;
  bool any = false;
  for (size_t i = 0; i < toolpath.paths.size(); ++i) {
    const PrintPath& path = toolpath.paths[i];
    for (size_t k = 0; k + 1 < path.points.size(); ++k) {
      const double g = gap_ratio(path.points[k], path.tool_axis(k), path.points[k + 1],
                                 path.tool_axis(k + 1), gap_offset_mm);
      if (std::abs(g - 1.0) <= 1e-9)
        ++report.flat;
      else if (g > 1.0)
        ++report.convex;
      else
        ++report.concave;
      if (!any || g < report.min_ratio) {
        report.min_ratio = g;
        report.min_path = static_cast<int>(i);
        report.min_edge = static_cast<int>(k);
      }
      if (!any || g > report.max_ratio) {
        report.max_ratio = g;
        report.max_path = static_cast<int>(i);
        report.max_edge = static_cast<int>(k);
      }
      any = true;
    }
  }
  return report;
}

Trajectory ConformalPlanner::plan(const Toolpath& toolpath, const TcpLimits& limits) const {
  return plan(toolpath, limits, nullptr);
}

Trajectory ConformalPlanner::plan(const Toolpath& toolpath, const TcpLimits& limits,
                                  ConformalPlanReport* report) const {
  const ConformalSettings& settings = settings_;
  const std::string limits_problem = limits.requested().validate();
  if (!limits_problem.empty()) throw InputError("limits", limits_problem);
  const JointMap* joints = limits.joint_map();
  const bool constant_speed =
      settings.control == ConformalControl::speed || settings.control == ConformalControl::both;
  const bool flow_follows =
      settings.control == ConformalControl::flow || settings.control == ConformalControl::both;
  // a jerk limit in force anywhere on the job: curvature-continuous blends and the
  // jerk-limited law over the TOPP-RA profile (jerk_time_law.hpp)
  Vec3 job_lo = toolpath.start_mm.cwiseMin(toolpath.end_mm);
  Vec3 job_hi = toolpath.start_mm.cwiseMax(toolpath.end_mm);
  for (const PrintPath& path : toolpath.paths)
    for (const Vec3& p : path.points) {
      job_lo = job_lo.cwiseMin(p);
      job_hi = job_hi.cwiseMax(p);
    }
  const bool jerk_limited =
      limits.requested().jerk_limited() || limits.over(job_lo, job_hi).jerk_limited();
  const auto time_law = [&](const PathGrid& grid, const std::vector<MachineLimits>& interval_limits,
                            const TimeLawOptions& options) {
    return jerk_limited ? jerk_limited_time_path(grid, interval_limits, settings.period_s, options)
                        : time_path(grid, interval_limits, settings.period_s, options);
  };
  const auto speed_bound = [&](const PathGrid& grid,
                               const std::vector<MachineLimits>& interval_limits,
                               const TimeLawOptions& options) {
    return jerk_limited ? jerk_constant_speed_bound(grid, interval_limits, options)
                        : constant_speed_bound(grid, interval_limits, options);
  };
  if (report) {
    *report = ConformalPlanReport{};
    report->gaps = conformal_report(toolpath, settings.gap_offset_mm);
    report->blend_deviation_bound_mm = 0.5 * settings.zone_mm;
  }

  std::vector<TrajectoryPiece> pieces;
  std::vector<std::string> warnings;
  size_t dropped_warnings = 0;
  const auto warn = [&](const std::string& text) {
    if (warnings.size() < kMaxDetailedWarnings)
      warnings.push_back(text);
    else
      ++dropped_warnings;
  };
  double t = 0.0;

  // the paths' heights, which travels clear
  const PathHeights heights(toolpath);
  // transitions lift; where the machine cannot reach the lifted poses (a machine without a z
  // axis) they go straight instead, and one warning says how often
  // (a machine that holds the TCP at z = 0, the XY stage, lifts nothing: every transition
  // used to try, and the job warned that all of them went straight)
  int unlifted = 0;
  std::string unlifted_first;
  const double lift_mm = joints && !joints->moves_z ? 0.0 : settings.lift_mm;
  const auto add_transition = [&](const Vec3& p0, const ToolOrientation& o0, const Vec3& p1,
                                  const ToolOrientation& o1, const std::string& name) {
    PathGrid grid =
        transition_grid(p0, o0, p1, o1, lift_mm, settings.ds_mm, name, &heights, jerk_limited);
    if (grid.points.empty()) return;
    if (joints) {
      try {
        attach_joints_with_headroom(grid, *joints);
      } catch (const InputError& error) {
        if (lift_mm <= 0.0) throw;
        PathGrid straight =
            transition_grid(p0, o0, p1, o1, 0.0, settings.ds_mm, name, nullptr, jerk_limited);
        attach_joints_with_headroom(straight, *joints);
        grid = std::move(straight);
        if (unlifted++ == 0) unlifted_first = error.what();
      }
    }
    const TimedPath timed = time_law(grid, interval_tcp_limits(grid, limits, kChunkMm), {});
    TrajectoryPiece piece = sampled_piece(timed.samples, t);
    piece.path_index = -1;
    piece.depositing = false;
    pieces.push_back(std::move(piece));
    t = pieces.back().t_end_s;
  };

  // One print path's flown-by geometry, its grid with the joints along it, and its time law;
  // `speed` and `both` cruise at the largest constant speed no limit slows.
  const auto plan_print_path = [&](const PrintPath& path, const std::string& name) {
    PlannedPath out;
    out.geometry = print_geometry(path, settings, jerk_limited);
    PathGrid grid = polyline_grid(fly_by_pieces(out.geometry.polyline, jerk_limited),
                                  settings.ds_mm, path.speed_mm_s, name);
    grid.points.front().tool_axis = path.tool_axis(0);
    grid.points.back().tool_axis = path.tool_axis(path.points.size() - 1);
    if (joints) attach_joints_with_headroom(grid, *joints);
    const std::vector<MachineLimits> interval_limits = interval_tcp_limits(grid, limits, kChunkMm);

    TimeLawOptions options;
    out.bound = constant_speed || report ? speed_bound(grid, interval_limits, options)
                                         : std::numeric_limits<double>::quiet_NaN();
    out.line_speed = path.speed_mm_s;
    if (constant_speed) {
      out.line_speed = std::min(path.speed_mm_s, out.bound);
      if (!(out.line_speed > 0.0))
        throw InputError(name, "no constant speed keeps the joints within their limits");
    }
    for (int round = 0; round < 8; ++round) {
      set_cruise_speed(grid, out.line_speed);
      out.timed = time_law(grid, interval_limits, options);
      if (!constant_speed) break;
      // the accelerations the law was planned with (the sampling margin, repairs) can lower
      // the constant speed: plan again at the speed they allow
      TimeLawOptions planned;
      planned.tcp_accel_scale = out.timed.tcp_accel_scale;
      const double lowered = speed_bound(grid, interval_limits, planned);
      if (lowered >= out.line_speed * (1 - 1e-12)) break;
      out.line_speed = lowered;
      options.tcp_accel_scale = out.timed.repair_scale;  // time_path adds its margins again
    }

    // decelerations the lagging flow can follow (flow_lag_s): bounds ahead of each slow-down,
    // planned again until none is lowered (down to kLagFloorShare of the line speed)
    if (settings.flow_lag_s > 0.0)
      for (int round = 0;
           round < kLagRounds && cap_decelerations(grid, out.timed.samples, settings.flow_lag_s,
                                                   kLagFloorShare * out.line_speed);
           ++round)
        out.timed = time_law(grid, interval_limits, options);
    return out;
  };

  // lead_in: the paths whose lead-in and lead-out were not taken, and why the first was not
  int leads_dropped = 0;
  std::string leads_dropped_first;

  Vec3 position = toolpath.start_mm;
  ToolOrientation orientation = toolpath.start_orientation();
  for (size_t index = 0; index < toolpath.paths.size(); ++index) {
    throw_if_interrupted();  // a signal asked to stop (core/interrupt.hpp)
    const PrintPath& path = toolpath.paths[index];
    const std::string name = path_name(path, index);
    validate_print_path(path, name, kSamePoint);
    PlannedPath planned = plan_print_path(path, name);

    // lead_in: the law's ramps from and to rest moved onto straight extensions of the end
    // edges, planned with the path as one and cut off it with the material off, so that the
    // path itself is printed at its cruise speed from end to end. The extensions are as long
    // as the ramps (with a margin), measured on the path's own law, and longer if the extended
    // law ramps farther. Not taken (a warning counts them) where the machine cannot reach the
    // extensions, or where they would lower the cruise speed.
    double lead_in_mm = 0.0, lead_out_mm = 0.0;
    if (settings.lead_in && settings.zone_mm > 0.0 && !path.has_arcs()) {
      RampLengths ramps = ramp_lengths(planned.timed.samples, planned.line_speed);
      // a path on or above the work surface, z = 0 (a table's or bed's top), does not lead
      // into it (a path below it, a CAM pass on a machine without a table, is not judged)
      double lowest_z = kInf;
      for (const Vec3& p : path.points) lowest_z = std::min(lowest_z, p.z());
      const bool on_work_surface = lowest_z >= -kWorkSurfaceTolerance_mm;
      for (int round = 0; round < 3; ++round) {
        const double in_mm = 1.25 * ramps.in_mm + 2.0 * settings.ds_mm;
        const double out_mm = 1.25 * ramps.out_mm + 2.0 * settings.ds_mm;
        const PrintPath extended = with_leads(path, in_mm, out_mm);
        if (on_work_surface && std::min(extended.points.front().z(), extended.points.back().z()) <
                                   -kWorkSurfaceTolerance_mm) {
          if (leads_dropped++ == 0)
            leads_dropped_first =
                name + ": its lead-in or lead-out would go below the work surface (z = 0)";
          break;
        }
        PlannedPath led;
        try {
          led = plan_print_path(extended, name + " with its lead-in");
        } catch (const InputError& error) {
          if (leads_dropped++ == 0) leads_dropped_first = error.what();
          break;
        }
        const auto stops = [](const PlannedPath& p) {
          return p.geometry.sharp_stops.size() + p.geometry.tiny_stops.size();
        };
        if (led.line_speed < planned.line_speed * (1 - 1e-3) || stops(led) != stops(planned)) {
          if (leads_dropped++ == 0)
            leads_dropped_first = name + ": its lead-in and lead-out would slow or stop it";
          break;
        }
        const RampLengths led_ramps = ramp_lengths(led.timed.samples, led.line_speed);
        if (led_ramps.in_mm <= in_mm && led_ramps.out_mm <= out_mm) {
          // where the law passes the path's ends (the leads are straight: planes across them)
          led.whole = sampled_piece(led.timed.samples, 0.0);
          const size_t n = path.points.size();
          led.print_from_s = crossing_time(*led.whole, path.points[0],
                                           (path.points[1] - path.points[0]).normalized(), false);
          led.print_to_s =
              crossing_time(*led.whole, path.points[n - 1],
                            (path.points[n - 1] - path.points[n - 2]).normalized(), true);
          if (!(led.print_to_s > led.print_from_s)) {
            if (leads_dropped++ == 0)
              leads_dropped_first = name + ": its ends could not be found on its extended law";
            break;
          }
          planned = std::move(led);
          lead_in_mm = in_mm;
          lead_out_mm = out_mm;
          break;
        }
        ramps = led_ramps;
        if (round == 2 && leads_dropped++ == 0)
          leads_dropped_first = name + ": its law kept ramping beyond its lead-in and lead-out";
      }
    }
    const PathGeometry& geometry = planned.geometry;
    const PathSamples& samples = planned.timed.samples;
    const double line_speed = planned.line_speed;

    const size_t first_point = lead_in_mm > 0.0 ? 1 : 0;  // the path's point 0 in the geometry
    for (const size_t i : geometry.sharp_stops) {
      std::ostringstream msg;
      msg << name << ": stops at point " << i - first_point
          << ": the path turns by more than 170 deg";
      warn(msg.str());
    }
    for (const size_t i : geometry.tiny_stops) {
      std::ostringstream msg;
      msg << name << ": stops at point " << i - first_point
          << ": the tool axis turns too sharply there to fly "
          << "by within zone_ori_deg = " << settings.zone_ori_deg << " deg";
      warn(msg.str());
    }
    if (geometry.max_deviation_mm > 0.5 * settings.zone_mm * (1 + 1e-9)) {
      std::ostringstream msg;
      msg << name << ": the blended path passes " << geometry.max_deviation_mm
          << " mm from a point, beyond zone_mm / 2 = " << 0.5 * settings.zone_mm << " mm";
      warn(msg.str());
    }

    // with leads: the law's piece cut where it passes the path's ends, material off on the leads
    const bool led = planned.whole.has_value();
    if (led)
      add_transition(position, orientation, samples.position_mm.front(),
                     ToolOrientation{samples.tool_axis.front(), samples.roll_rad.front()},
                     "transition to " + name);
    else
      add_transition(position, orientation, path.front(), path.orientation(0),
                     "transition to " + name);
    const auto add_lead = [&](double t0, double t1) {
      TrajectoryPiece lead = resampled_piece(*planned.whole, t0, t1, t, settings.period_s);
      lead.path_index = -1;
      lead.depositing = false;
      pieces.push_back(std::move(lead));
      t = pieces.back().t_end_s;
    };
    if (led) add_lead(0.0, planned.print_from_s);
    TrajectoryPiece piece = led ? resampled_piece(*planned.whole, planned.print_from_s,
                                                  planned.print_to_s, t, settings.period_s)
                                : sampled_piece(samples, t);
    piece.path_index = static_cast<int>(index);
    piece.depositing = true;
    piece.desired_speed_mm_s = path.speed_mm_s;
    piece.flow_fraction = constant_speed ? line_speed / path.speed_mm_s : 1.0;
    auto& motion = std::get<SampledMotion>(piece.motion);
    motion.flow_fraction.resize(motion.position_mm.size());
    for (size_t k = 0; k < motion.flow_fraction.size(); ++k)
      motion.flow_fraction[k] =
          flow_follows ? motion.velocity_mm_s[k].norm() / path.speed_mm_s : piece.flow_fraction;
    if (report) {
      ConformalPathReport entry;
      entry.path_index = static_cast<int>(index);
      entry.desired_speed_mm_s = path.speed_mm_s;
      entry.constant_speed_bound_mm_s = std::min(planned.bound, path.speed_mm_s);
      entry.line_speed_mm_s = line_speed;
      entry.flow_fraction_min =
          *std::min_element(motion.flow_fraction.begin(), motion.flow_fraction.end());
      entry.flow_fraction_max =
          *std::max_element(motion.flow_fraction.begin(), motion.flow_fraction.end());
      entry.stop_points =
          static_cast<int>(geometry.sharp_stops.size() + geometry.tiny_stops.size()) +
          (settings.zone_mm <= 0.0 ? static_cast<int>(path.points.size()) - 2 : 0);
      entry.max_blend_deviation_mm = geometry.max_deviation_mm;
      entry.adjusted_samples = samples.adjusted_samples;
      entry.repair_rounds = planned.timed.repair_rounds;
      entry.lead_in_mm = lead_in_mm;
      entry.lead_out_mm = lead_out_mm;
      report->paths.push_back(entry);
    }
    pieces.push_back(std::move(piece));
    t = pieces.back().t_end_s;
    if (led) add_lead(planned.print_to_s, samples.duration_s());
    // where the next transition starts: the lead-out's end, or the path's
    position = led ? samples.position_mm.back() : path.back();
    orientation = led ? ToolOrientation{samples.tool_axis.back(), samples.roll_rad.back()}
                      : path.orientation(path.points.size() - 1);
  }
  add_transition(position, orientation, toolpath.end_mm, toolpath.end_orientation(),
                 "transition to the toolpath's end");
  if (pieces.empty()) {
    // nothing to print and nowhere to go: at rest at the start
    PathSamples rest;
    rest.period_s = settings.period_s;
    rest.s_mm = rest.sdot = rest.roll_rad = {0.0};
    rest.position_mm = {toolpath.start_mm};
    rest.velocity_mm_s = {Vec3::Zero()};
    rest.tool_axis = {vertical_tool_axis()};
    pieces.push_back(sampled_piece(rest, 0.0));
  }
  if (leads_dropped > 0) {
    std::ostringstream msg;
    msg << leads_dropped << " path(s) printed without a lead-in and lead-out, from rest to rest "
        << "(first: " << leads_dropped_first << ")";
    warnings.push_back(msg.str());
  }
  if (unlifted > 0) {
    std::ostringstream msg;
    msg << unlifted << " transition(s) could not lift by " << settings.lift_mm
        << " mm and went straight (first: " << unlifted_first << ")";
    warnings.push_back(msg.str());
  }
  if (dropped_warnings > 0)
    warnings.push_back("... and " + std::to_string(dropped_warnings) + " more warnings");
  return Trajectory("conformal", std::move(pieces), std::move(warnings));
}

std::vector<PlannerParameter> conformal_parameters() {
  return {
      {"control",
       0.0,
       0.0,
       0.0,
       "velocity control (sec. 4.1): none (joints slow the TCP, flow nominal), speed (one "
       "constant speed per line no joint slows, flow scaled alike), flow (flow follows the "
       "planned speed), both",
       false,
       {"none", "speed", "flow", "both"}},
      {"zone_mm",
       0.25,
       0.0,
       100.0,
       "fly-by zone (RobotStudio zone data): blend size min(zone, half the shorter edge) at every "
       "interior point; the path passes within zone/2 of each point; 0: stop at every point",
       false,
       {},
       "mm"},
      {"zone_ori_deg",
       1.5,
       0.01,
       90.0,
       "largest deviation of the blended tool axis from the path's axis at the nearest point; "
       "blends shrink to keep it",
       false,
       {},
       "deg"},
      {"gap_offset_mm",
       2.0,
       0.01,
       100.0,
       "offset d of the paper's gap test (1-4 mm): g = |offset-point gap| / |point gap|, > 1 "
       "convex, < 1 concave",
       false,
       {},
       "mm"},
      {"lift_mm",
       1.0,
       0.0,
       100.0,
       "transitions lift the nozzle this far along the tool axis, move and lower (0: straight)",
       false,
       {},
       "mm"},
      {"lead_in",
       0.0,
       0.0,
       1.0,
       "1: each path planned with straight extensions of its end edges as long as its ramps, "
       "printed only between them (material off on them): the path at its cruise speed from "
       "end to end; 0: from rest to rest on the path",
       false,
       {},
       "",
       /*whole_number=*/true},
      {"period_s", 0.001, 1e-5, 0.1, "sample period of the planned motion", false, {}, "s"},
      {"ds_mm",
       0.05,
       0.001,
       1.0,
       "grid step of the time-optimal parametrisation along the path",
       false,
       {},
       "mm"},
  };
}

ConformalSettings conformal_settings(const PlannerSpec& spec) {
  ConformalSettings settings;
  const std::string control = spec.get_choice("control", "none");
  if (control == "none")
    settings.control = ConformalControl::none;
  else if (control == "speed")
    settings.control = ConformalControl::speed;
  else if (control == "flow")
    settings.control = ConformalControl::flow;
  else if (control == "both")
    settings.control = ConformalControl::both;
  else
    throw InputError("planners.conformal.control", "'" + control + "' is not none|speed|flow|both");
  settings.zone_mm = spec.get("zone_mm", settings.zone_mm);
  settings.zone_ori_deg = spec.get("zone_ori_deg", settings.zone_ori_deg);
  settings.gap_offset_mm = spec.get("gap_offset_mm", settings.gap_offset_mm);
  settings.lift_mm = spec.get("lift_mm", settings.lift_mm);
  settings.period_s = spec.get("period_s", settings.period_s);
  settings.ds_mm = spec.get("ds_mm", settings.ds_mm);
  settings.lead_in = spec.get_switch("lead_in", settings.lead_in);
  return settings;
}

std::unique_ptr<Planner> make_conformal_planner(const PlannerSpec& spec) {
  return std::make_unique<ConformalPlanner>(conformal_settings(spec));
}

}  // namespace depotwin
