// The deposition of a simulated job: its steps from the recorded states, what still flows
// when the job ends, and the thickness a print should reach.
#pragma once

#include "core/recorded_run.hpp"
#include "core/toolpath.hpp"
#include "deposition/process.hpp"

namespace depotwin {

// The deposition step between two recorded states: the nozzle's chord, the shutter's open
// fraction at both ends and the flow command. The aerosol stream runs from job start to job
// end, so the step that straddles job_end_s is cut there (chord and flap linear in time);
// false for a step after the job's end (settling).
bool deposition_step(const StepState& before, const StepState& after, double job_end_s,
                     DepositionStep& step);

// Extrusion: what still flows from the nozzle when the job ends (the lag's ooze, Q tau) lands
// where the nozzle stopped, instead of vanishing with the last step. Nothing for aerosol or
// when no flow is left.
void deposit_remaining_flow(Process& process, const Vec3& nozzle_mm, double job_end_s);

// The centreline thickness (um) of a straight line printed at the first path's desired speed:
// the target the thickness plots draw
double target_thickness_um(const Process& process, const Toolpath& toolpath);

}  // namespace depotwin
