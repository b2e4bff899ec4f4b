// `depotwin validate`: every problem in one run, as `file:line: key: message`, exit 2; the arm's
// posture problems at the dotted key and line of the point they name.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <regex>
#include <string>

#include "pipeline/pipeline_test_util.hpp"

namespace depotwin {
namespace {

using testing_support::depotwin;
using testing_support::fresh_directory;
using testing_support::write_text;

// a parse error, two over-speed segments and an unreachable point, all in one run
TEST(ValidateVerb, ListsLoaderAndMachineProblemsInOneRun) {
  const std::string dir = fresh_directory("validate_all");
  const std::string path = write_text(dir, "all.yaml", R"(limits: {v_max: 4, a_max: abc}
toolpath:
  speed: 5
  polylines:
    - - [0, 0]
      - [10, 0]
      - [13, 4]
      - [70, 4]
)");
  const auto r = depotwin("validate " + path);
  EXPECT_EQ(r.status, 2) << r.output;
  const std::string expected =
      "error: " + path + ":1: limits.a_max: expected a number, got 'abc'\n" + "error: " + path +
      ":2: toolpath.offset: the print paths span x 0 to 70, y 0 to 4, z 0 mm; moved by (-35, -2, "
      "0) mm every point is within xy_stage's reach: add that to toolpath.offset (xy_stage "
      "centres on (0, 0, 0))\n" +
      "error: " + path +
      ":6: toolpath.polylines[0]: segment 0 (points 0 and 1): print speed 5 mm/s needs 5 mm/s "
      "on x, above limits v_max 4 (lower the speed or raise the limit)\n" +
      "error: " + path +
      ":8: toolpath.polylines[0]: segment 2 (points 2 and 3): print speed 5 mm/s needs 5 mm/s "
      "on x, above limits v_max 4 (lower the speed or raise the limit)\n" +
      "error: " + path +
      ":8: toolpath.polylines[0]: point 3 (70, 4, 0) mm is not reachable by xy_stage: joint x "
      "at -70 mm is outside its travel [-50, 50] mm, by 20 mm (TCP x = 70 mm)\n";
  EXPECT_EQ(r.output, expected);
}

// the arm: a segment out of reach for every roll is named by its key, line and point
TEST(ValidateVerb, ArmPostureProblemsNameTheSegmentAndLine) {
  const std::string dir = fresh_directory("validate_arm_segment");
  const std::string path = write_text(dir, "arm.yaml", R"(machine: arm6
limits: {v_max: 50, a_max: 500}
process: {type: extrusion}
toolpath:
  speed: 5
  start: [0, 0, 20]
  segments:
    - [[0, 0, 0], [10, 0, 0]]
    - [[0, 10, 0],
       [900, 10, 0]]
planners: [conformal]
)");
  const auto r = depotwin("validate " + path);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find(path + ":10: toolpath.segments[1]: point 1 (900.000, 10.000, "),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("toolpath path"), std::string::npos) << r.output;
}

// what loading notes, which every run repeats as a warning, validate prints too (here the
// rule a G-code file is read by)
TEST(ValidateVerb, PrintsTheNotesEveryRunWouldWarnOf) {
  const std::string dir = fresh_directory("validate_notes");
  write_text(dir, "square.gcode", "G21\nG90\nM83\nG1 X10 Y0 E1 F600\nG1 X10 Y10 E1\n");
  const std::string path = write_text(dir, "notes.yaml", R"(process: {type: extrusion}
toolpath: {gcode: square.gcode}
)");
  const auto r = depotwin("validate " + path);
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find(path + ": ok"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("\nwarning: toolpath.gcode: "), std::string::npos) << r.output;
}

// each planner's own warnings on its plan, which `plan` and `run` print, validate prints as
// they do (it had only the loader's notes): bezier slows or stops at corner_sweep's corners
TEST(ValidateVerb, PrintsThePlannersWarningsAsPlanDoes) {
  const std::string scenario = testing_support::scenario_path("corner_sweep.yaml");
  const auto validated = depotwin("validate --quiet " + scenario);
  ASSERT_EQ(validated.status, 0) << validated.output;
  const std::string slowed = "warning (bezier): path 3 corner 1: blend slowed to ";
  EXPECT_NE(validated.output.find(slowed), std::string::npos) << validated.output;
  const std::string dir = fresh_directory("validate_planner_warnings");
  const auto planned = depotwin("plan --quiet --planner bezier --out " + dir + "/out " + scenario);
  ASSERT_EQ(planned.status, 0) << planned.output;
  EXPECT_NE(planned.output.find(slowed), std::string::npos) << planned.output;
}

// two runs of one planner under labels: every verb names a warning by the run's label (`run`
// and `compare` named both "bezier")
TEST(ValidateVerb, WarningsNameTheRunByItsLabelInEveryVerb) {
  const std::string dir = fresh_directory("validate_labelled_warnings");
  std::string text =
      testing_support::read_text(testing_support::scenario_path("corner_sweep.yaml"));
  text.replace(text.find("planners:"), std::string::npos,
               "planners: [{name: bezier, delta: 0.3, label: wide}, {name: bezier, delta: 0.2, "
               "label: narrow}]\n");
  const std::string scenario = write_text(dir, "labelled.yaml", text);
  for (const std::string& verb :
       std::vector<std::string>{"validate --quiet", "plan --quiet --out " + dir + "/plan",
                                "run --quiet --no-render --out " + dir + "/run"}) {
    const auto r = depotwin(verb + " " + scenario);
    ASSERT_EQ(r.status, 0) << verb << ": " << r.output;
    EXPECT_NE(r.output.find("warning (wide): path 3 corner 1: "), std::string::npos)
        << verb << ": " << r.output;
    EXPECT_NE(r.output.find("warning (narrow): path "), std::string::npos)
        << verb << ": " << r.output;
    EXPECT_EQ(r.output.find("warning (bezier)"), std::string::npos) << verb << ": " << r.output;
  }
}

// a slicer's zig-zag of 0.45 mm steps at 60 mm/s gives lspb_mtt one warning per step (no
// LSPB in L/v): of that kind the verbs print three, then how many more there are, where
// metrics.json keeps every one; a warning of another kind (the rule the file is read by) is
// still printed
TEST(ValidateVerb, ManyWarningsOfOneKindArePrintedThreeThenCounted) {
  const std::string dir = fresh_directory("validate_many_warnings");
  std::string gcode = "M83\nG1 X0 Y0 Z0.2 F3600\n";
  for (int i = 0; i < 20; ++i)
    gcode += "G1 X" + std::string(i % 2 == 0 ? "20" : "0") + " Y" + std::to_string(0.45 * i) +
             " E0.6\nG1 Y" + std::to_string(0.45 * (i + 1)) + " E0.02\n";
  write_text(dir, "zigzag.gcode", gcode);
  const std::string scenario = write_text(dir, "zigzag.yaml", R"(machine: cartesian
limits: {v_max: 100, a_max: 1000}
process: {type: extrusion, bead_width_mm: 0.45, layer_height_mm: 0.2}
toolpath: {gcode: zigzag.gcode}
planners: [lspb_mtt]
)");
  const auto count = [](const std::string& text, const std::string& word) {
    size_t n = 0;
    for (size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) ++n;
    return n;
  };
  const auto planned = depotwin("plan --quiet --out " + dir + "/out " + scenario);
  ASSERT_EQ(planned.status, 0) << planned.output;
  const std::string metrics = testing_support::read_text(dir + "/out/lspb_mtt/metrics.json");
  const size_t all = count(metrics, ": no LSPB in L/v = ");
  ASSERT_GT(all, 10u) << metrics;
  const auto validated = depotwin("validate --quiet " + scenario);
  ASSERT_EQ(validated.status, 0) << validated.output;
  for (const auto* r : {&planned, &validated}) {
    EXPECT_EQ(count(r->output, "warning (lspb_mtt): path "), 3u) << r->output;
    EXPECT_NE(r->output.find("warning (lspb_mtt): ... and " + std::to_string(all - 3) +
                             " more like \"path 0 segment "),
              std::string::npos)
        << r->output;
    EXPECT_NE(r->output.find("toolpath.gcode: auto chose e"), std::string::npos) << r->output;
  }
  EXPECT_NE(planned.output.find("/out/lspb_mtt/metrics.json (\"warnings\")"), std::string::npos)
      << planned.output;
}

// the memory validate prints is the figure --max-memory is compared with: a budget 3 % below it
// refuses the job, 3 % above accepts it
TEST(ValidateVerb, TheMemoryItPrintsIsWhatMaxMemoryIsComparedWith) {
  const std::string scenario = testing_support::scenario_path("thompson_fig7.yaml");
  const auto r = depotwin("validate " + scenario);
  ASSERT_EQ(r.status, 0) << r.output;
  const std::smatch found = [&] {
    std::smatch match;
    std::regex_search(r.output, match, std::regex("about (\\d+) MB of memory, the runs' data "));
    return match;
  }();
  ASSERT_FALSE(found.empty()) << r.output;
  const double megabytes = std::stod(found[1].str());
  EXPECT_GT(megabytes, 250.0);  // the process's own share counts
  const auto budget = [&](double factor) {
    return depotwin("validate " + scenario + " --max-memory " +
                    std::to_string(std::lround(megabytes * factor)) + "M");  // MB of 1024^2
  };
  const auto below = budget(0.97);
  EXPECT_EQ(below.status, 2) << below.output;
  EXPECT_NE(below.output.find("of memory, more than --max-memory"), std::string::npos)
      << below.output;
  EXPECT_EQ(budget(1.03).status, 0);
}

// a conformal job's part counts in the memory estimate: the same plate as 200 and as 20 000
// triangles (the same hatch) differs by 1300 bytes a triangle, and a budget it exceeds names
// the part's share
TEST(ValidateVerb, ThePartsTrianglesCountInTheMemory) {
  const std::string dir = fresh_directory("validate_part_memory");
  // a binary STL of a 40 x 40 mm plate at z = 5 mm, n x n squares of two triangles
  const auto plate = [&](int n) {
    const std::string path = dir + "/plate" + std::to_string(n) + ".stl";
    std::ofstream out(path, std::ios::binary);
    out << std::string(80, ' ');
    const std::uint32_t count = static_cast<std::uint32_t>(2 * n * n);
    out.write(reinterpret_cast<const char*>(&count), 4);
    const auto facet = [&](std::initializer_list<float> corners) {
      const float normal[3] = {0.0f, 0.0f, 1.0f};
      out.write(reinterpret_cast<const char*>(normal), 12);
      for (const float value : corners) out.write(reinterpret_cast<const char*>(&value), 4);
      out.write("\0\0", 2);
    };
    const float side = 40.0f / static_cast<float>(n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const float x0 = -20.0f + side * static_cast<float>(i), x1 = x0 + side;
        const float y0 = -20.0f + side * static_cast<float>(j), y1 = y0 + side;
        facet({x0, y0, 5, x1, y0, 5, x1, y1, 5});
        facet({x0, y0, 5, x1, y1, 5, x0, y1, 5});
      }
    return path;
  };
  const auto megabytes = [&](int n, const std::string& options) {
    const std::string scenario = write_text(
        dir, "plate" + std::to_string(n) + ".yaml",
        "machine: arm6\nlimits: {v_max: 200, a_max: 2000}\nprocess: {type: extrusion}\n"
        "toolpath:\n  speed: 20\n  surface: {file: " +
            plate(n) + ", hatch_mm: 5, angles: [0], layers: 1}\nplanners: [conformal]\n");
    const auto r = depotwin("validate --quiet " + scenario + options);
    std::smatch match;
    std::regex_search(r.output, match, std::regex("about (\\d+) MB of memory"));
    return std::make_pair(match.empty() ? -1.0 : std::stod(match[1].str()), r);
  };
  const auto [coarse, coarse_run] = megabytes(10, "");
  const auto [fine, fine_run] = megabytes(100, "");
  ASSERT_GT(coarse, 0.0) << coarse_run.output;
  ASSERT_GT(fine, 0.0) << fine_run.output;
  EXPECT_NEAR(fine - coarse, 1300.0 * 19800.0 / (1024.0 * 1024.0), 1.0)
      << coarse_run.output << fine_run.output;
  const auto [refused_mb, refused] =
      megabytes(100, " --max-memory " + std::to_string(std::lround(coarse + 5.0)) + "M");
  EXPECT_EQ(refused.status, 2) << refused.output;
  EXPECT_NE(refused.output.find("); the part's 20000 triangles take about 25 MB; check "),
            std::string::npos)
      << refused.output;
}

}  // namespace
}  // namespace depotwin
