// Curve math of Giberti, Sbaglia & Urgo 2017 (papers/001): the quadratic (rational) Bezier
// blend that joins two straight lines at a corner, its derivatives, and the 2nd-order
// Taylor update of the curve parameter that moves along it at a prescribed speed.
#pragma once

#include "core/types.hpp"

namespace depotwin {

// A corner blend: control points entry (p_j^e), corner (p_j), exit (p_j^u) and the weight of
// the corner, eq. (18); weight 1 is the polynomial parabola of eq. (8).
struct BezierBlend {
  Vec3 entry_mm = Vec3::Zero();
  Vec3 corner_mm = Vec3::Zero();
  Vec3 exit_mm = Vec3::Zero();
  double weight = 1.0;

  // the blend built at `corner` between unit directions `in_dir` and `out_dir` with fillet
  // distance delta: entry and exit are where the lines meet the sphere of radius delta
  // around the corner (Fig. 1, in 3-D with spheres)
  static BezierBlend at_corner(const Vec3& corner_mm, const Vec3& in_dir, const Vec3& out_dir,
                               double delta_mm, double weight);

  Vec3 point(double u) const;
  // position and the first two derivatives with respect to u (quotient rule on eq. 18)
  void derivatives(double u, Vec3& p, Vec3& dp_du, Vec3& d2p_du2) const;
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
