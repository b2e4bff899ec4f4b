// `depotwin export`: the planned motion as G-code. Exact lines for a hand-made trajectory, the
// export -> import round trip on every shipped planar scenario, and the verb's refusals.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

#include "cli/export_verb.hpp"
#include "pipeline/job.hpp"
#include "pipeline/pipeline_test_util.hpp"
#include "toolpath/gcode.hpp"

namespace depotwin {
namespace {

using testing_support::depotwin;
using testing_support::fresh_directory;
using testing_support::read_text;
using testing_support::scenario_path;

// one depositing piece: (x0,0,0) to (x0 + 2,0,0) at a constant 2 mm/s, sampled every 1 ms
Trajectory straight_line_trajectory(double x0 = 0.0) {
  SampledMotion motion;
  for (int k = 0; k <= 1000; ++k) {
    motion.position_mm.push_back(Vec3(x0 + 0.002 * k, 0.0, 0.0));
    motion.velocity_mm_s.push_back(Vec3(2.0, 0.0, 0.0));
  }
  TrajectoryPiece piece;
  piece.t_end_s = 1.0;
  piece.path_index = 0;
  piece.depositing = true;
  piece.desired_speed_mm_s = 2.0;
  piece.motion = motion;
  return Trajectory("hand", {piece});
}

// the lines after the header (from the first G0), comments after ';' kept
std::string body(const std::string& gcode) {
  return gcode.substr(gcode.find("G0 "));
}

// A line off the 1e-4 mm grid (x from 0.123456789 mm) exported within 1e-5 mm: its ends are
// written to 6 decimals (rounding all three axes within a tenth of the tolerance) and the header
// names the tolerance as given; at the default 0.005 mm they keep 4 decimals. (4 decimals at
// any tolerance moved the ends 4.3e-5 mm and the header read "within 0 mm".)
TEST(ExportGcode, PositionsKeepTheDigitsTheToleranceNeeds) {
  const double x0 = 0.123456789;
  const Trajectory line = straight_line_trajectory(x0);
  GcodeExportJob job;
  job.process = "aerosol";
  GcodeExportSettings fine;
  fine.chord_tolerance_mm = 1e-5;
  const std::string gcode = trajectory_gcode(line, job, fine);
  EXPECT_NE(gcode.find("within 0.00001 mm"), std::string::npos) << gcode;
  EXPECT_NE(body(gcode).find("G0 X0.123457 Y0 Z0\n"), std::string::npos) << gcode;
  std::istringstream in(gcode);
  const Toolpath imported = parse_gcode(in, "fine.gcode", GcodeOptions{}).toolpath;
  ASSERT_EQ(imported.paths.size(), 1u);
  EXPECT_NEAR(imported.paths[0].points.front().x(), x0, 0.1 * fine.chord_tolerance_mm);
  EXPECT_NEAR(imported.paths[0].points.back().x(), x0 + 2.0, 0.1 * fine.chord_tolerance_mm);
  const std::string coarse = body(trajectory_gcode(line, job, GcodeExportSettings{}));
  EXPECT_EQ(coarse.rfind("G0 X0.1235 Y0 Z0\n", 0), 0u) << coarse;
}

// extrusion: one G1 with F = 2 mm/s x 60 and E = 0.4 x 0.2 x 2 / (pi 0.875^2) = 0.066520 mm
TEST(ExportGcode, ExtrusionLineHasFeedAndFilamentE) {
  GcodeExportJob job;
  job.scenario_name = "hand";
  job.planner = "hand";
  job.machine = "xy_stage";
  job.process = "extrusion";
  const std::string gcode = trajectory_gcode(straight_line_trajectory(), job, {});
  EXPECT_EQ(body(gcode), "G0 X0 Y0 Z0\nG1 X2 E0.06652 F120\n; end of job\n") << gcode;
  EXPECT_NE(gcode.find("G21 ; millimetres\nG90 ; absolute positions\nM83 ; relative extrusion\n"),
            std::string::npos)
      << gcode;
  EXPECT_NE(gcode.find("; G-code exported by depotwin 0.1.0\n"), std::string::npos) << gcode;
}

// aerosol: the shutter codes around the print move, no E; the codes are configurable
TEST(ExportGcode, AerosolLineIsBetweenShutterCodes) {
  GcodeExportJob job;
  job.process = "aerosol";
  EXPECT_EQ(body(trajectory_gcode(straight_line_trajectory(), job, {})),
            "G0 X0 Y0 Z0\nM3 ; shutter open\nG1 X2 F120\nM5 ; shutter closed\n; end of job\n");
  GcodeExportSettings fan;
  fan.open_code = "M106";
  fan.close_code = "M107";
  EXPECT_EQ(body(trajectory_gcode(straight_line_trajectory(), job, fan)),
            "G0 X0 Y0 Z0\nM106 ; shutter open\nG1 X2 F120\nM107 ; shutter closed\n; end of job\n");
}

// the distance from p to the segment a-b
double segment_distance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double length2 = ab.squaredNorm();
  const double u = length2 > 0.0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
  return (p - (a + u * ab)).norm();
}

// Segments bucketed in a grid of 1 mm cells: the distance from a point to the nearest one,
// capped at 1 mm (enough to check tolerances of micrometres).
class SegmentGrid {
 public:
  void add(const Vec3& a, const Vec3& b) {
    segments_.push_back({a, b});
    const Vec3 lo = a.cwiseMin(b), hi = a.cwiseMax(b);
    for (long x = cell(lo.x()); x <= cell(hi.x()); ++x)
      for (long y = cell(lo.y()); y <= cell(hi.y()); ++y)
        for (long z = cell(lo.z()); z <= cell(hi.z()); ++z)
          cells_[{x, y, z}].push_back(segments_.size() - 1);
  }
  double distance(const Vec3& p) const {
    double best = 1.0;
    for (long dx = -1; dx <= 1; ++dx)
      for (long dy = -1; dy <= 1; ++dy)
        for (long dz = -1; dz <= 1; ++dz) {
          const auto found = cells_.find({cell(p.x()) + dx, cell(p.y()) + dy, cell(p.z()) + dz});
          if (found == cells_.end()) continue;
          for (size_t i : found->second)
            best = std::min(best, segment_distance(p, segments_[i].first, segments_[i].second));
        }
    return best;
  }

