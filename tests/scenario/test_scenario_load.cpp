// Scenario files that must load, and the values they load into.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "planners/planner.hpp"
#include "scenario/scenario.hpp"
#include "scenario_test_util.hpp"
#include "toolpath/random_segments.hpp"

namespace depotwin {
namespace {

using testing_scenario::dump;
using testing_scenario::expect_problem;
using ScenarioLoad = testing_scenario::ScenarioFiles;

// the minimal form of docs/ARCHITECTURE.md, exactly as written there
const char* kMinimal = R"(
name: two_segments
machine: xy_stage
limits: {v_max: 4, a_max: 30}        # per axis, mm/s and mm/s^2
process: {type: aerosol}              # defaults for everything else
toolpath:
  speed: 3                            # mm/s on every print segment
  start: [0, 0]
  end: [20, 0]
  segments:                           # print segments, in this order
    - [[2, 2], [8, 2]]
    - [[8, 2], [5, 7]]
order: as_given                       # or a sequencer name, or {method: two_opt, seed: 1}
planners: [lspb_mtt]                  # names, or maps {name: bezier, delta: 0.3}
)";

void expect_point(const Vec3& actual, double x, double y, double z) {
  EXPECT_DOUBLE_EQ(actual.x(), x);
  EXPECT_DOUBLE_EQ(actual.y(), y);
  EXPECT_DOUBLE_EQ(actual.z(), z);
}

TEST_F(ScenarioLoad, MinimalFormLoadsWithExpectedValues) {
  const std::string path = write("two.yaml", kMinimal);
  const Scenario s = load_scenario(path);
  EXPECT_EQ(s.file, path);
  EXPECT_EQ(s.directory, dir_.lexically_normal().string());
  EXPECT_EQ(s.name, "two_segments");
  EXPECT_EQ(s.machine, "xy_stage");
  EXPECT_EQ(s.model_path, "");
  // limits: the same on every axis, no jerk limit, no joint limits
  for (const AxisLimits& axis : s.limits.axes) {
    EXPECT_EQ(axis.v_max_mm_s, 4.0);
    EXPECT_EQ(axis.a_max_mm_s2, 30.0);
    EXPECT_EQ(axis.j_max_mm_s3, 0.0);
  }
  EXPECT_FALSE(s.has_joint_limits);
  // process: aerosol with the struct's defaults
  const ProcessSpec defaults;
  EXPECT_EQ(s.process.type, "aerosol");
  EXPECT_EQ(s.process.sigma_mm, defaults.sigma_mm);
  EXPECT_EQ(s.process.flow_mm3_s, defaults.flow_mm3_s);
  // toolpath: 2-D points get z = 0
  expect_point(s.toolpath.start_mm, 0, 0, 0);
  expect_point(s.toolpath.end_mm, 20, 0, 0);
  ASSERT_EQ(s.toolpath.paths.size(), 2u);
  ASSERT_EQ(s.toolpath.paths[0].points.size(), 2u);
  expect_point(s.toolpath.paths[0].points[0], 2, 2, 0);
  expect_point(s.toolpath.paths[0].points[1], 8, 2, 0);
  ASSERT_EQ(s.toolpath.paths[1].points.size(), 2u);
  expect_point(s.toolpath.paths[1].points[0], 8, 2, 0);
  expect_point(s.toolpath.paths[1].points[1], 5, 7, 0);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(s.toolpath.paths[i].speed_mm_s, 3.0);
    EXPECT_EQ(s.toolpath.paths[i].source_index, i);
    EXPECT_TRUE(s.toolpath.paths[i].normals.empty());
  }
  EXPECT_DOUBLE_EQ(s.toolpath.print_length_mm(), 6.0 + std::sqrt(34.0));
  // order and planners
  EXPECT_EQ(s.order.method, "as_given");
  EXPECT_EQ(s.order.refine, "");
  EXPECT_EQ(s.order.cost_model, "machine");
  EXPECT_EQ(s.order.seed, 1u);
  ASSERT_EQ(s.planners.size(), 1u);
  EXPECT_EQ(s.planners[0].name, "lspb_mtt");
  EXPECT_TRUE(s.planners[0].params.empty());
  EXPECT_EQ(s.planners[0].line, 13);
  // untouched sections keep their defaults
  EXPECT_EQ(s.sim.timestep_s, SimSpec{}.timestep_s);
  EXPECT_EQ(s.outputs.render, OutputSpec{}.render);
  EXPECT_EQ(s.outputs.image_width, OutputSpec{}.image_width);
  EXPECT_TRUE(validate_scenario_file(path).empty());
}

