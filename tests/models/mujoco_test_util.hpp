// Shared by the model tests: raw MuJoCo with its reports turned into test failures, and owning
// handles for models and data.
#pragma once

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <stdexcept>
#include <string>

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

// installs the report hooks above, resets the warning count and loads models/<file>: null, with
// the test failed, when it does not load or loads with a warning
inline mjModel* load_test_model(const std::string& file) {
  mju_user_error = throw_error;
  mju_user_warning = count_warning;
  warning_count() = 0;
  char error[1000] = "";
  const std::string path = std::string(DEPOTWIN_MODELS_DIR) + "/" + file;
  mjModel* model = mj_loadXML(path.c_str(), nullptr, error, sizeof(error));
  if (!model)
    ADD_FAILURE() << path << ": " << error;
  else
    EXPECT_STREQ(error, "") << path << ": load warning";
  return model;
}

// no warning reported through the hook, nor counted in `data` (when there is one)
inline void expect_no_warnings(const mjData* data) {
  if (data) {
    for (int kind = 0; kind < mjNWARNING; ++kind)
      EXPECT_EQ(data->warning[kind].number, 0) << "MuJoCo warning kind " << kind;
  }
  EXPECT_EQ(warning_count(), 0);
}

}  // namespace depotwin::testing_models
