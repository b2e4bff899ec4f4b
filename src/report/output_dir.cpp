#include "report/output_dir.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <system_error>
#include <thread>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/number_text.hpp"

namespace depotwin {

namespace fs = std::filesystem;

namespace {

std::string staging_name(const std::string& final_path) {
  return final_path + ".partial-" + std::to_string(::getpid());
}

// Puts the folder `staging` in the place of `target` (absent, or a folder). Where the file
// system can exchange two names atomically (Linux renameat2), a reader of `target` sees the
// old folder or the new one, never neither; elsewhere the old folder is moved aside first, so
// a failure leaves it intact. The old folder is deleted afterwards.
void replace_directory(const std::string& staging, const std::string& target) {
  std::error_code error;
  const bool had_old = fs::exists(fs::symlink_status(target));
  if (had_old && fs::is_directory(fs::symlink_status(target)) &&
      ::renameat2(AT_FDCWD, staging.c_str(), AT_FDCWD, target.c_str(), RENAME_EXCHANGE) == 0) {
    fs::remove_all(staging, error);  // the old result, now under the staging name
    return;
  }
  // no exchange here: move the old result aside, the new one in, then drop the old one
  const std::string old = target + ".old-" + std::to_string(::getpid());
  if (had_old) {
    fs::rename(target, old, error);
    if (error) throw EnvironmentError("cannot replace " + target + ": " + error.message());
  }
  fs::rename(staging, target, error);
  if (error) {
    const std::string reason = error.message();
    if (had_old) fs::rename(old, target, error);
    throw EnvironmentError("cannot move results to " + target + ": " + reason);
  }
  if (had_old) fs::remove_all(old, error);
}

// `inner` is `outer` or lies inside it (both absolute and normalised)
bool is_within(const fs::path& inner, const fs::path& outer) {
  auto o = outer.begin();
  for (auto i = inner.begin(); o != outer.end(); ++i, ++o)
    if (i == inner.end() || *i != *o) return false;
  return true;
}

// a folder depotwin may replace: empty or holding the marker. A folder shaped like an old
// result (run folders with a metrics.json) is not enough: that name is common, and a user's
// files beside it would go with it
bool is_depotwin_output(const fs::path& folder) {
  std::error_code error;
  if (fs::exists(folder / kOutputMarker, error)) return true;
  return fs::is_empty(folder, error) && !error;
}

}  // namespace

bool is_marker_being_written(const std::string& file_name) {
  const std::string prefix = std::string(kOutputMarker) + ".tmp-";
  return file_name.rfind(prefix, 0) == 0;
}

std::string output_marker_line(const std::string& folder) {
  std::ifstream marker(fs::path(folder) / kOutputMarker);
  std::string first_line;
  if (!marker || !std::getline(marker, first_line)) return "";
  return first_line;
}

namespace {

// what the marker of `folder` says it is when that is not a run, compare or plan output
// folder ("a depotwin sweep folder (NAME)"), else ""
std::string marker_kind(const fs::path& folder) {
  const std::string first_line = output_marker_line(folder.string());
  const std::string sweep = "depotwin sweep folder";
  if (first_line.rfind(sweep, 0) != 0) return "";
  const std::size_t colon = first_line.find("):");
  return "a " + (colon == std::string::npos ? sweep : first_line.substr(0, colon + 1));
}

// "the nearest existing ancestor of `path`"
fs::path nearest_existing(fs::path path) {
  std::error_code error;
  while (!path.empty() && !fs::exists(path, error) && path.has_relative_path())
    path = path.parent_path();
  return path;
}

// how often a writer waiting for an output's lock tries again
constexpr std::chrono::milliseconds kLockPollPeriod{100};
// a lock held by a holder that has not written its name yet: polls (a tenth of the period
// each) before it is named "another depotwin process"
constexpr int kPollsForTheHoldersName = 10;
// what a depotwin lock file starts with (a file of that name holding anything else is not ours)
constexpr const char* kLockTextPrefix = "depotwin lock held by ";

// the lock file's text: who holds it, empty when it cannot be read
std::string lock_holder_text(int descriptor) {
  char text[256];
  const ssize_t size = ::pread(descriptor, text, sizeof text - 1, 0);
  std::string holder(text, size > 0 ? static_cast<size_t>(size) : 0);
  while (!holder.empty() && (holder.back() == '\n' || holder.back() == '\r')) holder.pop_back();
  return holder;
}

// the pid in `name` when it is `<base><tag><digits>`, else 0
pid_t staging_pid(const std::string& name, const std::string& base, const std::string& tag) {
  const std::string prefix = base + tag;
  if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) return 0;
  const std::string digits = name.substr(prefix.size());
  if (digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) return 0;
  return static_cast<pid_t>(std::stol(digits));
}

}  // namespace