TEST_F(ScenarioLoad, DefaultsWhenOnlyAToolpathIsGiven) {
  const std::string path = write("my_job.yaml", R"(
toolpath:
  speed: 2
  segments: [[[0, 0], [1, 0]]]
)");
  const Scenario s = load_scenario(path);
  EXPECT_EQ(s.name, "my_job");  // the file stem
  EXPECT_EQ(s.machine, "xy_stage");
  for (const AxisLimits& axis : s.limits.axes) {
    EXPECT_EQ(axis.v_max_mm_s, 4.0);
    EXPECT_EQ(axis.a_max_mm_s2, 30.0);
    EXPECT_EQ(axis.j_max_mm_s3, 0.0);
  }
  expect_point(s.toolpath.start_mm, 0, 0, 0);
  expect_point(s.toolpath.end_mm, 0, 0, 0);  // end defaults to start
  ASSERT_EQ(s.planners.size(), 2u);
  EXPECT_EQ(s.planners[0].name, "lspb_mtt");
  EXPECT_EQ(s.planners[1].name, "stop_and_go");
  EXPECT_EQ(s.order.label(), "as_given");
}

TEST_F(ScenarioLoad, EveryOtherKey) {
  std::filesystem::create_directories(dir_ / "models");
  write("models/my_stage.xml", "<mujoco/>\n");
  const std::string path = write("full.yaml", R"(
name: full_job
machine: {model: models/my_stage.xml, kinematics: linear_delta}
limits:
  v_max: 50
  a_max: 400
  j_max: 8000
  x: {v_max: 60}
  z: {v_max: 10, a_max: 100, j_max: 0}
  joint: {v_max: 200, a_max: 3000}
process:
  type: extrusion
  line_width_mm: 0.5
  bead_width_mm: 0.45
  layer_height_mm: 0.25
  tau_s: 0.08
  retract: true
toolpath:
  speed: 20
  start: [0, 0, 5]
  end: [100, 100, 5.5]
  polylines:
    - [[0, 0], [10, 0], [10, 10, 0.2]]
    - {points: [[20, 0], [30, 0]], speed: 40}
order: {method: christofides, refine: or_opt, cost_model: along_line, seed: 42}
planners:
  - stop_and_go
  - {name: lspb_mtt}
sim: {timestep_s: 0.0005, cell_mm: 0.05, kp_scale: 2.5, settle_s: 0.3}
outputs: {render: false, image_width: 320, image_height: 2048}
)");
  const Scenario s = load_scenario(path);
  EXPECT_EQ(s.name, "full_job");
  const std::string model = (dir_ / "models" / "my_stage.xml").lexically_normal().string();
  EXPECT_EQ(s.machine, "linear_delta");
  EXPECT_EQ(s.model_path, model);
  // limits: common values with per-axis overrides
  EXPECT_EQ(s.limits.axes[0].v_max_mm_s, 60.0);
  EXPECT_EQ(s.limits.axes[0].a_max_mm_s2, 400.0);
  EXPECT_EQ(s.limits.axes[0].j_max_mm_s3, 8000.0);
  EXPECT_EQ(s.limits.axes[1].v_max_mm_s, 50.0);
  EXPECT_EQ(s.limits.axes[1].a_max_mm_s2, 400.0);
  EXPECT_EQ(s.limits.axes[2].v_max_mm_s, 10.0);
  EXPECT_EQ(s.limits.axes[2].a_max_mm_s2, 100.0);
  EXPECT_EQ(s.limits.axes[2].j_max_mm_s3, 0.0);
  EXPECT_TRUE(s.has_joint_limits);
  EXPECT_EQ(s.joint_limits.v_max_mm_s, 200.0);
  EXPECT_EQ(s.joint_limits.a_max_mm_s2, 3000.0);
  EXPECT_EQ(s.joint_limits.j_max_mm_s3, 0.0);
  // process
  EXPECT_EQ(s.process.type, "extrusion");
  EXPECT_EQ(s.process.line_width_mm, 0.5);
  EXPECT_EQ(s.process.bead_width_mm, 0.45);
  EXPECT_EQ(s.process.layer_height_mm, 0.25);
  EXPECT_EQ(s.process.tau_s, 0.08);
  EXPECT_TRUE(s.process.retract);
  // toolpath: 3-D start/end, bare and map polylines, per-path speed
  expect_point(s.toolpath.start_mm, 0, 0, 5);
  expect_point(s.toolpath.end_mm, 100, 100, 5.5);
  ASSERT_EQ(s.toolpath.paths.size(), 2u);
  ASSERT_EQ(s.toolpath.paths[0].points.size(), 3u);
  expect_point(s.toolpath.paths[0].points[2], 10, 10, 0.2);
  EXPECT_EQ(s.toolpath.paths[0].speed_mm_s, 20.0);
  EXPECT_EQ(s.toolpath.paths[1].speed_mm_s, 40.0);
  EXPECT_EQ(s.toolpath.paths[1].source_index, 1);
  expect_point(s.toolpath.paths[1].points[0], 20, 0, 0);
  // order
  EXPECT_EQ(s.order.method, "christofides");
  EXPECT_EQ(s.order.refine, "or_opt");
  EXPECT_EQ(s.order.cost_model, "along_line");
  EXPECT_EQ(s.order.seed, 42u);
  // planners keep the file's order and lines
  ASSERT_EQ(s.planners.size(), 2u);
  EXPECT_EQ(s.planners[0].name, "stop_and_go");
  EXPECT_EQ(s.planners[0].line, 26);
  EXPECT_EQ(s.planners[1].name, "lspb_mtt");
  EXPECT_EQ(s.planners[1].line, 27);
  // sim and outputs
  EXPECT_EQ(s.sim.timestep_s, 0.0005);
  EXPECT_EQ(s.sim.cell_mm, 0.05);
  EXPECT_EQ(s.sim.kp_scale, 2.5);
  EXPECT_EQ(s.sim.settle_s, 0.3);
  EXPECT_FALSE(s.outputs.render);
  EXPECT_EQ(s.outputs.image_width, 320);
  EXPECT_EQ(s.outputs.image_height, 2048);
}

