#include "planners/motion/uniform/clothoid_blend.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>

#include "core/error.hpp"

namespace depotwin {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// samples per half of the unit blend for the per-axis maxima, and the slack added to them
// (a smooth function sampled every 1/256 is within ~2e-5 of its maximum)
constexpr int kShapeSamples = 256;
constexpr double kShapeSlack = 1e-4;

}  // namespace

void clothoid_integrals(double phi, double u, double& x, double& y) {
  // X = u sum_{k even} (-1)^{k/2} a^k / (k! (2k + 1)), Y = u sum_{k odd} ..., a = phi u^2: the
  // terms four at a time (signs +X, +Y, -X, -Y), by the reciprocals of k and 2k + 1 (no
  // division: the series is a chain of multiplies)
  constexpr int kTerms = 40;
  struct Reciprocals {
    double of_k[kTerms + 1] = {};
    double of_odd[kTerms + 1] = {};
    constexpr Reciprocals() {
      for (int k = 1; k <= kTerms; ++k) of_k[k] = 1.0 / k;
      for (int k = 0; k <= kTerms; ++k) of_odd[k] = 1.0 / (2 * k + 1);
    }
  };
  static constexpr Reciprocals kReciprocal;
  const double a = phi * u * u;
  double term = 1.0;  // a^k / k!
  x = 1.0;            // (k = 0)
  y = 0.0;
  for (int k = 1; k + 3 <= kTerms; k += 4) {
    term *= a * kReciprocal.of_k[k];
    y += term * kReciprocal.of_odd[k];
    term *= a * kReciprocal.of_k[k + 1];
    x -= term * kReciprocal.of_odd[k + 1];
    term *= a * kReciprocal.of_k[k + 2];
    y -= term * kReciprocal.of_odd[k + 2];
    term *= a * kReciprocal.of_k[k + 3];
    x += term * kReciprocal.of_odd[k + 3];
    if (std::abs(term) < 1e-18) break;
  }
  x *= u;
  y *= u;
}

double ClothoidBlend::turn_angle(const Vec3& d_in, const Vec3& d_out) {
  return std::atan2(d_in.cross(d_out).norm(), d_in.dot(d_out));
}

double ClothoidBlend::deviation_per_length(double theta) {
  double x = 0.0, y = 0.0;
  clothoid_integrals(0.5 * theta, 1.0, x, y);
  return y;
}

double ClothoidBlend::tangent_per_length(double theta) {
  double x = 0.0, y = 0.0;
  clothoid_integrals(0.5 * theta, 1.0, x, y);
  return x + y * std::tan(0.5 * theta);
}

ClothoidBlend::ClothoidBlend(const Vec3& corner_mm, const Vec3& d_in, const Vec3& d_out,
                             double half_length_mm)
    : corner_(corner_mm), d_in_(d_in), d_out_(d_out), half_length_(half_length_mm) {
  const double theta = turn_angle(d_in, d_out);
  if (!(theta > 0.0 && theta < kPi) || !(half_length_mm > 0.0))
    throw InternalError("a clothoid blend needs a turn in (0, pi) and a positive size");
  phi_ = 0.5 * theta;
  // the corner's plane: e2 is d_out's part normal to d_in
  e2_ = (d_out - d_out.dot(d_in) * d_in).normalized();
  n_out_ = std::cos(theta) * e2_ - std::sin(theta) * d_in;  // d_out turned +90 deg in-plane
  double x = 0.0, y = 0.0;
  clothoid_integrals(phi_, 1.0, x, y);
  tangent_length_ = half_length_ * (x + y * std::tan(phi_));
  deviation_ = half_length_ * y;
  start_ = corner_ - tangent_length_ * d_in_;
  end_ = corner_ + tangent_length_ * d_out_;
}

