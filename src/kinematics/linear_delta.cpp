// placeholder until the linear delta lands (issue 5)
#include "kinematics/linear_delta.hpp"

namespace depotwin {

std::unique_ptr<Machine> make_linear_delta() { return nullptr; }

}  // namespace depotwin
