#include "toolpath/hatching.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "core/error.hpp"
#include "core/pose.hpp"

namespace depotwin {

namespace {

constexpr const char* kKey = "toolpath.surface";
constexpr double kMaxGridPoints = 2e7;  // per layer
// an offset point nearer the face below it than its offset by more than this share of the layer
// height is a dent (drop_dents); a faceted smooth surface's interpolated normals stay well within
constexpr double kDentTolerance = 0.05;

void validate(const SurfaceHatchSpec& spec) {
  std::vector<Problem> problems;
  auto check = [&](bool ok, const std::string& field, const std::string& message) {
    if (!ok) problems.push_back(Problem{"", 0, std::string(kKey) + "." + field, message});
  };
  check(std::isfinite(spec.hatch_mm) && spec.hatch_mm > 0.0, "hatch_mm",
        "the hatch spacing must be positive");
  check(!spec.angles_deg.empty(), "angles_deg", "at least one hatch angle is needed");
  for (double a : spec.angles_deg) check(std::isfinite(a), "angles_deg", "angles must be finite");
  check(spec.layers >= 1, "layers", "at least one layer");
  check(std::isfinite(spec.layer_height_mm) && spec.layer_height_mm >= 0.0, "layer_height_mm",
        "the layer height must be finite and not negative");
  check(std::isfinite(spec.alpha) && spec.alpha >= 0.0 && spec.alpha <= 1.0, "alpha",
        "alpha must be in [0, 1]");
  check(std::isfinite(spec.speed_mm_s) && spec.speed_mm_s > 0.0, "speed_mm_s",
        "the print speed must be positive");
  check(std::isfinite(spec.min_normal_z) && spec.min_normal_z >= 0.0 && spec.min_normal_z < 1.0,
        "min_normal_z", "the least normal z must be in [0, 1)");
  check(std::isfinite(spec.max_jump_ratio) && spec.max_jump_ratio >= 1.0, "max_jump_ratio",
        "the jump ratio must be at least 1");
  check(std::isfinite(spec.chord_tolerance_mm) &&
            (spec.chord_tolerance_mm == 0.0 ||
             spec.chord_tolerance_mm >= SurfaceHatchSpec::kLeastChordTolerance_mm),
        "chord_tolerance_mm", "the chord tolerance must be 0 or at least 1e-4 mm");
  if (!problems.empty()) throw InputError(std::move(problems));
}

// one piece of a grid line on the surface: consecutive grid points
struct Piece {
  std::vector<int> index;  // along the line
  std::vector<Vec3> points;
  std::vector<Vec3> normals;  // smooth
};

// the grid of one hatch angle projected onto the surface, broken into pieces per line
struct AngleGrid {
  int lines = 0;
  int points_per_line = 0;
  std::vector<std::vector<Piece>> pieces;  // per line
  int printed_points = 0;                  // in the pieces
  std::vector<Vec3> lone_points;           // between printed pieces, in none (see close())
};

// n points spaced h, centred on [lo, hi]: the i-th at centre + (i - (n - 1) / 2) h. An STL
// holds floats: a part 20 mm wide from x 0.3 is 19.99999923 mm wide as read, and the grid
// would lose a point (every line half a spacing short at each end), so a width within a few
// float roundings of the coordinates below a whole number of spacings counts as that number
// (the outer points then lie that hair outside, where project_down still finds the rim).
struct Axis {
  int n = 1;
  double first = 0.0;  // the first point
  Axis(double lo, double hi, double h) {
    const double rounding = 4.0 * std::numeric_limits<float>::epsilon() *
                            std::max({std::abs(lo), std::abs(hi), hi - lo});
    n = static_cast<int>(std::floor((hi - lo + rounding) / h)) + 1;
    first = 0.5 * (lo + hi) - 0.5 * (n - 1) * h;
  }
};

// Chords that cut into the part refined (beyond the paper, whose points are the grid's): where
// the surface between two consecutive points of a piece rises more than
// spec.chord_tolerance_mm above their chord, a surface point is inserted and both halves are
// checked again, down to kMaxChordHalvings. The point is the surface halfway where that cuts
// (a ridge, or any stretch convex enough); else, where the chord lifted by the tolerance
// still meets the part (a step between the two points, whose edge the halfway point misses:
// a wall 0.7 of the way up from one to the next), the deepest of the surface where it enters
// the part (a hair on), where it leaves it (a hair back) and midway between. Heights are
// compared vertically, as the points are projected. Without it a roof of slope 0.7 hatched at 2 mm
// had the nozzle 0.7 mm inside the part on every line across its ridge, and a 2 mm step 0.7 of a
// spacing past a grid point had it 0.6 mm inside.
constexpr int kMaxChordHalvings = 10;
// a point found where a lifted chord meets the part is kept at least this share of the chord
// from its ends, and a chord shorter than twice that share of hatch_mm is not refined (a wall
// is met at its foot: the chord may climb it over a thousandth of a spacing)
constexpr double kChordEndShare = 1e-3;

void refine_piece(const SurfaceProjector& projector, Piece& piece, const Vec2& line_origin,
                  const Vec2& d, double first_u, double h, const SurfaceHatchSpec& spec) {
  const std::size_t n = piece.points.size();
  if (n < 2 || !(spec.chord_tolerance_mm > 0.0)) return;
  const auto along = [&](double u) -> Vec2 { return line_origin + u * d; };
  const Vec3 lift = spec.chord_tolerance_mm * Vec3::UnitZ();
  // a hair along the line: beside an edge Embree gives to one side only (as project_down's)
  const double hair =
      1e-5 *
      std::max((projector.upper_bound() - projector.lower_bound()).head<2>().maxCoeff(), 1.0);
  // the lifted chord a-b's crossings, forward (from a) and back (from b): each that of the
  // ray along the line, or where it misses, the first of two rays a hair either side (one
  // along the part's outline meets a wall's edge there on one side only, as a ray down does;
  // beside the line an oblique wall is met early, so the line's own crossing comes first)
  const Vec3 beside = hair * Vec3(-d.y(), d.x(), 0.0);
  constexpr std::size_t kRaysPerChord = 6;
  const auto add_lifted = [&](std::vector<std::pair<Vec3, Vec3>>& segments, const Vec3& a,
                              const Vec3& b) {
    for (const double side : {0.0, 1.0, -1.0})  // forward
      segments.emplace_back(a + lift + side * beside, b + lift + side * beside);
    for (const double side : {0.0, 1.0, -1.0})  // back
      segments.emplace_back(b + lift + side * beside, a + lift + side * beside);
  };
  // the crossing of rays [first, first + 3): the line's own, else the earlier beside it
  const auto crossing_of = [](const std::vector<std::optional<double>>& met, std::size_t first) {
    if (met[first]) return met[first];
    const std::optional<double>&one = met[first + 1], &other = met[first + 2];
    return !one ? other : !other ? one : std::optional<double>(std::min(*one, *other));
  };
  // every chord's halfway point and lifted crossings at once (one batch per piece)
  std::vector<Vec2> halfway(n - 1);
  std::vector<std::pair<Vec3, Vec3>> lifted;
  lifted.reserve(kRaysPerChord * (n - 1));
  for (std::size_t m = 0; m + 1 < n; ++m) {
    halfway[m] = along(first_u + (piece.index[m] + 0.5) * h);
    add_lifted(lifted, piece.points[m], piece.points[m + 1]);
  }
  std::vector<std::optional<SurfaceHit>> hits;
  projector.project_down(halfway, hits);
  std::vector<std::optional<double>> crossings;
  projector.first_crossings(lifted, crossings);
  // the surface point at fraction t of the chord a-b if it rises above the chord by more than
  // `least` (how much; else 0), and is no step away from its ends (a shelf above the chord: a
  // point there would be a spike, where the grid's own points break the line)
  const double max_jump = spec.max_jump_ratio * h;
  const auto rise_above = [&](const std::optional<SurfaceHit>& hit, const Vec3& a, const Vec3& b,
                              double t, double least) {
    // (a chord up a steep slope is longer than the jump: a point on it lies within the chord)
    const double reach = std::max(max_jump, (b - a).norm());
    if (!hit || !hit->faces_up(spec.min_normal_z) || (hit->point_mm - a).norm() > reach ||
        (hit->point_mm - b).norm() > reach)
      return 0.0;
    const double rise = hit->point_mm.z() - (a.z() + t * (b.z() - a.z()));
    return rise > least ? rise : 0.0;
  };
  // the point to insert between (ua, a) and (ub, b), at u along the line, given the surface
  // halfway and the lifted chord's crossings (fractions from a, and from b going back)
  struct Cut {
    double u = 0.0;
    SurfaceHit hit;
  };
  const auto cut_between = [&](double ua, const Vec3& a, double ub, const Vec3& b,
                               const std::optional<SurfaceHit>& middle,
                               const std::optional<double>& forward,
                               const std::optional<double>& backward) -> std::optional<Cut> {
    if (rise_above(middle, a, b, 0.5, spec.chord_tolerance_mm) > 0.0)
      return Cut{0.5 * (ua + ub), *middle};
    if (!(ub - ua > 2.0 * kChordEndShare * h) || (!forward && !backward)) return std::nullopt;
    // where the lifted chord enters the part, a hair on (a wall's top, beyond its foot), where
    // it leaves it, a hair back, and halfway between: the deepest. At the crossing itself the
    // surface is the tolerance above the chord, a hair on by the chord's slope times the hair
    // more: a point must rise more than that allows (else a point beside a descending chord's
    // start would be refined again and again, each a hair on)
    const double t_in = forward ? *forward : 0.0;
    const double t_out = backward ? 1.0 - *backward : 1.0;
    const double slope = std::abs(b.z() - a.z()) / (ub - ua);
    const double least = spec.chord_tolerance_mm + 4.0 * hair * (1.0 + slope);
    std::optional<Cut> deepest;
    double deepest_rise = 0.0;
    for (const double u_raw : {ua + t_in * (ub - ua) + hair, ua + t_out * (ub - ua) - hair,
                               ua + 0.5 * (t_in + t_out) * (ub - ua)}) {
      const double u =
          std::clamp(u_raw, ua + kChordEndShare * (ub - ua), ub - kChordEndShare * (ub - ua));
      const Vec2 xy = along(u);
      const std::optional<SurfaceHit> hit = projector.project_down(xy.x(), xy.y());
      const double rise = rise_above(hit, a, b, (u - ua) / (ub - ua), least);
      if (rise > deepest_rise) {
        deepest_rise = rise;
        deepest = Cut{u, *hit};
      }
    }
    return deepest;
  };
  // the same for a chord inside a refined one, one ray at a time
  const auto check = [&](double ua, const Vec3& a, double ub, const Vec3& b) {
    const Vec2 middle = along(0.5 * (ua + ub));
    std::vector<std::pair<Vec3, Vec3>> segments;
    add_lifted(segments, a, b);
    std::vector<std::optional<double>> met;
    projector.first_crossings(segments, met);
    return cut_between(ua, a, ub, b, projector.project_down(middle.x(), middle.y()),
                       crossing_of(met, 0), crossing_of(met, 3));
  };
  Piece refined;
  // the points strictly between (ua, a) and (ub, b), in order, given the cut between them
  const auto insert_between = [&](auto&& self, double ua, const Vec3& a, double ub, const Vec3& b,
                                  const std::optional<Cut>& cut, int index, int depth) -> void {
    if (!cut) return;
    const double um = cut->u;
    const Vec3 m = cut->hit.point_mm;
    if (depth < kMaxChordHalvings) self(self, ua, a, um, m, check(ua, a, um, m), index, depth + 1);
    refined.index.push_back(index);
    refined.points.push_back(m);
    refined.normals.push_back(cut->hit.normal);
    if (depth < kMaxChordHalvings) self(self, um, m, ub, b, check(um, m, ub, b), index, depth + 1);
  };
  for (std::size_t m = 0; m < n; ++m) {
    refined.index.push_back(piece.index[m]);
    refined.points.push_back(piece.points[m]);
    refined.normals.push_back(piece.normals[m]);
    if (m + 1 == n) break;
    const double ua = first_u + piece.index[m] * h, ub = first_u + piece.index[m + 1] * h;
    insert_between(insert_between, ua, piece.points[m], ub, piece.points[m + 1],
                   cut_between(ua, piece.points[m], ub, piece.points[m + 1], hits[m],
                               crossing_of(crossings, kRaysPerChord * m),
                               crossing_of(crossings, kRaysPerChord * m + 3)),
                   piece.index[m], 1);
  }
  piece = std::move(refined);
}

// A path offset along the surface normal folds back over a concave crease (a groove's floor):
// the points either side are pushed past each other, and the line would lay material twice
// over the crease. Measured along the path's own horizontal direction t (first point to last),
// a fold is where that coordinate goes back. The offset lines either side cross (in the plane
// of t and z): the line of a segment before the fold, from its start on, meets the line of a
// segment after it, up to its end; the points between are cut out for that crossing, which
// lies on both sides' offsets. Returns how many folds were cut; `info` is kept in step.
std::size_t trim_folds(PrintPath& path, HatchPathInfo& info, double window_mm) {
  std::size_t cut = 0;
  if (path.points.size() < 3) return cut;
  Vec2 t = (path.points.back() - path.points.front()).head<2>();
  if (!(t.norm() > 0.0)) return cut;
  t.normalize();
  const auto at = [&](std::size_t i) {
    return Vec2(path.points[i].head<2>().dot(t), path.points[i].z());
  };
  // the crossing of segment a's line (s along it, from point a) and segment b's (v along it)
  const auto crossing = [&](std::size_t a, std::size_t b, double& s, double& v) {
    const Vec2 p = at(a), r = at(a + 1) - p, q = at(b), w = at(b + 1) - q;
    const double denominator = r.x() * w.y() - r.y() * w.x();
    if (std::abs(denominator) < 1e-12 * r.norm() * w.norm()) return false;  // parallel
    const Vec2 qp = q - p;
    s = (qp.x() * w.y() - qp.y() * w.x()) / denominator;
    v = (qp.x() * r.y() - qp.y() * r.x()) / denominator;
    const double u = p.x() + s * r.x();
    return s >= 0.0 && v <= 1.0 && u >= p.x() && u <= at(b + 1).x();
  };
  for (std::size_t f = 0; f + 1 < path.points.size(); ++f) {
    if (at(f + 1).x() > at(f).x()) continue;
    // the fold turns back after point f: the nearest segments either side whose lines cross
    bool found = false;
    for (std::size_t a = f; !found && a-- > 0;) {
      if (at(f).x() - at(a).x() > window_mm) break;
      for (std::size_t b = f + 1; !found && b + 1 < path.points.size(); ++b) {
        if (at(b).x() - at(f).x() > window_mm) break;
        double s = 0.0, v = 0.0;
        if (!crossing(a, b, s, v)) continue;
        // points a+1 .. b become the crossing; its data from segment a, where it lies on it
        const double on_a = std::min(s, 1.0);
        const auto lerp = [&](const Vec3& x, const Vec3& y) { return Vec3(x + on_a * (y - x)); };
        const Vec3 point = path.points[a] + s * (path.points[a + 1] - path.points[a]);
        const Vec3 axis = lerp(path.normals[a], path.normals[a + 1]).normalized();
        const Vec3 surface = lerp(info.surface_points_mm[a], info.surface_points_mm[a + 1]);
        const Vec3 normal = lerp(info.surface_normals[a], info.surface_normals[a + 1]).normalized();
        const int index = info.point_index[a];
        // (a crossing on a kept point is that point: consecutive points must differ)
        const bool distinct = (point - path.points[a]).norm() > kJoinTolerance_mm &&
                              (point - path.points[b + 1]).norm() > kJoinTolerance_mm;
        const auto replace = [&](auto& values, const auto& value) {
          values.erase(values.begin() + static_cast<std::ptrdiff_t>(a + 1),
                       values.begin() + static_cast<std::ptrdiff_t>(b + 1));
          if (distinct) values.insert(values.begin() + static_cast<std::ptrdiff_t>(a + 1), value);
        };
        replace(path.points, point);
        replace(path.normals, axis);
        replace(info.surface_points_mm, surface);
        replace(info.surface_normals, normal);
        replace(info.point_index, index);
        ++cut;
        found = true;
        f = a;  // go on from the crossing
      }
    }
  }
  return cut;
}

// A layer's point offset along the normal lies `offset` from its own face; a grid point exactly
// on a concave crease (a groove's floor on a grid line) has one side's normal only, so its
// offset lies over the other side, nearer that face than the offset: the nozzle would dig into
// the layers below (a V-groove of slope 0.7 at 1 mm layers: 0.40 mm into layer 0). Such a point
// is dropped where the chord between its neighbours keeps the offset from the surface there
// (over a concave crease the chord passes above it), as if the crease lay between grid points
// (from the layer where the neighbours pass each other, trim_folds has cut the path at their
// offsets' crossing first, and the crossing keeps the offset from both faces). The clearance is the
// distance from the facet plane right below the point (exact over a flat face). Returns how many
// were dropped; `info` is kept in step.
std::size_t drop_dents(PrintPath& path, HatchPathInfo& info, const SurfaceProjector& projector,
                       double offset, double tolerance) {
  const auto clearance = [&](const Vec3& p) {
    const std::optional<SurfaceHit> hit = projector.project_down(p.x(), p.y());
    return hit ? (p - hit->point_mm).dot(hit->facet_normal) : INFINITY;
  };
  std::size_t dropped = 0;
  for (std::size_t i = 1; i + 1 < path.points.size();) {
    // (over a crease at point i its neighbours' normals turn by the faces' angle phi from its
    // own, and its clearance from the far face is offset cos phi: where no neighbour turns that
    // far, no ray is cast)
    const Vec3& n = info.surface_normals[i];
    const double turn =
        1.0 - std::min(n.dot(info.surface_normals[i - 1]), n.dot(info.surface_normals[i + 1]));
    if (!(offset * turn > tolerance)) {
      ++i;
      continue;
    }
    const Vec3& p = path.points[i];
    const double own = clearance(p);
    if (own >= offset - tolerance) {
      ++i;
      continue;
    }
    // the chord's point beside p (its nearest in the plane)
    const Vec3& a = path.points[i - 1];
    const Vec3& b = path.points[i + 1];
    const Vec2 ab = (b - a).head<2>();
    const double along = ab.squaredNorm() > 0.0
                             ? std::clamp((p - a).head<2>().dot(ab) / ab.squaredNorm(), 0.0, 1.0)
                             : 0.5;
    const double chord = clearance(a + along * (b - a));
    if (!(chord >= offset - tolerance)) {
      ++i;
      continue;
    }
    const auto drop = [&](auto& values) {
      values.erase(values.begin() + static_cast<std::ptrdiff_t>(i));
    };
    drop(path.points);
    drop(path.normals);
    drop(info.point_index);
    drop(info.surface_points_mm);
    drop(info.surface_normals);
    ++dropped;
  }
  return dropped;
}

// Offset along the normal over a convex crease (a ridge) between two consecutive points (or on
// one of them), each side's point moves along its own side's normal, and the chord between the
// two offsets cuts the corner the layer below rounds: a roof of slope 0.7 at 1 mm layers, 0.52
// mm from the ridge at layer 1, half a layer into the one below. The layer's true offset there
// is the arc of radius `offset` about the crease, from one side's normal to the other's: where
// the chord's sagitta to that arc exceeds `tolerance`, the arc's points are added, its two ends
// and as many between as keep each chord's sagitta within the tolerance. The crease is where
// the two points' tangent planes cross in the line's vertical plane, when that lies between
// them (or on one) and the slope along the line falls across it (convex); over a concave
// crease the offsets meet instead (trim_folds, drop_dents).
// Returns how many points were added.
std::size_t round_convex_creases(PrintPath& path, HatchPathInfo& info, double offset,
                                 double tolerance, double alpha) {
  std::size_t added = 0;
  if (path.points.size() < 2) return added;
  const Vec3 up = vertical_tool_axis();
  // the line's horizontal direction
  Vec3 along = path.points.back() - path.points.front();
  along.z() = 0.0;
  if (!(along.norm() > 0.0)) return added;
  along.normalize();
  // the largest turn one chord of the arc may take: offset (1 - cos(turn / 2)) = tolerance
  const double largest_turn = 2.0 * std::acos(std::max(-1.0, 1.0 - tolerance / offset));
  for (std::size_t i = 0; i + 1 < path.points.size(); ++i) {
    const Vec3 s0 = info.surface_points_mm[i], s1 = info.surface_points_mm[i + 1];
    const Vec3 n0 = info.surface_normals[i], n1 = info.surface_normals[i + 1];
    const double turn = std::acos(std::clamp(n0.dot(n1), -1.0, 1.0));
    if (!(turn > largest_turn)) continue;
    // the tangent planes' crossing c = s0 + u along + w z in the line's vertical plane
    const double a = along.dot(n0), b = n0.z(), c = along.dot(n1), d = n1.z();
    const double rhs = (s1 - s0).dot(n1);
    const double determinant = a * d - b * c;
    if (!(std::abs(determinant) > 1e-9)) continue;
    const double u = -b * rhs / determinant, w = a * rhs / determinant;
    const double length = (s1 - s0).dot(along);
    if (!(u >= -kJoinTolerance_mm && u <= length + kJoinTolerance_mm)) continue;
    // convex: the surface's slope along the line falls from the first side to the second
    if (!(-a / b > -c / d)) continue;
    const Vec3 crease = s0 + u * along + w * Vec3::UnitZ();
    // the arc from n0 to n1 about the crease (the normals' slerp), its ends included
    const int pieces = static_cast<int>(
        std::min(std::ceil(turn / largest_turn), double{SurfaceHatchSpec::kMaxCreaseChords}));
    std::vector<Vec3> normals;
    for (int k = 0; k <= pieces; ++k) {
      const double f = static_cast<double>(k) / pieces;
      normals.push_back(
          ((std::sin((1.0 - f) * turn) * n0 + std::sin(f * turn) * n1) / std::sin(turn))
              .normalized());
    }
    std::size_t at = i + 1;
    for (int k = 0; k <= pieces; ++k) {
      const Vec3 point = crease + offset * normals[static_cast<std::size_t>(k)];
      if ((point - path.points[at - 1]).norm() <= kJoinTolerance_mm ||
          (point - path.points[at]).norm() <= kJoinTolerance_mm)
        continue;
      const auto where = static_cast<std::ptrdiff_t>(at);
      const std::size_t nearer = 2 * k <= pieces ? i : at;  // (point i + 1 is now at `at`)
      path.points.insert(path.points.begin() + where, point);
      path.normals.insert(path.normals.begin() + where,
                          slerp_axis(up, normals[static_cast<std::size_t>(k)], alpha));
      info.point_index.insert(info.point_index.begin() + where, info.point_index[nearer]);
      info.surface_points_mm.insert(info.surface_points_mm.begin() + where, crease);
      info.surface_normals.insert(info.surface_normals.begin() + where,
                                  normals[static_cast<std::size_t>(k)]);
      ++at;
      ++added;
    }
    i = at - 1;  // on from the arc's last point (the next segment is its end to point i + 1)
  }
  return added;
}

// Whether the surface between two consecutive grid points a and b, farther apart than the
// jump (max_jump_ratio * hatch_mm), is one steep slope rather than a step: at a quarter, half
// and three quarters of the way it faces up and lies within a quarter of their height
// difference of the straight line between them. A step's wall does not face up and either side
// of it lies at a's or b's height; a slope steeper than acos(1 / max_jump_ratio) (70.5 deg)
// that still faces up is surface, and a line across it runs on (it used to break at every
// point and leave the slope bare without a word).
bool rises_evenly(const SurfaceProjector& projector, const Vec3& a, const Vec3& b,
                  double min_normal_z) {
  const double band = 0.25 * std::abs(b.z() - a.z());
  for (const double t : {0.25, 0.5, 0.75}) {
    const Vec3 straight = a + t * (b - a);
    const std::optional<SurfaceHit> hit = projector.project_down(straight.x(), straight.y());
    if (!hit || !hit->faces_up(min_normal_z) ||
        !(std::abs(hit->point_mm.z() - straight.z()) <= band))
      return false;
  }
  return true;
}

AngleGrid project_grid(const SurfaceProjector& projector, double angle_deg,
                       const SurfaceHatchSpec& spec) {
  const double theta = deg_to_rad(angle_deg);
  const Vec2 d(std::cos(theta), std::sin(theta));  // along the lines
  const Vec2 e(-d.y(), d.x());                     // across them
  const TriangleMesh& mesh = projector.mesh();
  double u_lo = INFINITY, u_hi = -INFINITY, v_lo = INFINITY, v_hi = -INFINITY;
  for (const Vec3& p : mesh.vertices) {
    const Vec2 xy = p.head<2>();
    u_lo = std::min(u_lo, xy.dot(d));
    u_hi = std::max(u_hi, xy.dot(d));
    v_lo = std::min(v_lo, xy.dot(e));
    v_hi = std::max(v_hi, xy.dot(e));
  }
  const double h = spec.hatch_mm;
  const Axis along(u_lo, u_hi, h);
  const Axis across(v_lo, v_hi, h);
  if (static_cast<double>(along.n) * across.n > kMaxGridPoints) {
    throw InputError(std::string(kKey) + ".hatch_mm",
                     "the hatch grid over the part would have " +
                         std::to_string(static_cast<double>(along.n) * across.n) +
                         " points per layer (at most 2e7): the spacing is too fine");
  }

  AngleGrid grid;
  grid.lines = across.n;
  grid.points_per_line = along.n;
  grid.pieces.resize(static_cast<std::size_t>(across.n));
  const double max_jump = spec.max_jump_ratio * h;
  std::vector<Vec2> xy(static_cast<std::size_t>(along.n));
  std::vector<std::optional<SurfaceHit>> hits;
  for (int j = 0; j < across.n; ++j) {
    const double v = across.first + j * h;
    for (int i = 0; i < along.n; ++i)
      xy[static_cast<std::size_t>(i)] = (along.first + i * h) * d + v * e;
    projector.project_down(xy, hits);  // one line per batch: memory stays one line
    std::vector<Piece>& line = grid.pieces[static_cast<std::size_t>(j)];
    Piece piece;
    // a piece of one point is no line: between two printed pieces of the line (a groove's
    // floor, a ridge's top, narrower than two spacings) it is kept aside for the report; at a
    // line's end (the rim of a dome) the line merely stops a point short
    std::vector<std::pair<Vec3, std::size_t>> lone;  // the point, the pieces before it
    auto close = [&] {
      if (piece.points.size() >= 2) {
        grid.printed_points += static_cast<int>(piece.points.size());
        refine_piece(projector, piece, v * e, d, along.first, h, spec);
        line.push_back(std::move(piece));
      } else if (piece.points.size() == 1) {
        lone.emplace_back(piece.points.front(), line.size());
      }
      piece = Piece{};
    };
    for (int i = 0; i < along.n; ++i) {
      const std::optional<SurfaceHit>& hit = hits[static_cast<std::size_t>(i)];
      if (!hit || !hit->faces_up(spec.min_normal_z)) {
        close();
        continue;
      }
      if (!piece.points.empty() && (hit->point_mm - piece.points.back()).norm() > max_jump &&
          !rises_evenly(projector, piece.points.back(), hit->point_mm, spec.min_normal_z))
        close();
      piece.index.push_back(i);
      piece.points.push_back(hit->point_mm);
      piece.normals.push_back(hit->normal);
    }
    close();
    for (const auto& [point, pieces_before] : lone)
      if (pieces_before > 0 && pieces_before < line.size()) grid.lone_points.push_back(point);
  }
  return grid;
}

}  // namespace

std::string SurfaceHatch::describe(std::size_t path, std::size_t point) const {
  if (path >= info.size()) return "path " + std::to_string(path);
  const HatchPathInfo& i = info[path];
  std::string text = "layer " + std::to_string(i.layer) + ", line " + std::to_string(i.line);
  if (point < i.point_index.size()) text += ", point " + std::to_string(i.point_index[point]);
  return text;
}

SurfaceHatch hatch_surface(const TriangleMesh& placed_part_mm, const SurfaceHatchSpec& spec) {
  validate(spec);
  return hatch_surface(SurfaceProjector(placed_part_mm), spec);
}

SurfaceHatch hatch_surface(const SurfaceProjector& projector, const SurfaceHatchSpec& spec) {
  validate(spec);
  SurfaceHatch result;
  if (projector.mesh().empty()) return result;

  std::map<double, AngleGrid> grids;  // per distinct angle, projected once
  const Vec3 up = vertical_tool_axis();
  for (int layer = 0; layer < spec.layers; ++layer) {
    const double angle = spec.angles_deg[static_cast<std::size_t>(layer) % spec.angles_deg.size()];
    auto found = grids.find(angle);
    if (found == grids.end())
      found = grids.emplace(angle, project_grid(projector, angle, spec)).first;
    const AngleGrid& grid = found->second;
    // each angle's lone points, once
    if (std::none_of(result.lone_points.begin(), result.lone_points.end(),
                     [&](const LoneGridPoints& lone) { return lone.angle_deg == angle; })) {
      LoneGridPoints lone;
      lone.angle_deg = angle;
      lone.count = static_cast<int>(grid.lone_points.size());
      lone.grid_points = grid.printed_points + lone.count;
      if (!grid.lone_points.empty()) lone.lower_mm = lone.upper_mm = grid.lone_points.front();
      for (const Vec3& p : grid.lone_points) {
        lone.lower_mm = lone.lower_mm.cwiseMin(p);
        lone.upper_mm = lone.upper_mm.cwiseMax(p);
      }
      result.lone_points.push_back(lone);
    }
    result.lines_per_layer.push_back(grid.lines);
    result.points_per_line.push_back(grid.points_per_line);
    const double offset = layer * spec.layer_height_mm;

    int printed_lines = 0;
    for (int j = 0; j < grid.lines; ++j) {
      const std::vector<Piece>& pieces = grid.pieces[static_cast<std::size_t>(j)];
      if (pieces.empty()) continue;
      const bool reversed = printed_lines++ % 2 == 1;
      for (std::size_t k = 0; k < pieces.size(); ++k) {
        const Piece& piece = pieces[reversed ? pieces.size() - 1 - k : k];
        PrintPath path;
        HatchPathInfo info;
        info.layer = layer;
        info.line = j;
        info.reversed = reversed;
        const std::size_t n = piece.points.size();
        for (std::size_t m = 0; m < n; ++m) {
          const std::size_t at = reversed ? n - 1 - m : m;
          const Vec3& p = piece.points[at];
          const Vec3& normal = piece.normals[at];
          const Vec3 point =
              p + offset * (spec.offset == SurfaceHatchSpec::Offset::normal ? normal : up);
          if (!point.allFinite()) throw InternalError("hatch_surface: a non-finite point");
          if (!path.points.empty() && (point - path.points.back()).norm() <= kJoinTolerance_mm)
            continue;  // consecutive points must differ
          path.points.push_back(point);
          path.normals.push_back(slerp_axis(up, normal, spec.alpha));
          info.point_index.push_back(piece.index[at]);
          info.surface_points_mm.push_back(p);
          info.surface_normals.push_back(normal);
        }
        // offset along the normal: folds cut out, a point left over a concave crease too near
        // its far side dropped, and the offset's arc added over a convex crease
        if (offset > 0.0 && spec.offset == SurfaceHatchSpec::Offset::normal) {
          trim_folds(path, info, 4.0 * offset + 2.0 * spec.hatch_mm);
          drop_dents(path, info, projector, offset, kDentTolerance * spec.layer_height_mm);
          if (spec.chord_tolerance_mm > 0.0)
            round_convex_creases(path, info, offset, spec.chord_tolerance_mm, spec.alpha);
        }
        if (path.points.size() < 2) continue;
        path.speed_mm_s = spec.speed_mm_s;
        path.layer = layer;
        path.source_index = static_cast<int>(result.toolpath.paths.size());
        result.toolpath.paths.push_back(std::move(path));
        result.info.push_back(std::move(info));
      }
    }
  }
  return result;
}

HiddenSurface hidden_top_surface(const SurfaceProjector& projector, double min_normal_z) {
  HiddenSurface result;
  const TriangleMesh& mesh = projector.mesh();
  if (mesh.empty()) return result;
  const double size_mm = (projector.upper_bound() - projector.lower_bound()).norm();
  const double tolerance_mm = std::max(1e-3, 1e-6 * size_mm);
  Vec3 lower = Vec3::Constant(INFINITY), upper = Vec3::Constant(-INFINITY);

  // samples in batches (a mesh of millions of triangles keeps its memory to one batch)
  constexpr std::size_t kBatch = 4096;
  std::vector<Vec3> samples;
  std::vector<int> owner;
  std::vector<double> weight;
  std::vector<Vec2> xy;
  std::vector<std::optional<SurfaceHit>> hits;
  auto flush = [&] {
    xy.resize(samples.size());
    for (std::size_t k = 0; k < samples.size(); ++k) xy[k] = samples[k].head<2>();
    projector.project_down(xy, hits);
    for (std::size_t k = 0; k < samples.size(); ++k) {
      const std::optional<SurfaceHit>& hit = hits[k];
      if (!hit || hit->triangle == owner[k] || hit->point_mm.z() <= samples[k].z() + tolerance_mm)
        continue;
      result.hidden_area_mm2 += weight[k];
      for (int corner : mesh.triangles[static_cast<std::size_t>(owner[k])]) {
        lower = lower.cwiseMin(mesh.vertices[static_cast<std::size_t>(corner)]);
        upper = upper.cwiseMax(mesh.vertices[static_cast<std::size_t>(corner)]);
      }
    }
    samples.clear();
    owner.clear();
    weight.clear();
  };
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    if (mesh.facet_normal(t).z() <= min_normal_z) continue;  // a wall or an underside
    const double area = mesh.facet_area_mm2(t);
    result.up_area_mm2 += area;
    const Vec3& a = mesh.vertices[static_cast<std::size_t>(mesh.triangles[t][0])];
    const Vec3& b = mesh.vertices[static_cast<std::size_t>(mesh.triangles[t][1])];
    const Vec3& c = mesh.vertices[static_cast<std::size_t>(mesh.triangles[t][2])];
    // the centroids of the four triangles of the midpoint subdivision
    for (const Vec3& sample : {Vec3((4.0 * a + b + c) / 6.0), Vec3((a + 4.0 * b + c) / 6.0),
                               Vec3((a + b + 4.0 * c) / 6.0), Vec3((a + b + c) / 3.0)}) {
      samples.push_back(sample);
      owner.push_back(static_cast<int>(t));
      weight.push_back(0.25 * area);
    }
    if (samples.size() >= kBatch) flush();
  }
  if (!samples.empty()) flush();
  if (result.hidden_area_mm2 > 0.0) {
    result.lower_mm = lower;
    result.upper_mm = upper;
  }
  return result;
}

}  // namespace depotwin
