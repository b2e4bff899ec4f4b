// Speed of the G-code importer: parsing a generated 10^6-line slicer-style file (target at
// least 2 M lines/s) and `inspect` on it from the file (target at most 1 s).
#include <benchmark/benchmark.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "cli/inspect.hpp"
#include "toolpath/gcode.hpp"

using namespace depotwin;

namespace {

constexpr int kLines = 1000000;

// A slicer-like file: per layer a Z change, a travel, a retract/prime, then print moves
// zig-zagging over 50 mm with relative E, a comment every 100 lines, an arc every 50.
const std::string& generated_text() {
  static const std::string text = [] {
    std::string out;
    out.reserve(static_cast<size_t>(kLines) * 32);
    out += "; generated for bench_gcode\nG21\nG90\nM83\n";
    int lines = 4;
    int layer = 0;
    char buffer[96];
    while (lines < kLines) {
      ++layer;
      std::snprintf(buffer, sizeof buffer, ";LAYER:%d\nG1 Z%.3f F600\nG0 X10 Y10 F6000\nG1 E.8\n",
                    layer, 0.2 * layer);
      out += buffer;
      lines += 4;
      double x = 10.0, y = 10.0;
      for (int i = 0; i < 2000 && lines < kLines; ++i, ++lines) {
        if (i % 100 == 99) {
          out += "; a comment line\n";
          continue;
        }
        if (i % 50 == 49) {
          // a half circle of radius 0.2 to the next row
          y += 0.4;
          std::snprintf(buffer, sizeof buffer, "G2 X%.3f Y%.3f I0 J0.2 E0.0300\n", x, y);
        } else {
          x = (i % 2 == 0) ? 60.0 - (x - 10.0) : x;
          y += 0.01;
          std::snprintf(buffer, sizeof buffer, "G1 X%.3f Y%.3f E%.5f F1800\n", x, y, 1.6625);
        }
        out += buffer;
      }
      out += "G1 E-.8\n";
      ++lines;
    }
    return out;
  }();
  return text;
}

void BM_ParseGcode(benchmark::State& state) {
  const std::string& text = generated_text();
  for (auto _ : state) {
    GcodeProgram program = parse_gcode_program(text, "bench.gcode", GcodeOptions{});
    benchmark::DoNotOptimize(program);
  }
  state.counters["lines_per_s"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * kLines, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ParseGcode)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_InspectGcodeFile(benchmark::State& state) {
  // inspect as the verb does it: read the file, parse, facts, JSON
  const std::string path =
      (std::filesystem::temp_directory_path() / "depotwin_bench_gcode.gcode").string();
  {
    std::ofstream out(path, std::ios::binary);
    out << generated_text();
  }
  for (auto _ : state) {
    const GcodeProgram program = read_gcode_program(path, GcodeOptions{});
    nlohmann::json json = gcode_facts_json(gcode_facts(program, PrintRule::automatic));
    benchmark::DoNotOptimize(json);
  }
  state.counters["lines_per_s"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * kLines, benchmark::Counter::kIsRate);
  std::filesystem::remove(path);
}
BENCHMARK(BM_InspectGcodeFile)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
