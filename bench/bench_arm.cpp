// What the arm's kinematics cost (kinematics/arm6): closed-form inverse kinematics against its
// forward kinematics in the same run, over 4096 seeded random reachable poses.
//   BM_Arm6Forward            forward(q): TCP position, tool axis and roll (the baseline)
//   BM_Arm6AllBranches        branch_solutions(pose): the tool transform and all eight branches
//                             (no allocation); counters: full solves/s and branch solutions/s
//   BM_Arm6Solutions          solutions(pose): every solution within the ranges (turns of j6)
//   BM_Arm6InverseNear        inverse_near(pose, seed): the path-following call of the simulation
//   BM_Arm6IkOverFk           all-branch IK and FK timed alternately (process CPU time, so that
//                             other load on the machine does not count): their ratio
//   BM_Arm6CartesianLimits    cartesian_limits over a 10 mm box and over the whole part's box
#include <benchmark/benchmark.h>

#include <ctime>
#include <random>
#include <vector>

#include "kinematics/arm6.hpp"

namespace depotwin {
namespace {

constexpr size_t kPoses = 4096;  // a power of two: index by mask

struct Samples {
  std::vector<Arm6Joints> joints;
  std::vector<Pose> poses;
};

// random joints within the ranges whose poses the configured branch reaches
const Samples& samples() {
  static const Samples cached = [] {
    const Arm6 arm;
    Samples s;
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    JointVector check;
    while (s.joints.size() < kPoses) {
      Arm6Joints q;
      for (int j = 0; j < 6; ++j) {
        const JointLimit& limit = arm.joint_limits()[j];
        q[j] = limit.min + (limit.max - limit.min) * unit(rng);
      }
      const Pose pose = arm.forward(q);
      if (!arm.inverse(pose, check)) continue;
      s.joints.push_back(q);
      s.poses.push_back(pose);
    }
    return s;
  }();
  return cached;
}

void BM_Arm6Forward(benchmark::State& state) {
  const Arm6 arm;
  const Samples& s = samples();
  size_t i = 0;
  for (auto _ : state) {
    Pose pose = arm.forward(s.joints[i++ & (kPoses - 1)]);
    benchmark::DoNotOptimize(pose);
  }
  state.counters["fk_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Arm6Forward);

void BM_Arm6AllBranches(benchmark::State& state) {
  const Arm6 arm;
  const Samples& s = samples();
  Arm6Branches branches;
  size_t i = 0;
  for (auto _ : state) {
    const bool solved = arm.branch_solutions(s.poses[i++ & (kPoses - 1)], branches);
    benchmark::DoNotOptimize(solved);
    benchmark::DoNotOptimize(branches);
  }
  const double solves = static_cast<double>(state.iterations());
  state.counters["full_ik_per_s"] = benchmark::Counter(solves, benchmark::Counter::kIsRate);
  state.counters["branch_solutions_per_s"] =
      benchmark::Counter(8.0 * solves, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Arm6AllBranches);

void BM_Arm6Solutions(benchmark::State& state) {
  const Arm6 arm;
  const Samples& s = samples();
  Arm6Solutions solutions;
  size_t i = 0;
  long found = 0;
  for (auto _ : state) {
    found += arm.solutions(s.poses[i++ & (kPoses - 1)], solutions);
    benchmark::DoNotOptimize(solutions);
  }
  state.counters["solutions_in_range_per_pose"] =
      static_cast<double>(found) / static_cast<double>(state.iterations());
  state.counters["poses_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Arm6Solutions);

void BM_Arm6InverseNear(benchmark::State& state) {
  const Arm6 arm;
  const Samples& s = samples();
  std::vector<JointVector> seeds;
  for (const Arm6Joints& q : s.joints) seeds.emplace_back(q.begin(), q.end());
  JointVector joints(6);
  size_t i = 0;
  for (auto _ : state) {
    const size_t k = i++ & (kPoses - 1);
    const bool solved = arm.inverse_near(s.poses[k], seeds[k], joints);
    benchmark::DoNotOptimize(solved);
    benchmark::DoNotOptimize(joints.data());
  }
  state.counters["per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Arm6InverseNear);

// the all-branch inverse against the forward kinematics, alternately over the same poses
void BM_Arm6IkOverFk(benchmark::State& state) {
  const Arm6 arm;
  const Samples& s = samples();
  Arm6Branches branches;
  double ik_s = 0.0, fk_s = 0.0;
  long rounds = 0;
  const auto cpu_s = [] { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; };
  for (auto _ : state) {
    double start = cpu_s();
    for (const Pose& pose : s.poses) {
      const bool solved = arm.branch_solutions(pose, branches);
      benchmark::DoNotOptimize(solved);
      benchmark::DoNotOptimize(branches);
    }
    ik_s += cpu_s() - start;
    start = cpu_s();
    for (const Arm6Joints& q : s.joints) {
      Pose pose = arm.forward(q);
      benchmark::DoNotOptimize(pose);
    }
    fk_s += cpu_s() - start;
    ++rounds;
  }
  const double count = static_cast<double>(rounds) * static_cast<double>(kPoses);
  state.counters["full_ik_per_s"] = count / ik_s;
  state.counters["fk_per_s"] = count / fk_s;
  state.counters["ik_over_fk"] = ik_s / fk_s;
}
BENCHMARK(BM_Arm6IkOverFk)->Unit(benchmark::kMillisecond);

void BM_Arm6CartesianLimits(benchmark::State& state) {
  const Arm6 arm;
  const MachineLimits requested = MachineLimits::uniform(1e4, 1e6);
  const Vec3 lo = state.range(0) == 0 ? Vec3(-5, -5, 0) : Vec3(-75, -65, 0);
  const Vec3 hi = state.range(0) == 0 ? Vec3(5, 5, 10) : Vec3(75, 65, 40);
  for (auto _ : state) {
    MachineLimits limits = arm.cartesian_limits(requested, lo, hi);
    benchmark::DoNotOptimize(limits);
  }
  state.counters["per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Arm6CartesianLimits)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace depotwin

BENCHMARK_MAIN();
