#include "pipeline/models_dir.hpp"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <system_error>
#include <utility>

namespace depotwin {

namespace fs = std::filesystem;

namespace {

// the models folder and where the choice came from
std::pair<std::string, const char*> find_models_directory() {
  // an explicit choice wins
  if (const char* from_env = std::getenv("DEPOTWIN_MODELS_DIR"); from_env && *from_env)
    return {from_env, "from $DEPOTWIN_MODELS_DIR"};
  // an installed binary: <prefix>/bin/depotwin next to <prefix>/share/depotwin/models
  std::error_code error;
  const fs::path binary = fs::read_symlink("/proc/self/exe", error);
  if (!error) {
    const fs::path installed = binary.parent_path().parent_path() / "share" / "depotwin" / "models";
    if (fs::is_directory(installed, error))
      return {installed.string(), "beside the installed binary"};
  }
  // a build tree: the sources it was configured from
  return {DEPOTWIN_MODELS_DIR, "the source tree this binary was built from"};
}

}  // namespace

std::string models_directory() {
  return find_models_directory().first;
}

std::string models_directory_text() {
  const auto [folder, origin] = find_models_directory();
  return folder + " (" + origin + ")";
}

}  // namespace depotwin