OutputLock::OutputLock(const std::string& target_path, const std::string& shown_path,
                       const std::string& verb, bool wait)
    : lock_path_(target_path + ".lock") {
  auto refuse = [&](const std::string& why) { throw InputError("--out", shown_path + ": " + why); };
  const std::string folder = fs::path(target_path).parent_path().string();
  bool told = false;
  int unnamed_polls = 0;
  while (true) {
    throw_if_interrupted();
    // O_CLOEXEC: a child process (gnuplot, ffmpeg) never inherits the lock
    descriptor_ = ::open(lock_path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (descriptor_ < 0) {
      const int why = errno;
      if (why == ELOOP || why == EISDIR)
        refuse(lock_path_ + " is in the way (a link or a folder, not depotwin's lock file)");
      refuse("cannot write in " + folder + ": " + std::strerror(why));
    }
    if (::flock(descriptor_, LOCK_EX | LOCK_NB) == 0) {
      // the file held must still be the one of that name: a holder removes it before it lets
      // go, and a waiter that took the lock of the removed file tries again
      struct stat held {
      }, named{};
      if (::fstat(descriptor_, &held) == 0 && ::stat(lock_path_.c_str(), &named) == 0 &&
          held.st_dev == named.st_dev && held.st_ino == named.st_ino)
        break;
      ::close(descriptor_);
      descriptor_ = -1;
      continue;
    }
    const int why = errno;
    const std::string holder = lock_holder_text(descriptor_);
    ::close(descriptor_);
    descriptor_ = -1;
    if (why != EWOULDBLOCK && why != EINTR)
      refuse("cannot lock " + lock_path_ + ": " + std::strerror(why));
    const bool named = holder.rfind(kLockTextPrefix, 0) == 0;
    const std::string who = named ? holder.substr(std::strlen(kLockTextPrefix))
                                  : std::string("another depotwin process");
    // a holder writes its name just after it takes the lock: a few polls to read it
    if (!named && ++unnamed_polls <= kPollsForTheHoldersName) {
      std::this_thread::sleep_for(kLockPollPeriod / 10);
      continue;
    }
    if (!wait)
      refuse("is being written by " + who + " (" + lock_path_ +
             " is locked); run again when it is done, or without --no-wait to wait for it");
    if (!told) {
      std::cerr << "waiting: " << terminal_text(shown_path) << " is being written by " << who
                << "; this run goes on when it is done (--no-wait: exit instead)" << std::endl;
      told = true;
    }
    std::this_thread::sleep_for(kLockPollPeriod);
  }

  // ours: empty (just made) or a depotwin lock file left by a writer killed outright
  const std::string text = lock_holder_text(descriptor_);
  if (!text.empty() && text.rfind(kLockTextPrefix, 0) != 0) {
    ::close(descriptor_);
    descriptor_ = -1;
    refuse(lock_path_ + " exists and is not depotwin's lock file; remove it");
  }
  const std::string holder = std::string(kLockTextPrefix) + "pid " + std::to_string(::getpid()) +
                             " (`depotwin " + verb + "`)\n";
  if (::ftruncate(descriptor_, 0) != 0 ||
      ::pwrite(descriptor_, holder.data(), holder.size(), 0) != static_cast<ssize_t>(holder.size()))
    refuse("cannot write " + lock_path_ + ": " + std::strerror(errno));
}

void OutputLock::release() {
  if (descriptor_ < 0) return;
  // removed while still held, so the next holder makes a fresh one
  ::unlink(lock_path_.c_str());
  ::close(descriptor_);
  descriptor_ = -1;
}

namespace {

// `entry`, named like a writer's staging, is what that writer leaves: a `.partial-` or `.old-`
// folder that is a depotwin output (its marker, or being given one, or empty), or a `.tmp-`
// file that is empty or begins as `export`'s G-code does. A user's own `results.old-2023`
// folder or `job.gcode.tmp-1` file is not (it was deleted once: the pid alone decided).
bool left_by_a_writer(const fs::directory_entry& entry, const std::string& tag) {
  std::error_code error;
  const fs::file_status status = entry.symlink_status(error);
  if (tag == ".tmp-") {
    if (!fs::is_regular_file(status)) return false;
    std::ifstream file(entry.path(), std::ios::binary);
    std::string start(std::strlen(kExportedGcodeStart), '\0');
    file.read(start.data(), static_cast<std::streamsize>(start.size()));
    return file.gcount() == 0 || (file && start == kExportedGcodeStart);
  }
  if (!fs::is_directory(status)) return false;
  if (is_depotwin_output(entry.path())) return true;
  // killed between making the folder and renaming its marker into place
  int n_entries = 0;
  bool only_the_marker_being_written = true;
  for (const fs::directory_entry& inner : fs::directory_iterator(entry.path(), error)) {
    ++n_entries;
    only_the_marker_being_written =
        only_the_marker_being_written && is_marker_being_written(inner.path().filename().string());
  }
  return !error && n_entries == 1 && only_the_marker_being_written;
}

}  // namespace

void remove_stale_staging(const std::string& target_path) {
  const fs::path target(target_path);
  const std::string base = target.filename().string();
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(target.parent_path(), error)) {
    const std::string name = entry.path().filename().string();
    for (const char* tag : {".partial-", ".old-", ".tmp-"}) {
      const pid_t pid = staging_pid(name, base, tag);
      if (pid <= 0 || pid == ::getpid()) continue;
      // a live process keeps its folder (even a reused pid: then it stays until that ends)
      if (::kill(pid, 0) == 0 || errno != ESRCH) continue;
      if (!left_by_a_writer(entry, tag)) continue;
      std::error_code ignored;
      fs::remove_all(entry.path(), ignored);
    }
  }
}