TEST_F(ScenarioLoad, AerosolParameters) {
  const Scenario s = load_scenario(write("a.yaml", R"(
process: {type: aerosol, flow_mm3_s: 0, sigma_mm: 0.05, line_width_mm: 0, shutter_time_s: 0.01}
toolpath: {speed: 1, segments: [[[0, 0], [1, 1]]]}
)"));
  EXPECT_EQ(s.process.flow_mm3_s, 0.0);  // 0: derived
  EXPECT_EQ(s.process.sigma_mm, 0.05);
  EXPECT_EQ(s.process.line_width_mm, 0.0);  // 0: default width
  EXPECT_EQ(s.process.shutter_time_s, 0.01);
}

// the string and map forms of `order:`
TEST_F(ScenarioLoad, OrderForms) {
  struct Case {
    std::string text, method, refine;
    std::uint64_t seed;
  };
  const std::vector<Case> cases{
      {"nearest_neighbor", "nearest_neighbor", "", 1},
      {"two_opt", "nearest_neighbor", "two_opt", 1},
      {"christofides+three_opt", "christofides", "three_opt", 1},
      {"{method: two_opt, seed: 1}", "nearest_neighbor", "two_opt", 1},
      {"{method: or_opt, seed: 18446744073709551615}", "nearest_neighbor", "or_opt",
       18446744073709551615ull},
      {"{method: random, seed: 7}", "random", "", 7},
      {"{method: christofides+two_opt, refine: two_opt}", "christofides", "two_opt", 1},
      {"{method: nearest_neighbor, refine: none}", "nearest_neighbor", "", 1},
  };
  for (const Case& c : cases) {
    const Scenario s = load_scenario(write("o.yaml", "order: " + c.text +
                                                         "\ntoolpath: {speed: 1, segments: "
                                                         "[[[0, 0], [1, 0]]]}\n"));
    EXPECT_EQ(s.order.method, c.method) << c.text;
    EXPECT_EQ(s.order.refine, c.refine) << c.text;
    EXPECT_EQ(s.order.seed, c.seed) << c.text;
    EXPECT_EQ(s.order.cost_model, "machine") << c.text;
  }
}

// speeds exactly at an axis limit are feasible: 5 mm/s along (3, 4) needs 3 on x and 4 on y
TEST_F(ScenarioLoad, PrintSpeedExactlyAtTheLimitIsAccepted) {
  const std::vector<Problem> problems = problems_of(R"(
limits: {v_max: 4, a_max: 30, x: {v_max: 3}}
toolpath: {speed: 5, segments: [[[0, 0], [3, 4]]]}
)");
  EXPECT_TRUE(problems.empty()) << dump(problems);
}

TEST_F(ScenarioLoad, GcodeToolpathRelativeToTheScenarioFile) {
  const std::string path =
      std::string(DEPOTWIN_SOURCE_DIR) + "/tests/scenario/data/gcode_square.yaml";
  const Scenario s = load_scenario(path);
  EXPECT_EQ(s.name, "gcode_square");
  EXPECT_EQ(s.process.type, "extrusion");
  EXPECT_EQ(s.process.bead_width_mm, 0.45);
  expect_point(s.toolpath.start_mm, 0, 0, 5);
  expect_point(s.toolpath.end_mm, 0, 0, 5);
  ASSERT_EQ(s.toolpath.paths.size(), 3u);
  EXPECT_EQ(s.toolpath.paths[0].points.size(), 3u);
  EXPECT_EQ(s.toolpath.paths[0].speed_mm_s, 10.0);
  EXPECT_EQ(s.toolpath.paths[1].speed_mm_s, 20.0);
  EXPECT_EQ(s.toolpath.paths[2].speed_mm_s, 5.0);
  expect_point(s.toolpath.paths[2].points.back(), 40, 15, 0.2);
  EXPECT_DOUBLE_EQ(s.toolpath.print_length_mm(), 20.0 + 10.0 + 15.0);
}

// an ASCII STL of the given facets, each three "x y z" vertices in the order written
std::string ascii_stl(const std::string& name,
                      const std::vector<std::array<std::string, 3>>& facets) {
  std::string text = "solid " + name + "\n";
  for (const std::array<std::string, 3>& facet : facets) {
    text += " facet normal 0 0 0\n  outer loop\n";
    for (const std::string& vertex : facet) text += "   vertex " + vertex + "\n";
    text += "  endloop\n endfacet\n";
  }
  return text + "endsolid " + name + "\n";
}

// an aerosol scenario on the arm hatching `stl` at 2 mm, with more surface keys after it
std::string surface_scenario(const std::string& stl, const std::string& more_keys = "") {
  return "machine: arm6\nlimits: {v_max: 200, a_max: 2000}\nprocess: {type: aerosol}\n"
         "toolpath:\n  speed: 10\n  surface: {file: " +
         stl + ", hatch_mm: 2" + more_keys + "}\n";
}

// the STL's unit scales every vertex: a patch written in metres (as CAD programs often
// export) and in inches hatches as the same patch written in mm
TEST_F(ScenarioLoad, SurfaceUnitsScaleThePart) {
  const auto patch = [](double scale) {
    // (every digit: a hatch line may fall on the patch's edge)
    const auto corner = [&](double x, double y, double z) {
      char text[96];
      std::snprintf(text, sizeof text, "%.17g %.17g %.17g", x * scale, y * scale, z * scale);
      return std::string(text);
    };
    return ascii_stl("patch", {{corner(0, 0, 1), corner(9.5, 0, 2), corner(9.5, 9.5, 2)},
                               {corner(0, 0, 1), corner(9.5, 9.5, 2), corner(0, 9.5, 1)}});
  };
  write("mm.stl", patch(1.0));
  write("m.stl", patch(1e-3));
  write("inch.stl", patch(1.0 / 25.4));
  const Scenario mm = load_scenario(write("mm.yaml", surface_scenario("mm.stl")));
  const Scenario m = load_scenario(write("m.yaml", surface_scenario("m.stl", ", units: m")));
  const Scenario inch =
      load_scenario(write("inch.yaml", surface_scenario("inch.stl", ", units: inch")));
  ASSERT_GT(mm.toolpath.paths.size(), 3u);
  for (const Scenario* other : {&m, &inch}) {
    ASSERT_EQ(other->toolpath.paths.size(), mm.toolpath.paths.size());
    for (size_t p = 0; p < mm.toolpath.paths.size(); ++p) {
      ASSERT_EQ(other->toolpath.paths[p].points.size(), mm.toolpath.paths[p].points.size());
      for (size_t i = 0; i < mm.toolpath.paths[p].points.size(); ++i)
        EXPECT_LT((other->toolpath.paths[p].points[i] - mm.toolpath.paths[p].points[i]).norm(),
                  1e-4);
    }
  }
}

// A surface STL wound clockwise seen from above (a patch exported facing down) is turned
// over, and one facet wound against its neighbour turned to match it: the same hatch as the
// same patch wound counter-clockwise, tool axes up, and a note that every run reports. The
// patch: the plane z = 1 + 0.1 x over 10 x 10 mm, two facets.
TEST_F(ScenarioLoad, ASurfaceFacingDownIsTurnedUpAndSaysSo) {
  // each facet up or down
  const auto patch = [](bool first_up, bool second_up) {
    const std::array<std::string, 3> first{"0 0 1", "10 0 2", "10 10 2"};
    const std::array<std::string, 3> second{"0 0 1", "10 10 2", "0 10 1"};
    // a facet facing down: its corners in the opposite order (the first kept first)
    const auto turned = [](const std::array<std::string, 3>& c) {
      return std::array<std::string, 3>{c[0], c[2], c[1]};
    };
    return ascii_stl("patch",
                     {first_up ? first : turned(first), second_up ? second : turned(second)});
  };
  write("up.stl", patch(true, true));
  write("down.stl", patch(false, false));
  // one facet each way: turned to match its neighbour (of equal area: the first's winding
  // kept), then the whole up
  write("mixed_up.stl", patch(true, false));
  write("mixed_down.stl", patch(false, true));
  const auto scenario = [&](const std::string& stl) {
    return load_scenario(write(stl + ".yaml", surface_scenario(stl, ", alpha: 1")));
  };
  const Scenario up = scenario("up.stl");
  const Scenario down = scenario("down.stl");
  const Scenario mixed_up = scenario("mixed_up.stl");
  const Scenario mixed_down = scenario("mixed_down.stl");
  EXPECT_TRUE(up.notes.empty());
  ASSERT_EQ(down.notes.size(), 1u);
  EXPECT_EQ(down.notes[0],
            "toolpath.surface: 'down.stl' faced down or inside out (its triangles wound "
            "clockwise seen from outside); its triangles were turned over");
  const std::string against =
      "' were wound against their neighbours; they were turned over to match them";
  ASSERT_EQ(mixed_up.notes.size(), 1u);
  EXPECT_EQ(mixed_up.notes[0], "toolpath.surface: 1 of 2 triangles of 'mixed_up.stl" + against);
  ASSERT_EQ(mixed_down.notes.size(), 2u);
  EXPECT_EQ(mixed_down.notes[0], "toolpath.surface: 1 of 2 triangles of 'mixed_down.stl" + against);
  // a file facing up that the scenario's rotation turns over: the note names the rotation,
  // not the file; one facing down turned up by the rotation has no note
  const Scenario rotated = load_scenario(
      write("rotated.yaml", surface_scenario("up.stl",
                                             ", rotation: [180, 0, 0], offset: [0, 10, "
                                             "3]")));
  ASSERT_EQ(rotated.notes.size(), 1u);
  EXPECT_EQ(rotated.notes[0],
            "toolpath.surface: 'up.stl' faces down as rotation [180, 0, 0] places it (the file "
            "faces up); its triangles were turned over, so the side now on top is printed");
  EXPECT_TRUE(
      load_scenario(write("rotated_down.yaml", surface_scenario("down.stl",
                                                                ", rotation: [180, 0, 0], offset: "
                                                                "[0, 10, 3]")))
          .notes.empty());
  ASSERT_GT(up.toolpath.paths.size(), 3u);
  const Vec3 normal = Vec3(-0.1, 0, 1).normalized();
  for (const Scenario* other : {&down, &mixed_up, &mixed_down}) {
    ASSERT_EQ(other->toolpath.paths.size(), up.toolpath.paths.size());
    for (size_t p = 0; p < up.toolpath.paths.size(); ++p) {
      const PrintPath& a = up.toolpath.paths[p];
      const PrintPath& b = other->toolpath.paths[p];
      ASSERT_EQ(a.points.size(), b.points.size());
      for (size_t i = 0; i < a.points.size(); ++i) {
        EXPECT_EQ(a.points[i], b.points[i]);
        EXPECT_LT((a.tool_axis(i) - normal).norm(), 1e-9);
        EXPECT_LT((b.tool_axis(i) - normal).norm(), 1e-9);
      }
    }
  }
}

// A Moebius strip (welded: a loop of neighbours asks for both windings) cannot be wound
// consistently: each triangle faces up on its own, loading says so, and the hatch covers the
// whole strip, both halves (only one was printed: the other faced down)
TEST_F(ScenarioLoad, AMoebiusStripFacesUpTriangleByTriangleAndSaysSo) {
  const double pi = 3.141592653589793;
  const int along = 60, across = 4;
  // vertex (i, j) of the strip; i = along is i = 0 with the width reversed (the half twist)
  const auto vertex = [&](int i, int j) {
    if (i == along) {
      i = 0;
      j = across - j;
    }
    const double u = 2.0 * pi * i / along, v = -10.0 + 20.0 * j / across;
    const double r = 30.0 + v * std::cos(u / 2.0);
    char text[96];
    std::snprintf(text, sizeof text, "%.9g %.9g %.9g", r * std::cos(u), r * std::sin(u),
                  20.0 + v * std::sin(u / 2.0));
    return std::string(text);
  };
  std::vector<std::array<std::string, 3>> facets;
  for (int i = 0; i < along; ++i)
    for (int j = 0; j < across; ++j) {
      facets.push_back({vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1)});
      facets.push_back({vertex(i, j), vertex(i + 1, j + 1), vertex(i, j + 1)});
    }
  write("mobius.stl", ascii_stl("mobius", facets));
  const Scenario strip = load_scenario(write("mobius.yaml", surface_scenario("mobius.stl")));
  ASSERT_EQ(strip.notes.size(), 1u);
  EXPECT_EQ(strip.notes[0],
            "toolpath.surface: 480 of 480 triangles of 'mobius.stl' form a surface that cannot be "
            "wound consistently (one side runs into the other, as on a Moebius strip); each now "
            "faces up on its own, so the side seen from above is printed");
  std::size_t left = 0, right = 0;
  for (const PrintPath& path : strip.toolpath.paths)
    for (const Vec3& point : path.points) (point.y() > 0.0 ? left : right) += 1;
  EXPECT_GT(left, 100u);
  EXPECT_GT(right, 100u);
  EXPECT_LT(std::abs(static_cast<double>(left) - static_cast<double>(right)),
            0.25 * static_cast<double>(left + right));
}

