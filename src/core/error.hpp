// Error types with the exit-status contract of the CLI:
//   InputError    -> exit 2: bad scenario, bad file, impossible limits (names file, line, key)
//   InternalError -> exit 1: a bug or a simulator failure
//   EnvironmentError (an InternalError) -> exit 1: the machine refused (a full disk, a folder
//                    that cannot be written, a program that cannot start); printed as an
//                    error, not as a bug
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace depotwin {

// One problem found in user input, printed as "file:line: key: message".
struct Problem {
  std::string file;
  int line = 0;  // 1-based; 0 when unknown
  std::string key;
  std::string message;

  std::string str() const;
};

// Bad user input. Carries every problem found, so `validate` can report them all at once.
class InputError : public std::runtime_error {
 public:
  explicit InputError(std::vector<Problem> problems);
  InputError(std::string file, int line, std::string key, std::string message);
  // a problem without a file (e.g. a command-line argument)
  InputError(std::string key, std::string message);

  const std::vector<Problem>& problems() const { return problems_; }

 private:
  std::vector<Problem> problems_;
};

// A failure that is not the user's fault (simulator divergence, I/O error, bug).
class InternalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The machine refused what the run needs, and said why: a write on a full disk or in a folder
// without permission, a file that cannot be moved into place, a helper program that cannot
// start. Neither the input's fault nor a bug; the message ends with the system's reason.
class EnvironmentError : public InternalError {
 public:
  using InternalError::InternalError;
};

constexpr int kExitOk = 0;
constexpr int kExitInternal = 1;
constexpr int kExitBadInput = 2;

}  // namespace depotwin
