#include "sweep/emit.hpp"

#include <algorithm>

namespace depotwin {

std::string shell_quoted(const std::string& text) {
  // plain words stay as they are; anything else in single quotes
  const bool plain = !text.empty() && std::all_of(text.begin(), text.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 ||
           std::string("_./=:,+-@%").find(c) != std::string::npos;
  });
  if (plain) return text;
  std::string quoted = "'";
  for (const char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

namespace {

// `depotwin sweep FILE --out DIR` with the rest of the arguments
std::string sweep_command(const EmitOptions& options, const std::string& rest) {
  return shell_quoted(options.executable) + " sweep " + shell_quoted(options.sweep_file) +
         " --out " + shell_quoted(options.out) + " " + rest;
}

}  // namespace

std::string slurm_script(const Sweep& sweep, const EmitOptions& options) {
  const std::string& name = sweep.spec().name;
  const std::uint64_t count = sweep.size();
  const std::uint64_t chunk = std::max<std::uint64_t>(1, options.chunk);
  const std::string logs = options.out + "/logs";
  std::string s;
  s += "#!/bin/bash\n";
  s += "# " + name + ": " + std::to_string(count) + " tasks of " + options.sweep_file +
       "\n# as a Slurm array job, then their merge into " + options.out +
       "/results.sqlite.\n# Written by `depotwin sweep --emit slurm`; submit with `bash "
       "THIS_FILE`.\n";
  s += "set -euo pipefail\n";
  s += "mkdir -p " + shell_quoted(logs) + "\n";
  s += "arrays=\"\"\n";
  // one array per chunk of indices (Slurm's MaxArraySize)
  for (std::uint64_t first = 0; first < count; first += chunk) {
    const std::uint64_t size = std::min(chunk, count - first);
    s += "\n# tasks " + std::to_string(first) + ".." + std::to_string(first + size - 1) + "\n";
    s += "job=$(sbatch --parsable <<'SBATCH'\n";
    s += "#!/bin/bash\n";
    s += "#SBATCH --job-name=" + shell_quoted(name) + "\n";
    s += "#SBATCH --array=0-" + std::to_string(size - 1) + "%" +
         std::to_string(std::max(1, options.max_running)) + "\n";
    s += "#SBATCH --ntasks=1\n#SBATCH --cpus-per-task=1\n";
    s += "#SBATCH --output=" + shell_quoted(logs + "/slurm-%A_%a.log") + "\n";
    s += "export DEPOTWIN_SWEEP_TASK_OFFSET=" + std::to_string(first) + "\n";
    s += "# each task's output in its own log, named by its task index\n";
    s += "exec >" + shell_quoted(logs) + "/task-$((SLURM_ARRAY_TASK_ID + " + std::to_string(first) +
         ")).log 2>&1\n";
    s += "status=0\n";
    s += sweep_command(options, "--task env --quiet") + " || status=$?\n";
    s += "# 101: the task failed and recorded why; the array index succeeds so that the merge "
         "lists it\n";
    s += "if [ \"$status\" -eq 101 ]; then exit 0; fi\n";
    s += "exit \"$status\"\n";
    s += "SBATCH\n)\n";
    s += "arrays=\"$arrays:${job%%;*}\"\n";
  }
  s += "\n# the merge, once every array index succeeded\n";
  s += "merge=$(sbatch --parsable --dependency=\"afterok$arrays\" --kill-on-invalid-dep=yes "
       "<<'SBATCH'\n";
  s += "#!/bin/bash\n";
  s += "#SBATCH --job-name=" + shell_quoted(name + "-merge") + "\n";
  s += "#SBATCH --ntasks=1\n#SBATCH --cpus-per-task=1\n";
  s += "#SBATCH --output=" + shell_quoted(logs + "/merge.log") + "\n";
  s += sweep_command(options, "--merge --quiet") + "\n";
  s += "SBATCH\n)\n";
  // the user's words single-quoted, the job ids expanded between them
  s += "echo " + shell_quoted(name + ": submitted array job(s)") + "\"${arrays//:/ }\"" +
       shell_quoted(" (" + std::to_string(count) + " tasks) and merge job ") + "\"${merge%%;*}\"" +
       shell_quoted("; results in " + options.out) + "\n";
  return s;
}

std::string parallel_command(const Sweep& sweep, const EmitOptions& options) {
  const std::string logs = options.out + "/logs";
  const std::string task = sweep_command(options, "--task {} --quiet") + " > " +
                           shell_quoted(logs) + "/task-{}.log 2>&1";
  return "mkdir -p " + shell_quoted(logs) + " && seq 0 " + std::to_string(sweep.size() - 1) +
         " | parallel --jobs " + std::to_string(std::max(1, options.max_running)) +
         " --halt never --joblog " + shell_quoted(logs + "/parallel.joblog") + " " +
         shell_quoted(task) + "; " + sweep_command(options, "--merge") + "\n";
}

}  // namespace depotwin
