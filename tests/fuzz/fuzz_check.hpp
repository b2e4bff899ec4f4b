// Shared by the fuzz targets: what counts as a failure besides a crash, a sanitizer report or
// an exception other than InputError (each of which ends the run on its own).
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace depotwin::fuzz {

// a result that breaks its contract (e.g. a non-finite coordinate accepted as input): abort,
// so libFuzzer keeps the input as a crash
inline void require(bool condition, const char* what) {
  if (condition) return;
  std::fprintf(stderr, "fuzz: contract broken: %s\n", what);
  std::abort();
}

inline bool is_finite(double value) {
  return std::isfinite(value);
}

}  // namespace depotwin::fuzz
