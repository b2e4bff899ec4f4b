#include "core/error.hpp"

#include <sstream>

#include "core/number_text.hpp"

namespace depotwin {

std::string Problem::str() const {
  std::ostringstream out;
  // a file name or a message may hold bytes a terminal would act on: they are written as \xNN
  if (!file.empty()) {
    out << terminal_text(file);
    if (line > 0) out << ':' << line;
    out << ": ";
  }
  if (!key.empty()) out << terminal_text(key) << ": ";
  out << terminal_text(message);
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
