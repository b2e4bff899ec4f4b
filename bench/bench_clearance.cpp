// Clearance queries between a tool and a non-convex part of ~10^5 triangles
// (collision/part_clearance.hpp), as the arm's planner asks them (~10^5 per plan).
//   BM_BuildTree          the part's tree, once per part (the baseline for "how many queries
//                         pay for a build")
//   BM_SphereQuery        one sphere at the nozzle tip (the cheapest query: the baseline)
//   BM_ToolQuery          the tool: a capsule (nozzle body) and a box (head) on one link frame
//   BM_ToolQueryStopBelow the same with stop_below_mm = 2 ("closer than 2 mm?")
//   BM_ToolAlongPath      the tool at consecutive poses 0.2 mm apart (the planner's case: the
//                         tree's nodes stay in cache, where random poses fetch them from L3)
//   BM_ArmQuery           the tool and six link capsules above the part
//   BM_FclDistanceTool    the tool by plain fcl::distance(mesh, shape) per shape, for reference
//   BM_Ratios             all of the above on the same poses in one run, as ratios, with the
//                         largest difference between ours and fcl::distance (mm)
// Poses: the nozzle tip 0.5..8 mm off a random facet along its normal, the tool axis tilted up
// to 30 degrees from it, precomputed.
#include <benchmark/benchmark.h>

#include <fcl/fcl.h>

#include <cmath>
#include <random>
#include <vector>

#include "bench_clock.hpp"
#include "collision/part_clearance.hpp"

using namespace depotwin;

namespace {

using Type = CollisionShape::Type;

// a bumpy torus (closed, non-convex): major radius 80, minor 30 +- 3, 317 x 158 quads
TriangleMesh bumpy_torus() {
  const int nu = 317, nv = 158;
  TriangleMesh m;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = 2 * kPi * i / nu, v = 2 * kPi * j / nv;
      const double rho = 30 + 3 * std::sin(5 * u) * std::sin(7 * v);
      m.vertices.emplace_back((80 + rho * std::cos(v)) * std::cos(u),
                              (80 + rho * std::cos(v)) * std::sin(u), rho * std::sin(v));
    }
  auto id = [&](int i, int j) { return (i % nu) * nv + (j % nv); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

const TriangleMesh& part_mesh() {
  static const TriangleMesh mesh = bumpy_torus();
  return mesh;
}

const PartClearance& part() {
  static const PartClearance clearance(part_mesh());
  return clearance;
}

CollisionShape shape(Type type, Vec3 size, int link, Vec3 at) {
  CollisionShape s;
  s.type = type;
  s.size_mm = size;
  s.link = link;
  s.in_link.translation() = at;
  return s;
}

// link 0 is the tool frame at the nozzle tip, z along the tool axis
const std::vector<CollisionShape> kTool{shape(Type::capsule, Vec3(4, 15, 0), 0, Vec3(0, 0, 19)),
                                        shape(Type::box, Vec3(12, 10, 8), 0, Vec3(0, 0, 46))};

std::vector<CollisionShape> arm() {
  std::vector<CollisionShape> shapes = kTool;
  for (int k = 1; k <= 6; ++k)
    shapes.push_back(shape(Type::capsule, Vec3(25, 60, 0), k, Vec3::Zero()));
  return shapes;
}

struct Poses {
  std::vector<Eigen::Isometry3d> tool;                // the tool frame
  std::vector<std::vector<Eigen::Isometry3d>> links;  // tool frame + six links high above
};

const Poses& poses() {
  static const Poses p = [] {
    const TriangleMesh& m = part_mesh();
    std::mt19937 rng(11);
    std::uniform_int_distribution<size_t> facet(0, m.triangle_count() - 1);
    std::uniform_real_distribution<double> gap(0.5, 8), tilt(0, deg_to_rad(30)), turn(0, 2 * kPi),
        unit(-1, 1);
    Poses out;
    for (int i = 0; i < 1024; ++i) {
      const size_t t = facet(rng);
      const auto& tri = m.triangles[t];
      const Vec3 centre = (m.vertices[tri[0]] + m.vertices[tri[1]] + m.vertices[tri[2]]) / 3;
      const Vec3 n = m.facet_normal(t);
      const Vec3 side = n.unitOrthogonal();
      const Vec3 axis = Eigen::AngleAxisd(tilt(rng), Eigen::AngleAxisd(turn(rng), n) * side) * n;
      Eigen::Isometry3d tool = Eigen::Isometry3d::Identity();
      tool.linear() = Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), axis).toRotationMatrix();
      tool.translation() = centre + gap(rng) * n;
      out.tool.push_back(tool);
      std::vector<Eigen::Isometry3d> frames{tool};
      for (int k = 1; k <= 6; ++k) {
        Eigen::Isometry3d link = Eigen::Isometry3d::Identity();
        link.linear() =
            Eigen::AngleAxisd(kPi * unit(rng), Vec3(unit(rng), unit(rng), 1).normalized())
                .toRotationMatrix();
        link.translation() = Vec3(60 * unit(rng), 60 * unit(rng), 150 + 60 * k);
        frames.push_back(link);
      }
      out.links.push_back(frames);
    }
    return out;
  }();
  return p;
}

