// The scenario verbs of the CLI; each returns the process exit status.
#pragma once

#include <string>

namespace depotwin {

struct RunOptions {
  std::string scenario;
  std::string planners;  // comma list; empty: the scenario's
  std::string out;
  bool no_render = false;
  bool quiet = false;  // no progress line, nor the job's long steps (pipeline/step_heartbeat.hpp)
  // another writer of --out holds its lock: exit 2 instead of waiting (report/output_dir.hpp)
  bool no_wait = false;
  std::string max_memory;  // --max-memory (pipeline/job_check.hpp); empty: the default
  // ---- moving pictures: run.mp4 (RunSettings::video) ----
  bool video = false;
  double video_length_s = 30.0;
  // ---- end moving pictures ----
};

struct CompareOptions {
  RunOptions run;
  std::string orders;  // comma list of sequencers to compare instead of planners
};

int run_verb(const RunOptions& options);
int compare_verb(const CompareOptions& options);
int plan_verb(const RunOptions& options);
int validate_verb(const std::string& scenario, const std::string& max_memory = {},
                  bool quiet = false);

}  // namespace depotwin
