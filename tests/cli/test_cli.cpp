// The depotwin command line as users and outside tools call it: verbs, help, exit status,
// messages naming file/line/key, and nothing half-written on failure.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "pipeline/pipeline_test_util.hpp"

namespace depotwin {
namespace {

namespace fs = std::filesystem;
using testing_support::fresh_directory;
using testing_support::scenario_path;
using testing_support::write_text;

using Result = testing_support::CliResult;
using testing_support::depotwin;

TEST(Cli, HelpOnEveryVerb) {
  const Result top = depotwin("--help");
  EXPECT_EQ(top.status, 0);
  for (const char* verb : {"run", "compare", "plan", "move", "validate"}) {
    EXPECT_NE(top.output.find(verb), std::string::npos) << verb;
    const Result help = depotwin(std::string(verb) + " --help");
    EXPECT_EQ(help.status, 0) << verb;
    EXPECT_NE(help.output.find("Usage"), std::string::npos) << verb << ": " << help.output;
  }
  EXPECT_EQ(depotwin("").status, 2);  // a verb is required
  EXPECT_EQ(depotwin("fly-to-mars").status, 2);
}

// what a verb prints that cannot be written whole (a full disk: /dev/full) is an error, never
// a success with half a JSON document or script
TEST(Cli, StandardOutputThatCannotBeWrittenIsAnError) {
  for (const std::string arguments :
       {"describe planners --json", "move --q0 0 --q1 1 --vmax 1 --amax 1"}) {
    const Result r = testing_support::shell("{ " + std::string(DEPOTWIN_BINARY_DIR) + "/depotwin " +
                                            arguments + " > /dev/full; }");
    EXPECT_EQ(r.status, 1) << arguments << ": " << r.output;
    EXPECT_NE(r.output.find("error: the standard output could not be written whole: No space "
                            "left on device"),
              std::string::npos)
        << arguments << ": " << r.output;
  }
}

// the text after `prefix` up to the end of its line
std::string line_after(const std::string& text, const std::string& prefix) {
  const size_t at = text.find(prefix);
  if (at == std::string::npos) return "";
  const size_t begin = at + prefix.size();
  return text.substr(begin, text.find('\n', begin) - begin);
}

TEST(Cli, UnknownVerbIsNamedWithTheVerbs) {
  const Result r = depotwin("frobnicate --out x");
  EXPECT_EQ(r.status, 2) << r.output;
  const std::string verbs = line_after(r.output, "error: unknown verb 'frobnicate'; verbs are ");
  ASSERT_FALSE(verbs.empty()) << r.output;
  EXPECT_EQ(r.output.find("A subcommand is required"), std::string::npos) << r.output;
  for (const char* verb : {"run, ", "compare, ", "plan, ", "validate, ", "move"})
    EXPECT_NE(verbs.find(verb), std::string::npos) << verb << " missing from: " << verbs;

  // an option before any verb: named, with the same list of verbs
  const Result option = depotwin("--out x run");
  EXPECT_EQ(option.status, 2) << option.output;
  EXPECT_EQ(option.output.find("A subcommand is required"), std::string::npos) << option.output;
  EXPECT_NE(option.output.find("error: unknown option '--out' before the verb; a command reads "
                               "`depotwin VERB [OPTIONS]`, and the verbs are " +
                               verbs),
            std::string::npos)
      << option.output;
  EXPECT_EQ(depotwin("--version").status, 0);

  // no verb at all: the usage, and the same list of verbs
  const Result none = depotwin("");
  EXPECT_EQ(none.status, 2) << none.output;
  EXPECT_NE(none.output.find("Usage"), std::string::npos) << none.output;
  EXPECT_EQ(line_after(none.output, "error: a verb is required; verbs are "), verbs);
}

// a value the command line cannot read reads as every other error: "error:", the option, the
// value and what was expected, and where the options are listed (exit 2)
TEST(Cli, AValueThatIsNoNumberNamesTheOptionAndWhatWasExpected) {
  const Result jobs = depotwin("sweep x.yaml -j 1.5");
  EXPECT_EQ(jobs.status, 2);
  EXPECT_NE(jobs.output.find("error: --jobs: '1.5' is not a whole number above 0\n(depotwin "
                             "sweep --help lists the options)"),
            std::string::npos)
      << jobs.output;
  const Result at = depotwin("view x --at 2s");
  EXPECT_EQ(at.status, 2);
  EXPECT_NE(at.output.find("error: --at: '2s' is not a number\n"), std::string::npos) << at.output;
  const Result missing = depotwin("run");
  EXPECT_EQ(missing.status, 2);
  EXPECT_EQ(missing.output.rfind("error: scenario is required\n", 0), 0u) << missing.output;
}

// an option given twice is named with how to give several names (CLI11 said "--planner: At
// Most 1 required but received 2"); one that takes a single value is only told once
TEST(Cli, AnOptionGivenTwiceSaysHowToGiveItOnce) {
  const Result planners = depotwin("plan x.yaml --planner lspb_mtt --planner bezier");
  EXPECT_EQ(planners.status, 2);
  EXPECT_EQ(planners.output.rfind("error: --planner is given 2 times; give it once (several "
                                  "names go comma-separated in one: --planner a,b)\n",
                                  0),
            0u)
      << planners.output;
  const Result out = depotwin("run x.yaml --out a --out b --out c");
  EXPECT_EQ(out.status, 2);
  EXPECT_EQ(
      out.output.rfind("error: --out is given 3 times; give it once\n(depotwin run --help", 0), 0u)
      << out.output;
}

// a list option given empty is refused (exit 2), never read as "not given" (every planner)
TEST(Cli, EmptyNameListsAreRefused) {
  const std::string scenario = scenario_path("thompson_fig7.yaml");
  for (const std::string& args :
       {"compare " + scenario + " --planners ''", "compare " + scenario + " --orders ' , '",
        "run " + scenario + " --planner ''", "plan " + scenario + " --planner ','",
        "export " + scenario + " --planner '' --out x.gcode"}) {
    const Result r = depotwin(args);
    EXPECT_EQ(r.status, 2) << args << ": " << r.output;
    EXPECT_NE(r.output.find("is empty: name at least one, or leave the option out"),
              std::string::npos)
        << args << ": " << r.output;
  }
}

TEST(Cli, MoveOvershootCase) {
  // v0 = 4 towards a target 0.1 mm ahead: overshoot and come back, 0.282405 s
  const Result r = depotwin("move --q0 0 --q1 0.1 --v0 4 --v1 0 --vmax 4 --amax 30");
  ASSERT_EQ(r.status, 0) << r.output;
  const auto json = nlohmann::json::parse(r.output);
  EXPECT_NEAR(json["duration_s"].get<double>(), 0.282405, 5e-7);
  ASSERT_EQ(json["axes"].size(), 1u);
  const auto& phases = json["axes"][0]["phases"];
  ASSERT_EQ(phases.size(), 2u);
  EXPECT_DOUBLE_EQ(phases[0]["acceleration"].get<double>(), -30.0);
  EXPECT_NEAR(phases.back()["v_end"].get<double>(), 0.0, 1e-9);
}

TEST(Cli, MoveSynchronisesAxesAndRejectsBadInput) {
  const Result r = depotwin("move --q0 0,0 --q1 0,0.3 --v0 3,0 --v1 3,0 --vmax 4 --amax 30");
  ASSERT_EQ(r.status, 0) << r.output;
  // x (d = 0, v0 = v1 = 3) is blocked on (0, 0.4): the common duration is 0.4 s
  EXPECT_NEAR(nlohmann::json::parse(r.output)["duration_s"].get<double>(), 0.4, 1e-12);
  const Result bad = depotwin("move --q0 0 --q1 1 --v0 5 --vmax 4 --amax 30");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.output.find("--v0"), std::string::npos) << bad.output;
  EXPECT_EQ(depotwin("move --q0 0,1,2 --q1 1,2 --vmax 4 --amax 30").status, 2);
  EXPECT_EQ(depotwin("move --q0 x --q1 1 --vmax 4 --amax 30").status, 2);
}

// positions never broadcast: both lists name one position per axis
TEST(Cli, MovePositionListsMustMatch) {
  const Result r = depotwin("move --q0 0,0 --q1 10 --vmax 4 --amax 30");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("error: --q1: has 1 value but --q0 has 2 values"), std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("duration_s"), std::string::npos) << r.output;
  // a velocity or limit list: one per axis or one for all, nothing in between
  const Result v0 = depotwin("move --q0 0,0 --q1 1,2 --v0 0,0,0 --vmax 4 --amax 30,20,10");
  EXPECT_EQ(v0.status, 2) << v0.output;
  EXPECT_NE(v0.output.find("error: --v0: has 3 values but --q0 and --q1 have 2 values"),
            std::string::npos)
      << v0.output;
  EXPECT_NE(v0.output.find("error: --amax: has 3 values but --q0 and --q1 have 2 values"),
            std::string::npos)
      << v0.output;
}

