// Running gnuplot: find it, run one script in one process, wait, check the exit status and
// what it printed. Plots are rendered into a private temporary directory and moved into
// place only when gnuplot succeeded.
#pragma once

#include <string>
#include <vector>

#include "core/error.hpp"

namespace depotwin::plots {

// gnuplot is not installed (exit 1, like every InternalError)
class GnuplotNotFound : public InternalError {
 public:
  GnuplotNotFound();
};

// the executable to run: `program` itself when it contains a '/', else the first match on
// PATH; throws GnuplotNotFound when there is none
std::string find_gnuplot(const std::string& program);

// Run `gnuplot -d script` (no init files, LC_ALL=C) and wait for it. Throws InternalError with
// its stderr when it fails; returns the lines it printed on stderr otherwise (warnings).
std::vector<std::string> run_gnuplot(const std::string& executable, const std::string& script_path,
                                     const std::string& stderr_path);

// A fresh directory `<parent>/.plots-XXXXXX`, removed with its contents on destruction.
class TemporaryDirectory {
 public:
  explicit TemporaryDirectory(const std::string& parent);
  ~TemporaryDirectory();
  TemporaryDirectory(const TemporaryDirectory&) = delete;
  TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;

  const std::string& path() const { return path_; }
  std::string file(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

// write a file (binary), InternalError on failure
void write_text_file(const std::string& path, const std::string& content);
// rename `from` onto `to` (same file system), InternalError on failure
void move_into_place(const std::string& from, const std::string& to);

}  // namespace depotwin::plots
