#include "kinematics/linear_delta.hpp"
#include "kinematics/machine.hpp"
#include "kinematics/xy_stage.hpp"

namespace depotwin {

std::unique_ptr<Machine> make_machine(const std::string& name) {
  if (name == "xy_stage") return make_xy_stage();
  if (name == "linear_delta") return make_linear_delta();
  return nullptr;
}

std::vector<std::string> machine_names() { return {"xy_stage", "linear_delta"}; }

}  // namespace depotwin
