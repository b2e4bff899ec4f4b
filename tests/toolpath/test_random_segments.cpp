// Random instances as Ganganath et al. (papers/004, Sec. IV-A) describe them.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"
#include "toolpath/random_segments.hpp"

namespace depotwin {
namespace {

// closed segments p0-p1 and q0-q1 share a point: solve p0 + s d = q0 + t e (an
// implementation independent of the generator's orientation test)
bool segments_meet(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  const double dx = p1.x() - p0.x(), dy = p1.y() - p0.y();
  const double ex = q1.x() - q0.x(), ey = q1.y() - q0.y();
  const double denom = dx * ey - dy * ex;
  const double rx = q0.x() - p0.x(), ry = q0.y() - p0.y();
  if (std::abs(denom) < 1e-12) {  // parallel: collinear overlap?
    if (std::abs(rx * dy - ry * dx) > 1e-9) return false;
    const double len2 = dx * dx + dy * dy;
    const double t0 = (rx * dx + ry * dy) / len2;
    const double t1 = ((q1.x() - p0.x()) * dx + (q1.y() - p0.y()) * dy) / len2;
    return std::max(t0, t1) >= 0.0 && std::min(t0, t1) <= 1.0;
  }
  const double s = (rx * ey - ry * ex) / denom, t = (rx * dy - ry * dx) / denom;
  return s >= 0.0 && s <= 1.0 && t >= 0.0 && t <= 1.0;
}

TEST(RandomInstances, SegmentsAreOnTheBedWithinLengthAndNeverCross) {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    RandomSegmentsSpec spec;
    spec.count = 100;  // the paper's densest case
    spec.seed = seed;
    const Toolpath toolpath = make_random_segments(spec);
    ASSERT_EQ(toolpath.paths.size(), 100u);
    for (const Vec3& p : {toolpath.start_mm, toolpath.end_mm}) {
      EXPECT_TRUE(p.x() >= 0.0 && p.x() <= 100.0 && p.y() >= 0.0 && p.y() <= 100.0)
          << p.transpose();
    }
    for (size_t i = 0; i < toolpath.paths.size(); ++i) {
      const PrintPath& a = toolpath.paths[i];
      ASSERT_EQ(a.points.size(), 2u);
      EXPECT_EQ(a.source_index, static_cast<int>(i));
      EXPECT_DOUBLE_EQ(a.speed_mm_s, 3.0);
      EXPECT_GE(a.length_mm(), 10.0 - 1e-9);
      EXPECT_LE(a.length_mm(), 40.0 + 1e-9);
      for (const Vec3& p : a.points) {
        EXPECT_TRUE(p.x() >= -1e-9 && p.x() <= 100.0 + 1e-9 && p.y() >= -1e-9 &&
                    p.y() <= 100.0 + 1e-9)
            << p.transpose();
      }
      for (size_t j = 0; j < i; ++j) {
        const PrintPath& b = toolpath.paths[j];
        EXPECT_FALSE(segments_meet(a.front(), a.back(), b.front(), b.back()))
            << "seed " << seed << ": segments " << i << " and " << j << " cross";
      }
    }
  }
}

TEST(RandomInstances, LengthsStayUniformDespiteRejections) {
  // 10^4 lengths of U[10, 40]: mean 25 (sd of the mean 0.087), variance 75 (sd 0.67);
  // redrawing the length on rejection would pull both down at N = 100
  double sum = 0.0, sum_sq = 0.0;
  int count = 0;
  for (std::uint64_t seed = 1; seed <= 100; ++seed) {
    RandomSegmentsSpec spec;
    spec.count = 100;
    spec.seed = seed;
    for (const PrintPath& path : make_random_segments(spec).paths) {
      sum += path.length_mm(), sum_sq += path.length_mm() * path.length_mm(), ++count;
    }
  }
  const double mean = sum / count, variance = sum_sq / count - mean * mean;
  EXPECT_NEAR(mean, 25.0, 0.5);
  EXPECT_NEAR(variance, 75.0, 3.5);
}

TEST(RandomInstances, SameSeedSameInstanceOtherSeedOtherInstance) {
  RandomSegmentsSpec spec;
  spec.count = 20;
  spec.seed = 42;
  const Toolpath a = make_random_segments(spec), b = make_random_segments(spec);
  spec.seed = 43;
  const Toolpath c = make_random_segments(spec);
  ASSERT_EQ(a.paths.size(), b.paths.size());
  for (size_t i = 0; i < a.paths.size(); ++i) {
    EXPECT_EQ(a.paths[i].front(), b.paths[i].front());
    EXPECT_EQ(a.paths[i].back(), b.paths[i].back());
  }
  EXPECT_EQ(a.start_mm, b.start_mm);
  EXPECT_NE(a.paths[0].front(), c.paths[0].front());
}

TEST(RandomInstances, BedAndCountAreHonoured) {
  RandomSegmentsSpec spec;
  spec.count = 0;
  EXPECT_TRUE(make_random_segments(spec).paths.empty());
  spec.count = 50;
  spec.bed_x_mm = 300.0, spec.bed_y_mm = 60.0;
  spec.length_min_mm = 5.0, spec.length_max_mm = 15.0;
  spec.speed_mm_s = 7.0;
  for (const PrintPath& path : make_random_segments(spec).paths) {
    EXPECT_LE(path.length_mm(), 15.0 + 1e-9);
    EXPECT_DOUBLE_EQ(path.speed_mm_s, 7.0);
    for (const Vec3& p : path.points) EXPECT_LE(p.y(), 60.0 + 1e-9);
  }
}

TEST(RandomInstances, ImpossibleSpecsAreInputErrors) {
  RandomSegmentsSpec spec;
  spec.length_max_mm = 120.0;  // longer than the bed
  EXPECT_THROW(make_random_segments(spec), InputError);
  spec = {};
  spec.count = -1;
  EXPECT_THROW(make_random_segments(spec), InputError);
  spec = {};
  spec.length_min_mm = 30.0, spec.length_max_mm = 20.0;
  EXPECT_THROW(make_random_segments(spec), InputError);
  spec = {};
  spec.bed_x_mm = 0.0;
  EXPECT_THROW(make_random_segments(spec), InputError);
  spec = {};
  spec.speed_mm_s = -3.0;
  EXPECT_THROW(make_random_segments(spec), InputError);
}

TEST(RandomInstances, ABedTooFullIsRefusedWithinTheBudgetOfTriesInAll) {
  // 2 000 segments of 10-40 mm cannot all lie on 90 x 90 mm without crossing: the last ones
  // took up to 10^6 tries each (a minute, found by fuzz_scenario); the whole instance now gets
  // 10^6 + 100 n tries, and the message counts them
  RandomSegmentsSpec spec;
  spec.count = 2000;
  spec.bed_x_mm = spec.bed_y_mm = 90.0;
  spec.seed = 7;
  try {
    make_random_segments(spec);
    FAIL() << "2000 segments were placed on 90 x 90 mm";
  } catch (const InputError& e) {
    ASSERT_EQ(e.problems().size(), 1u);
    EXPECT_NE(e.problems()[0].message.find("(1200000 for all)"), std::string::npos)
        << e.problems()[0].message;
  }
}

}  // namespace
}  // namespace depotwin
