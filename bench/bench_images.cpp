// The share of a run's wall time spent on images (issue: "plots and renders must not
// dominate a run"; target: under half of `depotwin run thompson_fig7`).
//
//   BM_RunImageShare   the depotwin binary on scenarios/thompson_fig7.yaml (two planners),
//                      once with images and once with --no-render per iteration, alternately
//                      so that both see the same machine state; counters are the medians
//                      (s) and image_share = 1 - without / with
#include <benchmark/benchmark.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

extern char** environ;

namespace {

namespace fs = std::filesystem;

// wall seconds of the CLI with these arguments (output to /dev/null); aborts the benchmark
// when it does not exit 0
double run_cli(benchmark::State& state, std::vector<std::string> arguments) {
  arguments.insert(arguments.begin(), DEPOTWIN_CLI);
  std::vector<char*> argv;
  for (std::string& argument : arguments) argv.push_back(argument.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  const auto start = std::chrono::steady_clock::now();
  pid_t child = 0;
  const int spawn_error =
      posix_spawn(&child, DEPOTWIN_CLI, &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  int status = 0;
  if (spawn_error != 0 || waitpid(child, &status, 0) < 0 || !WIFEXITED(status) ||
      WEXITSTATUS(status) != 0) {
    state.SkipWithError("depotwin run failed");
    return 0.0;
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values.empty() ? 0.0 : values[values.size() / 2];
}

void BM_RunImageShare(benchmark::State& state) {
  const std::string scenario = std::string(DEPOTWIN_SCENARIOS_DIR) + "/thompson_fig7.yaml";
  const fs::path out =
      fs::temp_directory_path() / ("depotwin_bench_images_" + std::to_string(::getpid()));
  std::vector<double> with_images, without_images;
  for (auto _ : state) {
    with_images.push_back(run_cli(state, {"run", scenario, "--out", out.string(), "--quiet"}));
    without_images.push_back(
        run_cli(state, {"run", scenario, "--out", out.string(), "--quiet", "--no-render"}));
  }
  std::error_code ignored;
  fs::remove_all(out, ignored);
  const double with_s = median(with_images), without_s = median(without_images);
  state.counters["with_images_s"] = with_s;
  state.counters["without_images_s"] = without_s;
  state.counters["image_share"] = with_s > 0.0 ? 1.0 - without_s / with_s : 0.0;
}
BENCHMARK(BM_RunImageShare)->Unit(benchmark::kMillisecond)->Iterations(21)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