// one limit for every axis: a 10 mm and a 2 mm move from rest at v_max 4, a_max 30 (no jerk
// limit); the long axis sets the time: 10/4 + 4/30 s (a trapezoid from and to rest)
TEST(Cli, MoveLimitsBroadcastToEveryAxis) {
  const Result r = depotwin("move --q0 0,0 --q1 10,2 --vmax 4 --amax 30");
  ASSERT_EQ(r.status, 0) << r.output;
  const auto json = nlohmann::json::parse(r.output);
  ASSERT_EQ(json["axes"].size(), 2u);
  for (const auto& axis : json["axes"]) {
    EXPECT_EQ(axis["v_max"].get<double>(), 4.0);
    EXPECT_EQ(axis["a_max"].get<double>(), 30.0);
    EXPECT_EQ(axis["v0"].get<double>(), 0.0);
  }
  EXPECT_EQ(json["axes"][1]["q1"].get<double>(), 2.0);
  EXPECT_NEAR(json["duration_s"].get<double>(), 10.0 / 4.0 + 4.0 / 30.0, 1e-9);
}

TEST(Cli, ValidateReportsEveryProblemWithFileLineAndKey) {
  EXPECT_EQ(depotwin("validate " + scenario_path("thompson_fig7.yaml")).status, 0);
  const std::string dir = fresh_directory("cli_validate");
  const std::string path = write_text(dir, "bad.yaml",
                                      "name: bad\n"
                                      "limits: {v_max: -4, a_max: 30}\n"
                                      "toolpath:\n"
                                      "  speed: 3\n"
                                      "  segments:\n"
                                      "    - [[0, 0], [0, 0]]\n"
                                      "colour: blue\n");
  const Result r = depotwin("validate " + path);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find(path + ":2: limits.v_max"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(path + ":6: toolpath.segments[0]"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(path + ":7: colour"), std::string::npos) << r.output;
}

// a file name, a key or a verb holding terminal escape sequences (a hostile download's name)
// is echoed with those bytes as \xNN: no message can recolour the terminal or overwrite a line
TEST(Cli, NamesWithControlBytesAreEchoedDisarmed) {
  const std::string dir = fresh_directory("cli_control_bytes");
  const std::string scenario = scenario_path("thompson_fig7.yaml");
  // the same scenario under a name with ESC [31m and a CR in it; a key with ESC in it
  const std::string name = "fig7\x1B[31m\rred.yaml";
  fs::copy_file(scenario, fs::path(dir) / name);
  const std::string bad = write_text(dir, "bad.yaml", "name: bad\nco\x1B[2Jlour: blue\n");
  const std::string quoted = "\"" + dir + "/$(printf 'fig7\\033[31m\\rred.yaml')\"";
  for (const std::string& arguments :
       {"validate " + quoted, "validate " + bad, "validate " + quoted + "x",
        std::string("\"$(printf 'fr\\033[2Job')\"")}) {
    const Result r = depotwin(arguments);
    EXPECT_EQ(r.output.find('\x1B'), std::string::npos) << arguments << ": " << r.output;
    EXPECT_EQ(r.output.find('\r'), std::string::npos) << arguments << ": " << r.output;
  }
  EXPECT_NE(depotwin("validate " + quoted).output.find("fig7\\x1B[31m\\x0Dred.yaml: ok"),
            std::string::npos);
  const Result missing = depotwin("validate " + quoted + "x");
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.output.find("fig7\\x1B[31m\\x0Dred.yamlx: scenario file not found"),
            std::string::npos)
      << missing.output;
  const Result key = depotwin("validate " + bad);
  EXPECT_EQ(key.status, 2);
  EXPECT_NE(key.output.find("bad.yaml:2: control byte 0x1B at column 3"), std::string::npos)
      << key.output;
  EXPECT_NE(depotwin("\"$(printf 'fr\\033[2Job')\"").output.find("unknown verb 'fr\\x1B[2Job'"),
            std::string::npos);
}

