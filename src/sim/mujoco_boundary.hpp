// The thin boundary around MuJoCo's C handles (MuJoCo's own test/fixture.h style):
// unique_ptr owners with deleters, model loading that turns every failure into an
// InputError naming the file, names resolved once, and MuJoCo's process-wide error and
// warning hooks.
//
// How MuJoCo 2.2.2 failures end a run:
// - mju_error (fatal: out of memory, corrupt state). 2.2.2's mju_error *returns* into the
//   C engine when a user handler returns, and a C++ exception thrown through MuJoCo's C
//   frames (compiled without unwind tables) is undefined behaviour. So the handler prints
//   "depotwin: internal error: MuJoCo: <message>" to stderr and calls std::exit(1)
//   (= InternalError's exit status) without ever returning into MuJoCo.
// - mju_warning (divergence: NaN/huge qpos/qvel/qacc/ctrl, full buffers). The handler only
//   records the message (thread-local) and returns, which is safe; MuJoCo also counts the
//   warning in mjData::warning[]. The caller checks both after every mj_step1/mj_step2 pair
//   (check_warnings) and throws InternalError from C++ code, so the run ends with a clear
//   message instead of MuJoCo's silent reset of the state.
#pragma once

#include <mujoco/mujoco.h>

#include <memory>
#include <string>

namespace depotwin {

struct MjModelDeleter {
  void operator()(mjModel* model) const { mj_deleteModel(model); }
};
struct MjDataDeleter {
  void operator()(mjData* data) const { mj_deleteData(data); }
};
using ModelPtr = std::unique_ptr<mjModel, MjModelDeleter>;
using DataPtr = std::unique_ptr<mjData, MjDataDeleter>;

// set mju_user_error / mju_user_warning (idempotent; call before any other MuJoCo call)
void install_mujoco_handlers();

// load and compile an MJCF file. InputError("path:line: model: <MuJoCo's message>") for a
// missing file, malformed XML or a model that does not compile (compiler warnings included)
ModelPtr load_model(const std::string& path);
// the same from MJCF text held in memory (through an mjVFS); `name` is used in messages
ModelPtr load_model_from_string(const std::string& mjcf, const std::string& name = "inline.xml");

DataPtr make_data(const mjModel& model);
// a copy of `data` owned by the caller (for the renderer, which needs a mutable mjData)
DataPtr copy_data(const mjModel& model, const mjData& data);

// id of a named element; InputError naming the model file, the element kind and `purpose`
// when it is missing
int require_id(const mjModel& model, int object_type, const std::string& name,
               const std::string& model_path, const std::string& purpose);

// InternalError when MuJoCo raised a warning since the last call (any mjData::warning
// counter set, or a message received by the warning hook); `where` says during what
// (e.g. "in the simulation"), t_s when (negative: no time). No allocation unless it throws.
void check_warnings(const mjData& data, const char* where, double t_s = -1.0);
// clear the counters and any pending warning message (after a reset)
void clear_warnings(mjData& data);

// Subnormal numbers flushed to zero (x86 SSE: MXCSR flush-to-zero and denormals-are-zero)
// on this thread while the scope lives; the previous mode comes back on destruction.
// A servo resting on its target decays its velocity and acceleration geometrically into
// the subnormal range (below 2.2e-308) within a second, and every MuJoCo routine touching
// them then runs at microcode-assist speed (about +0.2 us per step on the XY stage with its
// shutter at rest). Flushing changes values only below 2.2e-308, far under any last bit
// of the state they are added to. Elsewhere than x86 the scope does nothing.
// suspend() gives the caller's mode back for a while (around user callbacks), resume()
// flushes again.
class FlushSubnormalsScope {
 public:
  FlushSubnormalsScope();
  ~FlushSubnormalsScope();
  FlushSubnormalsScope(const FlushSubnormalsScope&) = delete;
  FlushSubnormalsScope& operator=(const FlushSubnormalsScope&) = delete;
  void suspend();
  void resume();

 private:
  unsigned int saved_mode_ = 0;
};

}  // namespace depotwin
