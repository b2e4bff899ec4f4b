// A corner of a polyline blended by a symmetric pair of clothoids (Euler spirals): the
// curvature rises linearly in arc length from 0 at the blend's start to kappa_m at its apex and
// falls linearly back to 0 at its end. Why clothoids (and not a quintic or a B-spline): the
// path is tangent and curvature-continuous (G2) at both ends and inside, it is parametrised
// by arc length exactly (|p'| = 1, so the time law's speed is the TCP's speed), its curvature
// rate dkappa/ds is constant on each half (so the jerk of a constant-speed traversal,
// v^3 (kappa' N - kappa^2 t), is known in closed form and bounded), and everything about it
// scales with one length, so the least blend for a speed and the largest within a tolerance
// are closed forms of a few per-corner constants. A quintic or B-spline blend would need its
// arc length inverted numerically and its curvature bounds searched per size.
//
// Geometry (the corner C, unit directions d_in, d_out, the turn theta = angle(d_in, d_out) in
// (0, pi), phi = theta / 2; each half has length L): in the corner's plane with e1 = d_in and
// e2 the unit normal towards d_out, the first half is
//   p(s) = S + L (X(s / L) e1 + Y(s / L) e2),  X(u) = int_0^u cos(phi w^2) dw,
//                                               Y(u) = int_0^u sin(phi w^2) dw,
// its tangent angle phi (s / L)^2, its curvature kappa(s) = 2 phi s / L^2 (kappa_m = 2 phi / L
// at the apex), and the second half is its mirror image about the corner's bisector. The
// blend starts T = L (X(1) + Y(1) tan phi) before the corner on the incoming line and ends T
// after it on the outgoing one. Its largest distance from the polyline is at the apex, equal
// to the apex's offset from either line: L Y(1) (the deviation). Everything scales with L.
#pragma once

#include <array>

#include "core/limits.hpp"
#include "core/types.hpp"

namespace depotwin {

// X(u), Y(u) of the header (Fresnel-type integrals, power series: |phi u^2| <= pi / 2)
void clothoid_integrals(double phi, double u, double& x, double& y);

// Per-axis maxima of a blend of half-length 1 (everything else follows by scaling): over the
// blend, |t_k| (the tangent's components), |kappa N_k| (the curvature vector's) and
// |kappa' N_k - kappa^2 t_k| (the third derivative's, p''' = kappa' N - kappa^2 t).
struct BlendShape {
  Vec3 tangent = Vec3::Zero();
  Vec3 curvature = Vec3::Zero();
  Vec3 third = Vec3::Zero();
};

class ClothoidBlend {
 public:
  ClothoidBlend() = default;
  // the blend of half-length half_length_mm at corner (directions unit, turn in (0, pi))
  ClothoidBlend(const Vec3& corner_mm, const Vec3& d_in, const Vec3& d_out, double half_length_mm);

  // the turn angle (rad) of the corner: pi minus the interior ("joint") angle
  static double turn_angle(const Vec3& d_in, const Vec3& d_out);
  // deviation / half-length and tangent length / half-length for a turn theta
  static double deviation_per_length(double theta);
  static double tangent_per_length(double theta);
  // the per-axis maxima at half-length 1 (BlendShape) for the corner's directions
  static BlendShape unit_shape(const Vec3& d_in, const Vec3& d_out);

  double length_mm() const { return 2.0 * half_length_; }
  double half_length_mm() const { return half_length_; }
  double tangent_length_mm() const { return tangent_length_; }
  double deviation_mm() const { return deviation_; }
  double turn_rad() const { return 2.0 * phi_; }
  const Vec3& start_mm() const { return start_; }
  const Vec3& end_mm() const { return end_; }
  const Vec3& corner_mm() const { return corner_; }

  // position and the arc-length derivatives p', p'', p''' at arc length s in [0, length]
  void at(double s_mm, Vec3& position_mm, Vec3& d1, Vec3& d2, Vec3& d3) const;
  Vec3 position(double s_mm) const;
  // curvature |p''| at s
  double curvature(double s_mm) const;

 private:
  Vec3 corner_ = Vec3::Zero(), d_in_ = Vec3::UnitX(), d_out_ = Vec3::UnitX();
  Vec3 e2_ = Vec3::UnitY();     // in-plane normal of d_in towards d_out
  Vec3 n_out_ = Vec3::UnitY();  // in-plane normal of d_out (d_out turned +90 deg)
  Vec3 start_ = Vec3::Zero(), end_ = Vec3::Zero();
  double phi_ = 0.0, half_length_ = 0.0, tangent_length_ = 0.0, deviation_ = 0.0;
};

// The constant speed at which a blend of half-length `half_length_mm` of that shape stays
// within the per-axis limits (speed, acceleration v^2 |kappa N_k|, jerk v^3 |p'''_k|); an axis
// without a jerk limit (0) does not bound it.
double blend_speed_bound(const BlendShape& unit, double half_length_mm,
                         const MachineLimits& limits);
// The least half-length whose constant-speed traversal at speed_mm_s keeps the limits;
// infinity when the blend's tangent alone exceeds an axis' speed limit at that speed.
double blend_half_length_for_speed(const BlendShape& unit, double speed_mm_s,
                                   const MachineLimits& limits);

}  // namespace depotwin