// `describe outputs` lists the files and metrics.json keys that `plan` and `run` write, no
// more and no fewer: a plan writes what is "run, plan"; a rendered run of one layer on the
// XY stage that and what is "run" or "run, rendered"
TEST(Cli, DescribeOutputsListsWhatPlanAndRunWrite) {
  const Result described = depotwin("describe outputs --json");
  ASSERT_EQ(described.status, 0) << described.output;
  const auto outputs = nlohmann::json::parse(described.output);
  const auto listed = [&](const char* list, const std::vector<std::string>& when) {
    std::vector<std::string> names;
    for (const auto& entry : outputs.at(list))
      if (std::find(when.begin(), when.end(), entry.at("written")) != when.end())
        names.push_back(entry.at("name"));
    std::sort(names.begin(), names.end());
    return names;
  };
  const auto written = [](const std::string& folder) {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(folder))
      names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  };
  const auto keys_of = [](const std::string& metrics_file) {
    std::vector<std::string> keys;
    const auto metrics = nlohmann::json::parse(testing_support::read_text(metrics_file));
    for (const auto& [key, value] : metrics.items()) keys.push_back(key);
    std::sort(keys.begin(), keys.end());
    return keys;
  };
  const std::string dir = fresh_directory("cli_describe_outputs");
  const std::string fig7 = scenario_path("thompson_fig7.yaml");
  ASSERT_EQ(depotwin("plan " + fig7 + " --planner lspb_mtt --quiet --out " + dir + "/plan").status,
            0);
  EXPECT_EQ(written(dir + "/plan/lspb_mtt"), listed("files", {"run, plan"}));
  EXPECT_EQ(keys_of(dir + "/plan/lspb_mtt/metrics.json"), listed("metrics_keys", {"run, plan"}));
  ASSERT_EQ(depotwin("run " + fig7 + " --planner lspb_mtt --quiet --out " + dir + "/run").status,
            0);
  EXPECT_EQ(written(dir + "/run/lspb_mtt"), listed("files", {"run, plan", "run", "run, rendered"}));
  EXPECT_EQ(keys_of(dir + "/run/lspb_mtt/metrics.json"),
            listed("metrics_keys", {"run, plan", "run"}));
}

