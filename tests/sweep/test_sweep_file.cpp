// Sweep files and scenario overrides: the tasks a file makes (mixed-radix order, zips, ranges),
// the overrides applied to the scenario's YAML tree and validated by the loader (problems at
// the sweep file's lines), input hashes, and every bad input listed at once.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>

#include "pipeline/pipeline_test_util.hpp"
#include "scenario/overrides.hpp"
#include "scenario/sweep_file.hpp"
#include "sweep/sweep.hpp"

namespace depotwin {
namespace {

using testing_support::fresh_directory;
using testing_support::read_text;
using testing_support::scenario_path;
using testing_support::write_text;

// the problems of an InputError as "file:line: key: message" lines
std::vector<std::string> problems_of(const std::function<void()>& action) {
  std::vector<std::string> lines;
  try {
    action();
  } catch (const InputError& error) {
    for (const Problem& problem : error.problems()) lines.push_back(problem.str());
  }
  return lines;
}

TEST(SweepFile, GridTasksCountInMixedRadixWithTheLastKeyFastest) {
  const std::string dir = fresh_directory("sweep_grid");
  const std::string file =
      write_text(dir, "s.yaml", "base: " + scenario_path("thompson_fig11.yaml") + R"(
grid:
  planner: [lspb_mtt, stop_and_go, bezier]
  toolpath.speed: [1, 2, 3]
  limits.a_max: [10, 30, 100]
)");
  const Sweep sweep(file, dir + "/out");
  ASSERT_EQ(sweep.size(), 27u);
  EXPECT_EQ(sweep.spec().name, "s");  // the file's stem
  // task 16 = 1 x 9 + 2 x 3 + 1: stop_and_go, speed 3, a_max 30
  const SweepTask task = sweep.task(16);
  ASSERT_EQ(task.parameters.size(), 3u);
  EXPECT_EQ(task.parameters[0].second.text, "stop_and_go");
  EXPECT_EQ(task.parameters[1].second.text, "3");
  EXPECT_EQ(task.parameters[2].second.text, "30");
  EXPECT_EQ(task.parameters_text(), "planner=stop_and_go, toolpath.speed=3, limits.a_max=30");
  EXPECT_EQ(sweep.task_folder_name(16), "tasks/0016");
  EXPECT_EQ(sweep.task(26).parameters_text(), "planner=bezier, toolpath.speed=3, limits.a_max=100");
}

TEST(SweepFile, ZipAdvancesTogetherAfterTheGridAndRangesExpand) {
  const std::string dir = fresh_directory("sweep_zip");
  const std::string file = write_text(dir, "s.yaml",
                                      "name: zipped\nbase: " + scenario_path("ganganath_n20.yaml") +
                                          R"(
set: {planner: lspb_mtt}
grid:
  order: [as_given, christofides+three_opt]
zip:
  toolpath.random_segments.seed: {from: 1, to: 200}
  toolpath.speed: {from: 0.5, to: 100, step: 0.5}
)");
  const Sweep sweep(file, "");
  EXPECT_EQ(sweep.out_directory(), "results/zipped");
  ASSERT_EQ(sweep.size(), 400u);  // 2 orders x 200 zipped pairs
  // task 201 = order 1, zip position 1
  const SweepTask task = sweep.task(201);
  EXPECT_EQ(task.parameters_text(),
            "order=christofides+three_opt, toolpath.random_segments.seed=2, toolpath.speed=1");
  EXPECT_EQ(sweep.task(399).parameters_text(),
            "order=christofides+three_opt, toolpath.random_segments.seed=200, "
            "toolpath.speed=100");
  // the set: override first, then the parameters in file order
  ASSERT_EQ(task.overrides.size(), 4u);
  EXPECT_EQ(task.overrides[0].key, "planner");
  EXPECT_EQ(task.overrides[3].key, "toolpath.speed");
  EXPECT_EQ(task.overrides[3].line, 8);
}

TEST(SweepFile, RangesByStepAndCountIncludeTheirEndsAndReadAsWritten) {
  const std::string dir = fresh_directory("sweep_ranges");
  const std::string file =
      write_text(dir, "s.yaml", "base: " + scenario_path("giberti_circle.yaml") + R"(
grid:
  planners[0].delta: {from: 0.1, to: 0.5, step: 0.1}
  toolpath.speed: {from: 5, to: 20, count: 4}
)");
  const SweepSpec spec = read_sweep_file(file);
  ASSERT_EQ(spec.grid.size(), 2u);
  std::vector<std::string> deltas, speeds;
  for (const SweepValue& v : spec.grid[0].values) deltas.push_back(v.yaml);
  for (const SweepValue& v : spec.grid[1].values) speeds.push_back(v.yaml);
  // 0.1 + 2 x 0.1 is written 0.3, not 0.30000000000000004
  EXPECT_EQ(deltas, (std::vector<std::string>{"0.1", "0.2", "0.3", "0.4", "0.5"}));
  EXPECT_EQ(speeds, (std::vector<std::string>{"5", "10", "15", "20"}));
  EXPECT_DOUBLE_EQ(*spec.grid[0].values[2].number, 0.3);
  EXPECT_EQ(spec.task_count, 20u);
}

TEST(SweepFile, EveryProblemOfTheFileIsListedWithItsLine) {
  const std::string dir = fresh_directory("sweep_bad_file");
  const std::string file = write_text(dir, "bad.yaml", R"(base: nowhere.yaml
colour: blue
keep: everything
grid:
  toolpath.speed: []
  limits..a_max: [1, 2]
  limits.v_max: 4
  order: [as_given, as_given]
zip:
  limits.x.v_max: [1, 2]
  limits.y.v_max: [1, 2, 3]
  toolpath.speed: [1, 2]
)");
  const std::vector<std::string> problems = problems_of([&] { read_sweep_file(file); });
  const std::string dot = dir + "/";
  const std::vector<std::string> expected{
      file + ":2: colour: unknown key (expected one of: name, base, keep, set, grid, zip)",
      file + ":1: base: scenario file 'nowhere.yaml' not found (looked for " + dot +
          "nowhere.yaml)",
      file +
          ":3: keep: expected metrics (each task keeps metrics.json) or all (everything "
          "`run --no-render` writes), got 'everything'",
      file + ":5: grid.toolpath.speed: is an empty list: a parameter needs at least one value",
      file +
          ":6: grid.limits..a_max: expected a key name at character 8 (keys are names joined "
          "by dots, with [index] for list entries: planners[0].delta)",
      file +
          ":7: grid.limits.v_max: expected a list of values or a range {from, to, step | "
          "count}, got '4' (a value every task gets goes under set:)",
      file + ":8: grid.order: lists as_given twice",
      file + ":12: zip.toolpath.speed: given twice (a key is set, swept in grid: or zipped, once)",
      file +
          ":11: zip.limits.y.v_max: has 3 values, zip.limits.x.v_max 2: zipped lists advance "
          "together, so they need one length",
  };
  EXPECT_EQ(problems, expected);
}

// numbers are one value whatever their text: 2, 2.0, 2e0 and +2 would run one task four times
TEST(SweepFile, ANumberWrittenTwoWaysIsOneValue) {
  const std::string dir = fresh_directory("sweep_number_twice");
  const std::string file = write_text(dir, "twice.yaml",
                                      "base: nowhere.yaml\ngrid:\n  toolpath.speed: [2, 2.0, 3]\n"
                                      "  limits.a_max: [2e1, 20.5, +20]\n");
  const std::vector<std::string> problems = problems_of([&] { read_sweep_file(file); });
  const auto has = [&](const std::string& text) {
    return std::find(problems.begin(), problems.end(), text) != problems.end();
  };
  EXPECT_TRUE(has(file + ":3: grid.toolpath.speed: lists 2.0 twice (2 and 2.0 are one value)"));
  EXPECT_TRUE(has(file + ":4: grid.limits.a_max: lists +20 twice (2e1 and +20 are one value)"));
  // a range whose values read alike as written would run one task several times
  const std::string close = write_text(
      dir, "close.yaml",
      "base: nowhere.yaml\ngrid:\n  toolpath.speed: {from: 1, to: 1.000000000001, count: 3}\n");
  const std::vector<std::string> range = problems_of([&] { read_sweep_file(close); });
  EXPECT_NE(std::find(range.begin(), range.end(),
                      close + ":3: grid.toolpath.speed: values 0 and 1 of the range both read 1: "
                              "its values are closer than the digits a value is written with "
                              "(widen the range or take fewer values)"),
            range.end())
      << ::testing::PrintToString(range);
}

TEST(SweepFile, AnEmptyGridAndAMissingBaseAreErrors) {
  const std::string dir = fresh_directory("sweep_empty");
  const std::string file = write_text(dir, "empty.yaml", "grid: {}\n");
  EXPECT_EQ(problems_of([&] { read_sweep_file(file); }),
            (std::vector<std::string>{
                file + ":1: base: missing: the scenario every task starts from (base: FILE.yaml)",
                file + ":1: grid: is empty: name at least one key and its values"}));
}

TEST(SweepFile, APathThatIsNotARegularFileIsNamed) {
  const std::string dir = fresh_directory("sweep_not_a_file");
  const std::string fifo = dir + "/pipe.yaml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(problems_of([&] { read_sweep_file(fifo); }),
            std::vector<std::string>{fifo + ": sweep file is not a regular file"});
  EXPECT_EQ(problems_of([&] { read_sweep_file(dir); }),
            std::vector<std::string>{dir + ": sweep file is a directory, not a file"});
  EXPECT_EQ(problems_of([&] { read_sweep_file(dir + "/none.yaml"); }),
            std::vector<std::string>{dir + "/none.yaml: sweep file not found"});
}

// a sweep file is read by the scenario's rules: UTF-8 text, one document, and a size a
// settings file may have (a 300 MB sparse file is refused before a byte is read)
TEST(SweepFile, TextOneDocumentAndASizeAsAScenarios) {
  const std::string dir = fresh_directory("sweep_text");
  const std::string latin1 = write_text(dir, "latin1.yaml", "name: caf\xE9\nbase: b.yaml\n");
  EXPECT_EQ(
      problems_of([&] { read_sweep_file(latin1); }),
      std::vector<std::string>{latin1 + ":1: byte 0xE9 at column 10 is not UTF-8: a sweep is UTF-8 "
                                        "text (YAML); save it as UTF-8"});
  const std::string two =
      write_text(dir, "two.yaml", "base: b.yaml\ngrid: {toolpath.speed: [1]}\n---\nbase: c\n");
  EXPECT_EQ(
      problems_of([&] { read_sweep_file(two); }),
      std::vector<std::string>{two + ":4: more than one YAML document (---): a sweep file holds "
                                     "one"});
  const std::string huge = write_text(dir, "huge.yaml", "base: b.yaml\n");
  std::filesystem::resize_file(huge, 300u << 20);
  EXPECT_EQ(
      problems_of([&] { read_sweep_file(huge); }),
      std::vector<std::string>{huge + ": the sweep file holds 300.0 MB, more than the 256 MB a "
                                      "sweep file may: its settings are text; long paths go in a "
                                      "G-code or STL file it names"});
  EXPECT_EQ(
      problems_of([&] { load_scenario(huge); }),
      std::vector<std::string>{huge + ": the scenario file holds 300.0 MB, more than the 256 MB a "
                                      "scenario file may: its settings are text; long paths go in "
                                      "a G-code or STL file it names"});
}

// the base scenario's text with overrides, as the loader reads it
Scenario load_with(const std::string& base, const std::vector<ScenarioOverride>& overrides) {
  return load_scenario(base, read_text(base), overrides);
}

ScenarioOverride at(const std::string& key, const std::string& value, int line = 7) {
  return ScenarioOverride{key, value, "sweep.yaml", line};
}

TEST(ScenarioOverrides, SetScalarsListEntriesAndCreateMissingKeys) {
  const std::string fig7 = scenario_path("thompson_fig7.yaml");
  const Scenario scenario =
      load_with(fig7, {at("toolpath.speed", "2"), at("limits.a_max", "100"),
                       at("limits.j_max", "500"), at("sim.settle_s", "0.25"),
                       at("planners[1]", "{name: stop_and_go, label: baseline}")});
  for (const PrintPath& path : scenario.toolpath.paths) EXPECT_EQ(path.speed_mm_s, 2.0);
  EXPECT_EQ(scenario.limits.axes[0].a_max_mm_s2, 100.0);
  EXPECT_EQ(scenario.limits.axes[1].j_max_mm_s3, 500.0);
  EXPECT_EQ(scenario.sim.settle_s, 0.25);
  ASSERT_EQ(scenario.planners.size(), 2u);
  EXPECT_EQ(scenario.planners[1].run_label(), "baseline");
}

TEST(ScenarioOverrides, PlannerKeepsOneOfTheScenarioWithItsParametersOrNamesAnother) {
  const std::string fig3 = scenario_path("giberti_fig3.yaml");
  // by name: the scenario's own entry, delta 0.45 kept
  Scenario scenario = load_with(fig3, {at("planner", "bezier")});
  ASSERT_EQ(scenario.planners.size(), 1u);
  EXPECT_EQ(scenario.planners[0].get("delta", 0.0), 0.45);
  // planners[0].delta applies to the base's list, before the choice
  scenario = load_with(fig3, {at("planner", "bezier"), at("planners[0].delta", "0.2")});
  EXPECT_EQ(scenario.planners[0].get("delta", 0.0), 0.2);
  // a planner the scenario does not list: its defaults
  scenario = load_with(scenario_path("thompson_fig7.yaml"), {at("planner", "bezier")});
  ASSERT_EQ(scenario.planners.size(), 1u);
  EXPECT_EQ(scenario.planners[0].name, "bezier");
  EXPECT_TRUE(scenario.planners[0].params.empty());
  // a name in a map of one's own
  scenario =
      load_with(scenario_path("thompson_fig7.yaml"), {at("planner", "{name: bezier, delta: 0.3}")});
  EXPECT_EQ(scenario.planners[0].get("delta", 0.0), 0.3);
}

TEST(ScenarioOverrides, ScalarsTakeTheirMapFormAndNullRemovesAKey) {
  // a planner name becomes {name: X}, an order name {method: X}
  const std::string fig7 = scenario_path("thompson_fig7.yaml");
  Scenario scenario =
      load_with(fig7, {at("planners[0].label", "first"), at("order.refine", "two_opt")});
  EXPECT_EQ(scenario.planners[0].run_label(), "first");
  EXPECT_EQ(scenario.order.method, "as_given");
  EXPECT_EQ(scenario.order.refine, "two_opt");
  // segments removed, a polyline in their place
  scenario = load_with(
      fig7, {at("toolpath.segments", "~"), at("toolpath.polylines", "[[[0, 0], [5, 0], [8, 6]]]")});
  ASSERT_EQ(scenario.toolpath.paths.size(), 1u);
  EXPECT_EQ(scenario.toolpath.paths[0].points.size(), 3u);
  // the random instances' seed
  const std::string n20 = scenario_path("ganganath_n20.yaml");
  const Scenario seed_7 = load_with(n20, {});
  const Scenario seed_8 = load_with(n20, {at("toolpath.random_segments.seed", "8")});
  ASSERT_EQ(seed_7.toolpath.paths.size(), 20u);
  ASSERT_EQ(seed_8.toolpath.paths.size(), 20u);
  EXPECT_NE(seed_7.toolpath.paths[0].points[0], seed_8.toolpath.paths[0].points[0]);
}

TEST(ScenarioOverrides, ProblemsOfAnOverrideAreAtItsLineOthersAtTheScenarios) {
  const std::string fig7 = scenario_path("thompson_fig7.yaml");
  const std::vector<std::string> problems = problems_of([&] {
    load_with(fig7, {at("limits.a_maxx", "10", 4), at("limits.v_max", "-1", 5),
                     at("planners[5].delta", "0.1", 6), at("toolpath.speed.x", "1", 7),
                     at("process.sigma_mm", "[1, 2]", 8)});
  });
  const std::vector<std::string> expected{
      "sweep.yaml:6: planners[5].delta: planners has 2 entries in the base scenario "
      "(planners[0]..planners[1])",
      "sweep.yaml:7: toolpath.speed.x: toolpath.speed is '3' in the base scenario, not a map: "
      "override toolpath.speed as a whole",
      "sweep.yaml:4: limits.a_maxx: unknown key (expected one of: v_max, a_max, j_max, x, y, z, "
      "joint)",
      "sweep.yaml:5: limits.v_max: must be in [1e-06, 1e+06], got -1",
      "sweep.yaml:8: process.sigma_mm: expected a number, got a list",
  };
  EXPECT_EQ(problems, expected);

  // a speed above the limits is the base file's segment, at its line
  const std::vector<std::string> speed =
      problems_of([&] { load_with(fig7, {at("toolpath.speed", "5")}); });
  ASSERT_EQ(speed.size(), 5u);
  EXPECT_EQ(speed[0], fig7 +
                          ":21: toolpath.segments[0]: print speed 5 mm/s needs 5 mm/s on x, "
                          "above limits v_max 4 (lower the speed or raise the limit)");

  // an unknown section an override makes on its way (`bogus.key` makes `bogus`) is the
  // override's, at its line (it was the base file's line 1)
  const std::vector<std::string> made =
      problems_of([&] { load_with(fig7, {at("bogus.key", "1", 9)}); });
  ASSERT_EQ(made.size(), 1u);
  EXPECT_EQ(made[0].rfind("sweep.yaml:9: bogus: unknown key (expected one of: name,", 0), 0u)
      << made[0];
}

// an alias (*ax) is the anchored node itself in the tree: an override inside it would change
// every place it is named (limits.x.a_max set y's as well, silently), so it is refused; a
// whole value is unbound from its key first and replaces only that key's
TEST(ScenarioOverrides, AnAliasedNodeIsNotEditedThroughOneOfItsNames) {
  const std::string dir = fresh_directory("override_alias");
  std::string text = read_text(scenario_path("thompson_fig7.yaml"));
  const std::string limits = "limits: {v_max: 4, a_max: 30}\n";
  ASSERT_NE(text.find(limits), std::string::npos);
  text.replace(text.find(limits), limits.size(),
               "limits:\n  x: &axis {v_max: 4, a_max: 30}\n  y: *axis\n");
  const std::string base = write_text(dir, "aliased.yaml", text);
  const std::vector<std::string> inside =
      problems_of([&] { load_with(base, {at("limits.x.a_max", "10", 4)}); });
  ASSERT_EQ(inside.size(), 1u);
  EXPECT_EQ(inside[0],
            "sweep.yaml:4: limits.x.a_max: limits.x is an anchored node (&) that an alias (*) "
            "repeats in the base scenario: an override there would change every place the alias "
            "names; write limits.x out in the base scenario");
  const Scenario whole = load_with(base, {at("limits.x", "{v_max: 4, a_max: 10}")});
  EXPECT_EQ(whole.limits.axes[0].a_max_mm_s2, 10.0);
  EXPECT_EQ(whole.limits.axes[1].a_max_mm_s2, 30.0);
  const Scenario other = load_with(base, {at("limits.y", "{v_max: 4, a_max: 10}")});
  EXPECT_EQ(other.limits.axes[0].a_max_mm_s2, 30.0);
  EXPECT_EQ(other.limits.axes[1].a_max_mm_s2, 10.0);
}

TEST(ScenarioOverrides, HashesFollowTheInputsNotTheWorkingDirectory) {
  const std::string dir = fresh_directory("sweep_hash");
  const std::string fig7 = read_text(scenario_path("thompson_fig7.yaml"));
  const std::string base = write_text(dir, "base.yaml", fig7);
  const std::string sweep_text = "base: base.yaml\ngrid:\n  planner: [lspb_mtt, stop_and_go]\n";
  const std::string file = write_text(dir, "s.yaml", sweep_text);
  const std::string hash_0 = Sweep(file, "").input_hash(Sweep(file, "").task(0));
  const std::string hash_1 = Sweep(file, "").input_hash(Sweep(file, "").task(1));
  EXPECT_EQ(hash_0.size(), 16u);
  EXPECT_NE(hash_0, hash_1);
  // the same sweep from another working directory: the same hash
  const std::string here = std::filesystem::current_path().string();
  std::filesystem::current_path(dir);
  const Sweep relative("s.yaml", "");
  EXPECT_EQ(relative.input_hash(relative.task(0)), hash_0);
  std::filesystem::current_path(here);
  // the same text again: the same hash
  write_text(dir, "base.yaml", fig7);
  EXPECT_EQ(Sweep(file, "").input_hash(Sweep(file, "").task(0)), hash_0);
  // a changed limit: another hash
  std::string changed = fig7;
  changed.replace(changed.find("a_max: 30"), 9, "a_max: 31");
  write_text(dir, "base.yaml", changed);
  EXPECT_NE(Sweep(file, "").input_hash(Sweep(file, "").task(0)), hash_0);

  // a file the scenario reads: its bytes count
  std::string with_model = fig7;
  with_model.replace(with_model.find("machine: xy_stage"), 17,
                     "machine: {model: stage.xml, kinematics: xy_stage}");
  write_text(dir, "base.yaml", with_model);
  write_text(dir, "stage.xml", "<mujoco model=\"one\"/>\n");
  const std::string model_one = Sweep(file, "").input_hash(Sweep(file, "").task(0));
  write_text(dir, "stage.xml", "<mujoco model=\"two, longer\"/>\n");
  EXPECT_NE(Sweep(file, "").input_hash(Sweep(file, "").task(0)), model_one);
}

// A private copy of the shipped xy_stage model that DEPOTWIN_MODELS_DIR points at while the
// object lives (the previous value comes back after), so a test can retune the machine
class PrivateModelsFolder {
 public:
  explicit PrivateModelsFolder(const std::string& dir)
      : folder_(dir + "/models"),
        shipped_(read_text(std::string(DEPOTWIN_SOURCE_DIR) + "/models/xy_stage.xml")) {
    std::filesystem::create_directories(folder_);
    write_stage(shipped_);
    const char* previous = std::getenv("DEPOTWIN_MODELS_DIR");
    had_previous_ = previous != nullptr;
    previous_ = previous ? previous : "";
    ::setenv("DEPOTWIN_MODELS_DIR", folder_.c_str(), 1);
  }
  ~PrivateModelsFolder() {
    if (had_previous_)
      ::setenv("DEPOTWIN_MODELS_DIR", previous_.c_str(), 1);
    else
      ::unsetenv("DEPOTWIN_MODELS_DIR");
  }
  PrivateModelsFolder(const PrivateModelsFolder&) = delete;
  PrivateModelsFolder& operator=(const PrivateModelsFolder&) = delete;

