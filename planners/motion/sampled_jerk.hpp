// The jerk of a sampled motion as the plan's 1 ms finite differences see it. A SampledMotion is
// read by cubic Hermite interpolation of its samples (core/trajectory.hpp): its acceleration is
// linear inside a sample period and may step at a sample where the samples are not exactly
// those of a twice-differentiable motion (rounding of a Taylor update, a jerk that starts inside
// a period). A step of da shows as a jerk of about da / h to a finite difference with step h,
// while a step that repeats at every sample (a smooth rounding) cancels out of it; so the check
// is the finite differences themselves, on the interpolation, from several start offsets.
#pragma once

#include <vector>

#include "core/types.hpp"

namespace depotwin {

// The largest ratio to j_max (per axis; 0: not limited) of the finite-difference jerk of the
// Hermite interpolation of (positions, velocities) at `period_s`: third differences of the
// positions over 3 fd periods and second differences of the velocities over 2, sampled from
// kJerkCheckOffsets start offsets spread over one fd period, windows inside the motion only
// (it is at rest, or continues smoothly, beyond its ends), less what rounding alone makes of
// the differences: a few ulps of the largest coordinate on every position, plus
// position_rounding_mm (a move the caller made to samples, e.g. onto a line's exact end).
// per_period (optional, one per sample period): the largest ratio of the windows that touch
// that period.
constexpr int kJerkCheckOffsets = 8;
double sampled_jerk_ratio(const std::vector<Vec3>& positions, const std::vector<Vec3>& velocities,
                          double period_s, const Vec3& j_max_mm_s3,
                          std::vector<double>* per_period = nullptr, double fd_period_s = 0.001,
                          double position_rounding_mm = 0.0);

// How far rounding may have moved any of these positions: kSampleRoundingUlps of the largest
// coordinate, plus extra_mm (a move the caller made, e.g. a sample put onto a line's exact end)
constexpr double kSampleRoundingUlps = 16.0;
double sample_position_rounding_mm(const std::vector<Vec3>& positions, double extra_mm = 0.0);

// position and velocity of the cubic Hermite interpolation at time t (clamped to the samples)
void hermite_state(const std::vector<Vec3>& positions, const std::vector<Vec3>& velocities,
                   double period_s, double t, Vec3& position, Vec3& velocity);

}  // namespace depotwin
