// The shipped G-code files (scenarios/gcode/): each one's moves, lengths, layers and rule,
// computed by hand from the file, through the importer and `inspect`'s facts.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "cli/inspect.hpp"
#include "core/error.hpp"
#include "scratch_folder.hpp"
#include "toolpath/gcode.hpp"

namespace depotwin {
namespace {

const std::string kDir = std::string(DEPOTWIN_SOURCE_DIR) + "/scenarios/gcode/";

GcodeFacts facts_of(const std::string& name, PrintRule rule = PrintRule::automatic) {
  return gcode_facts(read_gcode_program(kDir + name, GcodeOptions{}), rule);
}

void expect_box(const Box3& box, const Vec3& lo, const Vec3& hi) {
  ASSERT_FALSE(box.empty);
  EXPECT_LT((box.lo - lo).norm(), 1e-9) << box.lo.transpose();
  EXPECT_LT((box.hi - hi).norm(), 1e-9) << box.hi.transpose();
}

TEST(GcodeFiles, SpacesInsideWords) {
  // G0 Z15, G0 Z0 (X0 Y0: no displacement), three 10 mm G1 (one modal), G0 Z15; feed rule
  const GcodeFacts facts = facts_of("spaces_in_words.ngc");
  EXPECT_EQ(facts.rule, "feed");
  EXPECT_EQ(facts.n_print_moves, 3);
  EXPECT_EQ(facts.n_travel_moves, 3);
  EXPECT_DOUBLE_EQ(facts.print_length_mm, 30.0);
  EXPECT_DOUBLE_EQ(facts.travel_length_mm, 45.0);
  EXPECT_EQ(facts.layer_z_values, std::vector<double>{0.0});
  expect_box(facts.print_bbox, Vec3(0, 0, 0), Vec3(10, 10, 0));
  // F600 = 10 mm/s from the first G1 on (45 mm); the two G0 before any F are left out
  EXPECT_NEAR(facts.feed_rate_time_s, 4.5, 1e-12);
  // the firmware takes longer: it accelerates, and the two G0 take their time at the top speed
  EXPECT_GT(facts.estimated_time_s, facts.feed_rate_time_s);
  EXPECT_EQ(facts.n_moves_without_feed, 2);
}

TEST(GcodeFiles, InspectListsIgnoredAxisWords) {
  // a Bambu Lab start: two G380 probes and a G29.1 z trim whose axis words were not moves,
  // then a 10 mm line (M83) and a helical lift (G2 P1, a travel)
  const std::string text =
      "G90\nM83\nG91\nG380 S2 Z30 F300\nG380 S2 Z-25 F300\nG90\nG29.1 Z0\n"
      "G1 X0 Y0 Z0.2 F600\nG1 X10 E0.5\nG2 Z1 I0.5 J0 P1\n";
  const GcodeFacts facts =
      gcode_facts(parse_gcode_program(text, "bambu.gcode", GcodeOptions{}), PrintRule::automatic);
  EXPECT_EQ(facts.n_print_moves, 1);
  EXPECT_DOUBLE_EQ(facts.print_length_mm, 10.0);
  EXPECT_EQ(facts.n_travel_moves, 2);
  // the travel from the origin at z 0 (the probes moved nothing) to z 0.2, then the helix
  EXPECT_NEAR(facts.travel_length_mm, 0.2 + std::hypot(kPi, 0.8), 1e-12);
  const nlohmann::json json = gcode_facts_json(facts);
  const nlohmann::json expected = nlohmann::json::parse(
      R"([{"code": "G380", "n_lines": 2, "first_line": 4},
          {"code": "G29.1", "n_lines": 1, "first_line": 7}])");
  EXPECT_EQ(json["ignored_axis_words"], expected) << json["ignored_axis_words"].dump();
  // a file without such codes lists none
  EXPECT_EQ(gcode_facts_json(facts_of("arcs.gcode"))["ignored_axis_words"],
            nlohmann::json::array());
}

TEST(GcodeFiles, RArcFullCircleAndLongArc) {
  // a quarter of radius 10 (5 pi), a full circle of radius 5 (10 pi), 270 degrees of radius 10
  // (15 pi): one path of 30 pi mm
  const GcodeFacts facts = facts_of("arcs.gcode");
  EXPECT_EQ(facts.rule, "e");
  EXPECT_EQ(facts.n_print_moves, 3);
  EXPECT_EQ(facts.n_print_arcs, 3);
  EXPECT_EQ(facts.n_print_paths, 1);
  EXPECT_NEAR(facts.print_length_mm, 30.0 * kPi, 1e-9);
  EXPECT_EQ(facts.n_travel_moves, 1);
  EXPECT_NEAR(facts.travel_length_mm, std::sqrt(100.0 + 0.04), 1e-12);
  EXPECT_NEAR(facts.extrusion_e_total, 3.0, 1e-12);
  // the long arc passes (-10, 0) and (0, -10)
  expect_box(facts.print_bbox, Vec3(-10, -10, 0.2), Vec3(10, 10, 0.2));
  // the import keeps the arcs exact and chords them on demand within a sagitta
  const GcodeImport imported = read_gcode(kDir + "arcs.gcode", GcodeOptions{});
  ASSERT_EQ(imported.toolpath.paths.size(), 1u);
  const PrintPath& path = imported.toolpath.paths[0];
  ASSERT_EQ(path.points.size(), 4u);
  EXPECT_NEAR(path.length_mm(), 30.0 * kPi, 1e-9);
  EXPECT_NEAR(path.arcs[1].sweep_rad, 2.0 * kPi, 1e-12);
  EXPECT_NEAR(path.arcs[2].sweep_rad, 1.5 * kPi, 1e-12);
  std::vector<size_t> source;
  const PrintPath chorded = path.chorded(0.01, &source);
  EXPECT_FALSE(chorded.has_arcs());
  // chords of radius 10 over 90 degrees: n = ceil(pi/2 / (2 acos(1 - 0.001))) = 18
  EXPECT_EQ(arc_chord_count(10.0, kPi / 2, 0.01), 18);
  EXPECT_EQ(chorded.points.size(),
            1u + 18 + arc_chord_count(5.0, 2 * kPi, 0.01) + arc_chord_count(10.0, 1.5 * kPi, 0.01));
  EXPECT_EQ(source.size(), chorded.points.size());
  EXPECT_EQ(source.back(), 3u);
  // every chord point on its circle; the chorded length within the sagitta's bound below
  for (size_t i = 1; i <= 18; ++i) EXPECT_NEAR(chorded.points[i].head<2>().norm(), 10.0, 1e-9);
  EXPECT_LT(chorded.length_mm(), 30.0 * kPi);
  EXPECT_GT(chorded.length_mm(), 30.0 * kPi * (1.0 - 0.001));
}

TEST(GcodeFiles, HelixAndG18Arc) {
  // one turn of radius 5 rising 2 mm: sqrt((10 pi)^2 + 2^2); then half a circle of radius 5
  const GcodeFacts facts = facts_of("helix.ngc");
  EXPECT_EQ(facts.rule, "feed");
  EXPECT_EQ(facts.n_print_moves, 2);
  EXPECT_EQ(facts.n_print_arcs, 2);
  EXPECT_NEAR(facts.print_length_mm, std::hypot(10.0 * kPi, 2.0) + 5.0 * kPi, 1e-9);
  // G18 G3 turns positively about +Y: from x = 5 down through z = 2 - 5 to x = -5
  expect_box(facts.print_bbox, Vec3(-5, -5, -3), Vec3(5, 5, 2));
  // F300: 5 mm/s (the G0 before it has no feed rate)
  EXPECT_NEAR(facts.feed_rate_time_s, (std::hypot(10.0 * kPi, 2.0) + 5.0 * kPi) / 5.0, 1e-9);
  EXPECT_GT(facts.estimated_time_s, facts.feed_rate_time_s);
  EXPECT_EQ(facts.n_moves_without_feed, 1);
  // no move stays at one z (the G18 arc ends where it starts, but dips): the run's start
  EXPECT_EQ(facts.layer_z_values, std::vector<double>{0.0});
  // a helix reversed is the same curve
  const GcodeImport imported = read_gcode(kDir + "helix.ngc", GcodeOptions{});
  const PrintPath& path = imported.toolpath.paths.at(0);
  const PrintPath back = path.reversed();
  for (double s : {0.1, 0.37, 0.8})
    EXPECT_LT((back.edge_point(1, s) - path.edge_point(0, 1.0 - s)).norm(), 1e-12);
}

TEST(GcodeFiles, G91Block) {
  const GcodeFacts facts = facts_of("relative_moves_g91.gcode");
  EXPECT_EQ(facts.rule, "e");
  EXPECT_EQ(facts.n_print_moves, 4);
  EXPECT_DOUBLE_EQ(facts.print_length_mm, 60.0);
  EXPECT_EQ(facts.n_travel_moves, 2);  // G1 Z0.3 without E, G0 X50 Y50
  EXPECT_NEAR(facts.travel_length_mm, 0.3 + std::sqrt(5000.0), 1e-12);
  expect_box(facts.print_bbox, Vec3(0, 0, 0.3), Vec3(20, 10, 0.3));
  EXPECT_DOUBLE_EQ(facts.extrusion_e_total, 3.0);
}

TEST(GcodeFiles, M83RelativeExtrusionAndShortNumbers) {
  // Z.2, E.8 prime, E-.8 retracts (two), two print paths of 30 and 20 mm
  const GcodeFacts facts = facts_of("relative_e_m83.gcode");
  EXPECT_EQ(facts.n_print_moves, 3);
  EXPECT_EQ(facts.n_print_paths, 2);
  EXPECT_DOUBLE_EQ(facts.print_length_mm, 50.0);
  EXPECT_EQ(facts.n_travel_moves, 3);
  EXPECT_NEAR(facts.travel_length_mm, 0.2 + std::sqrt(200.0) + 10.0, 1e-12);
  EXPECT_EQ(facts.n_retractions, 2);
  EXPECT_NEAR(facts.extrusion_e_total, 2.5, 1e-12);
  EXPECT_EQ(facts.layer_z_values, std::vector<double>{0.2});
}

// the facts of G-code text, whose print paths must be the import's
GcodeFacts facts_split_as_imported(const std::string& text, const std::string& name) {
  const GcodeProgram program = parse_gcode_program(text, name, GcodeOptions{});
  const GcodeFacts facts = gcode_facts(program, PrintRule::automatic);
  EXPECT_EQ(import_gcode_program(program, GcodeOptions{}).toolpath.paths.size(),
            static_cast<std::size_t>(facts.n_print_paths));
  return facts;
}

TEST(GcodeFiles, PrintPathsSplitAtFeedChangesAsTheImportSplitsThem) {
  // a CAM contour whose plunge, cut and lead-out run at three feeds is one connected run but
  // three print paths, as a scenario imports it (a path has one speed)
  const std::string text =
      "G21 G90\nG0 X0 Y0 Z5\nM3 S1000\nG1 Z0 F300\nG1 X20 F1200\nG1 Y10\nG1 X0 F600\n"
      "M5\nG0 Z5\n";
  const GcodeFacts facts = facts_split_as_imported(text, "contour.nc");
  EXPECT_EQ(facts.n_print_moves, 4);
  EXPECT_EQ(facts.n_print_paths, 3);
}

TEST(GcodeFiles, PrintPathsSplitAtASlicersLayerMarkAsTheImportSplitsThem) {
  // one connected climb at one feed with a ;LAYER_CHANGE in it (a spiral vase's turn): two
  // print paths and two layers, in inspect as in the import
  const std::string text =
      "G1 X0 Y0 Z0.2 F1200\nG1 X10 Z0.3 E1\nG1 Y10 Z0.4 E2\n;LAYER_CHANGE\nG1 X0 Z0.5 E3\n"
      "G1 Y0 Z0.6 E4\n";
  const GcodeFacts facts = facts_split_as_imported(text, "vase.gcode");
  EXPECT_EQ(facts.n_print_paths, 2);
  EXPECT_EQ(facts.layer_z_values, (std::vector<double>{0.2, 0.4}));
}

TEST(GcodeFiles, AerosolShutterCodes) {
  // auto: no E, M3/M5 present -> shutter: 25 + 20 mm printed, the G1 with M5 is a travel
  const GcodeFacts facts = facts_of("aerosol_m3_m5.ngc");
  EXPECT_EQ(facts.rule, "shutter");
  EXPECT_EQ(facts.n_print_moves, 3);
  EXPECT_EQ(facts.n_print_paths, 2);
  EXPECT_DOUBLE_EQ(facts.print_length_mm, 45.0);
  EXPECT_EQ(facts.n_travel_moves, 3);
  EXPECT_NEAR(facts.travel_length_mm, 1.0 + std::sqrt(425.0) + std::sqrt(500.0), 1e-12);
  // the feed rule prints the closed-shutter G1 too
  const GcodeFacts feed = facts_of("aerosol_m3_m5.ngc", PrintRule::feed);
  EXPECT_EQ(feed.n_print_moves, 4);
  EXPECT_NEAR(feed.print_length_mm, 45.0 + std::sqrt(425.0), 1e-12);
  // other codes: with M106/M107 nothing opens, so nothing prints
  GcodeOptions fan;
  fan.rule = PrintRule::shutter;
  fan.open_code = "M106";
  fan.close_code = "M107";
  EXPECT_EQ(
      gcode_facts(read_gcode_program(kDir + "aerosol_m3_m5.ngc", fan), fan.rule).n_print_moves, 0);
  // the import: two paths at F300 = 5 mm/s
  const GcodeImport imported = read_gcode(kDir + "aerosol_m3_m5.ngc", GcodeOptions{});
  EXPECT_EQ(imported.rule, PrintRule::shutter);
  ASSERT_EQ(imported.toolpath.paths.size(), 2u);
  EXPECT_DOUBLE_EQ(imported.toolpath.paths[0].speed_mm_s, 5.0);
  EXPECT_EQ(imported.point_lines[1], (std::vector<int>{11, 11}));
}

TEST(GcodeFiles, CuraPurgeLine) {
  // two 180 mm purge lines and a 2 x 10 mm start of the wall, all at z = 0.3
  const GcodeFacts facts = facts_of("cura_purge.gcode");
  EXPECT_EQ(facts.rule, "e");
  EXPECT_EQ(facts.n_print_moves, 4);
  EXPECT_EQ(facts.n_print_paths, 3);
  EXPECT_DOUBLE_EQ(facts.print_length_mm, 380.0);
  EXPECT_EQ(facts.n_travel_moves, 5);
  EXPECT_NEAR(facts.travel_length_mm,
              2.0 + std::sqrt(0.01 + 400.0 + 2.89) + 0.3 + 1.7 + std::sqrt(92.16 + 100.0 + 2.89),
              1e-9);
  EXPECT_EQ(facts.n_retractions, 1);
  EXPECT_NEAR(facts.extrusion_e_total, 30.66, 1e-12);
  EXPECT_EQ(facts.layer_z_values, std::vector<double>{0.3});
  expect_box(facts.print_bbox, Vec3(0.1, 10, 0.3), Vec3(20, 200, 0.3));
  // the file's `;LAYER_COUNT:1`, as many layers as the import finds
  EXPECT_EQ(gcode_facts_json(facts)["slicer_notes"]["layer_count"], 1);
}

TEST(GcodeFiles, FiveLayerSquare) {
  const GcodeFacts facts = facts_of("square_5_layers.gcode");
  EXPECT_EQ(facts.n_print_moves, 20);
  EXPECT_NEAR(facts.print_length_mm, 400.0, 1e-9);
  EXPECT_EQ(facts.n_travel_moves, 6);  // five Z steps and the first XY travel
  EXPECT_NEAR(facts.travel_length_mm, 1.0 + std::sqrt(200.0), 1e-9);
  ASSERT_EQ(facts.layer_z_values.size(), 5u);
  for (int k = 0; k < 5; ++k) EXPECT_NEAR(facts.layer_z_values[k], 0.2 * (k + 1), 1e-12);
  EXPECT_NEAR(facts.extrusion_e_total, 13.3, 1e-9);
  // 400 mm at 20 mm/s, 1 mm of Z at 10 mm/s, sqrt(200) mm at 100 mm/s
  EXPECT_NEAR(facts.feed_rate_time_s, 20.0 + 0.1 + std::sqrt(200.0) / 100.0, 1e-9);
  EXPECT_GT(facts.estimated_time_s, facts.feed_rate_time_s);
  // layers [1, 3]: three paths numbered 0..2 from z = 0.4
  GcodeOptions options;
  options.first_layer = 1;
  options.last_layer = 3;
  const GcodeImport selected = read_gcode(kDir + "square_5_layers.gcode", options);
  ASSERT_EQ(selected.toolpath.paths.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(selected.toolpath.paths[k].layer, k);
    EXPECT_NEAR(selected.toolpath.paths[k].front().z(), 0.2 * (k + 2), 1e-12);
  }
  EXPECT_EQ(selected.first_layer, 1);
  EXPECT_EQ(selected.layer_z_mm.size(), 5u);
  ASSERT_TRUE(selected.first_point_mm.has_value());
  EXPECT_LT((*selected.first_point_mm - Vec3(10, 10, 0.4)).norm(), 1e-12);
  // a range outside the file is one clear error
  options.last_layer = 5;
  try {
    read_gcode(kDir + "square_5_layers.gcode", options);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problems().at(0).message, "layers [1, 5] not in the file's 5 layers (0 to 4)");
  }
}

