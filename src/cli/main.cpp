// depotwin: the command line. Each verb is a thin wrapper around the pipeline.
// Exit status: 0 success, 2 bad input (file:line: key: message), 1 internal failure.
#include <CLI/CLI.hpp>
#include <iostream>

#include "cli/move_verb.hpp"
#include "cli/verbs.hpp"
#include "core/error.hpp"

using namespace depotwin;

namespace {

void print_problems(const InputError& error) {
  for (const Problem& problem : error.problems()) std::cerr << "error: " << problem.str() << '\n';
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "DepoTwin: a physics-simulated digital twin of material-deposition machines.\n"
      "Plan a scenario's toolpath, simulate the machine in MuJoCo, record where material\n"
      "lands, and score thickness uniformity, velocity error and waste."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "depotwin 0.1.0");

  // run / compare / plan / validate share the scenario argument
  RunOptions run_options;
  CLI::App* run = app.add_subcommand("run", "plan, simulate, deposit and score a scenario");
  run->add_option("scenario", run_options.scenario, "scenario YAML file")->required();
  run->add_option("--planner", run_options.planners,
                  "planner(s) to run, comma-separated (default: all of the scenario's)");
  run->add_option("--out", run_options.out, "output directory (default: results/<scenario name>)");
  run->add_flag("--no-render", run_options.no_render, "write no images or plots");
  run->add_flag("--quiet", run_options.quiet, "no progress line");

  CompareOptions compare_options;
  CLI::App* compare =
      app.add_subcommand("compare", "run several planners on the same toolpath and compare them");
  compare->add_option("scenario", compare_options.run.scenario, "scenario YAML file")->required();
  compare->add_option("--planners", compare_options.run.planners,
                      "planners to compare, comma-separated (default: all of the scenario's)");
  compare->add_option("--orders", compare_options.orders,
                      "print orders to compare instead, comma-separated, e.g. "
                      "as_given,nearest_neighbor,christofides+three_opt");
  compare->add_option("--out", compare_options.run.out,
                      "output directory (default: results/<scenario name>)");
  compare->add_flag("--no-render", compare_options.run.no_render, "write no images or plots");
  compare->add_flag("--quiet", compare_options.run.quiet, "no progress line");

  RunOptions plan_options;
  CLI::App* plan = app.add_subcommand("plan", "plan only (no simulation): trajectory and planned metrics");
  plan->add_option("scenario", plan_options.scenario, "scenario YAML file")->required();
  plan->add_option("--planner", plan_options.planners,
                   "planner(s), comma-separated (default: all of the scenario's)");
  plan->add_option("--out", plan_options.out, "output directory (default: results/<scenario name>)");

  std::string validate_scenario;
  CLI::App* validate = app.add_subcommand("validate", "load and check a scenario; explain every problem");
  validate->add_option("scenario", validate_scenario, "scenario YAML file")->required();

  std::string q0, q1, v0, v1, vmax, amax, jmax;
  CLI::App* move = app.add_subcommand(
      "move", "minimum-time move of one to six axes (comma lists, one value per axis), as JSON");
  move->add_option("--q0", q0, "start positions, mm")->required();
  move->add_option("--q1", q1, "end positions, mm")->required();
  move->add_option("--v0", v0, "start velocities, mm/s")->default_str("0");
  move->add_option("--v1", v1, "end velocities, mm/s")->default_str("0");
  move->add_option("--vmax", vmax, "velocity limits, mm/s")->required();
  move->add_option("--amax", amax, "acceleration limits, mm/s^2")->required();
  move->add_option("--jmax", jmax, "jerk limits, mm/s^3 (0: none)");

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
      app.exit(e);
      return kExitBadInput;
    }
    if (*run) return run_verb(run_options);
    if (*compare) return compare_verb(compare_options);
    if (*plan) return plan_verb(plan_options);
    if (*validate) return validate_verb(validate_scenario);
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
  } catch (const InputError& error) {
    print_problems(error);
    return kExitBadInput;
  } catch (const InternalError& error) {
    std::cerr << "internal error: " << error.what() << '\n';
    return kExitInternal;
  } catch (const std::exception& error) {
    std::cerr << "internal error: " << error.what() << '\n';
    return kExitInternal;
  }
  return kExitInternal;
}
