// A 64-bit FNV-1a hash, for the sweep's input hashes (a cache key: a task whose inputs hash
// alike is up to date). Stable across runs, platforms and builds.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

namespace depotwin {

class Fnv1a64 {
 public:
  Fnv1a64& add(const std::string& bytes) {
    for (const char c : bytes) {
      state_ ^= static_cast<unsigned char>(c);
      state_ *= 0x100000001b3ULL;
    }
    // a separator, so ("ab", "c") and ("a", "bc") differ
    state_ ^= 0xffU;
    state_ *= 0x100000001b3ULL;
    return *this;
  }
  std::uint64_t value() const { return state_; }
  // 16 lowercase hex digits
  std::string hex() const {
    char text[17];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(state_));
    return text;
  }

 private:
  std::uint64_t state_ = 0xcbf29ce484222325ULL;
};

}  // namespace depotwin
