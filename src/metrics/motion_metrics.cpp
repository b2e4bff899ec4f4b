#include "metrics/motion_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>

#include "core/interrupt.hpp"
#include "metrics/polyline_distance.hpp"

namespace depotwin {

void MotionSamples::reserve(size_t n) {
  t_s.reserve(n);
  position_mm.reserve(n);
  velocity_mm_s.reserve(n);
  depositing.reserve(n);
  path_index.reserve(n);
  desired_speed_mm_s.reserve(n);
}

void MotionSamples::push_back(double t, const Vec3& p, const Vec3& v, bool deposit, int path,
                              double desired) {
  t_s.push_back(t);
  position_mm.push_back(p);
  velocity_mm_s.push_back(v);
  depositing.push_back(deposit ? 1 : 0);
  path_index.push_back(path);
  desired_speed_mm_s.push_back(desired);
}

// half of trajectory.csv's time resolution (its times are written to 1e-6 s)
constexpr double kEndMergeWithin_s = 5e-7;

MotionSamples sample_trajectory(const Trajectory& trajectory, double period_s) {
  MotionSamples samples;
  const double duration = trajectory.duration_s();
  long count = static_cast<long>(std::floor(duration / period_s + 1e-9)) + 1;
  samples.reserve(count + 1);
  // an end within half a microsecond after the last grid sample takes that sample's place:
  // trajectory.csv writes times to the microsecond, where the two would share one time
  if (count > 1 && duration - (count - 1) * period_s < kEndMergeWithin_s) --count;
  for (long k = 0; k < count; ++k) {
    const TrajectorySample s = trajectory.at(k * period_s);
    samples.push_back(s.t_s, s.position_mm, s.velocity_mm_s, s.depositing, s.path_index,
                      s.desired_speed_mm_s);
  }
  // the exact end, so that the final rest state is always included
  if ((count - 1) * period_s < duration - 1e-12) {
    const TrajectorySample s = trajectory.at(duration);
    samples.push_back(s.t_s, s.position_mm, s.velocity_mm_s, s.depositing, s.path_index,
                      s.desired_speed_mm_s);
  }
  return samples;
}

namespace {

// time weight of sample k: half the interval to each neighbour
double time_weight(const MotionSamples& s, size_t k) {
  const double before = k > 0 ? s.t_s[k] - s.t_s[k - 1] : 0.0;
  const double after = k + 1 < s.size() ? s.t_s[k + 1] - s.t_s[k] : 0.0;
  return 0.5 * (before + after);
}

bool depositing_with_target(const MotionSamples& s, size_t k) {
  return s.depositing[k] && s.desired_speed_mm_s[k] > 0.0;
}

}  // namespace

std::vector<double> relative_speed_error(const MotionSamples& samples) {
  std::vector<double> error(samples.size(), 0.0);
  for (size_t k = 0; k < samples.size(); ++k) {
    if (!depositing_with_target(samples, k)) continue;
    const double desired = samples.desired_speed_mm_s[k];
    error[k] = std::abs(samples.velocity_mm_s[k].norm() - desired) / desired;
  }
  return error;
}

VelocityErrorStats velocity_error(const MotionSamples& samples) {
  return velocity_error(samples, {});
}

VelocityErrorStats velocity_error(const MotionSamples& samples,
                                  const std::vector<TimeSpan>& excluded) {
  VelocityErrorStats stats;
  const std::vector<double> error = relative_speed_error(samples);
  std::vector<std::pair<double, double>> weighted;  // (error, time weight)
  double total_time = 0.0, sum_sq = 0.0, length = 0.0, length_over = 0.0;
  // the spans are in time order (speed_ramps): one cursor walks them beside the samples
  size_t span = 0;
  for (size_t k = 0; k < samples.size(); ++k) {
    if (!depositing_with_target(samples, k)) continue;
    const double t = samples.t_s[k];
    while (span < excluded.size() && excluded[span].end_s <= t) ++span;
    if (span < excluded.size() && excluded[span].begin_s < t) continue;
    const double w = time_weight(samples, k);
    const double ds = samples.velocity_mm_s[k].norm() * w;  // path length of this sample
    stats.max_rel = std::max(stats.max_rel, error[k]);
    sum_sq += error[k] * error[k] * w;
    total_time += w;
    length += ds;
    if (error[k] > 0.01) length_over += ds;
    weighted.push_back({error[k], w});
  }
  if (total_time <= 0.0) return stats;
  stats.counted_s = total_time;
  stats.rms_rel = std::sqrt(sum_sq / total_time);
  stats.frac_len_over_1pct = length > 0.0 ? length_over / length : 0.0;
  // time-weighted 95th percentile: the smallest error with >= 95 % of the time at or below it
  std::sort(weighted.begin(), weighted.end());
  double cumulative = 0.0;
  for (const auto& [e, w] : weighted) {
    cumulative += w;
    if (cumulative >= 0.95 * total_time) {
      stats.p95_rel = e;
      break;
    }
  }
  return stats;
}

std::vector<TimeSpan> speed_ramps(const MotionSamples& planned) {
  std::vector<TimeSpan> ramps;
  const size_t n = planned.size();
  // a ramp's span reaches half a sample period beyond its outer samples
  const auto half_gap = [&](size_t a, size_t b) { return 0.5 * (planned.t_s[b] - planned.t_s[a]); };
  // at speed: within the tolerance of the desired speed, or of `ceiling` where that is lower
  const auto reached = [&](size_t k, double ceiling) {
    return planned.velocity_mm_s[k].norm() >=
           (1.0 - kRampTolerance_rel) * std::min(planned.desired_speed_mm_s[k], ceiling);
  };
  size_t k = 0;
  while (k < n) {
    if (!depositing_with_target(planned, k)) {
      ++k;
      continue;
    }
    // one printed stretch [first, last]
    const size_t first = k;
    while (k + 1 < n && depositing_with_target(planned, k + 1)) ++k;
    const size_t last = k++;
    // (at the run's own ends: half the neighbouring period inside it, or a nanosecond)
    const double inner = last > first ? half_gap(first, first + 1) : 1e-9;
    const double before = first > 0 ? half_gap(first - 1, first) : inner;
    const double after = last + 1 < n ? half_gap(last, last + 1) : inner;
    // A stretch that never reaches its desired speed is at speed where it holds its own top
    // speed: a line held below the speed on purpose (the limits, or conformal's constant
    // scale-down) has a steady part, whose error is that shortfall. Peaks that do not hold
    // it (short moves' triangles, however many) are ramp throughout.
    double ceiling = std::numeric_limits<double>::infinity();
    size_t steady_first = first;
    while (steady_first <= last && !reached(steady_first, ceiling)) ++steady_first;
    size_t steady_last = last;
    if (steady_first > last) {
      ceiling = 0.0;
      for (size_t i = first; i <= last; ++i)
        ceiling = std::max(ceiling, planned.velocity_mm_s[i].norm());
      // the first and last runs of samples at that speed held kHeldTopSpeed_s or longer
      std::optional<size_t> first_held, last_held;
      for (size_t i = first; i <= last;) {
        if (!reached(i, ceiling)) {
          ++i;
          continue;
        }
        size_t end = i;
        while (end < last && reached(end + 1, ceiling)) ++end;
        if (planned.t_s[end] - planned.t_s[i] >= kHeldTopSpeed_s) {
          if (!first_held) first_held = i;
          last_held = end;
        }
        i = end + 1;
      }
      if (!(ceiling > 0.0) || !first_held) {
        ramps.push_back({planned.t_s[first] - before, planned.t_s[last] + after});
        continue;
      }
      steady_first = *first_held;
      steady_last = *last_held;
    }
    while (!reached(steady_last, ceiling)) --steady_last;
    // each ramp takes in the first (last) sample at speed: the servo follows a period late
    if (steady_first > first)
      ramps.push_back(
          {planned.t_s[first] - before,
           planned.t_s[steady_first] +
               (steady_first < last ? half_gap(steady_first, steady_first + 1) : after)});
    if (steady_last < last) {
      const TimeSpan end_ramp{
          planned.t_s[steady_last] -
              (steady_last > first ? half_gap(steady_last - 1, steady_last) : before),
          planned.t_s[last] + after};
      // at speed at one sample only: the two ramps share it, one span (its time counted once)
      if (steady_first > first && ramps.back().end_s > end_ramp.begin_s)
        ramps.back().end_s = end_ramp.end_s;
      else
        ramps.push_back(end_ramp);
    }
  }
  return ramps;
}

double total_time_s(const std::vector<TimeSpan>& spans) {
  double total = 0.0;
  for (const TimeSpan& span : spans) total += span.end_s - span.begin_s;
  return total;
}

double distance_to_polyline(const Vec3& point, const std::vector<Vec3>& polyline) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i + 1 < polyline.size(); ++i)
    best = std::min(best, point_segment_distance(point, polyline[i], polyline[i + 1]));
  if (polyline.size() == 1) best = (polyline[0] - point).norm();
  return best;
}