 private:
  static long cell(double v) { return static_cast<long>(std::floor(v)); }
  std::vector<std::pair<Vec3, Vec3>> segments_;
  std::map<std::array<long, 3>, std::vector<size_t>> cells_;
};

// the planned depositing motion every 1 ms, as polylines (one per depositing piece)
std::vector<std::vector<Vec3>> planned_print_polylines(const Trajectory& trajectory) {
  std::vector<std::vector<Vec3>> polylines;
  for (const TrajectoryPiece& piece : trajectory.pieces()) {
    if (!piece.depositing || piece.t_end_s <= piece.t_begin_s) continue;
    polylines.emplace_back();
    const double duration_s = piece.t_end_s - piece.t_begin_s;
    const int steps = static_cast<int>(std::ceil(duration_s / 0.001));
    for (int k = 0; k <= steps; ++k) {
      Vec3 p, v, a;
      evaluate_motion(piece, std::min(duration_s, 0.001 * k), p, v, a);
      polylines.back().push_back(p);
    }
  }
  return polylines;
}

double polyline_length(const std::vector<Vec3>& points) {
  double length = 0.0;
  for (size_t i = 1; i < points.size(); ++i) length += (points[i] - points[i - 1]).norm();
  return length;
}

// Every shipped scenario that 3-axis G-code can represent (the planar ones), every planner:
// exported, imported again, the print length agrees to 0.1 % and the two paths lie within
// the chord tolerance of each other both ways (Hausdorff distance), plus the 0.05 um of the
// written numbers' rounding. Conformal scenarios are skipped: their tool axis tilts.
TEST(ExportGcode, RoundTripOnEveryShippedPlanarScenario) {
  const std::string dir = fresh_directory("export_round_trip");
  GcodeExportSettings settings;
  const double tolerance_mm = settings.chord_tolerance_mm + 1e-4;
  std::set<std::string> exported, skipped;
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(DEPOTWIN_SCENARIOS_DIR))
    if (entry.path().extension() == ".yaml") files.push_back(entry.path().string());
  std::sort(files.begin(), files.end());
  for (const std::string& file : files) {
    const Scenario scenario = load_scenario(file);
    if (scenario.surface) {
      skipped.insert(scenario.name);
      continue;
    }
    const PreparedJob job = prepare_job(scenario);
    for (const PlannerSpec& spec : scenario.planners) {
      SCOPED_TRACE(scenario.name + " / " + spec.run_label());
      const Trajectory trajectory = plan_job(job, spec).trajectory;
      GcodeExportJob export_job;
      export_job.process = scenario.process.type;
      export_job.bead_width_mm = scenario.process.bead_width_mm;
      export_job.layer_height_mm = scenario.process.layer_height_mm;
      const std::string gcode = trajectory_gcode(trajectory, export_job, settings);
      // the importer's automatic rule finds E (extrusion) or the M3/M5 shutter (aerosol)
      std::istringstream in(gcode);
      const GcodeImport import = parse_gcode(in, scenario.name + ".gcode", GcodeOptions{});
      EXPECT_EQ(import.rule,
                scenario.process.type == "extrusion" ? PrintRule::e : PrintRule::shutter);
      // the header's counts are the file's: a move whose E the digits cannot show (the flow's
      // last trickle) is written without E and counted as the travel a reader takes it for
      // (uniform's export said 657 print moves where the file had 654: three wrote no E, one
      // wrote E0)
      const std::string counts = "print moves (";
      const std::size_t counts_at = gcode.find(counts);
      ASSERT_NE(counts_at, std::string::npos);
      const std::size_t count_begin = gcode.rfind(' ', gcode.rfind(' ', counts_at - 1) - 1) + 1;
      std::size_t moves_in_file = 0;
      for (const PrintPath& path : import.toolpath.paths) moves_in_file += path.points.size() - 1;
      EXPECT_EQ(std::stoul(gcode.substr(count_begin)), moves_in_file);
      const std::size_t length_at = gcode.find("print length ", counts_at) + 13;
      EXPECT_NEAR(std::stod(gcode.substr(length_at)), import.toolpath.print_length_mm(),
                  1e-3 + 1e-4 * import.toolpath.print_length_mm());
      EXPECT_EQ(gcode.find(" E0 "), std::string::npos);
      EXPECT_EQ(gcode.find(" E0\n"), std::string::npos);
      // the file as a firmware reads it: every move at its F, and its dwells, take the plan's
      // time (one straight G0 per transition, at the planned path's length over its time, made
      // thompson_fig11's uniform file 16.25 s of its 17.79; a corner's loop was a pause); its E
      // adds up to the header's E total (each written E's rounding carried to the next: a
      // stop_and_go ramp's E0.00124735 written E0.00125 put 0.12 % more E in the file)
      const GcodeProgram program = parse_gcode_program(gcode, "exported.gcode", GcodeOptions{});
      double file_time_s = program.dwell_s;
      for (const GcodeMove& move : program.moves)  // (the first, to the job's start, has no F)
        if (&move != &program.moves.front() || move.feed_mm_s > 0.0)
          file_time_s += move.length_mm / move.feed_mm_s;
      EXPECT_NEAR(file_time_s, trajectory.duration_s(), 2e-3 * trajectory.duration_s());
      if (export_job.process == "extrusion") {
        const std::size_t e_at = gcode.find("E total ");
        ASSERT_NE(e_at, std::string::npos);
        EXPECT_NEAR(program.extrusion_e_total, std::stod(gcode.substr(e_at + 8)), 5e-4);
      }
      // arcs (G2/G3 written where the plan runs on a circle) as fine chords for the distances
      const Toolpath imported = import.toolpath.chorded(1e-5);

      // print length: the planned motion's against the file's
      const std::vector<std::vector<Vec3>> planned = planned_print_polylines(trajectory);
      double planned_length_mm = 0.0;
      for (const auto& polyline : planned) planned_length_mm += polyline_length(polyline);
      EXPECT_NEAR(imported.print_length_mm(), planned_length_mm, 1e-3 * planned_length_mm);

      // Hausdorff distance: planned samples to the file's lines, the file's points to the plan
      SegmentGrid imported_grid, planned_grid;
      for (const PrintPath& path : imported.paths)
        for (size_t i = 1; i < path.points.size(); ++i)
          imported_grid.add(path.points[i - 1], path.points[i]);
      for (const auto& polyline : planned)
        for (size_t i = 1; i < polyline.size(); ++i) planned_grid.add(polyline[i - 1], polyline[i]);
      double planned_to_file_mm = 0.0, file_to_planned_mm = 0.0;
      for (const auto& polyline : planned)
        for (const Vec3& p : polyline)
          planned_to_file_mm = std::max(planned_to_file_mm, imported_grid.distance(p));
      for (const PrintPath& path : imported.paths)
        for (size_t i = 0; i < path.points.size(); ++i) {
          file_to_planned_mm = std::max(file_to_planned_mm, planned_grid.distance(path.points[i]));
          if (i > 0)
            file_to_planned_mm =
                std::max(file_to_planned_mm,
                         planned_grid.distance(0.5 * (path.points[i - 1] + path.points[i])));
        }
      EXPECT_LE(planned_to_file_mm, tolerance_mm);
      EXPECT_LE(file_to_planned_mm, tolerance_mm);
      exported.insert(scenario.name);
    }
  }
  EXPECT_EQ(skipped,
            (std::set<std::string>{"shembekar_beam", "shembekar_bonnet", "shembekar_fillet"}));
  // every other shipped scenario went through the round trip (at least the six planar paper
  // scenarios and the imported G-code one)
  EXPECT_EQ(exported.size() + skipped.size(), files.size());
  EXPECT_GE(exported.size(), 7u);
  EXPECT_EQ(exported.count("gcode_rounded_square"), 1u);
}

