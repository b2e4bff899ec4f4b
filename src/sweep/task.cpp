#include "sweep/task.hpp"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "core/file_io.hpp"
#include "pipeline/job_check.hpp"
#include "pipeline/run.hpp"
#include "report/metrics_json.hpp"
#include "report/output_dir.hpp"

namespace depotwin {

namespace fs = std::filesystem;

std::string task_record_json(const TaskRecord& record) {
  nlohmann::ordered_json json;
  json["index"] = record.index;
  nlohmann::ordered_json parameters = nlohmann::ordered_json::object();
  for (const auto& [key, value] : record.parameters) parameters[key] = value;
  json["parameters"] = parameters;
  json["input_hash"] = record.input_hash;
  json["status"] = record.status;
  json["error"] = record.error;
  json["wall_s"] = record.wall_s;
  json["run"] = record.run;
  json["depotwin"] = record.depotwin_version;
  return json.dump(2) + "\n";
}

std::optional<TaskRecord> read_task_record(const std::string& folder) {
  std::ifstream in(folder + "/task.json", std::ios::binary);
  if (!in) return std::nullopt;
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  try {
    const nlohmann::ordered_json json = nlohmann::ordered_json::parse(text);
    TaskRecord record;
    record.index = json.at("index").get<std::uint64_t>();
    for (const auto& [key, value] : json.at("parameters").items())
      record.parameters.emplace_back(key, value.get<std::string>());
    record.input_hash = json.at("input_hash").get<std::string>();
    record.status = json.at("status").get<std::string>();
    record.error = json.at("error").get<std::string>();
    record.wall_s = json.at("wall_s").get<double>();
    record.run = json.at("run").get<std::string>();
    record.depotwin_version = json.value("depotwin", "");
    return record;
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;  // not a record of ours: the task is not up to date
  }
}

bool task_up_to_date(const Sweep& sweep, std::uint64_t index, const std::string& input_hash) {
  const std::string folder = sweep.found_task_folder(index);
  const std::optional<TaskRecord> record = read_task_record(folder);
  if (!record || record->status != "ok" || record->input_hash != input_hash) return false;
  // its metrics.json whole: one cut short (a full disk, a copy interrupted) is run again, as
  // the merge asks, instead of being skipped for ever
  std::ifstream in(fs::path(folder) / record->run / "metrics.json", std::ios::binary);
  if (!in) return false;
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  return nlohmann::json::accept(text);
}

namespace {

TaskRecord blank_record(const SweepTask& task, const std::string& input_hash) {
  TaskRecord record;
  record.index = task.index;
  for (const auto& [key, value] : task.parameters) record.parameters.emplace_back(key, value.text);
  record.input_hash = input_hash;
  record.status = "failed";
  record.depotwin_version = sweep_depotwin_version();
  return record;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// every problem on its own line, as the CLI prints them
std::string problems_text(const InputError& error) {
  std::string text;
  for (const Problem& problem : error.problems())
    text += (text.empty() ? "" : "\n") + problem.str();
  return text;
}

}  // namespace

TaskRecord run_task(const Sweep& sweep, const SweepTask& task, const std::string& input_hash) {
  const auto start = std::chrono::steady_clock::now();
  TaskRecord record = blank_record(task, input_hash);
  // the task's folder, staged beside its place: an older result is replaced whole at the end
  OutputFolder out(sweep.task_folder(task.index), "sweep", sweep.spec().base);
  try {
    // like `depotwin run --no-render` with the task's one planner
    const Scenario scenario = sweep.load_task(task);
    if (scenario.planners.size() != 1)
      throw InputError(sweep.spec().file, sweep.spec().base_line, "base",
                       "the task's scenario lists " + std::to_string(scenario.planners.size()) +
                           " planners; a task runs one");
    const PlannerSpec& planner = scenario.planners.front();
    // the one validator's second stage, as `run` makes it: the plan's steps and memory
    // against sim.max_steps and the default --max-memory before anything is simulated
    const PreparedJob job = prepare_checked_job(scenario, {planner}, JobBudget{}, true, true);
    RunSettings settings;
    settings.render = false;
    settings.progress = false;
    const SimulatedRun run = simulate_job(job, planner, settings);
    const std::string run_folder = (fs::path(out.path()) / planner.run_label()).string();
    if (sweep.spec().keep == "all") {
      write_run(job, run, run_folder, settings);
    } else {
      fs::create_directories(run_folder);
      write_file_atomically(run_folder + "/metrics.json", metrics_json_text(run.report));
    }
    record.status = "ok";
    record.run = planner.run_label();
  } catch (const InputError& error) {
    record.error = problems_text(error);
  } catch (const EnvironmentError& error) {
    record.error = error.what();  // the machine's refusal (a full disk), not a bug
  } catch (const std::runtime_error& error) {
    // InternalError, a library's error; other exceptions (a request to stop) are not the
    // task's failure and leave its folder as it was
    record.error = std::string("internal error: ") + error.what();
  } catch (const std::logic_error& error) {
    record.error = std::string("internal error: ") + error.what();
  } catch (const std::bad_alloc&) {
    record.error = "internal error: out of memory";
  } catch (const nlohmann::json::exception& error) {
    record.error = std::string("internal error: ") + error.what();
  }
  record.wall_s = seconds_since(start);
  write_file_atomically(out.path() + "/task.json", task_record_json(record));
  out.commit();
  return record;
}

void record_task_failure(const Sweep& sweep, const SweepTask& task, const std::string& input_hash,
                         const std::string& error, double wall_s) {
  TaskRecord record = blank_record(task, input_hash);
  record.error = error;
  record.wall_s = wall_s;
  OutputFolder out(sweep.task_folder(task.index), "sweep", sweep.spec().base);
  write_file_atomically(out.path() + "/task.json", task_record_json(record));
  out.commit();
}

}  // namespace depotwin
