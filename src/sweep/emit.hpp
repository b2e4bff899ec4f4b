// `depotwin sweep FILE --emit slurm|parallel`: the sweep handed to a scheduler clusters run,
// printed as a script on stdout. Both run `depotwin sweep FILE --out DIR --task I` once per
// task, then `--merge`; paths are absolute, so the script runs from anywhere.
//
// Slurm: a bash script that submits an sbatch array job (`--array=0-(N-1)%M`, one task per
// array index, `--task env`, logs in DIR/logs/task-%a.log) and a merge job after it
// (`--dependency=afterok:<array> --kill-on-invalid-dep=yes`). A task that fails and records
// its failure exits 101; the array script maps that to 0, so the merge still runs and lists
// the failure; a task that dies without a record fails its array index and the merge is
// cancelled (run `--merge` by hand to see what is missing). Slurm caps an array's indices
// (MaxArraySize, 1001 by default), so a sweep of more than `chunk` tasks becomes several
// arrays of `chunk`, each task told its offset by DEPOTWIN_SWEEP_TASK_OFFSET, the merge after
// all of them.
//
// GNU parallel: one command line that feeds the indices to `parallel --jobs M`, each task's
// output into DIR/logs/task-<i>.log, a job log in DIR/logs/parallel.joblog, then the merge.
#pragma once

#include <cstdint>
#include <string>

#include "sweep/sweep.hpp"

namespace depotwin {

struct EmitOptions {
  std::string executable;      // the depotwin binary, absolute
  std::string sweep_file;      // absolute
  std::string out;             // the results folder, absolute
  int max_running = 0;         // M: at most this many tasks at once (slurm %M, parallel --jobs)
  std::uint64_t chunk = 1000;  // slurm: the most indices per array
};

std::string slurm_script(const Sweep& sweep, const EmitOptions& options);
std::string parallel_command(const Sweep& sweep, const EmitOptions& options);

// `text` quoted for a POSIX shell
std::string shell_quoted(const std::string& text);

}  // namespace depotwin
