#include "core/error.hpp"

#include <sstream>

namespace depotwin {

std::string Problem::str() const {
  std::ostringstream out;
  if (!file.empty()) {
    out << file;
    if (line > 0) out << ':' << line;
    out << ": ";
  }
  if (!key.empty()) out << key << ": ";
  out << message;
  return out.str();
}

namespace {
std::string join_problems(const std::vector<Problem>& problems) {
  std::string text;
  for (const Problem& p : problems) {
    if (!text.empty()) text += '\n';
    text += p.str();
  }
  return text;
}
}  // namespace

InputError::InputError(std::vector<Problem> problems)
    : std::runtime_error(join_problems(problems)), problems_(std::move(problems)) {}

InputError::InputError(std::string file, int line, std::string key, std::string message)
    : InputError(std::vector<Problem>{
          Problem{std::move(file), line, std::move(key), std::move(message)}}) {}

InputError::InputError(std::string key, std::string message)
    : InputError(std::vector<Problem>{Problem{"", 0, std::move(key), std::move(message)}}) {}

}  // namespace depotwin
