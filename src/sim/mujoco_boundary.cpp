#include "sim/mujoco_boundary.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <regex>
#include <vector>

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

#include "core/error.hpp"

namespace depotwin {

namespace {

// the last warning message MuJoCo sent to this thread (MuJoCo's hooks are plain C
// function pointers, so the message can only be handed over through thread-local storage)
thread_local char tls_pending_warning[1024] = "";
thread_local bool tls_has_pending_warning = false;

// fatal MuJoCo error: never return into the C engine (see the header)
void on_mujoco_error(const char* message) {
  std::fprintf(stderr, "depotwin: internal error: MuJoCo: %s\n", message);
  std::fflush(stderr);
  std::exit(kExitInternal);
}

// MuJoCo warning: record it for check_warnings, which throws from C++ code
void on_mujoco_warning(const char* message) {
  std::snprintf(tls_pending_warning, sizeof tls_pending_warning, "%s", message);
  tls_has_pending_warning = true;
}

// MuJoCo's multi-line compiler messages on one line
std::string one_line(const std::string& text) {
  std::string line;
  for (char c : text) {
    if (c == '\n' || c == '\r') {
      if (!line.empty() && line.back() != ' ') line += "; ";
    } else {
      line += c;
    }
  }
  while (!line.empty() && (line.back() == ' ' || line.back() == ';')) line.pop_back();
  return line;
}

// the line number in a MuJoCo parse/compile message ("Line number=3", "line 3", "line = 3")
int line_in_message(const std::string& message) {
  static const std::regex kLine(R"([Ll]ine(?: number)?\s*=?\s*(\d+))");
  std::smatch match;
  if (std::regex_search(message, match, kLine)) return std::atoi(match[1].str().c_str());
  return 0;
}

ModelPtr finish_load(mjModel* model, const char* error, const std::string& path) {
  const std::string message = one_line(error);
  if (!model) {
    throw InputError(path, line_in_message(message), "model",
                     message.empty() ? "MuJoCo could not load the model" : message);
  }
  ModelPtr owned(model);
  if (!message.empty())
    throw InputError(path, line_in_message(message), "model", "MuJoCo compiler: " + message);
  return owned;
}

const char* warning_name(int index) {
  switch (index) {
    case mjWARN_INERTIA:
      return "near-singular inertia matrix";
    case mjWARN_CONTACTFULL:
      return "contact buffer full";
    case mjWARN_CNSTRFULL:
      return "constraint buffer full";
    case mjWARN_VGEOMFULL:
      return "visual geom buffer full";
    case mjWARN_BADQPOS:
      return "bad qpos (NaN, Inf or huge)";
    case mjWARN_BADQVEL:
      return "bad qvel (NaN, Inf or huge)";
    case mjWARN_BADQACC:
      return "bad qacc (NaN, Inf or huge)";
    case mjWARN_BADCTRL:
      return "bad ctrl (NaN, Inf or huge)";
    default:
      return "unknown warning";
  }
}

}  // namespace

void install_mujoco_handlers() {
  mju_user_error = on_mujoco_error;
  mju_user_warning = on_mujoco_warning;
}

ModelPtr load_model(const std::string& path) {
  install_mujoco_handlers();
  if (!std::ifstream(path).good())
    throw InputError(path, 0, "model", "the model file does not exist or cannot be read");
  char error[1024] = "";
  mjModel* model = mj_loadXML(path.c_str(), nullptr, error, sizeof error);
  return finish_load(model, error, path);
}

ModelPtr load_model_from_string(const std::string& mjcf, const std::string& name) {
  install_mujoco_handlers();
  // mjVFS holds 2000 file names of 1000 bytes: far too big for the stack
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  if (mj_makeEmptyFileVFS(vfs.get(), name.c_str(), static_cast<int>(mjcf.size())) != 0) {
    mj_deleteVFS(vfs.get());
    throw InternalError("cannot create the in-memory model file " + name);
  }
  const int file = mj_findFileVFS(vfs.get(), name.c_str());
  std::memcpy(vfs->filedata[file], mjcf.data(), mjcf.size());
  char error[1024] = "";
  mjModel* model = mj_loadXML(name.c_str(), vfs.get(), error, sizeof error);
  mj_deleteVFS(vfs.get());
  return finish_load(model, error, name);
}

DataPtr make_data(const mjModel& model) {
  DataPtr data(mj_makeData(&model));
  if (!data) throw InternalError("MuJoCo could not allocate mjData");
  return data;
}

DataPtr copy_data(const mjModel& model, const mjData& data) {
  DataPtr copy = make_data(model);
  mj_copyData(copy.get(), &model, &data);
  return copy;
}

int require_id(const mjModel& model, int object_type, const std::string& name,
               const std::string& model_path, const std::string& purpose) {
  const int id = mj_name2id(&model, object_type, name.c_str());
  if (id < 0) {
    const char* kind = object_type == mjOBJ_JOINT      ? "joint"
                       : object_type == mjOBJ_ACTUATOR ? "actuator"
                       : object_type == mjOBJ_SITE     ? "site"
                       : object_type == mjOBJ_BODY     ? "body"
                       : object_type == mjOBJ_CAMERA   ? "camera"
                       : object_type == mjOBJ_NUMERIC  ? "custom numeric"
                                                       : "element";
    throw InputError(model_path, 0, std::string(kind) + " " + name,
                     "not found in the model (" + purpose + ")");
  }
  return id;
}

void check_warnings(const mjData& data, const char* where, double t_s) {
  std::string context;
  const auto describe = [&]() {
    context = where;
    if (t_s >= 0.0) {
      char at[64];
      std::snprintf(at, sizeof at, " at t = %.4f s", t_s);
      context += at;
    }
  };
  for (int i = 0; i < mjNWARNING; ++i) {
    if (data.warning[i].number > 0) {
      describe();
      std::string message = "MuJoCo warning " + context + ": " + warning_name(i) + " (index " +
                            std::to_string(data.warning[i].lastinfo) + ")";
      if (tls_has_pending_warning) message += ": " + one_line(tls_pending_warning);
      tls_has_pending_warning = false;
      throw InternalError(message +
                          " - the simulation diverged or overflowed; try a smaller "
                          "sim timestep or lower servo gains");
    }
  }
  if (tls_has_pending_warning) {
    tls_has_pending_warning = false;
    describe();
    throw InternalError("MuJoCo warning " + context + ": " + one_line(tls_pending_warning));
  }
}

void clear_warnings(mjData& data) {
  for (int i = 0; i < mjNWARNING; ++i) data.warning[i] = mjWarningStat{0, 0};
  tls_has_pending_warning = false;
}

// MXCSR bit 15 flush-to-zero (subnormal results), bit 6 denormals-are-zero (subnormal inputs)
#if defined(__SSE2__)
constexpr unsigned int kFlushSubnormalsMxcsr = 0x8040;
FlushSubnormalsScope::FlushSubnormalsScope() : saved_mode_(_mm_getcsr()) {
  _mm_setcsr(saved_mode_ | kFlushSubnormalsMxcsr);
}
FlushSubnormalsScope::~FlushSubnormalsScope() {
  _mm_setcsr(saved_mode_);
}
void FlushSubnormalsScope::suspend() {
  _mm_setcsr(saved_mode_);
}
void FlushSubnormalsScope::resume() {
  _mm_setcsr(saved_mode_ | kFlushSubnormalsMxcsr);
}
#else
FlushSubnormalsScope::FlushSubnormalsScope() = default;
FlushSubnormalsScope::~FlushSubnormalsScope() = default;
void FlushSubnormalsScope::suspend() {}
void FlushSubnormalsScope::resume() {}
#endif

}  // namespace depotwin