// An up-facing area under another part of the surface gets no deposit, and every run says
// how much and where: a shelf at z 20 over half of a plate at z 1 hides 3000 of 9000 mm²; so
// does a groove's floor narrower than two spacings
TEST_F(ScenarioLoad, ASurfaceUnderAnOverhangIsNoted) {
  // counter-clockwise quads seen from above: (x0, x1, z)
  const auto quads = [](const std::vector<std::array<double, 3>>& rectangles) {
    std::vector<std::array<std::string, 3>> facets;
    for (const auto& r : rectangles) {
      const std::string z = " " + std::to_string(r[2]);
      const std::string x0 = std::to_string(r[0]), x1 = std::to_string(r[1]);
      facets.push_back({x0 + " -30" + z, x1 + " -30" + z, x1 + " 30" + z});
      facets.push_back({x0 + " -30" + z, x1 + " 30" + z, x0 + " 30" + z});
    }
    return ascii_stl("shelf", facets);
  };
  write("shelf.stl", quads({{-50, 0, 20}, {-50, 0, 1}, {0, 50, 1}}));
  write("plate.stl", quads({{-50, 0, 1}, {0, 50, 1}}));
  const auto scenario = [&](const std::string& stl) {
    return load_scenario(write(stl + ".yaml", surface_scenario(stl)));
  };
  const Scenario shelf = scenario("shelf.stl");
  ASSERT_EQ(shelf.notes.size(), 1u);
  EXPECT_EQ(shelf.notes[0],
            "toolpath.surface: 33.3 % of the up-facing area of 'shelf.stl' (3000 of 9000 mm², "
            "within x -50 to 0, y -30 to 30, z 1 mm) lies under another part of the surface: "
            "the hatch is projected from above onto the top surface only, so that area gets no "
            "deposit");
  // the hatch itself: nothing printed at z 1 where the shelf is above
  for (const PrintPath& path : shelf.toolpath.paths)
    for (const Vec3& p : path.points) EXPECT_TRUE(p.x() >= -1e-9 || p.z() == 20.0) << p.transpose();
  EXPECT_TRUE(scenario("plate.stl").notes.empty());
  // a groove 2 mm wide at a 2 mm hatch: one grid point of each line on its floor, between the
  // line's two printed pieces, is printed by no line; every run says so
  write("groove.stl", quads({{-50, -1, 10}, {-1, 1, 1}, {1, 50, 10}}));
  const Scenario groove = scenario("groove.stl");
  ASSERT_EQ(groove.notes.size(), 1u);
  EXPECT_EQ(groove.notes[0],
            "toolpath.surface: at 0°, 31 of the 1581 up-facing grid points of 'groove.stl' "
            "(within x 0, y -30 to 30, z 1 mm) stand alone between steps or walls (a stretch "
            "narrower than two hatch_mm spacings, such as a groove's floor): a line needs two "
            "points, so lines at that angle leave them bare; a smaller hatch_mm reaches them");
}