// estimated_time_s is the firmware's trapezoids, in closed form on straight lines: a move of L
// at feed v from rest to rest with acceleration a takes L / v + v / a (when L >= v^2 / a)
TEST(GcodeFiles, EstimatedTimeIsTheFirmwaresTrapezoids) {
  const auto estimate = [](const std::string& text, const std::string& mode = "marlin") {
    const GcodeProgram program = parse_gcode_program(text, "estimate.gcode", GcodeOptions{});
    InspectBaseline baseline;
    baseline.mode = mode;
    return gcode_facts(program, PrintRule::automatic, baseline).estimated_time_s;
  };
  // the cartesian machine: 300 mm/s and 3000 mm/s^2 in x and y
  const double a = 3000.0;
  EXPECT_NEAR(estimate("G21 G90\nG1 X100 F3000\n"), 100.0 / 50.0 + 50.0 / a, 1e-9);
  EXPECT_NEAR(estimate("G21 G90\nG1 X100 F3000\n", "klipper"), 100.0 / 50.0 + 50.0 / a, 1e-9);
  // on a diagonal (3-4-5) Marlin's acceleration is a / |u_y|; Klipper's max_accel is the same
  // in every direction, as the firmware planner has it (inspect once gave Klipper Marlin's)
  EXPECT_NEAR(estimate("G21 G90\nG1 X60 Y80 F3000\n"), 100.0 / 50.0 + 50.0 / (a / 0.8), 1e-9);
  EXPECT_NEAR(estimate("G21 G90\nG1 X60 Y80 F3000\n", "klipper"), 100.0 / 50.0 + 50.0 / a, 1e-9);
  // two collinear moves are one queue: no stop between them
  EXPECT_NEAR(estimate("G1 X40 F3000\nG1 X100\n"), 100.0 / 50.0 + 50.0 / a, 1e-9);
  // a dwell, and a retraction at 30 mm/s, each empty the queue: two stops and their own times
  EXPECT_NEAR(estimate("G1 X40 F3000\nG4 P250\nG1 X100\n"), 100.0 / 50.0 + 2.0 * 50.0 / a + 0.25,
              1e-9);
  EXPECT_NEAR(estimate("M83\nG1 X40 E1 F3000\nG1 E-0.8 F1800\nG1 X100 E1 F3000\n"),
              100.0 / 50.0 + 2.0 * 50.0 / a + 0.8 / 30.0, 1e-9);
  // no F: the axis' top speed, 300 mm/s, reached after 15 mm of the 100
  EXPECT_NEAR(estimate("G0 X100\n"), 100.0 / 300.0 + 300.0 / a, 1e-9);
  // a corner costs time: the 90 degree junction is slower than going on straight
  EXPECT_GT(estimate("G1 X50 F3000\nG1 Y50\n"), 100.0 / 50.0 + 50.0 / a);
}

