// A convex primitive attached to a machine link, for distance and contact queries (the arm's
// links and tool against the part: collision/part_clearance.hpp). Sizes follow MuJoCo's geom
// conventions, in mm, so a shape and the MJCF geom it mirrors read alike.
#pragma once

#include <Eigen/Geometry>
#include <string>

#include "core/types.hpp"

namespace depotwin {

struct CollisionShape {
  enum class Type { sphere, capsule, cylinder, box };
  Type type = Type::sphere;
  // sphere: (radius); capsule, cylinder: (radius, half-length along the local z axis);
  // box: (half extents x, y, z)
  Vec3 size_mm = Vec3::Zero();
  // the shape's frame in its link's frame (translation in mm)
  Eigen::Isometry3d in_link = Eigen::Isometry3d::Identity();
  int link = 0;      // which link frame it rides on (the machine numbers its links)
  std::string name;  // for messages: the MJCF geom it mirrors
};

}  // namespace depotwin