void ClothoidBlend::at(double s, Vec3& position, Vec3& d1, Vec3& d2, Vec3& d3) const {
  const double length = 2.0 * half_length_;
  s = std::clamp(s, 0.0, length);
  const double L = half_length_;
  const bool first = s <= L;
  // distance from the nearer end, and the tangent angle measured from d_in
  const double r = first ? s : length - s;
  const double u = r / L;
  const double psi = first ? phi_ * u * u : 2.0 * phi_ - phi_ * u * u;
  const double kappa = 2.0 * phi_ * r / (L * L);
  const double kappa_rate = (first ? 2.0 : -2.0) * phi_ / (L * L);
  double x = 0.0, y = 0.0;
  clothoid_integrals(phi_, u, x, y);
  if (first)
    position = start_ + L * (x * d_in_ + y * e2_);
  else
    position = end_ - L * x * d_out_ + L * y * n_out_;
  // t = cos psi e1 + sin psi e2, N = t turned +90 deg, p'' = kappa N, p''' = kappa' N - kappa^2 t
  const Vec3 t = std::cos(psi) * d_in_ + std::sin(psi) * e2_;
  const Vec3 normal = -std::sin(psi) * d_in_ + std::cos(psi) * e2_;
  d1 = t;
  d2 = kappa * normal;
  d3 = kappa_rate * normal - kappa * kappa * t;
  if (s == 0.0) position = start_;
  if (s == length) position = end_;
}

Vec3 ClothoidBlend::position(double s) const {
  Vec3 p, d1, d2, d3;
  at(s, p, d1, d2, d3);
  return p;
}

double ClothoidBlend::curvature(double s) const {
  Vec3 p, d1, d2, d3;
  at(s, p, d1, d2, d3);
  return d2.norm();
}

namespace {

// the per-axis maxima of |t|, |p''| and |p'''| over the unit blend's samples (see unit_shape), on
// vectors of the axes that move (Vec3, or the plane's Vector2d: a planar corner's z is 0 at every
// sample, so its maxima stay 0)
template <class Vector>
void unit_shape_maxima(const Vector& d_in, const Vector& e2, double phi, double theta,
                       Vector& tangent, Vector& curvature, Vector& third) {
  // cos and sin of phi u^2 at u = k / N by the chirp recurrence: the angle grows by
  // phi (2k + 1) / N^2 from sample k to k + 1, a rotation whose own angle grows by 2 phi / N^2
  // (no sincos per sample; rounding drifts by ~N^2 eps = 7e-12, far within kShapeSlack). The
  // second half's theta - phi u^2 follows by the difference formulas
  const double angle_step = phi / (static_cast<double>(kShapeSamples) * kShapeSamples);
  double cos_psi = 1.0, sin_psi = 0.0;
  double cos_turn = std::cos(angle_step), sin_turn = std::sin(angle_step);
  const double cos_growth = std::cos(2.0 * angle_step), sin_growth = std::sin(2.0 * angle_step);
  const double cos_theta = std::cos(theta), sin_theta = std::sin(theta);
  tangent.setZero(), curvature.setZero(), third.setZero();
  for (int k = 0; k <= kShapeSamples; ++k) {
    const double u = static_cast<double>(k) / kShapeSamples;
    const double kappa = 2.0 * phi * u;
    for (int half = 0; half < 2; ++half) {
      const double c = half == 0 ? cos_psi : cos_theta * cos_psi + sin_theta * sin_psi;
      const double s = half == 0 ? sin_psi : sin_theta * cos_psi - cos_theta * sin_psi;
      const double rate = half == 0 ? 2.0 * phi : -2.0 * phi;
      const Vector t = c * d_in + s * e2;
      const Vector normal = -s * d_in + c * e2;
      const Vector d2 = kappa * normal, d3 = rate * normal - kappa * kappa * t;
      tangent = tangent.cwiseMax(t.cwiseAbs());
      curvature = curvature.cwiseMax(d2.cwiseAbs());
      third = third.cwiseMax(d3.cwiseAbs());
    }
    // (psi, turn) -> (psi + turn, turn + growth)
    const double next_cos = cos_psi * cos_turn - sin_psi * sin_turn;
    sin_psi = sin_psi * cos_turn + cos_psi * sin_turn;
    cos_psi = next_cos;
    const double next_cos_turn = cos_turn * cos_growth - sin_turn * sin_growth;
    sin_turn = sin_turn * cos_growth + cos_turn * sin_growth;
    cos_turn = next_cos_turn;
  }
}

}  // namespace