// A planner parameter from the registry: its default loads, a value past its range does
// not. Skipped while no registered planner declares parameters.
TEST_F(ScenarioLoad, PlannerParametersFromTheRegistry) {
  const PlannerInfo* planner = nullptr;
  for (const PlannerInfo& info : planner_registry())
    if (!info.parameters.empty() && !planner) planner = &info;
  if (!planner) GTEST_SKIP() << "no registered planner declares parameters yet";
  const PlannerParameter& parameter = planner->parameters.front();
  const std::string head = "toolpath: {speed: 1, segments: [[[0, 0], [1, 0]]]}\nplanners:\n";
  std::ostringstream good;
  good.precision(17);
  good << head << "  - {name: " << planner->name << ", " << parameter.name << ": "
       << parameter.default_value << "}\n";
  const Scenario s = load_scenario(write("p.yaml", good.str()));
  ASSERT_EQ(s.planners.size(), 1u);
  ASSERT_EQ(s.planners[0].params.count(parameter.name), 1u);
  EXPECT_EQ(s.planners[0].params.at(parameter.name), std::vector<double>{parameter.default_value});

  // out of range: above the maximum (or below the minimum when the maximum is unbounded)
  const double outside = std::isfinite(parameter.max_value)
                             ? parameter.max_value + 1.0 + std::abs(parameter.max_value)
                             : parameter.min_value - 1.0 - std::abs(parameter.min_value);
  std::ostringstream bad;
  bad.precision(17);
  bad << head << "  - {name: " << planner->name << ", " << parameter.name << ": " << outside
      << "}\n";
  expect_problem(problems_of(bad.str()), scenario_path(), "planners[0]." + parameter.name, 3,
                 "is outside");
}