StagedDirectory::StagedDirectory(std::string final_path) : final_path_(std::move(final_path)) {
  // strip trailing slashes so the staging name sits beside the final directory
  while (final_path_.size() > 1 && final_path_.back() == '/') final_path_.pop_back();
  staging_path_ = staging_name(final_path_);
  std::error_code error;
  fs::remove_all(staging_path_, error);
  fs::create_directories(staging_path_, error);
  if (error) throw EnvironmentError("cannot create " + staging_path_ + ": " + error.message());
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
  replace_directory(staging_path_, final_path_);
  committed_ = true;
}

OutputFolder::OutputFolder(const std::string& final_path, const std::string& verb,
                           const std::string& scenario_file, bool wait,
                           const std::vector<std::string>& input_files)
    : final_path_(final_path) {
  auto refuse = [&](const std::string& why) {
    throw InputError("--out", final_path_ + ": " + why);
  };
  if (final_path_.empty()) throw InputError("--out", "an empty path names no folder");

  // the folder by its absolute name; a symlink to a folder stands for its target
  std::error_code error;
  fs::path target = fs::absolute(final_path_, error).lexically_normal();
  if (!target.has_filename()) target = target.parent_path();  // a trailing '/'
  if (fs::is_symlink(fs::symlink_status(target, error))) {
    target = fs::canonical(target, error);
    if (error) refuse("is a symbolic link to nothing");
  }
  if (!target.has_relative_path()) refuse("is the root folder");

  // a file, or a path under a file; an existing folder is replaced whole, so it must be ours
  // and hold nothing we need (checked again once the lock is ours: DIR may change meanwhile)
  const auto check_target = [&]() {
    const fs::file_status status = fs::status(target, error);
    if (fs::exists(status) && !fs::is_directory(status)) refuse("is a file, not a folder");
    const fs::path existing = nearest_existing(target.parent_path());
    if (!fs::is_directory(existing, error))
      refuse("lies under " + existing.string() + ", which is a file, not a folder");
    if (!fs::is_directory(status)) return;
    const fs::path canonical = fs::canonical(target, error);
    if (is_within(fs::current_path(error), canonical))
      refuse("holds the current directory; choose a folder of its own for the results");
    const fs::path scenario = fs::weakly_canonical(scenario_file, error);
    if (!scenario_file.empty() && is_within(scenario, canonical))
      refuse("holds the scenario file " + scenario_file +
             "; choose a folder of its own for the results");
    for (const std::string& input : input_files)
      if (!input.empty() && is_within(fs::weakly_canonical(input, error), canonical))
        refuse("holds " + input +
               ", which the scenario reads; choose a folder of its own for the results");
    if (const std::string kind = marker_kind(target); !kind.empty())
      refuse("is " + kind + ", not a run's; choose a folder of its own for the results");
    if (!is_depotwin_output(target))
      refuse("exists and is not a depotwin output folder (it has files but no " +
             std::string(kOutputMarker) +
             " marker); it is replaced whole, so choose an empty or new folder, or remove it");
    if (::access(target.c_str(), W_OK | X_OK) != 0)
      refuse(std::string("cannot be replaced: ") + std::strerror(errno));
    // a mount point (a container's volume, an NFS root) cannot be swapped with a folder
    // beside it: say so now, not after the work
    struct stat own_status = {};
    struct stat parent_status = {};
    if (::stat(target.c_str(), &own_status) == 0 &&
        ::stat(target.parent_path().c_str(), &parent_status) == 0 &&
        own_status.st_dev != parent_status.st_dev)
      refuse("is a mount point, which cannot be replaced whole; give a folder inside it");
  };
  check_target();

  target_path_ = target.string();
  staging_path_ = staging_name(target_path_);
  fs::create_directories(target.parent_path(), error);
  if (error) refuse("cannot create " + target.parent_path().string() + ": " + error.message());
  if (::access(target.parent_path().c_str(), W_OK | X_OK) != 0)
    refuse("cannot write in " + target.parent_path().string() + ": " + std::strerror(errno));

  // one writer at a time: wait for (or refuse) another; then DIR again, and what writers
  // killed outright left beside it
  lock_ = std::make_unique<OutputLock>(target_path_, final_path_, verb, wait);
  check_target();
  remove_stale_staging(target_path_);

  // the staging folder beside it is the probe: creating it proves the parent writable (as
  // root, access(2) says yes even on a read-only mount)
  fs::remove_all(staging_path_, error);
  if (!fs::create_directory(staging_path_, error) || error)
    refuse("cannot write in " + target.parent_path().string() + ": " +
           (error ? error.message() : "the staging folder exists"));

  // the marker: the next verb run into this folder may replace it
  try {
    write_file_atomically(staging_path_ + "/" + kOutputMarker,
                          "depotwin output folder, written by `depotwin " + verb +
                              "`; the next depotwin run, compare or plan into it replaces it "
                              "whole\n");
  } catch (const InternalError& failure) {
    fs::remove_all(staging_path_, error);
    refuse(std::string("cannot write in it: ") + failure.what());
  } catch (...) {
    // (the destructor does not run for an object not made: the staging folder goes here)
    fs::remove_all(staging_path_, error);
    throw;
  }
}

OutputFolder::~OutputFolder() {
  // the staging folder goes before the lock does (lock_ is destroyed after this body)
  if (committed_) return;
  std::error_code ignored;
  fs::remove_all(staging_path_, ignored);
}

void OutputFolder::commit() {
  // the run was asked to stop: DIR keeps its earlier result
  throw_if_interrupted();
  // a folder that appeared meanwhile and is not ours is left alone (a writer that takes no
  // lock: an older depotwin, or another program)
  std::error_code error;
  if (fs::is_directory(fs::symlink_status(target_path_, error)) &&
      !is_depotwin_output(target_path_))
    throw InputError("--out", final_path_ +
                                  ": appeared during the run and is not a depotwin output "
                                  "folder; the results were not written");
  replace_directory(staging_path_, target_path_);
  committed_ = true;
  lock_->release();
}

}  // namespace depotwin
