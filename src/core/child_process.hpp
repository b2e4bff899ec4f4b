// Child processes under the parent's control (gnuplot, ffmpeg). Each is spawned
//   - in a process group of its own, so a terminal's Ctrl-C reaches depotwin alone, which
//     records the signal first and then ends its children (core/interrupt.hpp): a child found
//     killed while a signal is recorded means "interrupted", never "the program failed";
//   - with an empty signal mask and SIGINT, SIGTERM and SIGPIPE at their defaults;
//   - registered with the interrupt handler from its spawn until just before it is reaped;
//   - through util-linux's `setpriv --pdeathsig KILL` where it is installed (Debian: always,
//     util-linux is essential), so the kernel kills it when the thread that spawned it ends,
//     which includes a SIGKILL of depotwin. Only a parent killed in the instant between the
//     spawn and setpriv's prctl(2) can leave a child behind.
#pragma once

#include <spawn.h>
#include <sys/types.h>

#include <string>
#include <vector>

namespace depotwin {

// Spawns `arguments` (arguments[0]: a path, or a program name looked up on PATH) with the file
// actions (null: none) and the environment (null: ours). Returns 0, or the errno value of the
// failure (ENOENT: no such program) as posix_spawn does.
int spawn_child_process(pid_t& pid, const std::vector<std::string>& arguments,
                        const posix_spawn_file_actions_t* actions,
                        char* const* environment = nullptr);

// Waits for the child (EINTR retried) and reaps it; returns its wait status. The child leaves
// the interrupt handler's table before it is reaped.
int wait_child_process(pid_t pid);

// SIGKILL, then reap: a child given up on
void end_child_process(pid_t pid);

// the program's path: `program` itself when it contains a '/', else the first executable
// match on PATH; empty when there is none
std::string find_program(const std::string& program);

}  // namespace depotwin
