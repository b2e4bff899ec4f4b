// The test process's own scratch folder under the system's temporary folder,
// depotwin_test_<pid>: removed when the process ends with every test passed, kept for
// inspection after a failure. Without it each ctest run left its outputs behind (the examples'
// runs alone hold 166 MB), one folder per test process.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

namespace depotwin::testing_support {

inline const std::filesystem::path& scratch_root() {
  // made on first use, after GoogleTest's UnitTest (which the tests' registration makes before
  // main), so it is destroyed before it and can still ask whether every test passed
  struct Root {
    pid_t owner = ::getpid();
    std::filesystem::path path =
        std::filesystem::temp_directory_path() / ("depotwin_test_" + std::to_string(owner));
    ~Root() {
      // a forked child that exits through here must not remove its parent's folder
      if (::getpid() != owner || !::testing::UnitTest::GetInstance()->Passed()) return;
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  };
  static const Root root;
  return root.path;
}

// a fresh, empty folder `name` in the scratch folder (removed first if a test made it before)
inline std::string fresh_directory(const std::string& name) {
  const std::filesystem::path dir = scratch_root() / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

// the path of a file `name` in the scratch folder, which is made if missing
inline std::string scratch_file(const std::string& name) {
  std::filesystem::create_directories(scratch_root());
  return (scratch_root() / name).string();
}

}  // namespace depotwin::testing_support