TEST(Cli, PlanWritesMetricsAndTrajectory) {
  const std::string dir = fresh_directory("cli_plan");
  const Result r =
      depotwin("plan " + scenario_path("thompson_fig7.yaml") + " --planner lspb_mtt --out " + dir);
  ASSERT_EQ(r.status, 0) << r.output;
  const auto metrics =
      nlohmann::json::parse(testing_support::read_text(dir + "/lspb_mtt/metrics.json"));
  // a plan has planned figures only: every one under its planned_ name, none unprefixed
  for (const char* key : {"scenario", "planner", "time_s", "planned_velocity_error",
                          "planned_velocity_error_steady", "planned_path_error_mm", "warnings"})
    EXPECT_TRUE(metrics.contains(key)) << key;
  for (const char* key : {"velocity_error", "path_error_mm", "thickness", "waste"})
    EXPECT_FALSE(metrics.contains(key)) << key;
  const std::string csv = testing_support::read_text(dir + "/lspb_mtt/trajectory.csv");
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "t_s,x_mm,y_mm,z_mm,vx_mm_s,vy_mm_s,vz_mm_s,speed_mm_s,depositing,path,"
            "desired_speed_mm_s");
  // 1 ms samples over the whole plan
  const double total = metrics["time_s"]["total"].get<double>();
  EXPECT_NEAR(std::count(csv.begin(), csv.end(), '\n') - 1, std::floor(total * 1000) + 2, 1.0);
  EXPECT_FALSE(fs::exists(dir + "/stop_and_go"));
  // the last line names the folder written (it said DIR/<planner>/ literally)
  EXPECT_NE(r.output.find("plans written to " + dir + "/lspb_mtt/ (metrics.json, trajectory.csv)"),
            std::string::npos)
      << r.output;
  // --planners, as compare spells it, is the same option; several folders in braces
  const Result both = depotwin("plan " + scenario_path("thompson_fig7.yaml") +
                               " --planners lspb_mtt,stop_and_go --out " + dir);
  ASSERT_EQ(both.status, 0) << both.output;
  EXPECT_TRUE(fs::exists(dir + "/stop_and_go/metrics.json"));
  EXPECT_NE(both.output.find("plans written to " + dir + "/{lspb_mtt,stop_and_go}/"),
            std::string::npos)
      << both.output;
}

// a scenario with a broken piece, run end to end: exit 2, a clear message, no output folder
void expect_bad_run(const std::string& name, const std::string& scenario_text,
                    const std::string& message, const std::string& extra_file = "",
                    const std::string& extra_text = "") {
  const std::string dir = fresh_directory("cli_bad_" + name);
  if (!extra_file.empty()) write_text(dir, extra_file, extra_text);
  const std::string path = write_text(dir, "scenario.yaml", scenario_text);
  const std::string out = dir + "/results";
  const Result r = depotwin("run " + path + " --no-render --quiet --out " + out);
  EXPECT_EQ(r.status, 2) << name << ": " << r.output;
  EXPECT_NE(r.output.find(message), std::string::npos) << name << ": " << r.output;
  EXPECT_FALSE(fs::exists(out)) << name << ": output folder left behind";
  // nothing staged either
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_EQ(entry.path().filename().string().find(".partial"), std::string::npos) << entry.path();
}

std::string scenario_with_machine(const std::string& machine,
                                  const std::string& segment = "[[0, 0], [5, 0]]") {
  return "name: bad\nmachine: " + machine +
         "\nlimits: {v_max: 4, a_max: 30}\ntoolpath:\n  speed: 3\n  segments:\n    - " + segment +
         "\n";
}

TEST(Cli, BadRunsExitWithStatusTwoAndLeaveNothingBehind) {
  expect_bad_run("unknown_machine", scenario_with_machine("warp_stage"), "machine");
  expect_bad_run("missing_mjcf", scenario_with_machine("missing.xml"), "missing.xml");
  expect_bad_run("malformed_mjcf", scenario_with_machine("broken.xml"), "broken.xml", "broken.xml",
                 "<mujoco><worldbody><body name='x'></mujoco>");
  // a Cartesian stage model without the `nozzle` site
  std::string model =
      testing_support::read_text(std::string(DEPOTWIN_MODELS_DIR) + "/xy_stage.xml");
  const size_t site = model.find("name=\"nozzle\"");
  ASSERT_NE(site, std::string::npos);
  model.replace(site, 13, "name=\"nozzle_renamed\"");
  expect_bad_run("no_nozzle", scenario_with_machine("no_nozzle.xml"), "nozzle", "no_nozzle.xml",
                 model);
  // a print segment beyond the +-50 mm travel
  expect_bad_run("outside_travel", scenario_with_machine("xy_stage", "[[0, 0], [80, 0]]"),
                 "travel");
}

