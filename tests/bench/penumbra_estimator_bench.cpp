// The back-projection estimator's cost per (light, texel) evaluation
// (methods/backprojection/penumbra_estimator.cpp) against the number of blocker polygons in the
// shaft and the rows across the light. Run:
//   build/shadowbake_bench --benchmark_filter=PenumbraEstimator
#include <benchmark/benchmark.h>

#include <array>
#include <random>
#include <vector>

#include "methods/backprojection/penumbra_estimator.h"

namespace sb {
namespace {

void BM_PenumbraEstimator(benchmark::State& state) {
  const int polygons = int(state.range(0)), rows = int(state.range(1));
  LightDesc d;
  d.name = "panel";
  d.position = Vec3(0, 0, 2);
  d.normal = Vec3(0, 0, -1);
  d.width = 1.2;
  d.height = 0.6;
  d.power = 100;
  const Light light(d);
  const PenumbraEstimator estimator(light, rows, 1e-4);
  // 64 texels on the floor, each with `polygons` small triangles across its line to the light
  // (pieces of a mesh between it and the light).
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  struct Case {
    Vec3 y;
    std::vector<std::array<Vec3, 3>> triangles;
    std::vector<BlockerPolygon> polys;
  };
  std::vector<Case> cases(64);
  for (Case& c : cases) {
    c.y = Vec3(u(rng) - 0.5, u(rng) - 0.5, 0);
    for (int k = 0; k < polygons; ++k) {
      const double along = 0.3 + 0.4 * u(rng);
      const Vec3 centre = c.y + along * (light.centre() - c.y) +
                          Vec3(0.4 * (u(rng) - 0.5), 0.4 * (u(rng) - 0.5), 0);
      std::array<Vec3, 3> t;
      const double size = 0.6 / std::sqrt(double(polygons));
      for (Vec3& v : t) v = centre + size * Vec3(u(rng) - 0.5, u(rng) - 0.5, 0);
      c.triangles.push_back(t);
    }
    for (std::size_t k = 0; k < c.triangles.size(); ++k)
      c.polys.push_back({c.triangles[k].data(), 3, Vec3::UnitZ(), std::uint32_t(k)});
  }
  double sum = 0;
  for (auto _ : state)
    for (const Case& c : cases)
      sum += estimator.visibility(c.y, Vec3::UnitZ(), c.y, c.polys).visibility;
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(cases.size()));
}
BENCHMARK(BM_PenumbraEstimator)
    ->ArgsProduct({{1, 4, 16, 64, 256}, {16, 32, 64}})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace sb
