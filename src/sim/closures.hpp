// Closed kinematic chains in the model (internal to sim/): equality constraints such as a
// linear delta's rod-to-platform <connect>s, assembled around the servo joints before a run
// and measured during it.
#pragma once

#include "sim/model_binding.hpp"

namespace depotwin {

// Close the equality constraints (a linear delta's rods on its platform) around the servo
// joints as they are set: the other joints (rod hinges, the platform's free joint) start from
// the model's reference pose, which matches the servo joints only at home. Gauss-Newton on
// the constraint residuals over the other degrees of freedom (least-norm steps), then their
// velocities so the constraints' rates vanish too. Without it a run starting away from home
// would start with the chain torn open by tens of mm and snap it shut in the first steps.
void assemble_closures(BoundModel& bound);

// largest residual of the equality constraints (connect closures), mm; 0 without
double constraint_violation_mm(const mjData& data);

}  // namespace depotwin