BlendShape ClothoidBlend::unit_shape(const Vec3& d_in, const Vec3& d_out) {
  // the derivatives depend on the tangent angle and the curvature only (no positions needed):
  // at half-length 1, psi = phi u^2 and kappa = 2 phi u on the first half (u from the start),
  // psi = 2 phi - phi u^2 and kappa = 2 phi u on the second (u from the end), kappa' = +-2 phi
  const double theta = turn_angle(d_in, d_out), phi = 0.5 * theta;
  const Vec3 e2 = (d_out - d_out.dot(d_in) * d_in).normalized();
  BlendShape shape;
  if (d_in.z() == 0.0 && e2.z() == 0.0) {
    Eigen::Vector2d tangent, curvature, third;
    unit_shape_maxima<Eigen::Vector2d>(d_in.head<2>(), e2.head<2>(), phi, theta, tangent, curvature,
                                       third);
    shape.tangent.head<2>() = tangent;
    shape.curvature.head<2>() = curvature;
    shape.third.head<2>() = third;
  } else {
    unit_shape_maxima<Vec3>(d_in, e2, phi, theta, shape.tangent, shape.curvature, shape.third);
  }
  // what the samples may miss between them, against the largest norms (t and the normal are
  // orthonormal: |d2| = kappa and |d3| = sqrt(4 phi^2 + kappa^4), largest at u = 1)
  const double curvature_norm = 2.0 * phi;
  const double third_norm = std::sqrt(4.0 * phi * phi + std::pow(2.0 * phi, 4));
  shape.tangent.array() += kShapeSlack;
  shape.curvature.array() += kShapeSlack * curvature_norm;
  shape.third.array() += kShapeSlack * third_norm;
  return shape;
}

double blend_speed_bound(const BlendShape& unit, double half_length_mm,
                         const MachineLimits& limits) {
  double bound = kInf;
  for (int axis = 0; axis < 3; ++axis) {
    const AxisLimits& limit = limits.axes[axis];
    if (unit.tangent[axis] > 0.0) bound = std::min(bound, limit.v_max_mm_s / unit.tangent[axis]);
    // v^2 kappa N_k / L <= a_k, v^3 p'''_k / L^2 <= j_k
    if (unit.curvature[axis] > 0.0)
      bound = std::min(bound, std::sqrt(limit.a_max_mm_s2 * half_length_mm / unit.curvature[axis]));
    if (unit.third[axis] > 0.0 && limit.j_max_mm_s3 > 0.0)
      bound = std::min(
          bound, std::cbrt(limit.j_max_mm_s3 * half_length_mm * half_length_mm / unit.third[axis]));
  }
  return bound;
}

double blend_half_length_for_speed(const BlendShape& unit, double speed_mm_s,
                                   const MachineLimits& limits) {
  double length = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    const AxisLimits& limit = limits.axes[axis];
    if (speed_mm_s * unit.tangent[axis] > limit.v_max_mm_s * (1 + 1e-12)) return kInf;
    length = std::max(length, speed_mm_s * speed_mm_s * unit.curvature[axis] / limit.a_max_mm_s2);
    if (limit.j_max_mm_s3 > 0.0)
      length = std::max(length,
                        std::sqrt(std::pow(speed_mm_s, 3) * unit.third[axis] / limit.j_max_mm_s3));
  }
  return length;
}

}  // namespace depotwin
