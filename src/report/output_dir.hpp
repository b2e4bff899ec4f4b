// Nothing half-written: a run's output directory is staged beside its final place and
// renamed only when complete; its files are written with write_file_atomically.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/file_io.hpp"

namespace depotwin {

// The marker file in every verb's output folder: a folder holding it is depotwin's to replace.
inline constexpr const char* kOutputMarker = ".depotwin";
// how a file `depotwin export` writes begins (its first comment)
inline constexpr const char* kExportedGcodeStart = "; G-code exported by depotwin";

// the first line of `folder`'s marker file ("depotwin output folder, written by ...", "depotwin
// sweep folder (NAME): ..."), "" when it has none: what kind of folder it is
std::string output_marker_line(const std::string& folder);
// `file_name` is the marker on its way: the temporary file it is written through, then renamed
bool is_marker_being_written(const std::string& file_name);

// A directory built under a temporary name (`<final>.partial-<pid>`) and renamed to its
// final name by commit(), replacing an older result. Destroyed without commit(), it is
// removed with everything in it.
class StagedDirectory {
 public:
  explicit StagedDirectory(std::string final_path);
  ~StagedDirectory();
  StagedDirectory(const StagedDirectory&) = delete;
  StagedDirectory& operator=(const StagedDirectory&) = delete;

  const std::string& path() const { return staging_path_; }
  const std::string& final_path() const { return final_path_; }
  std::string file(const std::string& name) const { return staging_path_ + "/" + name; }
  void commit();

 private:
  std::string final_path_;
  std::string staging_path_;
  bool committed_ = false;
};

// One writer at a time for an output (a folder or a file): an advisory lock, flock(2), on the
// file `<target>.lock` beside it. The lock is not on the output itself, whose name is swapped
// to a new folder at commit, nor on the parent, which would make unrelated outputs wait. Its
// holder writes "pid N, `depotwin VERB`" in it, and removes it before it lets go; a waiter that
// then holds the lock of a removed file opens the name again. A holder killed outright leaves
// the file but not the lock (the kernel drops it with the process): the next writer takes the
// file over, so no stale state blocks anyone. The descriptor is close-on-exec, so a child
// process never holds the lock.
class OutputLock {
 public:
  // target_path: the output's absolute path; shown_path: as the user gave it (messages);
  // verb: names the holder. While another process holds the lock, waits (saying so once on
  // stderr, and stopping for a signal: core/interrupt.hpp) or, with wait false, throws
  // InputError (key "--out"). InputError too when the lock file cannot be created (the folder
  // cannot be written in) or a file of that name is not depotwin's.
  OutputLock(const std::string& target_path, const std::string& shown_path, const std::string& verb,
             bool wait);
  ~OutputLock() { release(); }
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;

  const std::string& lock_path() const { return lock_path_; }
  // removes the lock file and lets go (idempotent)
  void release();

 private:
  std::string lock_path_;
  int descriptor_ = -1;
};

// Removes what writers of `target_path` killed outright left beside it: `<target>.partial-<pid>`
// and `<target>.old-<pid>` folders and `<target>.tmp-<pid>` files whose process is dead (kill(2)
// says no such process; a live pid, even a reused one, is left alone), and only where they are
// a writer's: a folder that is a depotwin output (marker, or empty), a file that is empty or
// begins with kExportedGcodeStart; anything else of such a name is the user's and stays. Call
// it holding the target's OutputLock: no live writer of the target can then be staging.
void remove_stale_staging(const std::string& target_path);

// A verb's whole output folder (`--out DIR`): staged beside DIR, written with the
// kOutputMarker file, and swapped in whole by commit() (one atomic exchange where the file
// system has it), so no file of an earlier result survives beside the new ones. DIR's
// OutputLock is held from before the staging folder exists until the commit is done.
//
// The constructor checks DIR before any planning or simulation and throws InputError (key
// "--out") when DIR is a file or lies under one, cannot be written in, holds the current
// directory, the scenario file or a file it reads, is a sweep's folder (its marker says so),
// or exists with files but is not a depotwin output (no
// marker, and not shaped like an older depotwin result: only comparison.* files and folders
// holding a metrics.json). A folder that is not ours is never deleted. It then takes the lock
// (waiting for another writer, or with wait false refusing), checks DIR again, and removes
// stale staging folders of dead writers. Destroyed without commit() (an exception, an
// interrupt), the staging folder is removed with everything in it.
class OutputFolder {
 public:
  // verb: names the writer in the marker and lock files; scenario_file and input_files (the
  // files the scenario reads: G-code, STL, MJCF): refused as part of DIR, which is replaced
  // whole; wait: for another writer of DIR (false: InputError while one writes)
  OutputFolder(const std::string& final_path, const std::string& verb,
               const std::string& scenario_file, bool wait = true,
               const std::vector<std::string>& input_files = {});
  ~OutputFolder();
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  // where the verb writes: the staging folder
  const std::string& path() const { return staging_path_; }
  // DIR as given (for messages)
  const std::string& final_path() const { return final_path_; }
  // Replaces DIR by the staging folder and lets go of the lock. A signal that asked to stop
  // before it (core/interrupt.hpp) throws Interrupted instead, leaving DIR as it was; one that
  // comes after it finds the new result in place. InternalError when the file system refuses.
  void commit();

 private:
  std::string final_path_;    // as given
  std::string target_path_;   // absolute, symlinks of DIR itself resolved
  std::string staging_path_;  // <target>.partial-<pid>
  std::unique_ptr<OutputLock> lock_;
  bool committed_ = false;
};

}  // namespace depotwin