  const std::string& shipped() const { return shipped_; }
  void write_stage(const std::string& mjcf) const { write_text(folder_, "xy_stage.xml", mjcf); }

 private:
  std::string folder_, shipped_, previous_;
  bool had_previous_ = false;
};

// A shipped machine (`machine: xy_stage`) reads its MJCF from the models folder: those bytes
// count too, so a retuned model makes every task stale (and another folder of the same
// models gives the same hash)
TEST(ScenarioOverrides, HashesFollowTheShippedMachinesModel) {
  const std::string dir = fresh_directory("sweep_hash_model");
  write_text(dir, "base.yaml", read_text(scenario_path("thompson_fig7.yaml")));
  const std::string file =
      write_text(dir, "s.yaml", "base: base.yaml\ngrid:\n  planner: [lspb_mtt, stop_and_go]\n");
  std::string as_shipped;
  {
    const PrivateModelsFolder models(dir);
    as_shipped = Sweep(file, "").input_hash(Sweep(file, "").task(0));
    // a body heavier (a digit put before its first mass)
    std::string heavier = models.shipped();
    const std::size_t mass = heavier.find("mass=\"");
    ASSERT_NE(mass, std::string::npos);
    heavier.insert(mass + 6, "1");
    models.write_stage(heavier);
    const std::string retuned = Sweep(file, "").input_hash(Sweep(file, "").task(0));
    models.write_stage(models.shipped());
    const std::string restored = Sweep(file, "").input_hash(Sweep(file, "").task(0));
    EXPECT_NE(retuned, as_shipped);
    EXPECT_EQ(restored, as_shipped);
  }
  // the models folder the tests run with (the shipped one): the same bytes, the same hash
  EXPECT_EQ(Sweep(file, "").input_hash(Sweep(file, "").task(0)), as_shipped);
}

// a scenario that names no machine runs the default one, xy_stage: its model counts the same
TEST(ScenarioOverrides, HashesFollowTheDefaultMachinesModel) {
  const std::string dir = fresh_directory("sweep_hash_default_model");
  const PrivateModelsFolder models(dir);
  std::string fig7 = read_text(scenario_path("thompson_fig7.yaml"));
  const std::size_t named = fig7.find("machine: xy_stage\n");
  ASSERT_NE(named, std::string::npos);
  fig7.erase(named, std::string("machine: xy_stage\n").size());
  write_text(dir, "base.yaml", fig7);
  const std::string file =
      write_text(dir, "s.yaml", "base: base.yaml\ngrid:\n  planner: [lspb_mtt, stop_and_go]\n");
  const std::string as_shipped = Sweep(file, "").input_hash(Sweep(file, "").task(0));
  models.write_stage(models.shipped() + "<!-- retuned -->\n");
  const std::string retuned = Sweep(file, "").input_hash(Sweep(file, "").task(0));
  EXPECT_NE(retuned, as_shipped);
}

TEST(SweepTasks, ValidateAllListsEachProblemOnceWithTheTasksItConcerns) {
  const std::string dir = fresh_directory("sweep_validate");
  const std::string file =
      write_text(dir, "s.yaml", "base: " + scenario_path("thompson_fig7.yaml") + R"(
grid:
  toolpath.speed: [2, 5]
  limits.a_max: [30, -1]
)");
  const Sweep sweep(file, "");
  const std::vector<std::string> problems = problems_of([&] { sweep.validate_all(2, false); });
  ASSERT_EQ(problems.size(), 7u);
  // two planners in the base and no `planner` key: every task
  EXPECT_EQ(problems[0], file +
                             ":1: base: the scenario lists 2 planners (lspb_mtt, stop_and_go) "
                             "and a task runs one: sweep planner: in grid: (or choose one "
                             "under set:) (every task)");
  EXPECT_EQ(problems[1],
            file +
                ":4: limits.a_max: must be in [1e-06, 1e+09], got -1 (2 tasks: 1, 3; task 1: "
                "toolpath.speed=2, limits.a_max=-1)");
  EXPECT_EQ(problems[2].substr(0, problems[2].rfind(" (2 tasks")),
            scenario_path("thompson_fig7.yaml") +
                ":21: toolpath.segments[0]: print speed 5 mm/s needs 5 mm/s on x, above limits "
                "v_max 4 (lower the speed or raise the limit)");
  EXPECT_NE(problems[2].find("(2 tasks: 2, 3; task 2: toolpath.speed=5, limits.a_max=30)"),
            std::string::npos)
      << problems[2];
}

TEST(SweepTasks, TaskIndexFromTheCommandLineOrTheScheduler) {
  EXPECT_EQ(task_index_from("3", 4), 3u);
  EXPECT_THROW(task_index_from("4", 4), InputError);
  EXPECT_THROW(task_index_from("-1", 4), InputError);
  EXPECT_THROW(task_index_from("two", 4), InputError);
  ::unsetenv("SLURM_ARRAY_TASK_ID");
  ::unsetenv("JOB_COMPLETION_INDEX");
  ::unsetenv("DEPOTWIN_SWEEP_TASK_OFFSET");
  EXPECT_THROW(task_index_from("env", 4), InputError);
  // a Kubernetes Indexed Job
  ::setenv("JOB_COMPLETION_INDEX", "2", 1);
  EXPECT_EQ(task_index_from("env", 4), 2u);
  // Slurm first, with its chunk's offset
  ::setenv("SLURM_ARRAY_TASK_ID", "1", 1);
  EXPECT_EQ(task_index_from("env", 4), 1u);
  ::setenv("DEPOTWIN_SWEEP_TASK_OFFSET", "1000", 1);
  EXPECT_EQ(task_index_from("env", 2000), 1001u);
  EXPECT_THROW(task_index_from("env", 1001), InputError);
  ::unsetenv("SLURM_ARRAY_TASK_ID");
  ::unsetenv("JOB_COMPLETION_INDEX");
  ::unsetenv("DEPOTWIN_SWEEP_TASK_OFFSET");
}

}  // namespace
}  // namespace depotwin
