// Fuzz target: the scenario loader (scenario/scenario.hpp, yaml-cpp underneath) on arbitrary
// text. The loader reads a file, so each input is written to scenario.yaml in a private
// temporary directory that also holds the files a scenario may name: part.stl (a small dome,
// for `surface:`), path.gcode (arcs, for `gcode:`) and model.xml (the XY stage's MJCF, for
// `machine: {model: ...}`), copied from tests/fuzz/fixtures/. Bad
// input must be an InputError; a scenario loaded must hold finite paths at positive speeds,
// usable limits and at least one planner.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.hpp"
#include "fuzz/fuzz_check.hpp"
#include "scenario/scenario.hpp"

namespace {

namespace fs = std::filesystem;
using depotwin::fuzz::is_finite;
using depotwin::fuzz::require;

fs::path work_dir;

void remove_work_dir() {
  std::error_code error;
  if (!work_dir.empty()) fs::remove_all(work_dir, error);
}

void check_scenario(const depotwin::Scenario& scenario) {
  require(!scenario.planners.empty(), "a planner to run");
  require(scenario.limits.validate().empty(), "usable limits");
  require(scenario.toolpath.start_mm.allFinite() && scenario.toolpath.end_mm.allFinite(),
          "finite start and end");
  require(!scenario.toolpath.paths.empty(), "print paths");
  for (const depotwin::PrintPath& path : scenario.toolpath.paths) {
    require(path.points.size() >= 2, "two points a path at least");
    require(is_finite(path.speed_mm_s) && path.speed_mm_s > 0.0, "a finite positive speed");
    for (const depotwin::Vec3& point : path.points) require(point.allFinite(), "finite points");
    for (const depotwin::Vec3& normal : path.normals) require(normal.allFinite(), "finite normals");
  }
  const depotwin::SimSpec& sim = scenario.sim;
  require(is_finite(sim.timestep_s) && sim.timestep_s > 0.0 && is_finite(sim.control_period_s) &&
              sim.control_period_s > 0.0,
          "a finite positive timestep and control period");
  require(is_finite(sim.cell_mm) && is_finite(sim.kp_scale) && is_finite(sim.settle_s),
          "finite sim");
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  // a private directory with the fixtures beside the scenario file, in memory when /dev/shm is
  // there (rewriting a file on ext4 flushes it to disk: most of the time per input)
  std::error_code error;
  const fs::path base = fs::is_directory("/dev/shm", error) && ::access("/dev/shm", W_OK) == 0
                            ? fs::path("/dev/shm")
                            : fs::temp_directory_path();
  std::string pattern = (base / "depotwin-fuzz-scenario-XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr) {
    std::perror("fuzz_scenario: mkdtemp");
    std::abort();
  }
  work_dir = pattern;
  std::atexit(remove_work_dir);
  for (const char* name : {"part.stl", "path.gcode", "model.xml"})
    fs::copy_file(fs::path(DEPOTWIN_FUZZ_FIXTURES_DIR) / name, work_dir / name);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const fs::path file = work_dir / "scenario.yaml";
  {
    std::error_code error;
    fs::remove(file, error);  // a new file rather than a truncated one (no flush on ext4)
    std::ofstream out(file, std::ios::binary);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    require(static_cast<bool>(out), "the input written to scenario.yaml");
  }
  try {
    check_scenario(depotwin::load_scenario(file.string()));
  } catch (const depotwin::InputError& error) {
    require(!error.problems().empty(), "an InputError names a problem");
  }
  return 0;
}