// the tool along a path: a helix around the tube, 0.2 mm per step, the tip 8 mm off the
// unbumped tube (2..11 mm off the bumps), the axis tilted 20 degrees: consecutive queries near
// each other, as a planner asks along a move
const std::vector<Eigen::Isometry3d>& path_poses() {
  static const std::vector<Eigen::Isometry3d> p = [] {
    std::vector<Eigen::Isometry3d> out;
    double u = 0, v = 0;
    for (int i = 0; i < 4096; ++i) {
      const Vec3 centre(80 * std::cos(u), 80 * std::sin(u), 0);
      const Vec3 n(std::cos(v) * std::cos(u), std::cos(v) * std::sin(u), std::sin(v));
      const Vec3 along = n.unitOrthogonal();
      Eigen::Isometry3d tool = Eigen::Isometry3d::Identity();
      tool.linear() = Eigen::Quaterniond::FromTwoVectors(
                          Vec3::UnitZ(), Eigen::AngleAxisd(deg_to_rad(20), along) * n)
                          .toRotationMatrix();
      tool.translation() = centre + (30 + 8) * n;
      out.push_back(tool);
      // 0.2 mm per step on the tip's circle (radius 38 around the tube), advancing around the
      // ring 1/50 as fast
      v += 0.2 / 38;
      u += 0.2 / 38 / 50;
    }
    return out;
  }();
  return p;
}

// the same part as a plain FCL model, for fcl::distance
struct FclPart {
  std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> model =
      std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
  FclPart() {
    const TriangleMesh& m = part_mesh();
    std::vector<fcl::Vector3d> v(m.vertices.begin(), m.vertices.end());
    std::vector<fcl::Triangle> t;
    for (const auto& tri : m.triangles) t.emplace_back(tri[0], tri[1], tri[2]);
    model->beginModel();
    model->addSubModel(v, t);
    model->endModel();
  }
};

const FclPart& fcl_part() {
  static const FclPart p;
  return p;
}

double fcl_tool_distance(const Eigen::Isometry3d& tool) {
  static const fcl::Capsuled capsule(kTool[0].size_mm.x(), 2 * kTool[0].size_mm.y());
  static const fcl::Boxd box(2 * kTool[1].size_mm);
  const fcl::DistanceRequestd request(true);
  double best = std::numeric_limits<double>::infinity();
  const fcl::CollisionGeometryd* shapes[2] = {&capsule, &box};
  for (int k = 0; k < 2; ++k) {
    fcl::DistanceResultd result;
    fcl::distance(fcl_part().model.get(), fcl::Transform3d::Identity(), shapes[k],
                  tool * kTool[k].in_link, request, result);
    best = std::min(best, result.min_distance);
  }
  return best;
}