// --limits file: the file's settings in force at each move over the machine's (300 mm/s and
// 3000 mm/s^2 in x and y), in the same closed forms; --limits machine ignores them
TEST(GcodeFiles, EstimateUnderTheFilesOwnLimits) {
  const auto estimate = [](const std::string& text, const std::string& limits = "file",
                           const std::string& mode = "marlin") {
    const GcodeProgram program = parse_gcode_program(text, "estimate.gcode", GcodeOptions{});
    InspectBaseline baseline;
    baseline.mode = mode;
    baseline.limits = limits;
    return gcode_facts(program, PrintRule::automatic, baseline).estimated_time_s;
  };
  const double a = 3000.0;
  // Marlin: a move with E at M204 P, one without at T; Klipper: the smaller of the two
  const std::string accels = "M204 P500 T2000\nM83\n";
  EXPECT_NEAR(estimate(accels + "G1 X100 E1 F3000\n"), 2.0 + 50.0 / 500.0, 1e-9);
  EXPECT_NEAR(estimate(accels + "G1 X100 F3000\n"), 2.0 + 50.0 / 2000.0, 1e-9);
  EXPECT_NEAR(estimate(accels + "G1 X100 F3000\n", "file", "klipper"), 2.0 + 50.0 / 500.0, 1e-9);
  EXPECT_NEAR(estimate(accels + "G1 X100 E1 F3000\n", "machine"), 2.0 + 50.0 / a, 1e-9);
  // M201 and M203: an axis' own acceleration and feed rate
  EXPECT_NEAR(estimate("M201 X200\nG1 X100 F3000\n"), 2.0 + 50.0 / 200.0, 1e-9);
  EXPECT_NEAR(estimate("M203 X20\nG1 X100 F3000\n"), 100.0 / 20.0 + 20.0 / a, 1e-9);
  // a change between two collinear moves: one queue, each move at its own acceleration (up at
  // 500 over the first, down at 1000 over the second)
  EXPECT_NEAR(estimate("M204 T500\nG1 X100 F3000\nM204 T1000\nG1 X200\n"),
              200.0 / 50.0 + 50.0 / (2.0 * 500.0) + 50.0 / (2.0 * 1000.0), 1e-9);
  // Klipper's square-corner velocity: its default written out changes nothing, a slower one
  // slows the corner; a junction deviation as large as the corner's turn lets it go faster
  const std::string corner = "G1 X50 F3000\nG1 Y50\n";
  const double klipper = estimate(corner, "machine", "klipper");
  EXPECT_EQ(estimate("SET_VELOCITY_LIMIT SQUARE_CORNER_VELOCITY=5\n" + corner, "file", "klipper"),
            klipper);
  EXPECT_GT(estimate("SET_VELOCITY_LIMIT SQUARE_CORNER_VELOCITY=1\n" + corner, "file", "klipper"),
            klipper);
  EXPECT_LT(estimate("M205 J1\n" + corner), estimate(corner, "machine"));
  // no such source of limits
  try {
    estimate(corner, "slicer");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problems().at(0).key, "--limits");
  }
}