TEST(Cli, RunAndCompareWriteResults) {
  const std::string dir = fresh_directory("cli_compare");
  const Result r =
      depotwin("compare " + scenario_path("thompson_fig7.yaml") +
               " --no-render --quiet --orders as_given,nearest_neighbor+two_opt --planners "
               "lspb_mtt --out " +
               dir);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir + "/as_given/metrics.json"));
  EXPECT_TRUE(fs::exists(dir + "/nearest_neighbor+two_opt/metrics.json"));
  const auto table = nlohmann::json::parse(testing_support::read_text(dir + "/comparison.json"));
  ASSERT_EQ(table["runs"].size(), 2u);
  const auto& reordered = table["runs"][1]["metrics"]["order"];
  EXPECT_EQ(reordered["method"], "nearest_neighbor");
  EXPECT_EQ(reordered["refine"], "two_opt");
  // the sequencer's objective never beats its own lower bound
  EXPECT_GE(reordered["cost_s"].get<double>(), reordered["lower_bound_s"].get<double>());
}

// ---------------------------------------------------------------------------------------
// the output folder: checked before any work, owned by the verb, replaced whole

// the names in a folder, sorted (dot files included)
std::vector<std::string> folder_names(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir))
    names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// `depotwin VERB thompson_fig7 ARGS --out OUT` refused with status 2 and `message`, before
// any simulation (no progress line, although every update would print one)
void expect_out_refused(const std::string& verb, const std::string& out,
                        const std::string& message) {
  ::setenv("DEPOTWIN_PROGRESS_PERIOD_S", "0", 1);
  const Result r = depotwin(verb + " " + scenario_path("thompson_fig7.yaml") + " --planner" +
                            (verb == "compare" ? "s" : "") + " lspb_mtt --out " + out +
                            (verb == "plan" ? "" : " --no-render"));
  ::unsetenv("DEPOTWIN_PROGRESS_PERIOD_S");
  EXPECT_EQ(r.status, 2) << verb << ": " << r.output;
  EXPECT_NE(r.output.find("error: --out: " + out + ": " + message), std::string::npos)
      << verb << ": " << r.output;
  EXPECT_EQ(r.output.find("simulating"), std::string::npos) << verb << ": " << r.output;
  EXPECT_EQ(r.output.find("scenario thompson_fig7"), std::string::npos) << verb << ": " << r.output;
}

TEST(CliOut, AFileOrAPathUnderAFileIsBadInput) {
  const std::string dir = fresh_directory("cli_out_file");
  const std::string file = write_text(dir, "notes.txt", "keep me\n");
  for (const std::string verb : {"run", "compare", "plan"}) {
    expect_out_refused(verb, file, "is a file, not a folder");
    expect_out_refused(verb, file + "/results/x", "lies under " + file + ", which is a file");
  }
  EXPECT_EQ(testing_support::read_text(file), "keep me\n");
  EXPECT_EQ(folder_names(dir), std::vector<std::string>{"notes.txt"});  // nothing staged
}

// a read-only folder; root writes anywhere, so as root the CLI runs as nobody (util-linux's
// setpriv)
TEST(CliOut, AReadOnlyFolderIsBadInput) {
  const std::string dir = fresh_directory("cli_out_read_only");
  fs::permissions(dir, fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                           fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
  const std::string as_user =
      ::geteuid() == 0 ? "setpriv --reuid=65534 --regid=65534 --clear-groups " : "";
  for (const std::string verb : {"run", "compare", "plan"}) {
    const std::string command = as_user + DEPOTWIN_BINARY_DIR + "/depotwin " + verb + " " +
                                scenario_path("thompson_fig7.yaml") +
                                (verb == "plan" ? "" : " --quiet") + " --out " + dir +
                                "/results 2>&1";
    FILE* pipe = ::popen(command.c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    std::string output;
    char buffer[4096];
    for (size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) output.append(buffer, n);
    const int status = ::pclose(pipe);
    EXPECT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, 2) << verb << ": " << output;
    EXPECT_NE(output.find("error: --out: " + dir + "/results: cannot write in " + dir +
                          ": Permission denied"),
              std::string::npos)
        << verb << ": " << output;
  }
  fs::permissions(dir, fs::perms::owner_all);
  EXPECT_TRUE(folder_names(dir).empty());
}

// a mount point cannot be swapped with the staging folder beside it: refused before any
// work (mounting a tmpfs needs root; elsewhere the test is skipped)
TEST(CliOut, AMountPointIsRefusedBeforeAnyWork) {
  const std::string dir = fresh_directory("cli_out_mount");
  fs::create_directories(dir + "/volume");
  const std::string mount = "mount -t tmpfs -o size=1m tmpfs '" + dir + "/volume' 2>/dev/null";
  if (::geteuid() != 0 || std::system(mount.c_str()) != 0)
    GTEST_SKIP() << "mounting a tmpfs needs root";
  const Result r =
      depotwin("plan " + scenario_path("thompson_fig7.yaml") + " --out " + dir + "/volume");
  const std::string unmount = "umount '" + dir + "/volume'";
  EXPECT_EQ(std::system(unmount.c_str()), 0);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("error: --out: " + dir + "/volume: is a mount point"), std::string::npos)
      << r.output;
  EXPECT_EQ(folder_names(dir), std::vector<std::string>{"volume"});
}