// Where the plan runs on a circle, the export writes arcs: bezier flies the rounded square's
// G3 corners exactly (all but each layer's last, where the path ends), so its export has G3
// moves whose centres are the file's corner centres; lspb_mtt follows the corners' chords,
// whose samples leave the circle by up to the 0.01 mm chord tolerance, more than the export's
// 0.005 mm: no arcs.
TEST(ExportGcode, ArcsWhereThePlanRunsOnACircle) {
  const Scenario scenario = load_scenario(scenario_path("gcode_rounded_square.yaml"));
  const PreparedJob job = prepare_job(scenario);
  GcodeExportJob export_job;
  export_job.process = "extrusion";
  const auto exported = [&](const std::string& planner) {
    for (const PlannerSpec& spec : scenario.planners)
      if (spec.name == planner)
        return trajectory_gcode(plan_job(job, spec).trajectory, export_job, GcodeExportSettings{});
    return std::string();
  };
  const std::string bezier = exported("bezier");
  std::istringstream lines(bezier);
  int corner_arcs = 0;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("G3 ", 0) != 0) continue;
    // a corner of radius 3: the centre 3 mm from the start (I, J relative to it). (The last
    // corner of each layer is flown on chords with small blends between them, which may fit
    // an arc of another radius within the tolerance, and be written as one.)
    const double i = std::stod(line.substr(line.find(" I") + 2));
    const double j = std::stod(line.substr(line.find(" J") + 2));
    if (std::abs(std::hypot(i, j) - 3.0) <= 1e-3) ++corner_arcs;
  }
  EXPECT_GE(corner_arcs, 9) << bezier;                 // three exact corners a layer, three layers
  EXPECT_EQ(bezier.find("\nG2 "), std::string::npos);  // every corner turns left
  EXPECT_EQ(exported("lspb_mtt").find("\nG3 "), std::string::npos);
}

