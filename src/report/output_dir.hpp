// Nothing half-written: files go to a temporary name and are renamed into place; a run's
// output directory is staged beside its final place and renamed only when complete.
#pragma once

#include <string>

namespace depotwin {

// Write `content` to `path` through a temporary file in the same directory and a rename.
// Throws InternalError on I/O failure (the target is then untouched).
void write_file_atomically(const std::string& path, const std::string& content);

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
