// validate_print_path (planners/motion/path_check.hpp), the check every planner makes before
// planning a path: each malformed path is refused with the problem named under the path's name, and
// a well-formed one passes.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/error.hpp"
#include "planners/motion/path_check.hpp"

namespace depotwin {
namespace {

PrintPath good_path() {
  PrintPath path;
  path.points = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0)};
  path.normals = {Vec3::UnitZ(), Vec3::UnitZ(), Vec3::UnitZ()};
  path.speed_mm_s = 5.0;
  return path;
}

// the message of the InputError the check throws ("" when it passes)
std::string problem(const PrintPath& path, double same_point_mm = 1e-6) {
  try {
    validate_print_path(path, "toolpath path 7", same_point_mm);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(PrintPathCheck, AWellFormedPathPasses) {
  EXPECT_EQ(problem(good_path()), "");
}

TEST(PrintPathCheck, EachMalformedPathIsNamedWithItsProblem) {
  struct Case {
    const char* what;
    void (*spoil)(PrintPath&);
    const char* message;
  };
  const Case cases[] = {
      {"one point", [](PrintPath& p) { p.points.resize(1), p.normals.resize(1); },
       "at least two points"},
      {"zero speed", [](PrintPath& p) { p.speed_mm_s = 0.0; }, "speed must be positive"},
      {"infinite speed", [](PrintPath& p) { p.speed_mm_s = INFINITY; }, "speed must be positive"},
      {"missing normal", [](PrintPath& p) { p.normals.pop_back(); }, "one normal per point"},
      {"missing roll", [](PrintPath& p) { p.rolls = {0.0}; }, "one roll per point"},
      {"NaN point", [](PrintPath& p) { p.points[1].x() = NAN; }, "point 1 is not finite"},
      {"repeated point", [](PrintPath& p) { p.points[2] = p.points[1]; },
       "segment 1 has zero length"},
      {"long normal", [](PrintPath& p) { p.normals[2] = Vec3(0, 0, 2); },
       "normal 2 is not a unit vector"},
  };
  for (const Case& c : cases) {
    PrintPath path = good_path();
    c.spoil(path);
    const std::string message = problem(path);
    EXPECT_NE(message.find("toolpath path 7"), std::string::npos) << c.what << ": " << message;
    EXPECT_NE(message.find(c.message), std::string::npos) << c.what << ": " << message;
  }
}

// an edge exactly as long as the same-point distance is refused, a longer one passes
TEST(PrintPathCheck, TheSamePointDistanceIsTheCallers) {
  PrintPath path = good_path();
  path.points[2] = path.points[1] + Vec3(0, 1e-3, 0);
  EXPECT_EQ(problem(path, 1e-6), "");
  EXPECT_NE(problem(path, 1e-3).find("segment 1 has zero length"), std::string::npos);
}

}  // namespace
}  // namespace depotwin