// Marlin's classic jerk (M205 X Y Z E, no M205 J): each axis's speed may jump by its jerk at a
// junction, by the difference of its speeds when it keeps its way and by the larger speed
// otherwise; when both moves may start from rest faster (their safe speeds), that is taken
TEST(GcodeFiles, EstimateUnderClassicJerk) {
  const auto estimate = [](const std::string& text, const std::string& mode = "marlin") {
    const GcodeProgram program = parse_gcode_program(text, "jerk.gcode", GcodeOptions{});
    InspectBaseline baseline;
    baseline.mode = mode;
    baseline.limits = "file";
    return gcode_facts(program, PrintRule::automatic, baseline).estimated_time_s;
  };
  // a trapezoid over length l from v0 up to v and down to v1 at acceleration a
  const auto trapezoid = [](double l, double v0, double v, double v1, double a) {
    return (v - v0) / a + (v - v1) / a + (l - (2 * v * v - v0 * v0 - v1 * v1) / (2 * a)) / v;
  };
  const double a = 1000.0;  // M204 P and T
  const std::string start = "M204 P1000 T1000\nM83\n";
  // 20 then 100 mm/s along x, jerk 10: the jump of 80 scales the junction to 20 * 10 / 80 =
  // 2.5 mm/s, and both moves' safe speed, 10, is taken instead (junction deviation: 20)
  const std::string speed_up = "G1 X50 F1200\nG1 X100 F6000\n";
  EXPECT_NEAR(estimate(start + "M205 X10 Y10\n" + speed_up),
              trapezoid(50, 0, 20, 10, a) + trapezoid(50, 10, 100, 0, a), 1e-9);
  EXPECT_NEAR(estimate(start + speed_up),
              trapezoid(50, 0, 20, 20, a) + trapezoid(50, 20, 100, 0, a), 1e-9);
  // a 90 deg corner at 50 mm/s, jerk 8: x stops and y starts, 50 each, so 8 mm/s. Its velocity
  // turns over tau = 8 / a (as every junction of the estimate), half on each move
  const double tau = 8.0 / a;
  EXPECT_NEAR(estimate(start + "M205 X8 Y8\nG1 X50 F3000\nG1 Y50\n"),
              2 * (trapezoid(50 - 0.5 * 8 * tau, 0, 50, 8, a) + 0.5 * tau), 1e-9);
  // the extruder's jerk: 0.05 then 0.25 mm of E per mm at 50 mm/s, 2.5 then 12.5 mm/s. E jerk
  // 2 scales the junction to 50 * 2 / 10 = 10 mm/s (the second move's safe speed, 2 / 0.25 =
  // 8, is below it); Marlin's default E jerk, 5, to 25 mm/s
  const std::string flow_step = "G1 X50 E2.5 F3000\nG1 X100 E12.5\n";
  EXPECT_NEAR(estimate(start + "M205 X10 Y10 E2\n" + flow_step),
              trapezoid(50, 0, 50, 10, a) + trapezoid(50, 10, 50, 0, a), 1e-9);
  EXPECT_NEAR(estimate(start + "M205 X10 Y10\n" + flow_step),
              trapezoid(50, 0, 50, 25, a) + trapezoid(50, 25, 50, 0, a), 1e-9);
  // a junction deviation set decides over the jerks; Klipper has no jerks
  const std::string corner = "G1 X50 F3000\nG1 Y50\n";
  EXPECT_EQ(estimate(start + "M205 X8 Y8 J0.02\n" + corner),
            estimate(start + "M205 J0.02\n" + corner));
  EXPECT_EQ(estimate(start + "M205 X1 Y1\n" + corner, "klipper"),
            estimate(start + corner, "klipper"));
}

