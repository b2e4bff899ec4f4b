// `depotwin sweep FILE`: a parameter study (src/sweep/). Modes:
//   (none)          run every task that is not up to date on -j N local workers, then merge
//   --list          the tasks: index, parameters, folder, state
//   --task I|env    one task in this process (a scheduler's array index with env)
//   --merge         results.sqlite, results.csv and summary.png from the task folders
//   --emit slurm    an sbatch array script (and its merge job) on stdout
//   --emit parallel the GNU parallel command line on stdout
// Every mode but --task and --merge loads every task's scenario first and lists every
// problem (exit 2, nothing written). Exit status: 0 when every task is ok; 100 + k when k
// tasks failed (or, for --merge, failed or are missing), 255 for 155 or more; 2 bad input;
// 1 internal failure.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace depotwin {

struct SweepOptions {
  std::string file;
  std::string out;  // results folder (empty: results/<sweep name>)
  bool list = false;
  std::string task;  // --task I | env
  int jobs = 0;      // -j: workers (0: one per core); --emit: tasks at once
  bool merge = false;
  std::string emit;  // slurm | parallel
  bool force = false;
  bool no_render = false;  // no summary.png
  bool quiet = false;
  bool no_wait = false;  // refuse, not wait, while another sweep or merge writes the folder
  bool worker = false;   // depotwin's own worker processes (hidden)
};

// the exit status that says k tasks failed: 100 + k, at most 255
int failed_tasks_status(unsigned long long failed);

// adds the verb and its options to the app
CLI::App* add_sweep_verb(CLI::App& app, SweepOptions& options);

int sweep_verb(const SweepOptions& options);

}  // namespace depotwin
