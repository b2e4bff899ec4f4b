#include "sim/model_binding.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/error.hpp"

namespace depotwin {

namespace {

// the names every model shares (sim/simulation.hpp)
constexpr const char* kNozzleSite = "nozzle";
constexpr const char* kSubstrateBody = "substrate";
constexpr const char* kShutterJoint = "shutter";

std::string format_number(double value) {
  char text[64];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

// a custom numeric's values; InputError when missing or too short
const mjtNum* require_numeric(const mjModel& model, const std::string& name, int size,
                              const std::string& path) {
  const int id = require_id(model, mjOBJ_NUMERIC, name, path, "the shutter's parameters");
  if (model.numeric_size[id] < size)
    throw InputError(path, 0, "custom numeric " + name,
                     "needs " + std::to_string(size) + " value(s)");
  return model.numeric_data + model.numeric_adr[id];
}

// (angular, linear) world velocity of the point at world position `point` moving with `body`:
// cvel is the body's velocity about its root's subtree centre of mass, moved to the point.
// The same arithmetic, in the same order, as mj_objectVelocity(.., flg_local = 0) through
// mju_transformSpatial: linear = v_com - (point - com) x w. Inline because it runs twice a
// step, where the library call's dispatch cost more than the six products.
void world_point_velocity(const mjModel& m, const mjData& d, int body, const mjtNum* point,
                          mjtNum velocity[6]) {
  const mjtNum* cvel = d.cvel + 6 * body;
  const mjtNum* com = d.subtree_com + 3 * m.body_rootid[body];
  const mjtNum dif[3] = {point[0] - com[0], point[1] - com[1], point[2] - com[2]};
  const mjtNum cross[3] = {dif[1] * cvel[2] - dif[2] * cvel[1], dif[2] * cvel[0] - dif[0] * cvel[2],
                           dif[0] * cvel[1] - dif[1] * cvel[0]};
  for (int i = 0; i < 3; ++i) {
    velocity[i] = cvel[i];
    velocity[3 + i] = cvel[3 + i] - cross[i];
  }
}

// the shutter blade: its servo and the custom numerics of its geometry and timing
void bind_shutter(BoundModel& bound, const SimSettings& settings) {
  mjModel& m = *bound.model;
  const std::string& model_path = bound.model_path;
  bound.has_shutter = true;
  bound.shutter = resolve_servo(m, kShutterJoint, model_path, "the shutter blade");
  if (m.jnt_type[bound.shutter.joint] != mjJNT_HINGE)
    throw InputError(model_path, 0, "joint shutter", "must be a hinge joint");
  const mjtNum* travel_deg = require_numeric(m, "shutter_travel_deg", 2, model_path);
  const mjtNum* overtravel = require_numeric(m, "shutter_overtravel", 1, model_path);
  const mjtNum* time_s = require_numeric(m, "shutter_time_s", 1, model_path);
  ShutterGeometry& geometry = bound.shutter_geometry;
  geometry.closed_angle_rad = deg_to_rad(travel_deg[0]);
  geometry.open_angle_rad = deg_to_rad(travel_deg[1]);
  geometry.overtravel = overtravel[0];
  geometry.time_s = settings.shutter_time_s > 0.0 ? settings.shutter_time_s : time_s[0];
  if (!(std::abs(travel_deg[1] - travel_deg[0]) > 1e-9))
    throw InputError(model_path, 0, "custom numeric shutter_travel_deg",
                     "the closed and open angles must differ");
  if (!(geometry.overtravel >= 0.0))
    throw InputError(model_path, 0, "custom numeric shutter_overtravel", "must be >= 0");
  if (!(geometry.time_s > 0.0))
    throw InputError(model_path, 0, "custom numeric shutter_time_s", "must be > 0");
  // the rest positions must lie inside the hinge's stops
  const double rest_closed = geometry.angle_at(-geometry.overtravel);
  const double rest_open = geometry.angle_at(1.0 + geometry.overtravel);
  if (m.jnt_limited[bound.shutter.joint] &&
      (std::min(rest_closed, rest_open) < m.jnt_range[2 * bound.shutter.joint] ||
       std::max(rest_closed, rest_open) > m.jnt_range[2 * bound.shutter.joint + 1]))
    throw InputError(model_path, 0, "joint shutter",
                     "range does not contain the blade's rest positions (travel plus "
                     "overtravel)");
}

}  // namespace

BoundModel bind_model(const std::string& model_path, const Machine& machine,
                      const SimSettings& settings, const std::string& model_text) {
  BoundModel bound;
  bound.model_path = model_path;
  bound.machine = &machine;
  bound.settings = settings;
  bound.model =
      model_text.empty() ? load_model(model_path) : load_model_from_string(model_text, model_path);
  mjModel& m = *bound.model;
  // every name the machine needs is looked for, and every one missing is reported at once
  std::vector<Problem> problems;
  const auto collect = [&](const auto& resolve) {
    try {
      resolve();
    } catch (const InputError& e) {
      problems.insert(problems.end(), e.problems().begin(), e.problems().end());
    }
  };
  // the TCP site and the work frame
  collect([&] {
    bound.nozzle_site = require_id(m, mjOBJ_SITE, kNozzleSite, model_path,
                                   "the TCP: where material meets the substrate");
  });
  collect([&] {
    bound.substrate_body =
        require_id(m, mjOBJ_BODY, kSubstrateBody, model_path, "the work frame the TCP is read in");
  });

  // one position servo per machine joint, its range covering the machine's travel
  for (const JointLimit& limit : machine.joint_limits()) {
    Servo servo;
    bool resolved = false;
    collect([&] {
      servo = resolve_servo(m, limit.name, model_path,
                            "machine " + machine.name() + " drives a joint of this name");
      resolved = true;
    });
    if (!resolved) continue;
    if (m.jnt_limited[servo.joint]) {
      const double lo = m.jnt_range[2 * servo.joint] / servo.user_to_si;
      const double hi = m.jnt_range[2 * servo.joint + 1] / servo.user_to_si;
      if (lo > limit.min + 1e-9 || hi < limit.max - 1e-9)
        problems.push_back(Problem{model_path, 0, "joint " + limit.name,
                                   "range [" + format_number(lo) + ", " + format_number(hi) + "] " +
                                       servo.unit + " is narrower than the machine's travel [" +
                                       format_number(limit.min) + ", " + format_number(limit.max) +
                                       "] " + servo.unit});
    }
    // kp_scale stiffens the servo; kv follows with the square root (same damping ratio)
    mjtNum* gain = m.actuator_gainprm + servo.actuator * mjNGAIN;
    mjtNum* bias = m.actuator_biasprm + servo.actuator * mjNBIAS;
    gain[0] *= settings.kp_scale;
    bias[1] *= settings.kp_scale;
    bias[2] *= std::sqrt(settings.kp_scale);
    servo.kp = gain[0];
    servo.kv = -bias[2];
    bound.joint_names.push_back(limit.name);
    bound.joints.push_back(std::move(servo));
  }

  // the optional shutter blade
  if (mj_name2id(&m, mjOBJ_JOINT, kShutterJoint) >= 0)
    collect([&] { bind_shutter(bound, settings); });
  if (!problems.empty()) throw InputError(std::move(problems));

  m.opt.timestep = settings.timestep_s;
  bound.control_stride = settings.control_stride();
  // the friction law depends on the timestep: fixed here, not per control update
  for (Servo& servo : bound.joints) fix_friction_law(m, servo);
  if (bound.has_shutter) fix_friction_law(m, bound.shutter);
  bound.data = make_data(m);
  mj_forward(bound.model.get(), bound.data.get());
  check_warnings(*bound.data, "after loading the model");
  return bound;
}

// nozzle site relative to the substrate frame, and its velocity relative to the substrate
void read_nozzle(const BoundModel& bound, Vec3& position_mm, Vec3& velocity_mm_s) {
  const mjModel* m = bound.model.get();
  const mjData* d = bound.data.get();
  const int nozzle_site = bound.nozzle_site, substrate_body = bound.substrate_body;
  const mjtNum* site = d->site_xpos + 3 * nozzle_site;
  const mjtNum* origin = d->xpos + 3 * substrate_body;
  const mjtNum* rotation = d->xmat + 9 * substrate_body;  // row-major, columns = body axes

  // velocity of the substrate point under the nozzle: v_origin + w x (p - origin)
  mjtNum site_velocity[6], body_velocity[6];
  world_point_velocity(*m, *d, m->site_bodyid[nozzle_site], site, site_velocity);
  world_point_velocity(*m, *d, substrate_body, origin, body_velocity);
  const Vec3 offset(site[0] - origin[0], site[1] - origin[1], site[2] - origin[2]);
  const Vec3 omega(body_velocity[0], body_velocity[1], body_velocity[2]);
  const Vec3 substrate_point_velocity =
      Vec3(body_velocity[3], body_velocity[4], body_velocity[5]) + omega.cross(offset);
  const Vec3 relative_velocity =
      Vec3(site_velocity[3], site_velocity[4], site_velocity[5]) - substrate_point_velocity;

  // both into the substrate frame: local = R^T world
  for (int axis = 0; axis < 3; ++axis) {
    double p = 0.0, v = 0.0;
    for (int row = 0; row < 3; ++row) {
      p += rotation[3 * row + axis] * offset[row];
      v += rotation[3 * row + axis] * relative_velocity[row];
    }
    position_mm[axis] = m_to_mm(p);
    velocity_mm_s[axis] = m_to_mm(v);
  }
}

double open_fraction(const BoundModel& bound, bool deposit_command) {
  if (!bound.has_shutter) return deposit_command ? 1.0 : 0.0;
  return shutter_open_fraction(bound.data->qpos[bound.shutter.qpos_adr], bound.shutter_geometry);
}

}  // namespace depotwin
