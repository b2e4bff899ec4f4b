#include "core/trajectory.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"

namespace depotwin {

Trajectory::Trajectory(std::string planner, std::vector<TrajectoryPiece> pieces,
                       std::vector<std::string> warnings, std::vector<PlanDecision> decisions)
    : planner_(std::move(planner)),
      pieces_(std::move(pieces)),
      warnings_(std::move(warnings)),
      decisions_(std::move(decisions)) {
  // the pieces must tile [0, duration] without gaps
  double t = 0.0;
  for (const TrajectoryPiece& piece : pieces_) {
    if (std::abs(piece.t_begin_s - t) > 1e-9 || piece.t_end_s < piece.t_begin_s)
      throw InternalError("trajectory pieces are not contiguous in time");
    t = piece.t_end_s;
  }
}

int Trajectory::piece_at(double t) const {
  if (pieces_.empty()) return -1;
  auto it =
      std::upper_bound(pieces_.begin(), pieces_.end(), t,
                       [](double time, const TrajectoryPiece& p) { return time < p.t_begin_s; });
  if (it == pieces_.begin()) return 0;
  return static_cast<int>(it - pieces_.begin()) - 1;
}

namespace {

// cubic Hermite interpolation between two samples of period h at fraction s in [0, 1]
void hermite(const Vec3& p0, const Vec3& v0, const Vec3& p1, const Vec3& v1, double h, double s,
             Vec3& p, Vec3& v, Vec3& a) {
  const double s2 = s * s, s3 = s2 * s;
  const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s;
  const double h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
  p = h00 * p0 + h10 * h * v0 + h01 * p1 + h11 * h * v1;
  // derivatives with respect to time (ds/dt = 1/h)
  const double d00 = 6 * s2 - 6 * s, d10 = 3 * s2 - 4 * s + 1;
  const double d01 = -6 * s2 + 6 * s, d11 = 3 * s2 - 2 * s;
  v = (d00 * p0 + d01 * p1) / h + d10 * v0 + d11 * v1;
  const double e00 = 12 * s - 6, e10 = 6 * s - 4, e01 = -12 * s + 6, e11 = 6 * s - 2;
  a = (e00 * p0 + e01 * p1) / (h * h) + (e10 * v0 + e11 * v1) / h;
}

}  // namespace

void evaluate_motion(const TrajectoryPiece& piece, double tau, Vec3& position_mm,
                     Vec3& velocity_mm_s, Vec3& acceleration_mm_s2) {
  if (const auto* phases = std::get_if<PhaseMotion>(&piece.motion)) {
    for (int axis = 0; axis < 3; ++axis) {
      const AxisState s = phases->axes[axis].at(tau);
      position_mm[axis] = s.q;
      velocity_mm_s[axis] = s.v;
      acceleration_mm_s2[axis] = s.a;
    }
    return;
  }
  const auto& sampled = std::get<SampledMotion>(piece.motion);
  const size_t n = sampled.position_mm.size();
  if (n == 0) throw InternalError("sampled trajectory piece without samples");
  if (n == 1 || tau <= 0.0) {
    position_mm = sampled.position_mm.front();
    velocity_mm_s = sampled.velocity_mm_s.front();
    acceleration_mm_s2.setZero();
    return;
  }
  const double h = sampled.period_s;
  const double k_real = tau / h;
  size_t k = static_cast<size_t>(std::floor(k_real));
  if (k >= n - 1) {
    position_mm = sampled.position_mm.back();
    velocity_mm_s = sampled.velocity_mm_s.back();
    acceleration_mm_s2.setZero();
    return;
  }
  hermite(sampled.position_mm[k], sampled.velocity_mm_s[k], sampled.position_mm[k + 1],
          sampled.velocity_mm_s[k + 1], h, k_real - static_cast<double>(k), position_mm,
          velocity_mm_s, acceleration_mm_s2);
}

namespace {

// the sample interval of a sampled piece at local time tau: index k and fraction in [0, 1];
// false past the last sample
bool sample_interval(const SampledMotion& sampled, size_t count, double tau, size_t& k,
                     double& fraction) {
  const double k_real = std::max(0.0, tau / sampled.period_s);
  k = static_cast<size_t>(std::floor(k_real));
  if (k + 1 >= count) return false;
  fraction = k_real - static_cast<double>(k);
  return true;
}

}  // namespace

void evaluate_tool_axis(const TrajectoryPiece& piece, double tau, const Vec3& position_mm,
                        const Vec3& velocity_mm_s, Vec3& tool_axis, Vec3& angular_velocity_rad_s,
                        double& roll_rad) {
  const ToolAxisMotion& motion = piece.tool_axis;
  // per-sample axes (and rolls) of a sampled piece: slerp between neighbouring samples
  if (const auto* sampled = std::get_if<SampledMotion>(&piece.motion);
      sampled != nullptr && !sampled->tool_axis.empty()) {
    const std::vector<Vec3>& axes = sampled->tool_axis;
    const std::vector<double>& rolls = sampled->roll_rad;
    size_t k = 0;
    double fraction = 0.0;
    if (!sample_interval(*sampled, axes.size(), tau, k, fraction)) {
      tool_axis = axes.back();
      angular_velocity_rad_s.setZero();
      roll_rad = rolls.empty() ? motion.roll_end : rolls.back();
      return;
    }
    tool_axis = slerp_axis(axes[k], axes[k + 1], fraction);
    angular_velocity_rad_s = slerp_rate(axes[k], axes[k + 1]) / sampled->period_s;
    roll_rad = rolls.empty() ? motion.roll_begin + fraction * (motion.roll_end - motion.roll_begin)
                             : rolls[k] + fraction * (rolls[k + 1] - rolls[k]);
    return;
  }
  if (motion.constant()) {
    tool_axis = motion.begin;
    angular_velocity_rad_s.setZero();
    roll_rad = motion.roll_begin;
    return;
  }
  // the fraction of the rotation done and its rate: along the chord, or smoothstep in time
  double fraction = 0.0, rate_per_s = 0.0;
  if (motion.along_chord) {
    const Vec3 chord = motion.chord_end_mm - motion.chord_begin_mm;
    const double length2 = chord.squaredNorm();
    if (length2 > 0.0) {
      fraction = (position_mm - motion.chord_begin_mm).dot(chord) / length2;
      rate_per_s = velocity_mm_s.dot(chord) / length2;
    }
    if (fraction <= 0.0 || fraction >= 1.0) rate_per_s = 0.0;
    fraction = std::clamp(fraction, 0.0, 1.0);
  } else {
    const double duration_s = piece.t_end_s - piece.t_begin_s;
    const double x = duration_s > 0.0 ? std::clamp(tau / duration_s, 0.0, 1.0) : 1.0;
    fraction = x * x * (3.0 - 2.0 * x);
    rate_per_s = duration_s > 0.0 ? 6.0 * x * (1.0 - x) / duration_s : 0.0;
  }
  tool_axis = slerp_axis(motion.begin, motion.end, fraction);
  angular_velocity_rad_s = rate_per_s * slerp_rate(motion.begin, motion.end);
  roll_rad = motion.roll_begin + fraction * (motion.roll_end - motion.roll_begin);
}

double evaluate_flow_fraction(const TrajectoryPiece& piece, double tau) {
  if (!piece.depositing) return 0.0;
  if (piece.flow_lead_s >= 0.0) {
    Vec3 p, v, a;
    evaluate_motion(piece, tau, p, v, a);
    return evaluate_flow_fraction(piece, tau, v, a);
  }
  const auto* sampled = std::get_if<SampledMotion>(&piece.motion);
  if (sampled == nullptr || sampled->flow_fraction.empty()) return piece.flow_fraction;
  const std::vector<double>& flow = sampled->flow_fraction;
  size_t k = 0;
  double fraction = 0.0;
  if (!sample_interval(*sampled, flow.size(), tau, k, fraction)) return flow.back();
  return flow[k] + fraction * (flow[k + 1] - flow[k]);
}

double evaluate_flow_fraction(const TrajectoryPiece& piece, double tau, const Vec3& velocity_mm_s,
                              const Vec3& acceleration_mm_s2) {
  if (!piece.depositing) return 0.0;
  if (piece.flow_lead_s < 0.0) return evaluate_flow_fraction(piece, tau);
  // pressure advance: the speed and its rate of change along the motion, d|v|/dt = v.a / |v|
  const double speed = velocity_mm_s.norm();
  const double speed_rate = speed > 0.0 ? velocity_mm_s.dot(acceleration_mm_s2) / speed : 0.0;
  if (!(piece.desired_speed_mm_s > 0.0)) return 0.0;
  const double fraction = (speed + piece.flow_lead_s * speed_rate) / piece.desired_speed_mm_s;
  return piece.flow_may_retract ? fraction : std::max(0.0, fraction);
}

namespace {

// what a sample says besides the motion: time, piece, path, deposition, desired speed
void describe_piece(const TrajectoryPiece& piece, int index, double t, TrajectorySample& sample) {
  sample.t_s = t;
  sample.piece_index = index;
  sample.path_index = piece.path_index;
  sample.depositing = piece.depositing;
  sample.desired_speed_mm_s = piece.desired_speed_mm_s;
}

}  // namespace

TrajectorySample Trajectory::at(double t) const {
  TrajectorySample sample;
  if (pieces_.empty()) return sample;
  t = std::clamp(t, 0.0, duration_s());
  const int index = piece_at(t);
  const TrajectoryPiece& piece = pieces_[index];
  describe_piece(piece, index, t, sample);
  evaluate_motion(piece, t - piece.t_begin_s, sample.position_mm, sample.velocity_mm_s,
                  sample.acceleration_mm_s2);
  evaluate_tool_axis(piece, t - piece.t_begin_s, sample.position_mm, sample.velocity_mm_s,
                     sample.tool_axis, sample.angular_velocity_rad_s, sample.roll_rad);
  sample.flow_fraction = evaluate_flow_fraction(piece, t - piece.t_begin_s, sample.velocity_mm_s,
                                                sample.acceleration_mm_s2);
  return sample;
}

TrajectorySample TrajectoryCursor::at(double t) {
  const std::vector<TrajectoryPiece>& pieces = trajectory_->pieces();
  TrajectorySample sample;
  if (pieces.empty()) return sample;
  t = std::clamp(t, 0.0, trajectory_->duration_s());
  // the last piece starting at or before t (Trajectory::piece_at), found forwards from the
  // previous one
  const int count = static_cast<int>(pieces.size());
  const int previous_piece = piece_;
  if (t < pieces[piece_].t_begin_s) piece_ = trajectory_->piece_at(t);
  while (piece_ + 1 < count && !(t < pieces[piece_ + 1].t_begin_s)) ++piece_;
  if (piece_ != previous_piece) phase_.fill(0);
  const TrajectoryPiece& piece = pieces[piece_];
  describe_piece(piece, piece_, t, sample);
  const double tau = t - piece.t_begin_s;
  const auto* phases = std::get_if<PhaseMotion>(&piece.motion);
  if (phases == nullptr) {
    evaluate_motion(piece, tau, sample.position_mm, sample.velocity_mm_s,
                    sample.acceleration_mm_s2);
  } else {
    // per axis, the phase searched forwards from the previous sample's
    for (int axis = 0; axis < 3; ++axis) {
      const AxisState state = phases->axes[axis].at(tau, phase_[axis]);
      sample.position_mm[axis] = state.q;
      sample.velocity_mm_s[axis] = state.v;
      sample.acceleration_mm_s2[axis] = state.a;
    }
  }
  evaluate_tool_axis(piece, tau, sample.position_mm, sample.velocity_mm_s, sample.tool_axis,
                     sample.angular_velocity_rad_s, sample.roll_rad);
  sample.flow_fraction =
      evaluate_flow_fraction(piece, tau, sample.velocity_mm_s, sample.acceleration_mm_s2);
  return sample;
}

double Trajectory::depositing_time_s() const {
  double total = 0.0;
  for (const TrajectoryPiece& piece : pieces_)
    if (piece.depositing) total += piece.t_end_s - piece.t_begin_s;
  return total;
}

double Trajectory::transition_time_s() const {
  return duration_s() - depositing_time_s();
}

}  // namespace depotwin