// a look-ahead chain is planned and emptied every 2^20 pieces (bounded memory on a file of
// arcs that never stops): 2^20 collinear moves of 0.001 mm, then one of 100 mm, are two
// chains from rest to rest, L / v + 2 v / a, where one chain would be L / v + v / a
TEST(GcodeFiles, EstimateStopsEveryMillionPieces) {
  const int kPieces = 1 << 20;
  std::string text = "G21 G90\nG1 X0 F3000\n";
  text.reserve(16 * kPieces);
  char line[48];
  for (int i = 1; i <= kPieces; ++i) {
    std::snprintf(line, sizeof line, "G1 X%.3f\n", 0.001 * i);
    text += line;
  }
  const double fine_length = 0.001 * kPieces;
  text += "G1 X" + std::to_string(fine_length + 100.0) + "\n";
  const GcodeProgram program = parse_gcode_program(text, "long.gcode", GcodeOptions{});
  const double a = 3000.0;  // cartesian: 300 mm/s and 3000 mm/s^2 in x
  EXPECT_NEAR(gcode_facts(program, PrintRule::automatic).estimated_time_s,
              (fine_length + 100.0) / 50.0 + 2.0 * 50.0 / a, 1e-6);
}

// an arc of radius above 34 m is cut into at most 4096 chords per turn for the estimate (at
// 0.01 mm, a circle of radius 1e9 mm took 7 * 10^5 and 1000 of them minutes): nearly straight
// chords, each at the feed rate, so a circle takes its length / feed plus one ramp
TEST(GcodeFiles, EstimateCutsHugeArcsCoarser) {
  std::string text = "G21 G90\nG1 X0 Y0 F6000\n";
  for (int i = 0; i < 1000; ++i) text += "G2 I999999999\n";
  const GcodeProgram program = parse_gcode_program(text, "huge.gcode", GcodeOptions{});
  const double length_mm = 1000.0 * 2.0 * kPi * 999999999.0;
  const GcodeFacts facts = gcode_facts(program, PrintRule::automatic);
  EXPECT_NEAR(facts.estimated_time_s, length_mm / 100.0, 1e-6 * length_mm / 100.0);
  EXPECT_NEAR(facts.feed_rate_time_s, length_mm / 100.0, 1e-9 * length_mm / 100.0);
}