// every key of random_segments reaches the generator: the loaded paths are the instance
// make_random_segments gives for those values (n, bed, length, seed, speed), moved by the
// offset; and, independently of the generator, they are 6 segments of 10 to 40 mm at 2 mm/s
// inside the 100 x 80 mm bed, which the offset centres on the origin
TEST_F(ScenarioLoad, RandomSegmentsKeysAreParsed) {
  const std::string path = write("r.yaml", R"(
toolpath:
  random_segments: {n: 6, bed: [100, 80], length: [10, 40], seed: 3, speed: 2}
  offset: [-50, -40]
limits: {v_max: 4, a_max: 30}
)");
  const Scenario s = load_scenario(path);
  ASSERT_EQ(s.toolpath.paths.size(), 6u);
  for (const PrintPath& p : s.toolpath.paths) {
    EXPECT_EQ(p.speed_mm_s, 2.0);
    ASSERT_EQ(p.points.size(), 2u);
    EXPECT_GE(p.length_mm(), 10.0 - 1e-9);
    EXPECT_LE(p.length_mm(), 40.0 + 1e-9);
    for (const Vec3& point : p.points) {
      EXPECT_LE(std::abs(point.x()), 50.0 + 1e-9);
      EXPECT_LE(std::abs(point.y()), 40.0 + 1e-9);
      EXPECT_EQ(point.z(), 0.0);
    }
  }

  // the same instance as the generator's for these values, offset
  RandomSegmentsSpec spec;
  spec.count = 6;
  spec.bed_x_mm = 100.0;
  spec.bed_y_mm = 80.0;
  spec.length_min_mm = 10.0;
  spec.length_max_mm = 40.0;
  spec.seed = 3;
  spec.speed_mm_s = 2.0;
  const Vec3 offset(-50.0, -40.0, 0.0);
  const Toolpath expected = make_random_segments(spec);
  ASSERT_EQ(expected.paths.size(), s.toolpath.paths.size());
  for (size_t i = 0; i < expected.paths.size(); ++i)
    for (size_t k = 0; k < 2; ++k)
      expect_point(s.toolpath.paths[i].points[k], expected.paths[i].points[k].x() + offset.x(),
                   expected.paths[i].points[k].y() + offset.y(), 0.0);
  // no start or end given: the instance's, offset
  expect_point(s.toolpath.start_mm, expected.start_mm.x() + offset.x(),
               expected.start_mm.y() + offset.y(), 0.0);
  expect_point(s.toolpath.end_mm, expected.end_mm.x() + offset.x(),
               expected.end_mm.y() + offset.y(), 0.0);

  // another seed is another instance (the seed is read, not defaulted)
  const Scenario other = load_scenario(write("r4.yaml", R"(
toolpath:
  random_segments: {n: 6, bed: [100, 80], length: [10, 40], seed: 4, speed: 2}
  offset: [-50, -40]
limits: {v_max: 4, a_max: 30}
)"));
  ASSERT_EQ(other.toolpath.paths.size(), 6u);
  EXPECT_NE(other.toolpath.paths[0].points[0], s.toolpath.paths[0].points[0]);
}

}  // namespace
}  // namespace depotwin

