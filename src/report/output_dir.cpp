#include "report/output_dir.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <system_error>

#include "core/error.hpp"

namespace depotwin {

namespace fs = std::filesystem;

StagedDirectory::StagedDirectory(std::string final_path) : final_path_(std::move(final_path)) {
  // strip trailing slashes so the staging name sits beside the final directory
  while (final_path_.size() > 1 && final_path_.back() == '/') final_path_.pop_back();
  staging_path_ = final_path_ + ".partial-" + std::to_string(::getpid());
  std::error_code error;
  fs::remove_all(staging_path_, error);
  fs::create_directories(staging_path_, error);
  if (error) throw InternalError("cannot create " + staging_path_ + ": " + error.message());
}

StagedDirectory::~StagedDirectory() {
  if (committed_) return;
  std::error_code ignored;
  fs::remove_all(staging_path_, ignored);
}

void StagedDirectory::commit() {
  std::error_code error;
  const fs::path target(final_path_);
  if (target.has_parent_path()) fs::create_directories(target.parent_path(), error);
  // replace an older result: move it aside first so a failure leaves it intact
  const std::string old = final_path_ + ".old-" + std::to_string(::getpid());
  const bool had_old = fs::exists(target);
  if (had_old) {
    fs::rename(target, old, error);
    if (error) throw InternalError("cannot replace " + final_path_ + ": " + error.message());
  }
  fs::rename(staging_path_, target, error);
  if (error) {
    if (had_old) fs::rename(old, target, error);
    throw InternalError("cannot move results to " + final_path_);
  }
  if (had_old) fs::remove_all(old, error);
  committed_ = true;
}

}  // namespace depotwin
