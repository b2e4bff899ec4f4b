// Nothing half-written: a file goes to a temporary name beside its target and is renamed
// into place, so a reader sees the old file or the whole new one.
#pragma once

#include <string>

namespace depotwin {

// Write `content` to `path` through a temporary file in the same directory and a rename.
// Throws InternalError on I/O failure (the target is then untouched).
void write_file_atomically(const std::string& path, const std::string& content);

// ": " and the system's text for `error_number` (errno: "No space left on device"), or "" for
// 0 (a stream that failed without saying why): the tail of "cannot write PATH"
std::string system_reason(int error_number);

// Why write_file_atomically must not write `path`, or "" when it may: an existing path that is
// not a regular file, which the rename would replace itself: a directory, a symbolic link
// (/dev/stdout would become a file), a device (/dev/null), a FIFO or a socket; "-", which
// names standard output elsewhere and a file called "-" here.
std::string replaceable_file_problem(const std::string& path);

// The whole file's bytes; InputError naming the path when it is not a regular file (checked
// first: a FIFO would block the read) or cannot be read.
std::string read_text_file(const std::string& path);

// Why the file a scenario names cannot be used, or "" when `resolved` is a regular file: kind
// and given name it as the user wrote it ("G-code file 'part.gcode' not found (looked for
// /jobs/part.gcode)", "... is a directory (/jobs), not a file"); given empty, for a message
// already prefixed with the path: "G-code file not found", "G-code file is a directory, ...";
// kind empty: "file not found".
std::string missing_file_problem(const std::string& kind, const std::string& given,
                                 const std::string& resolved);

// the most bytes a settings file (a scenario, a sweep) may hold: its long lists go in G-code
// or STL files, and a 3 GB file of NULs was read whole (6.3 GB of memory) before its first
// byte was refused
inline constexpr unsigned long long kMaxSettingsFileBytes = 256ull << 20;

// Why `path` is too large to be a `kind` file ("scenario", "sweep"), or "" (its size is read
// before any byte: a regular file, as missing_file_problem checks first).
std::string settings_file_size_problem(const std::string& kind, const std::string& path);

}  // namespace depotwin
