// depotwin: the command line. Each verb is a thin wrapper around the pipeline.
// Exit status: 0 success, 2 bad input (file:line: key: message), 1 internal failure, 130 or 143
// when SIGINT or SIGTERM stopped it (the output is then as it was before).
#include <CLI/CLI.hpp>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <functional>
#include <iostream>
#include <string>

#include "cli/cli_checks.hpp"
#include "cli/describe.hpp"
#include "cli/export_verb.hpp"  // export
#include "cli/inspect.hpp"      // inspect
#include "cli/move_verb.hpp"
#include "cli/sweep_verb.hpp"  // sweep
#include "cli/verbs.hpp"
#include "core/error.hpp"
#include "core/file_io.hpp"
#include "core/interrupt.hpp"
#include "core/number_text.hpp"
#include "pipeline/models_dir.hpp"
#include "viewer/viewer.hpp"  // view

using namespace depotwin;

namespace {

// --max-memory on the scenario verbs (pipeline/job_check.hpp)
const char* const kMaxMemoryHelp =
    "refuse a job estimated to need more memory than this, before any work: bytes or K, M, G, T "
    "(powers of 1024), e.g. 16G (default 8G)";

// a list option given with nothing in it (`--planners ''`): refused, not read as not given
const CLI::Validator kNamesGiven(
    [](std::string& value) {
      return value.find_first_not_of(" \t,") == std::string::npos
                 ? std::string("is empty: name at least one, or leave the option out")
                 : std::string();
    },
    "NAMES");

void print_problems(const InputError& error) {
  for (const Problem& problem : error.problems()) std::cerr << "error: " << problem.str() << '\n';
}

// the option of that name, in the verb given (parsed) or the app itself; nullptr if none
const CLI::Option* option_named(CLI::App& app, const std::string& name) {
  const CLI::Option* option = app.get_option_no_throw(name);
  for (CLI::App* verb : app.get_subcommands())
    if (const CLI::Option* found = verb->get_option_no_throw(name)) option = found;
  return option;
}

// CLI11's refusal of the command line, as every other error reads: "error: ...", a value that
// is no number named with what was expected ("Could not convert: --jobs = 1.5" alone does not
// say), then where the options are listed
void print_parse_error(CLI::App& app, const CLI::ParseError& error) {
  std::string text = error.what();
  static const std::string kConvert = "Could not convert: ";
  const std::size_t equals = text.find(" = ");
  if (text.rfind(kConvert, 0) == 0 && equals != std::string::npos) {
    const std::string name = text.substr(kConvert.size(), equals - kConvert.size());
    const std::string value = text.substr(equals + 3);
    const CLI::Option* option = option_named(app, name);
    const std::string type = option ? option->get_type_name() : std::string();
    const bool whole = type.rfind("INT", 0) == 0;
    const bool positive = type.find("POSITIVE") != std::string::npos;
    text = name + ": '" + value + "' is not " + (whole ? "a whole number" : "a number") +
           (positive ? " above 0" : "");
  }
  // "--planner: At Most 1 required but received 2": an option given twice
  static const std::string kAtMostOne = ": At Most 1 required but received ";
  const std::size_t at_most = text.find(kAtMostOne);
  if (at_most != std::string::npos) {
    const std::string name = text.substr(0, at_most);
    const CLI::Option* option = option_named(app, name);
    const bool takes_a_list =
        option != nullptr && option->get_description().find("comma-separated") != std::string::npos;
    text = name + " is given " + text.substr(at_most + kAtMostOne.size()) + " times; give it once" +
           (takes_a_list ? " (several names go comma-separated in one: " + name + " a,b)" : "");
  }
  std::string verb_name;
  for (const CLI::App* verb : app.get_subcommands()) verb_name = " " + verb->get_name();
  std::cerr << "error: " << terminal_text(text) << "\n(depotwin" << verb_name
            << " --help lists the options)\n";
}

// "run, compare, plan, ...": every verb the app knows, in the order they were added
std::string verb_list(CLI::App& app) {
  const std::function<bool(CLI::App*)> every = [](CLI::App*) { return true; };
  std::string list;
  for (const CLI::App* verb : app.get_subcommands(every))
    list += (list.empty() ? "" : ", ") + verb->get_name();
  return list;
}

// "error: <what><the verbs>" and where they are described; exit 2
int refuse_with_verbs(CLI::App& app, const std::string& what) {
  std::cerr << "error: " << what << verb_list(app) << "\n(depotwin --help says what each does)\n";
  return kExitBadInput;
}

// The verb comes first: without one, the usage and the verbs; an unknown one is named with
// the verbs (CLI11 alone says "A subcommand is required"). Returns the exit status when the
// command line is refused here, -1 otherwise.
int check_verb(CLI::App& app, int argc, char** argv) {
  if (argc < 2) {
    std::cerr << app.help() << "\nerror: a verb is required; verbs are " << verb_list(app) << '\n';
    return kExitBadInput;
  }
  const std::string first = argv[1];
  // --help, --version; any other option before the verb is named with the verbs (CLI11 alone
  // says "A subcommand is required")
  if (!first.empty() && first[0] == '-') {
    if (first == "-h" || first == "--help" || first == "--version") return -1;
    return refuse_with_verbs(app, "unknown option '" + terminal_text(first) +
                                      "' before the verb; a command reads `depotwin VERB "
                                      "[OPTIONS]`, and the verbs are ");
  }
  const std::function<bool(CLI::App*)> named = [&](CLI::App* verb) {
    return verb->check_name(first);
  };
  if (!app.get_subcommands(named).empty()) return -1;
  return refuse_with_verbs(app, "unknown verb '" + terminal_text(first) + "'; verbs are ");
}

}  // namespace

