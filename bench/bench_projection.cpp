// Projection onto a part (surface_projection.hpp): 10^6 grid points straight down onto a
// 10^5-triangle surface (target: <= 1 s on one core), by packets of 16 rays and by single
// rays, against two baselines measured in the same run: building the projector (Embree BVH
// and corner normals) and the trivial loop (the analytic height at every point, no search).
// Also one whole hatch (Algorithm 1) of the car bonnet.
#include <benchmark/benchmark.h>

#include <vector>

#include "toolpath/analytic_surfaces.hpp"
#include "toolpath/hatching.hpp"
#include "toolpath/surface_projection.hpp"

namespace {

using depotwin::SurfaceProjector;
using depotwin::Vec2;

constexpr int kGrid = 1000;  // 10^6 points

// a sphere cap, surface only, 224 x 224 cells: 100 352 triangles
depotwin::SphereCapParams cap_params() {
  depotwin::SphereCapParams p;
  p.mesh.solid = false;
  p.mesh.cell_mm = 40.0 / 224.0;
  return p;
}

const depotwin::TriangleMesh& cap_mesh() {
  static const depotwin::TriangleMesh mesh = depotwin::sphere_cap(cap_params());
  return mesh;
}

const std::vector<Vec2>& grid() {
  static const std::vector<Vec2> points = [] {
    std::vector<Vec2> xy;
    xy.reserve(kGrid * kGrid);
    const double step = 40.0 / kGrid;
    for (int j = 0; j < kGrid; ++j)
      for (int i = 0; i < kGrid; ++i)
        xy.emplace_back(-20.0 + (i + 0.5) * step, -20.0 + (j + 0.5) * step);
    return xy;
  }();
  return points;
}

void per_point(benchmark::State& state, std::size_t points) {
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * points));
}

// baseline: the projector's construction (BVH build, corner normals) for the same mesh
void BM_BuildProjector(benchmark::State& state) {
  const depotwin::TriangleMesh& mesh = cap_mesh();
  for (auto _ : state) {
    SurfaceProjector projector(mesh);
    benchmark::DoNotOptimize(&projector);
  }
  state.counters["triangles"] = static_cast<double>(mesh.triangle_count());
}
BENCHMARK(BM_BuildProjector)->Unit(benchmark::kMillisecond);

// baseline: the trivial loop, the analytic height at every grid point
void BM_AnalyticHeightLoop(benchmark::State& state) {
  const depotwin::HeightField field = depotwin::sphere_cap_field(cap_params());
  const std::vector<Vec2>& xy = grid();
  for (auto _ : state) {
    double sum = 0.0;
    for (const Vec2& p : xy) sum += field.z(p.x(), p.y());
    benchmark::DoNotOptimize(sum);
  }
  per_point(state, xy.size());
}
BENCHMARK(BM_AnalyticHeightLoop)->Unit(benchmark::kMillisecond);

// 10^6 points by packets of 16 (the batch call), exact double hits and smooth normals
void BM_ProjectBatch(benchmark::State& state) {
  const SurfaceProjector projector(cap_mesh());
  const std::vector<Vec2>& xy = grid();
  std::vector<std::optional<depotwin::SurfaceHit>> hits;
  for (auto _ : state) {
    projector.project_down(xy, hits);
    benchmark::DoNotOptimize(hits.data());
  }
  per_point(state, xy.size());
}
BENCHMARK(BM_ProjectBatch)->Unit(benchmark::kMillisecond);

// the same points one ray at a time (rtcIntersect1)
void BM_ProjectSingle(benchmark::State& state) {
  const SurfaceProjector projector(cap_mesh());
  const std::vector<Vec2>& xy = grid();
  for (auto _ : state) {
    int found = 0;
    for (const Vec2& p : xy) found += projector.project_down(p.x(), p.y()).has_value();
    benchmark::DoNotOptimize(found);
  }
  per_point(state, xy.size());
}
BENCHMARK(BM_ProjectSingle)->Unit(benchmark::kMillisecond);

// Algorithm 1 on the car bonnet (27 716 triangles): 0.5 mm, 0/90 deg, two layers
void BM_HatchBonnet(benchmark::State& state) {
  const SurfaceProjector projector(depotwin::car_bonnet(depotwin::CarBonnetParams{}));
  depotwin::SurfaceHatchSpec spec;
  spec.layers = 2;
  std::size_t points = 0;
  for (auto _ : state) {
    const depotwin::SurfaceHatch hatch = depotwin::hatch_surface(projector, spec);
    points = 0;
    for (const depotwin::PrintPath& path : hatch.toolpath.paths) points += path.points.size();
    benchmark::DoNotOptimize(points);
  }
  state.counters["points"] = static_cast<double>(points);
  per_point(state, points);
}
BENCHMARK(BM_HatchBonnet)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