// a folder with someone else's files is never replaced
TEST(CliOut, AFolderThatIsNotADepotwinOutputIsRefused) {
  const std::string dir = fresh_directory("cli_out_foreign");
  write_text(dir, "thesis.tex", "chapter 1\n");
  for (const std::string verb : {"run", "compare", "plan"})
    expect_out_refused(verb, dir, "exists and is not a depotwin output folder");
  EXPECT_EQ(folder_names(dir), std::vector<std::string>{"thesis.tex"});
  for (const auto& entry : fs::directory_iterator(fs::path(dir).parent_path()))
    EXPECT_EQ(entry.path().filename().string().find("cli_out_foreign."), std::string::npos)
        << entry.path();

  // nor one that holds the scenario
  const std::string scenario =
      write_text(dir, "fig7.yaml", testing_support::read_text(scenario_path("thompson_fig7.yaml")));
  const Result r = depotwin("plan " + scenario + " --out " + dir);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("error: --out: " + dir + ": holds the scenario file " + scenario),
            std::string::npos)
      << r.output;
}

// a compare's folder run into by `plan`: the old comparison.* and run folders are gone, and
// the folder carries the marker; without the marker, a folder shaped like a result is refused
TEST(CliOut, AVerbReplacesItsFolderWhole) {
  const std::string dir = fresh_directory("cli_out_replace");
  const std::string out = dir + "/results";
  const Result compare = depotwin("compare " + scenario_path("thompson_fig7.yaml") +
                                  " --planners lspb_mtt --no-render --quiet --out " + out);
  ASSERT_EQ(compare.status, 0) << compare.output;
  EXPECT_EQ(folder_names(out),
            (std::vector<std::string>{".depotwin", "comparison.csv", "comparison.json",
                                      "comparison.md", "lspb_mtt"}));
  const Result plan = depotwin("plan " + scenario_path("thompson_fig7.yaml") +
                               " --planner stop_and_go --out " + out + "/");
  ASSERT_EQ(plan.status, 0) << plan.output;
  EXPECT_EQ(folder_names(out), (std::vector<std::string>{".depotwin", "stop_and_go"}));
  EXPECT_EQ(folder_names(dir), std::vector<std::string>{"results"});  // nothing staged left

  // without the marker, a folder shaped like a result (run folders holding a metrics.json)
  // is the user's: refused, and their file beside the metrics stays
  fs::remove(out + "/.depotwin");
  write_text(out + "/stop_and_go", "model.ckpt", "weights\n");
  const Result again =
      depotwin("plan " + scenario_path("thompson_fig7.yaml") + " --planner lspb_mtt --out " + out);
  EXPECT_EQ(again.status, 2) << again.output;
  EXPECT_NE(again.output.find("is not a depotwin output folder"), std::string::npos)
      << again.output;
  EXPECT_TRUE(fs::exists(out + "/stop_and_go/model.ckpt"));
}

// every order under every planner, each in its own folder; the progress lines (every update
// printed: stderr is a pipe here) name the order and the planner, without \r
TEST(CliCompare, OrdersTimesPlanners) {
  const std::string dir = fresh_directory("cli_compare_cross");
  ::setenv("DEPOTWIN_PROGRESS_PERIOD_S", "0", 1);
  const Result r = depotwin("compare " + scenario_path("thompson_fig7.yaml") +
                            " --no-render --orders as_given,nearest_neighbor+two_opt "
                            "--planners lspb_mtt,stop_and_go --out " +
                            dir);
  ::unsetenv("DEPOTWIN_PROGRESS_PERIOD_S");
  ASSERT_EQ(r.status, 0) << r.output;
  const std::vector<std::string> labels{"as_given+lspb_mtt", "as_given+stop_and_go",
                                        "nearest_neighbor+two_opt+lspb_mtt",
                                        "nearest_neighbor+two_opt+stop_and_go"};
  const auto table = nlohmann::json::parse(testing_support::read_text(dir + "/comparison.json"));
  ASSERT_EQ(table["runs"].size(), labels.size());
  for (size_t i = 0; i < labels.size(); ++i) {
    // in order, each in its folder: the planner under the order
    const auto& metrics = table["runs"][i]["metrics"];
    EXPECT_EQ(metrics["planner"], i % 2 == 0 ? "lspb_mtt" : "stop_and_go") << i;
    EXPECT_EQ(metrics["order"]["method"], i < 2 ? "as_given" : "nearest_neighbor") << i;
    const auto folder =
        nlohmann::json::parse(testing_support::read_text(dir + "/" + labels[i] + "/metrics.json"));
    EXPECT_EQ(folder["planner"], metrics["planner"]) << labels[i];
    EXPECT_EQ(folder["order"]["method"], metrics["order"]["method"]) << labels[i];
    EXPECT_EQ(folder["time_s"]["total"], metrics["time_s"]["total"]) << labels[i];
    EXPECT_NE(r.output.find("thompson_fig7/" + labels[i] + ": simulating 100 % ("),
              std::string::npos)
        << r.output;
  }
  EXPECT_EQ(r.output.find('\r'), std::string::npos);
  // the same order under both planners: the same sequence, at the same cost
  EXPECT_EQ(table["runs"][2]["metrics"]["order"]["cost_s"],
            table["runs"][3]["metrics"]["order"]["cost_s"]);

  // a run named twice is refused before any work
  const Result twice = depotwin("compare " + scenario_path("thompson_fig7.yaml") +
                                " --orders as_given,as_given --out " + dir + "/twice");
  EXPECT_EQ(twice.status, 2) << twice.output;
  EXPECT_NE(twice.output.find("error: --orders: 'as_given' is named twice"), std::string::npos)
      << twice.output;
  EXPECT_FALSE(fs::exists(dir + "/twice"));
}

