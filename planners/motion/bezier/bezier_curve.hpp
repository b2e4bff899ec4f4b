// Curve math of Giberti, Sbaglia & Urgo 2017 (papers/001): the quadratic (rational) Bezier
// blend that joins two straight lines at a corner, its derivatives, and the 2nd-order
// Taylor update of the curve parameter that moves along it at a prescribed speed.
#pragma once

#include "core/types.hpp"

namespace depotwin {

// A corner blend: control points entry (p_j^e), corner (p_j), exit (p_j^u) and the weight of
// the corner, eq. (18); weight 1 is the polynomial parabola of eq. (8).
//
// Under a jerk limit (degree 4) the blend is curvature-continuous with its lines: the rational
// quartic with control points entry, (entry + corner) / 2, corner, (corner + exit) / 2, exit and
// weights 1, 1, w, 1, 1. Its first three and last three control points are collinear, so its
// curvature (and d2p/du2) is 0 at both ends, where the lines have none: crossing it at constant
// speed the acceleration ramps from 0 instead of stepping to v^2 kappa. It keeps the fillet
// distance delta (same entry and exit), the weight's meaning (larger pulls it towards the
// corner) and passes nearer the corner than the quadratic: 3/8 delta sin(theta/2) at w = 1
// against 1/2 delta sin(theta/2).
struct BezierBlend {
  Vec3 entry_mm = Vec3::Zero();
  Vec3 corner_mm = Vec3::Zero();
  Vec3 exit_mm = Vec3::Zero();
  double weight = 1.0;
  int degree = 2;  // 2: Giberti et al.'s blend, eq. (18); 4: the curvature-continuous quartic

  // the blend built at `corner` between unit directions `in_dir` and `out_dir` with fillet
  // distance delta: entry and exit are where the lines meet the sphere of radius delta
  // around the corner (Fig. 1, in 3-D with spheres)
  static BezierBlend at_corner(const Vec3& corner_mm, const Vec3& in_dir, const Vec3& out_dir,
                               double delta_mm, double weight);
  // the same entry, corner and exit as the quartic of degree 4 (see above)
  static BezierBlend curvature_continuous_at_corner(const Vec3& corner_mm, const Vec3& in_dir,
                                                    const Vec3& out_dir, double delta_mm,
                                                    double weight);

  Vec3 point(double u) const;
  // position and the first two derivatives with respect to u (quotient rule on eq. 18)
  void derivatives(double u, Vec3& p, Vec3& dp_du, Vec3& d2p_du2) const;
  // the same and the third derivative, any degree
  void derivatives(double u, Vec3& p, Vec3& dp_du, Vec3& d2p_du2, Vec3& d3p_du3) const;
  // d3p/ds3 by arc length at u: the jerk per cubed speed of a constant-speed traversal
  // (kappa' N - kappa^2 T + kappa tau B)
  Vec3 third_arc_derivative(double u) const;
  // arc length between parameters u0 <= u1 (Gauss-Legendre quadrature)
  double arc_length_mm(double u0 = 0.0, double u1 = 1.0) const;
};

// eqs. (15)-(16), (19)-(22): Floater's form of the rational first derivative, for m = 2.
// Kept as an independent check of BezierBlend::derivatives (see the tests).
Vec3 floater_first_derivative(const BezierBlend& blend, double u);
// eqs. (23)-(24): Floater's second derivative for m = 2 (with the index typo fixed, see .cpp)
Vec3 floater_second_derivative(const BezierBlend& blend, double u);

// The bracket of eqs. (3)-(5), (11), (12): (dp/du . d2p/du2) / |dp/du|^4.
double taylor_bracket(const Vec3& dp_du, const Vec3& d2p_du2);

// eq. (5) (eq. (4) when a = 0): the parameter increment over one sample period at speed v
// and along-path acceleration a.
double taylor_parameter_step(const Vec3& dp_du, const Vec3& d2p_du2, double speed_mm_s,
                             double accel_mm_s2, double period_s);

// eq. (11): the parameter at arc distance `distance_mm` from the start (u = 0) of a curve.
double parameter_at_distance_from_start(const Vec3& dp_du0, const Vec3& d2p_du20,
                                        double distance_mm);

// eq. (12): the arc distance still to go from u_f to u = 1, from the root of the
// 2nd-order Taylor relation.
double distance_to_end(const Vec3& dp_du, const Vec3& d2p_du2, double u_f);

}  // namespace depotwin
