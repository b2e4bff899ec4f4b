// Nothing half-written: a run's output directory is staged beside its final place and
// renamed only when complete; its files are written with write_file_atomically.
#pragma once

#include <string>

#include "core/file_io.hpp"

namespace depotwin {

// The marker file in every verb's output folder: a folder holding it is depotwin's to replace.
inline constexpr const char* kOutputMarker = ".depotwin";

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

// A verb's whole output folder (`--out DIR`): staged beside DIR, written with the
// kOutputMarker file, and swapped in whole by commit() (one atomic exchange where the file
// system has it), so no file of an earlier result survives beside the new ones.
//
// The constructor checks DIR before any planning or simulation and throws InputError (key
// "--out") when DIR is a file or lies under one, cannot be written in, holds the current
// directory or the scenario file, or exists with files but is not a depotwin output (no
// marker, and not shaped like an older depotwin result: only comparison.* files and folders
// holding a metrics.json). A folder that is not ours is never deleted. Destroyed without
// commit() (an exception), the staging folder is removed with everything in it.
class OutputFolder {
 public:
  // verb: names the writer in the marker file; scenario_file: refused as part of DIR
  OutputFolder(const std::string& final_path, const std::string& verb,
               const std::string& scenario_file);
  ~OutputFolder();
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  // where the verb writes: the staging folder
  const std::string& path() const { return staging_path_; }
  // DIR as given (for messages)
  const std::string& final_path() const { return final_path_; }
  // replaces DIR by the staging folder; InternalError when the file system refuses
  void commit();

 private:
  std::string final_path_;    // as given
  std::string target_path_;   // absolute, symlinks of DIR itself resolved
  std::string staging_path_;  // <target>.partial-<pid>
  bool committed_ = false;
};

}  // namespace depotwin