// progress on a pipe: plain lines, silenced by --quiet
TEST(CliProgress, PlainLinesOffATerminalAndNoneWhenQuiet) {
  const std::string dir = fresh_directory("cli_progress");
  const std::string run =
      "run " + scenario_path("thompson_fig7.yaml") + " --planner lspb_mtt --no-render --out " + dir;
  ::setenv("DEPOTWIN_PROGRESS_PERIOD_S", "0", 1);
  const Result shown = depotwin(run);
  const Result quiet = depotwin(run + " --quiet");
  ::unsetenv("DEPOTWIN_PROGRESS_PERIOD_S");
  ASSERT_EQ(shown.status, 0) << shown.output;
  EXPECT_NE(shown.output.find("thompson_fig7/lspb_mtt: simulating 100 % ("), std::string::npos)
      << shown.output;
  EXPECT_NE(shown.output.find("thompson_fig7/lspb_mtt: simulating done in "), std::string::npos)
      << shown.output;
  EXPECT_EQ(shown.output.find('\r'), std::string::npos);
  ASSERT_EQ(quiet.status, 0) << quiet.output;
  EXPECT_EQ(quiet.output.find("simulating"), std::string::npos) << quiet.output;
}

// ---------------------------------------------------------------------------------------
// the 6-DOF arm: a toolpath it cannot print is refused with file:line: key and the point

// scenarios/shembekar_beam.stl (the 65 x 14 mm arch centred on the origin) placed at `offset`
// and hatched every 4 mm along x: line k at y = -6 + 4 k, point i at x = -32 + 4 i (before the
// offset). The `surface:` key is on line 7.
std::string arm_beam_scenario(const std::string& offset, const std::string& extra = "") {
  return "name: arm_bad\n"
         "machine: arm6\n"
         "limits: {v_max: 200, a_max: 2000}\n"
         "process: {type: extrusion, bead_width_mm: 0.5, layer_height_mm: 0.5, tau_s: 0.02}\n"
         "toolpath:\n"
         "  speed: 30\n"
         "  surface:\n"
         "    file: " +
         scenario_path("shembekar_beam.stl") +
         "\n"
         "    offset: " +
         offset +
         "\n"
         "    hatch_mm: 4\n"
         "    angles: [0]\n"
         "planners: [conformal]\n" +
         extra;
}

// 600 mm beyond the work origin: 960 mm in front of the robot's base, far out of its reach
TEST(Cli, ArmPointOutOfReachIsNamed) {
  const std::string dir = fresh_directory("cli_arm_reach");
  const std::string path = write_text(dir, "reach.yaml", arm_beam_scenario("[600, 0, 0]"));
  const Result r = depotwin("validate " + path);
  EXPECT_EQ(r.status, 2) << r.output;
  const std::string where = path + ":7: toolpath.surface: ";
  // the job's start above the part (its default: at the surface's line, under its own key),
  // and the points of the hatch by layer, line and point
  EXPECT_NE(r.output.find(path + ":7: toolpath.start: the start (600.000, 0.000, "),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find(where + "layer 0, line 0, point 0 (568.000, -6.000, "), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find(where + "layer 0, line 1, point 16 (632.000, -2.000, "),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find(") mm is out of the arm's reach for every roll and branch of arm6"),
            std::string::npos)
      << r.output;
  // `run` refuses it the same way and leaves nothing behind
  expect_bad_run("arm_out_of_reach", arm_beam_scenario("[600, 0, 0]"), "is out of the arm's reach");
}

// every posture's wrist centre is closer than 1000 mm to the joint-1 axis: all singular
TEST(Cli, ArmSingularPointIsNamed) {
  const std::string dir = fresh_directory("cli_arm_singular");
  const std::string path = write_text(
      dir, "singular.yaml", arm_beam_scenario("[0, 0, 0]", "arm: {min_wrist_offset_mm: 1000}\n"));
  const Result r = depotwin("validate " + path);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(
      r.output.find(path + ":7: toolpath.surface: layer 0, line 0, point 0 (-32.000, -6.000, "),
      std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find(") mm is at a singularity for every roll and branch of arm6"),
            std::string::npos)
      << r.output;
  // the same scenario without the demand is fine
  const std::string fine = write_text(dir, "fine.yaml", arm_beam_scenario("[0, 0, 0]"));
  const Result ok = depotwin("validate " + fine);
  EXPECT_EQ(ok.status, 0) << ok.output;
  EXPECT_NE(ok.output.find("machine arm6, 4 print paths"), std::string::npos) << ok.output;
}

