// Nothing half-written: a run's output directory is staged beside its final place and
// renamed only when complete; its files are written with write_file_atomically.
#pragma once

#include <string>

#include "core/file_io.hpp"

namespace depotwin {

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

}  // namespace depotwin
