#include "core/file_io.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <system_error>

#include "core/error.hpp"

namespace depotwin {

namespace fs = std::filesystem;

void write_file_atomically(const std::string& path, const std::string& content) {
  const std::string temporary = path + ".tmp-" + std::to_string(::getpid());
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    errno = 0;
    out << content;
    out.flush();
    if (!out) {
      // why, as the system said it (a full disk: "No space left on device")
      const int why = errno;
      std::error_code ignored;
      fs::remove(temporary, ignored);
      throw EnvironmentError("cannot write " + path + system_reason(why));
    }
  }
  std::error_code error;
  fs::rename(temporary, path, error);
  if (error) {
    const std::string why = error.message();
    fs::remove(temporary, error);
    throw EnvironmentError("cannot move " + temporary + " to " + path + ": " + why);
  }
}

std::string system_reason(int error_number) {
  return error_number != 0 ? std::string(": ") + std::strerror(error_number) : std::string();
}

std::string replaceable_file_problem(const std::string& path) {
  if (path == "-")
    return "'-' (standard output) is not supported; name the file to write, e.g. job.gcode";
  std::error_code error;
  const fs::file_status status = fs::symlink_status(path, error);
  if (!fs::exists(status) || fs::is_regular_file(status)) return "";
  const std::string is = "'" + path + "' is ";
  if (fs::is_directory(status)) return is + "a directory; name a file in it";
  if (fs::is_symlink(status)) {
    const fs::path target = fs::read_symlink(path, error);
    return is + "a symbolic link (to '" + target.string() +
           "'), which the new file would replace; name the file itself";
  }
  return is +
         "not a regular file (a device, FIFO or socket), which the new file would "
         "replace; name a file to write";
}

std::string read_text_file(const std::string& path) {
  // checked before opening: reading a FIFO would wait for a writer
  const std::string problem = missing_file_problem("", "", path);
  if (!problem.empty()) throw InputError(path, 0, "", problem);
  std::ifstream in(path, std::ios::binary);
  std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in && !in.eof()) throw InputError(path, 0, "", "cannot read the file");
  return content;
}

std::string missing_file_problem(const std::string& kind, const std::string& given,
                                 const std::string& resolved) {
  std::error_code error;
  const fs::file_status status = fs::status(resolved, error);
  // (given empty: the message's prefix names the path already)
  const std::string noun = kind.empty() ? "file" : kind + " file";
  const std::string file = given.empty() ? noun : noun + " '" + given + "'";
  const std::string where = given.empty() ? "" : " (" + resolved + ")";
  if (fs::is_regular_file(status)) return "";
  if (fs::is_directory(status)) return file + " is a directory" + where + ", not a file";
  if (fs::exists(status)) return file + " is not a regular file" + where;
  // a path the system cannot follow (a loop of symbolic links, a name too long, a folder on
  // the way that cannot be searched) is not a missing file: its reason is said
  if (error && error != std::errc::no_such_file_or_directory)
    return file + " cannot be opened" + where + ": " + error.message();
  return file + " not found" + (given.empty() ? "" : " (looked for " + resolved + ")");
}

std::string settings_file_size_problem(const std::string& kind, const std::string& path) {
  std::error_code error;
  const std::uintmax_t bytes = fs::file_size(path, error);
  if (error || bytes <= kMaxSettingsFileBytes) return "";
  char size[64];
  std::snprintf(size, sizeof size, "%.1f MB", static_cast<double>(bytes) / (1 << 20));
  return "the " + kind + " file holds " + size + ", more than the " +
         std::to_string(kMaxSettingsFileBytes >> 20) + " MB a " + kind +
         " file may: its settings are text; long paths go in a G-code or STL file it names";
}

}  // namespace depotwin
