#include "planners/motion/sampled_jerk.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace depotwin {

double sample_position_rounding_mm(const std::vector<Vec3>& positions, double extra_mm) {
  double largest_coordinate = 0.0;
  for (const Vec3& p : positions)
    largest_coordinate = std::max(largest_coordinate, p.cwiseAbs().maxCoeff());
  return kSampleRoundingUlps * std::numeric_limits<double>::epsilon() * (1.0 + largest_coordinate) +
         extra_mm;
}

void hermite_state(const std::vector<Vec3>& positions, const std::vector<Vec3>& velocities,
                   double period_s, double t, Vec3& position, Vec3& velocity) {
  const size_t n = positions.size();
  const double k_real = std::max(0.0, t / period_s);
  const size_t k = static_cast<size_t>(std::floor(k_real));
  if (n < 2 || k >= n - 1) {
    position = positions.back();
    velocity = velocities.back();
    return;
  }
  // the same cubic as Trajectory::at: values and slopes at both ends of the period
  const double s = k_real - static_cast<double>(k), h = period_s;
  const double s2 = s * s, s3 = s2 * s;
  const Vec3 &p0 = positions[k], &p1 = positions[k + 1];
  const Vec3 &v0 = velocities[k], &v1 = velocities[k + 1];
  position = (2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * h * v0 + (-2 * s3 + 3 * s2) * p1 +
             (s3 - s2) * h * v1;
  velocity = (6 * s2 - 6 * s) / h * p0 + (3 * s2 - 4 * s + 1) * v0 + (-6 * s2 + 6 * s) / h * p1 +
             (3 * s2 - 2 * s) * v1;
}

double sampled_jerk_ratio(const std::vector<Vec3>& positions, const std::vector<Vec3>& velocities,
                          double period_s, const Vec3& j_max_mm_s3, std::vector<double>* per_period,
                          double fd_period_s, double position_rounding_mm) {
  const size_t n = positions.size();
  const size_t periods = n > 0 ? n - 1 : 0;
  if (per_period) per_period->assign(periods, 0.0);
  if (n < 2) return 0.0;
  const double duration = periods * period_s, H = fd_period_s;
  // what rounding alone makes of the differences: the positions' rounding on each position in
  // a third difference (1 + 3 + 3 + 1 of them, over H^3), and on each of the two positions an
  // interpolated velocity divides by the sample period (6 / h each) in a second difference
  // (1 + 2 + 1, over H^2). At j_max 0.01 mm/s^3, 8 mm from the origin, that read 0.1 % over the
  // limit on a straight S-curve
  const double position_rounding = sample_position_rounding_mm(positions, position_rounding_mm);
  const double rounding_from_positions = 8.0 * position_rounding / (H * H * H);
  const double rounding_from_velocities = 4.0 * 12.0 * position_rounding / (period_s * H * H);
  double worst = 0.0;
  std::vector<Vec3> p, v;
  for (int offset = 0; offset < kJerkCheckOffsets; ++offset) {
    const double t0 = H * offset / kJerkCheckOffsets;
    const long count = static_cast<long>(std::floor((duration - t0) / H + 1e-9)) + 1;
    if (count < 3) continue;
    p.resize(count);
    v.resize(count);
    for (long m = 0; m < count; ++m)
      hermite_state(positions, velocities, period_s, t0 + m * H, p[m], v[m]);
    for (long m = 0; m + 2 < count; ++m) {
      double ratio = 0.0;
      for (int axis = 0; axis < 3; ++axis) {
        if (!(j_max_mm_s3[axis] > 0.0)) continue;
        double jerk = std::abs(v[m + 2][axis] - 2 * v[m + 1][axis] + v[m][axis]) / (H * H) -
                      rounding_from_velocities;
        if (m + 3 < count)
          jerk = std::max(jerk, std::abs(p[m + 3][axis] - 3 * p[m + 2][axis] + 3 * p[m + 1][axis] -
                                         p[m][axis]) /
                                        (H * H * H) -
                                    rounding_from_positions);
        ratio = std::max(ratio, jerk / j_max_mm_s3[axis]);
      }
      worst = std::max(worst, ratio);
      if (!per_period || ratio == 0.0) continue;
      // the sample periods the window [t0 + m H, t0 + (m + 3) H] touches
      const double begin = t0 + m * H, end = std::min(duration, t0 + (m + 3) * H);
      const size_t first = std::min(periods - 1, static_cast<size_t>(begin / period_s));
      const size_t last = std::min(periods - 1, static_cast<size_t>(end / period_s));
      for (size_t k = first; k <= last; ++k) (*per_period)[k] = std::max((*per_period)[k], ratio);
    }
  }
  return worst;
}

}  // namespace depotwin