// the CLI: the header names the scenario and planner; the same input gives the same bytes
TEST(ExportVerb, WritesTheNamedPlannerDeterministically) {
  const std::string dir = fresh_directory("export_verb");
  const std::string scenario = scenario_path("thompson_fig7.yaml");
  const auto first =
      depotwin("export " + scenario + " --planner lspb_mtt --out " + dir + "/a.gcode");
  ASSERT_EQ(first.status, 0) << first.output;
  const auto second =
      depotwin("export " + scenario + " --planner lspb_mtt --out " + dir + "/b.gcode");
  ASSERT_EQ(second.status, 0) << second.output;
  const std::string gcode = read_text(dir + "/a.gcode");
  EXPECT_EQ(gcode, read_text(dir + "/b.gcode"));
  EXPECT_EQ(gcode.rfind("; G-code exported by depotwin 0.1.0\n; scenario: thompson_fig7 (" +
                            scenario + ")\n; planner: lspb_mtt\n; machine: xy_stage\n",
                        0),
            0u)
      << gcode.substr(0, 300);
  EXPECT_NE(gcode.find("\nM3 ; shutter open\n"), std::string::npos);
  size_t files = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 2u);  // no temporary file left beside them
}

// refusals: exit 2, the option or key named, nothing written
TEST(ExportVerb, RefusesBadOutputPlannerChoiceAndConformalScenarios) {
  const std::string dir = fresh_directory("export_refusals");
  const std::string fig7 = scenario_path("thompson_fig7.yaml");
  auto r = depotwin("export " + fig7 + " --planner lspb_mtt --out " + dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output, "error: --out: '" + dir + "' is a directory; name a file, e.g. " + dir +
                          "/job.gcode\n");
  r = depotwin("export " + fig7 + " --planner lspb_mtt --out " + dir + "/missing/job.gcode");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output, "error: --out: '" + dir + "/missing' is not a directory (for '" + dir +
                          "/missing/job.gcode')\n");
  r = depotwin("export " + fig7 + " --out " + dir + "/job.gcode");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output,
            "error: --planner: export writes one planner's motion; choose one of lspb_mtt, "
            "stop_and_go\n");
  r = depotwin("export " + scenario_path("shembekar_fillet.yaml") + " --out " + dir + "/job.gcode");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("toolpath: export writes 3-axis G-code, which cannot carry the tilted "
                          "tool axis of a conformal toolpath"),
            std::string::npos)
      << r.output;
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

// a built-in machine's MJCF is named by no key of the scenario: export wrote G-code over
// models/cartesian.xml, and every scenario on the machine then failed; the models' folder is
// refused (on a copy of it, so that a failure cannot harm the shipped one)
TEST(ExportVerb, NeverWritesInTheMachineModelsFolder) {
  namespace fs = std::filesystem;
  const std::string dir = fresh_directory("export_models");
  fs::copy(std::string(DEPOTWIN_SOURCE_DIR) + "/models", dir + "/models",
           fs::copy_options::recursive);
  const std::string model = dir + "/models/cartesian.xml";
  const std::string before = read_text(model);
  const auto r = testing_support::shell("DEPOTWIN_MODELS_DIR=" + dir + "/models " +
                                        std::string(DEPOTWIN_BINARY_DIR) + "/depotwin export " +
                                        scenario_path("gcode_rounded_square.yaml") +
                                        " --planner lspb_mtt --out " + model);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("error: --out: '" + model + "' is in the machine models' folder (" + dir +
                          "/models), which depotwin reads; name a file elsewhere"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(read_text(model), before);
}

}  // namespace
}  // namespace depotwin