void rate(benchmark::State& state) {
  state.counters["queries_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

void BM_BuildTree(benchmark::State& state) {
  const TriangleMesh& m = part_mesh();
  for (auto _ : state) {
    PartClearance p(m);
    benchmark::DoNotOptimize(p);
  }
  state.counters["triangles"] = static_cast<double>(m.triangle_count());
}
BENCHMARK(BM_BuildTree)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_SphereQuery(benchmark::State& state) {
  const auto& p = poses();
  const CollisionShape tip = shape(Type::sphere, Vec3(4, 0, 0), 0, Vec3(0, 0, 4));
  size_t i = 0;
  for (auto _ : state) {
    const auto& tool = p.tool[i++ & 1023];
    benchmark::DoNotOptimize(part().distance(tip, tool * tip.in_link));
  }
  rate(state);
}
BENCHMARK(BM_SphereQuery)->Unit(benchmark::kMicrosecond);

void BM_ToolQuery(benchmark::State& state) {
  const auto& p = poses();
  size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(part().clearance(kTool, {p.tool[i++ & 1023]}));
  rate(state);
}
BENCHMARK(BM_ToolQuery)->Unit(benchmark::kMicrosecond);

void BM_ToolAlongPath(benchmark::State& state) {
  const auto& p = path_poses();
  size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(part().clearance(kTool, {p[i++ & 4095]}));
  rate(state);
}
BENCHMARK(BM_ToolAlongPath)->Unit(benchmark::kMicrosecond);

void BM_ToolQueryStopBelow(benchmark::State& state) {
  const auto& p = poses();
  size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(part().clearance(kTool, {p.tool[i++ & 1023]}, 2.0));
  rate(state);
}
BENCHMARK(BM_ToolQueryStopBelow)->Unit(benchmark::kMicrosecond);

void BM_ArmQuery(benchmark::State& state) {
  const auto& p = poses();
  const auto shapes = arm();
  size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(part().clearance(shapes, p.links[i++ & 1023]));
  rate(state);
}
BENCHMARK(BM_ArmQuery)->Unit(benchmark::kMicrosecond);

void BM_FclDistanceTool(benchmark::State& state) {
  const auto& p = poses();
  size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(fcl_tool_distance(p.tool[i++ & 1023]));
  rate(state);
}
BENCHMARK(BM_FclDistanceTool)->Unit(benchmark::kMicrosecond);

// CPU time of this thread: the machine is shared, wall time counts other processes
using bench::thread_cpu_s;

// CPU seconds per call of f over every pose
template <typename F>
double per_pose_s(F&& f) {
  const size_t n = poses().tool.size();
  const double start = thread_cpu_s();
  for (size_t i = 0; i < n; ++i) f(i);
  return (thread_cpu_s() - start) / static_cast<double>(n);
}

void BM_Ratios(benchmark::State& state) {
  const auto& p = poses();
  const auto shapes = arm();
  const CollisionShape tip = shape(Type::sphere, Vec3(4, 0, 0), 0, Vec3(0, 0, 4));
  double sphere = 0, tool = 0, stop = 0, whole_arm = 0, fcl_tool = 0, build = 0, along = 0;
  double worst = 0;
  int contacts = 0;
  for (auto _ : state) {
    build += per_pose_s([&](size_t i) {
               if (i == 0) benchmark::DoNotOptimize(PartClearance(part_mesh()));
             }) *
             static_cast<double>(p.tool.size());
    sphere += per_pose_s(
        [&](size_t i) { benchmark::DoNotOptimize(part().distance(tip, p.tool[i] * tip.in_link)); });
    tool += per_pose_s(
        [&](size_t i) { benchmark::DoNotOptimize(part().clearance(kTool, {p.tool[i]})); });
    stop += per_pose_s(
        [&](size_t i) { benchmark::DoNotOptimize(part().clearance(kTool, {p.tool[i]}, 2.0)); });
    whole_arm += per_pose_s(
        [&](size_t i) { benchmark::DoNotOptimize(part().clearance(shapes, p.links[i])); });
    fcl_tool +=
        per_pose_s([&](size_t i) { benchmark::DoNotOptimize(fcl_tool_distance(p.tool[i])); });
    along += per_pose_s(
        [&](size_t i) { benchmark::DoNotOptimize(part().clearance(kTool, {path_poses()[i]})); });
  }
  for (size_t i = 0; i < p.tool.size(); ++i) {
    const double ours = part().clearance(kTool, {p.tool[i]}).distance_mm;
    const double theirs = fcl_tool_distance(p.tool[i]);
    if (ours <= 0) {
      ++contacts;  // fcl::distance says -1 in contact: no depth to compare
      continue;
    }
    worst = std::max(worst, std::abs(ours - theirs));
  }
  state.counters["tool_us"] = tool / state.iterations() * 1e6;
  state.counters["tool_over_sphere"] = tool / sphere;
  state.counters["stop2_over_tool"] = stop / tool;
  state.counters["path_over_tool"] = along / tool;
  state.counters["arm_over_tool"] = whole_arm / tool;
  state.counters["tool_over_fcl_distance"] = tool / fcl_tool;
  state.counters["build_over_tool_query"] = build / tool;
  state.counters["max_diff_vs_fcl_mm"] = worst;
  state.counters["contact_poses"] = contacts;
}
BENCHMARK(BM_Ratios)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