// parse the command line and run its verb; the exit status
int run_command_line(int argc, char** argv) {
  CLI::App app{
      "DepoTwin: a physics-simulated digital twin of material-deposition machines.\n"
      "Plan a scenario's toolpath, simulate the machine in MuJoCo, record where material\n"
      "lands, and score thickness uniformity, velocity error and waste.",
      "depotwin"};
  app.require_subcommand(1);
  // the version, and where the shipped machine models are read from (installed or source tree)
  app.set_version_flag("--version", "depotwin 0.1.0\nmodels: " + models_directory());

  // run / compare / plan / validate share the scenario argument
  RunOptions run_options;
  CLI::App* run = app.add_subcommand("run", "plan, simulate, deposit and score a scenario");
  run->add_option("scenario", run_options.scenario, "scenario YAML file")->required();
  run->add_option("--planner,--planners", run_options.planners,
                  "planner(s) to run, comma-separated (default: all of the scenario's)")
      ->check(kNamesGiven);
  run->add_option("--out", run_options.out, "output directory (default: results/<scenario name>)");
  run->add_flag("--no-render", run_options.no_render, "write no images or plots");
  run->add_flag("--quiet", run_options.quiet, "no progress lines");
  run->add_flag("--no-wait", run_options.no_wait,
                "exit (status 2) instead of waiting while another depotwin writes --out");
  run->add_option("--max-memory", run_options.max_memory, kMaxMemoryHelp);
  // ---- moving pictures (src/render/video.hpp) ----
  CLI::Option* run_video =
      run->add_flag("--video", run_options.video,
                    "also write run.mp4 in each run folder: the scene over time, the deposit "
                    "growing");
  run->add_option("--video-length", run_options.video_length_s,
                  "longest video, seconds: a longer run is sped up to fit (default 30)")
      ->check(positive_number())
      ->needs(run_video);
  // ---- end moving pictures ----

  CompareOptions compare_options;
  CLI::App* compare =
      app.add_subcommand("compare", "run several planners on the same toolpath and compare them");
  compare->add_option("scenario", compare_options.run.scenario, "scenario YAML file")->required();
  compare
      ->add_option("--planners,--planner", compare_options.run.planners,
                   "planners to compare, comma-separated (default: all of the scenario's)")
      ->check(kNamesGiven);
  compare
      ->add_option("--orders", compare_options.orders,
                   "print orders to compare instead, comma-separated, e.g. "
                   "as_given,nearest_neighbor,christofides+three_opt")
      ->check(kNamesGiven);
  compare->add_option("--out", compare_options.run.out,
                      "output directory (default: results/<scenario name>)");
  compare->add_flag("--no-render", compare_options.run.no_render, "write no images or plots");
  compare->add_flag("--quiet", compare_options.run.quiet, "no progress lines");
  compare->add_flag("--no-wait", compare_options.run.no_wait,
                    "exit (status 2) instead of waiting while another depotwin writes --out");
  compare->add_option("--max-memory", compare_options.run.max_memory, kMaxMemoryHelp);
  // ---- moving pictures (src/render/video.hpp) ----
  CLI::Option* compare_video = compare->add_flag("--video", compare_options.run.video,
                                                 "also write run.mp4 in each run folder");
  compare
      ->add_option("--video-length", compare_options.run.video_length_s,
                   "longest video, seconds: a longer run is sped up to fit (default 30)")
      ->check(positive_number())
      ->needs(compare_video);
  // ---- end moving pictures ----

  RunOptions plan_options;
  CLI::App* plan =
      app.add_subcommand("plan", "plan only (no simulation): trajectory and planned metrics");
  plan->add_option("scenario", plan_options.scenario, "scenario YAML file")->required();
  plan->add_option("--planner,--planners", plan_options.planners,
                   "planner(s), comma-separated (default: all of the scenario's)")
      ->check(kNamesGiven);
  plan->add_option("--out", plan_options.out,
                   "output directory (default: results/<scenario name>)");
  plan->add_flag("--no-wait", plan_options.no_wait,
                 "exit (status 2) instead of waiting while another depotwin writes --out");
  plan->add_option("--max-memory", plan_options.max_memory, kMaxMemoryHelp);
  plan->add_flag("--quiet", plan_options.quiet, "no progress lines");

  std::string validate_scenario, validate_max_memory;
  bool validate_quiet = false;
  CLI::App* validate = app.add_subcommand(
      "validate",
      "every check `run` makes before it simulates (the file, the MJCF model, the plans, the "
      "job's size); lists every problem");
  validate->add_option("scenario", validate_scenario, "scenario YAML file")->required();
  validate->add_option("--max-memory", validate_max_memory, kMaxMemoryHelp);
  validate->add_flag("--quiet", validate_quiet, "no progress lines");

  // ---- view (a finished run replayed in a window: src/viewer/viewer.cpp) ----
  ViewOptions view_options;
  double view_at_s = 0.0;
  CLI::App* view = app.add_subcommand(
      "view", "replay a finished run in an interactive MuJoCo window (needs a display)");
  view->add_option("run_dir", view_options.run_directory,
                   "a run's folder, e.g. results/<scenario>/<planner> (holds replay.json)")
      ->required();
  view->add_option("--screenshot", view_options.screenshot,
                   "render one frame in the window, write it to this PNG and exit");
  view->add_option("--at", view_at_s,
                   "start at this run time, s (default: the start; a screenshot: the end)");
  view->add_option("--width", view_options.width, "window width, pixels (default 1280)");
  view->add_option("--height", view_options.height, "window height, pixels (default 640)");
  view->footer(std::string("Keys and mouse:\n") + kViewControls);
  // ---- end view ----

  // ---- describe (the schema tables: src/cli/describe.cpp) ----
  std::string describe_topic;
  bool describe_as_json = false;
  CLI::App* describe = app.add_subcommand(
      "describe",
      "every parameter with its unit, range, default and meaning; topics: machines, planners, "
      "sequencers, processes, limits, toolpath, arm, sim, outputs, scenario");
  describe->add_option("topic", describe_topic, "what to describe (none: list the topics)");
  describe->add_flag("--json", describe_as_json, "print JSON instead of tables");
  // ---- end describe ----

  // ---- export (the planned motion as G-code: src/cli/export_verb.cpp) ----
  ExportOptions export_options;
  CLI::App* export_gcode = app.add_subcommand(
      "export", "plan a scenario with one planner and write its motion as G-code");
  export_gcode->add_option("scenario", export_options.scenario, "scenario YAML file")->required();
  export_gcode
      ->add_option("--planner", export_options.planner,
                   "the planner (run label) to export (default: the scenario's only one)")
      ->check(kNamesGiven);
  export_gcode->add_option("--out", export_options.out, "the G-code file to write")->required();
  export_gcode
      ->add_option("--tolerance", export_options.settings.chord_tolerance_mm,
                   "every planned point within this of the written lines, mm (default 0.005)")
      ->check(number_in(1e-6, 10.0));
  export_gcode
      ->add_option("--filament-diameter", export_options.settings.filament_diameter_mm,
                   "extrusion: E is filament length of this diameter, mm (default 1.75)")
      ->check(number_in(0.01, 100.0));
  export_gcode->add_option("--open", export_options.settings.open_code,
                           "aerosol: the shutter-open code (default M3)");
  export_gcode->add_option("--close", export_options.settings.close_code,
                           "aerosol: the shutter-close code (default M5)");
  export_gcode->add_flag("--no-wait", export_options.no_wait,
                         "exit (status 2) instead of waiting while another depotwin writes --out");
  export_gcode->add_flag("--quiet", export_options.quiet, "no progress lines");
  // ---- end export ----

  // ---- inspect (facts of a G-code file: src/cli/inspect.cpp) ----
  std::string inspect_file, inspect_rule = "auto";
  GcodeOptions inspect_options;
  CLI::App* inspect = app.add_subcommand(
      "inspect", "facts of a G-code file as JSON: moves, lengths, layers, boxes, arcs, time");
  inspect->add_option("file", inspect_file, "G-code file")->required();
  inspect->add_option("--rule", inspect_rule, "print rule: auto, e, shutter or feed (default auto)")
      ->check(CLI::IsMember({"auto", "e", "shutter", "feed"}));
  inspect->add_option("--open", inspect_options.open_code,
                      "shutter rule: the code that opens (default M3)");
  inspect->add_option("--close", inspect_options.close_code,
                      "shutter rule: the code that closes (default M5)");
  InspectBaseline inspect_baseline;
  inspect->add_option("--machine", inspect_baseline.machine,
                      "the machine whose limits estimated_time_s assumes (default cartesian)");
  inspect->add_option("--mode", inspect_baseline.mode,
                      "the firmware's look-ahead for estimated_time_s: marlin (junction "
                      "deviation) or klipper (square-corner velocity); default marlin");
  inspect->add_option("--limits", inspect_baseline.limits,
                      "the limits of estimated_time_s: machine (--machine's, the firmware's "
                      "defaults) or file (over them, the file's M201, M203, M204, M205 J or "
                      "jerks X Y Z E, and SET_VELOCITY_LIMIT in force at each move); default "
                      "machine");
  // ---- end inspect ----

  // ---- sweep (parameter studies: src/cli/sweep_verb.cpp, src/sweep/) ----
  SweepOptions sweep_options;
  CLI::App* sweep = add_sweep_verb(app, sweep_options);
  // ---- end sweep ----

  // positions give the axes, one value each; a velocity or limit list has one value per
  // axis, or one value for every axis
  std::string q0, q1, v0, v1, vmax, amax, jmax;
  CLI::App* move = app.add_subcommand(
      "move",
      "minimum-time move of one to six axes, as JSON. Comma lists: --q0 and --q1 give one "
      "position per axis (same count); --v0, --v1, --vmax, --amax, --jmax one value per axis "
      "or one value for every axis");
  move->add_option("--q0", q0, "start positions, mm, one per axis")->required();
  move->add_option("--q1", q1, "end positions, mm, one per axis")->required();
  move->add_option("--v0", v0, "start velocities, mm/s (one per axis, or one for all)")
      ->default_str("0");
  move->add_option("--v1", v1, "end velocities, mm/s (one per axis, or one for all)")
      ->default_str("0");
  move->add_option("--vmax", vmax, "velocity limits, mm/s (one per axis, or one for all)")
      ->required();
  move->add_option("--amax", amax, "acceleration limits, mm/s^2 (one per axis, or one for all)")
      ->required();
  move->add_option("--jmax", jmax, "jerk limits, mm/s^3, 0: none (one per axis, or one for all)");

  if (const int status = check_verb(app, argc, argv); status >= 0) return status;
  try {
    try {
      app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
      return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
      return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
      return app.exit(e);
    } catch (const CLI::ParseError& e) {
      print_parse_error(app, e);
      return kExitBadInput;
    }
    // an option given an empty value (`--task ""`, `--out ""`: an unset shell variable) is
    // bad input, never its default: `sweep --task ""` would run every task
    for (const CLI::App* verb : app.get_subcommands())
      for (const CLI::Option* option : verb->get_options())
        if (option->get_type_size() != 0 && option->count() > 0)
          for (const std::string& value : option->results())
            if (value.empty())
              throw InputError(option->get_name(),
                               "an empty value (give one, or leave the option out)");
    // the verbs that write: SIGINT, SIGTERM, SIGHUP and SIGPIPE stop them with their staging
    // folder removed, their children ended, the output as it was, exit 130, 143, 129 or 141
    // (core/interrupt.hpp); set before any thread starts (a local sweep's runner then takes the
    // signals itself, to end its workers). The others (validate, view, ...) write nothing and
    // keep the signals' default: they end at once.
    if (*run || *compare || *plan || *export_gcode || *sweep) install_interrupt_handlers();
    if (*run) return run_verb(run_options);
    if (*compare) return compare_verb(compare_options);
    if (*plan) return plan_verb(plan_options);
    if (*validate) return validate_verb(validate_scenario, validate_max_memory, validate_quiet);
    if (*view) {
      if (view->count("--at") > 0) view_options.at_s = view_at_s;
      return view_verb(view_options);
    }                                                                       // view
    if (*describe) return describe_verb(describe_topic, describe_as_json);  // describe
    if (*export_gcode) return export_verb(export_options);                  // export
    if (*sweep) return sweep_verb(sweep_options);                           // sweep
    // inspect
    if (*inspect) {
      inspect_options.rule = *print_rule_from_name(inspect_rule);
      inspect_gcode_file(inspect_file, inspect_options, inspect_baseline);
      return kExitOk;
    }
    if (*move) {
      MoveRequest request;
      request.q0 = parse_number_list(q0, "--q0");
      request.q1 = parse_number_list(q1, "--q1");
      request.v0 = parse_number_list(v0.empty() ? "0" : v0, "--v0");
      request.v1 = parse_number_list(v1.empty() ? "0" : v1, "--v1");
      request.v_max = parse_number_list(vmax, "--vmax");
      request.a_max = parse_number_list(amax, "--amax");
      if (!jmax.empty()) request.j_max = parse_number_list(jmax, "--jmax");
      std::cout << minimum_time_move_json(request).dump(2) << '\n';
      return kExitOk;
    }
  } catch (const Interrupted& stop) {
    // everything was cleaned up while the exception unwound
    std::cerr << "depotwin: " << stop.what() << "; stopped, the output is as it was\n";
    return stop.exit_status();
  } catch (const InputError& error) {
    print_problems(error);
    return kExitBadInput;
  } catch (const std::exception& error) {
    // a failure while a signal stops the run (a write cut short) is the interrupt's doing
    if (interrupt_requested()) {
      std::cerr << "depotwin: " << Interrupted(interrupt_signal()).what()
                << "; stopped, the output is as it was\n";
      return Interrupted(interrupt_signal()).exit_status();
    }
    // the machine's refusal (a full disk) is an error to act on, not a bug to report
    const bool refused = dynamic_cast<const EnvironmentError*>(&error) != nullptr;
    std::cerr << (refused ? "error: " : "internal error: ") << terminal_text(error.what()) << '\n';
    return kExitInternal;
  }
  return kExitInternal;
}

int main(int argc, char** argv) {
  const int status = run_command_line(argc, argv);
  // what a verb printed (a script, JSON, a table) may be cut short by a full disk or a closed
  // pipe: that must not end as success
  std::cout.flush();
  const bool flushed = std::fflush(stdout) == 0;
  if (!std::cout || !flushed || std::ferror(stdout) != 0) {
    const int reason = errno;
    // a writing verb's reader gone after its result was swapped in (`run ... | head`): the
    // result is whole; 128 + SIGPIPE, as the signal ends a verb that does not catch it
    if (interrupt_signal() == SIGPIPE) return Interrupted(SIGPIPE).exit_status();
    std::cerr << "error: the standard output could not be written whole" << system_reason(reason)
              << "\n";
    return status == kExitOk ? kExitInternal : status;
  }
  return status;
}