namespace depotwin {
namespace {

using ScenarioOffset = testing_scenario::ScenarioFiles;

TEST_F(ScenarioOffset, OffsetMovesEveryPointStartAndEnd) {
  const Scenario s = load_scenario(write("offset.yaml", R"(
toolpath:
  speed: 3
  start: [0, 0]
  end: [20, 0]
  offset: [-50, -40]
  segments:
    - [[2, 2], [8, 2]]
  )"));
  EXPECT_EQ(s.toolpath.start_mm, Vec3(-50, -40, 0));
  EXPECT_EQ(s.toolpath.end_mm, Vec3(-30, -40, 0));
  EXPECT_EQ(s.toolpath.paths[0].points[0], Vec3(-48, -38, 0));
  EXPECT_EQ(s.toolpath.paths[0].points[1], Vec3(-42, -38, 0));
  // a malformed offset is reported with its line and key
  try {
    load_scenario(
        write("bad_offset.yaml",
              "toolpath:\n  speed: 3\n  offset: [1]\n  segments:\n    - [[0, 0], [1, 0]]\n"));
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(":3: toolpath.offset"), std::string::npos) << e.what();
  }
}

TEST_F(ScenarioOffset, ControlPeriodMustBeAWholeNumberOfSteps) {
  const Scenario fine = load_scenario(
      write("period.yaml",
            "toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}\nsim: {timestep_s: 0.0005}\n"));
  EXPECT_DOUBLE_EQ(fine.sim.control_period_s, 0.001);  // the multiple nearest 1 ms
  try {
    load_scenario(write("bad_period.yaml",
                        "toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}\n"
                        "sim: {timestep_s: 0.0004, control_period_s: 0.001}\n"));
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(":2: sim.control_period_s"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace depotwin