std::vector<double> path_distances(const MotionSamples& samples, const Toolpath& toolpath) {
  std::vector<double> distances(samples.size(), std::numeric_limits<double>::quiet_NaN());
  // each path's segments binned once, when its first sample comes (polyline_distance.hpp)
  std::vector<std::unique_ptr<PolylineDistance>> distance(toolpath.paths.size());
  for (size_t k = 0; k < samples.size(); ++k) {
    // a long path's distances take seconds: a signal that asked to stop ends them
    if (k % 1024 == 0) throw_if_interrupted();
    const int path = samples.path_index[k];
    if (!samples.depositing[k] || path < 0 || path >= static_cast<int>(toolpath.paths.size()))
      continue;
    if (!distance[path])
      distance[path] = std::make_unique<PolylineDistance>(toolpath.paths[path].points);
    distances[k] = (*distance[path])(samples.position_mm[k]);
  }
  return distances;
}

PathErrorStats path_error(const MotionSamples& samples, const Toolpath& toolpath) {
  PathErrorStats stats;
  double sum_sq = 0.0, total_time = 0.0;
  const std::vector<double> distances = path_distances(samples, toolpath);
  for (size_t k = 0; k < samples.size(); ++k) {
    const double e = distances[k];
    if (std::isnan(e)) continue;  // nothing deposited, or no path
    const double w = time_weight(samples, k);
    stats.max_mm = std::max(stats.max_mm, e);
    sum_sq += e * e * w;
    total_time += w;
  }
  if (total_time > 0.0) stats.rms_mm = std::sqrt(sum_sq / total_time);
  return stats;
}

}  // namespace depotwin