TEST(GcodeFiles, InspectJsonKeys) {
  const nlohmann::json json = gcode_facts_json(facts_of("arcs.gcode"));
  for (const char* key :
       {"n_print_moves", "n_travel_moves", "print_length_mm", "travel_length_mm", "n_layers",
        "layer_z_values", "print_bbox", "all_moves_bbox", "n_print_arcs", "n_retractions",
        "extrusion_e_total", "estimated_time_s", "rule", "slicer_notes", "firmware_settings"})
    EXPECT_TRUE(json.contains(key)) << key;
  EXPECT_EQ(json["firmware_settings"], nlohmann::json::array());  // it sets none
  // a hand-written file declares nothing: every note null
  EXPECT_EQ(json["slicer_notes"], (nlohmann::json{{"slicer", nullptr},
                                                  {"estimated_time_s", nullptr},
                                                  {"layer_count", nullptr},
                                                  {"filament_used_mm", nullptr}}));
  EXPECT_EQ(json["n_layers"], 1);
  EXPECT_EQ(json["print_bbox"]["min"][0], -10.0);
}

// each firmware setting as one JSON object: its first value and line, its last value and how
// often it changed
TEST(GcodeFiles, InspectListsTheFirmwareSettingsAsSet) {
  const GcodeProgram program = parse_gcode_program(
      "M204 P800 ; first layer\nG1 X1 E1 F600\nM204 P1250\nG1 X2 E2\n", "s.gcode", GcodeOptions{});
  const nlohmann::json json = gcode_facts_json(gcode_facts(program, PrintRule::automatic));
  EXPECT_EQ(json["firmware_settings"],
            nlohmann::json::parse(R"([{"command": "M204", "parameter": "P", "value": 800,
                                       "line": 1, "last_value": 1250, "n_changes": 1}])"));
}