// A part sunk into the table: its hatch reaches below the table's top (z = 0). One problem at
// the surface's key gives the lowest point and the offset that lifts it onto the table; that
// offset is accepted. Paths below it on the arm are named point by point.
TEST(Cli, APartOrAPathBelowTheTableIsRefused) {
  const std::string dir = fresh_directory("cli_arm_below_table");
  const std::string path = write_text(dir, "sunk.yaml", arm_beam_scenario("[0, 0, -2]"));
  const Result r = depotwin("validate " + path);
  EXPECT_EQ(r.status, 2) << r.output;
  const std::string head = path + ":7: toolpath.surface: the hatch on '";
  ASSERT_NE(r.output.find(head), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(" mm, below the work surface (z = 0, the top of the table, bed or plate "
                          "the part stands on): the nozzle would be inside it; raise the part: "
                          "offset: [0, 0, "),
            std::string::npos)
      << r.output;
  // the lowest point: between 2 mm below (the beam's ends stand at z = 0) and 0
  double lowest_z = 0.0, raised_z = 0.0;
  const size_t at = r.output.find("reaches z = ");
  ASSERT_NE(at, std::string::npos) << r.output;
  ASSERT_EQ(std::sscanf(r.output.c_str() + at, "reaches z = %lf", &lowest_z), 1);
  EXPECT_GE(lowest_z, -2.0);
  EXPECT_LT(lowest_z, 0.0);
  const size_t fix = r.output.find("offset: [0, 0, ");
  ASSERT_EQ(std::sscanf(r.output.c_str() + fix, "offset: [0, 0, %lf]", &raised_z), 1);
  EXPECT_NEAR(raised_z, -2.0 - lowest_z, 1e-4);
  const std::string lifted =
      write_text(dir, "lifted.yaml", arm_beam_scenario("[0, 0, " + std::to_string(raised_z) + "]"));
  const Result ok = depotwin("validate " + lifted);
  EXPECT_EQ(ok.status, 0) << ok.output;
  expect_bad_run("arm_below_table", arm_beam_scenario("[0, 0, -2]"), "below the work surface");

  // an arm printing one polyline with `conformal`; `toolpath` its toolpath section's lines
  const auto arm_polyline = [&](const std::string& name, const std::string& toolpath) {
    return write_text(dir, name + ".yaml",
                      "name: " + name +
                          "\nmachine: arm6\nlimits: {v_max: 200, a_max: 2000}\n"
                          "process: {type: extrusion, bead_width_mm: 0.5, layer_height_mm: 0.5}\n"
                          "toolpath:\n  speed: 20\n" +
                          toolpath + "planners: [conformal]\n");
  };
  // a polyline dipping 0.5 mm into the table: its one point below is named
  const std::string dip =
      arm_polyline("dip", "  polylines:\n    - [[0, 0, 1], [10, 0, -0.5], [20, 0, 1]]\n");
  const Result d = depotwin("validate " + dip);
  EXPECT_EQ(d.status, 2) << d.output;
  EXPECT_NE(d.output.find(dip + ":8: toolpath.polylines[0]: point 1 (10.000, 0.000, -0.500) mm is "
                                "below the table's top (z = 0 of the work frame, where the part "
                                "stands): the nozzle would be inside the table"),
            std::string::npos)
      << d.output;
  EXPECT_EQ(d.output.find("point 0 ("), std::string::npos) << d.output;
  EXPECT_EQ(d.output.find("point 2 ("), std::string::npos) << d.output;
  EXPECT_NE(d.output.find(dip + ":5: toolpath: 1 print point(s) below the table's top, the "
                                "lowest at z = -0.500 mm: raise the toolpath by at least 0.500 mm"),
            std::string::npos)
      << d.output;
  // a start below the table is named at its key, and raising the print points is no advice
  const std::string low_start =
      arm_polyline("low_start",
                   "  start: [0, 0, -5]\n  end: [20, 0, 5]\n"
                   "  polylines:\n    - [[0, 0, 1], [10, 0, 1], [20, 0, 1]]\n");
  const Result l = depotwin("validate " + low_start);
  EXPECT_EQ(l.status, 2) << l.output;
  EXPECT_NE(l.output.find(low_start + ":7: toolpath.start: the start (0.000, 0.000, -5.000) mm is "
                                      "below the table's top"),
            std::string::npos)
      << l.output;
  EXPECT_EQ(l.output.find("raise the toolpath"), std::string::npos) << l.output;
}

// `arm:` on a machine without a wrist
TEST(Cli, ArmSettingsOnAPlanarMachineAreRefused) {
  const std::string dir = fresh_directory("cli_arm_planar");
  const std::string path =
      write_text(dir, "planar.yaml", scenario_with_machine("xy_stage") + "arm: {roll: fixed}\n");
  const Result r = depotwin("validate " + path);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find(path + ":8: arm: applies to machine arm6 (a 6-DOF arm), not to xy_stage"),
            std::string::npos)
      << r.output;
}

}  // namespace
}  // namespace depotwin
