// Shared by the model tests: raw MuJoCo with its reports turned into test failures, and owning
// handles for models and data.
#pragma once

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <stdexcept>

namespace depotwin::testing_models {

// MuJoCo reports through plain function pointers: errors throw, warnings are counted (and fail
// the test)
inline int& warning_count() {
  static int count = 0;
  return count;
}
inline void throw_error(const char* message) {
  throw std::runtime_error(message);
}
inline void count_warning(const char* message) {
  ++warning_count();
  ADD_FAILURE() << "MuJoCo warning: " << message;
}

struct ModelDeleter {
  void operator()(mjModel* model) const { mj_deleteModel(model); }
};
struct DataDeleter {
  void operator()(mjData* data) const { mj_deleteData(data); }
};

}  // namespace depotwin::testing_models