// a file that holds no code (a README, a YAML file, comments only) gives no facts: inspect
// refuses it rather than print zeros that read as an empty print
TEST(GcodeFiles, InspectRefusesAFileWithoutCode) {
  const auto code_lines = [](const std::string& text) {
    return parse_gcode_program(text, "x.gcode", GcodeOptions{}).n_code_lines;
  };
  EXPECT_EQ(code_lines("name: part\nmachine: cartesian\n"), 0);
  EXPECT_EQ(code_lines("; comment\n(comment)\n$H\nPRINT_START\n\n"), 0);
  EXPECT_EQ(code_lines("; comment\nM104 S200\nN10 G1 X1*3\n"), 2);
  EXPECT_EQ(no_code_problem(3, 0),
            "holds no G-code: none of its 3 lines has a G or M code (only comments, blank lines "
            "or named commands): is it a G-code file?");
  EXPECT_EQ(no_code_problem(1, 0).rfind("holds no G-code: its one line has no G or M code", 0), 0u);
  EXPECT_EQ(no_code_problem(0, 0), "is empty (no G-code)");
  EXPECT_EQ(no_code_problem(3, 1), "");

  const std::string path = testing_support::scratch_file("readme.gcode");
  std::ofstream(path) << "This folder holds the parts.\nSee the README.\n";
  try {
    inspect_gcode_file(path, GcodeOptions{}, InspectBaseline{});
    FAIL() << "inspect printed facts of a file without code";
  } catch (const InputError& e) {
    ASSERT_EQ(e.problems().size(), 1u);
    EXPECT_EQ(e.problems()[0].file, path);
    EXPECT_NE(e.problems()[0].message.find("none of its 2 lines has a G or M code"),
              std::string::npos)
        << e.problems()[0].message;
  }
}

}  // namespace
}  // namespace depotwin
