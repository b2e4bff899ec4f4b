// A planner decision's figure by name, for the planner tests (a missing figure fails the test).
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "core/trajectory.hpp"

namespace depotwin {

inline double figure(const PlanDecision& decision, const std::string& name) {
  for (const PlanFigure& figure : decision.figures)
    if (figure.name == name) return figure.value;
  ADD_FAILURE() << "no figure " << name;
  return 0.0;
}

}  // namespace depotwin
