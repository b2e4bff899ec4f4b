#include "render/scene.hpp"

#include <GL/osmesa.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/error.hpp"
#include "core/file_io.hpp"
#include "core/png.hpp"
#include "core/types.hpp"
#include "sim/mujoco_access.hpp"
#include "sim/mujoco_boundary.hpp"
#include "sim/simulation.hpp"

namespace depotwin {

namespace {

constexpr const char* kCameraName = "render_cam";
constexpr const char* kSubstrateBody = "substrate";
constexpr const char* kNozzleSite = "nozzle";
// the framed bounds fill this fraction of a panel's half-width and half-height
constexpr double kFill = 0.92;
// the close-up shows at least this far around the deposit's centre (mm), and looks down at
// least this steeply (deg)
constexpr double kMinCloseupHalf_mm = 3.0;
constexpr double kCloseupElevation_deg = 55.0;
// on a part the machine view looks down at least this steeply (deg)
constexpr double kPartElevation_deg = 40.0;
// in the close-up, geoms above the substrate outside its body tree (the print head) are drawn
// with this opacity, so that they hide nothing
constexpr float kGhostAlpha = 0.2f;
// framed renders: the key light comes from above, tilted this much towards the view
// direction, from this far away
constexpr double kShoulderLight = 0.35;
constexpr double kLightDistance_m = 0.6;
// a machine that carries the nozzle on a chain of bodies is seen broadside when its deposit
// region is this much longer than wide, the view turned this much towards the machine (deg)
// (machine_side_azimuth); the tool leans across the long side when this fraction of its lean is
constexpr double kElongated = 1.5;
constexpr double kChainTurn_deg = 25.0;
constexpr double kToolLean = 0.3;
// the deposit mesh floats this far above a flat plate (mm); on a part (a mesh seen from farther
// away) this fraction of the relief, if more
constexpr double kLift_mm = 0.005;
constexpr double kSurfaceLiftFraction = 0.02;
// the drawn height of the thickest deposit is at most this fraction of its bead's width
constexpr double kReliefPerBeadWidth = 0.5;
// the floor drawn under the machine (darker than the substrate plates, so that they stand
// out): colour, half-width and drop below the lowest geom (in model extents)
constexpr float kBackdropColour[4] = {0.50f, 0.52f, 0.55f, 1.0f};
constexpr double kBackdropHalfWidth = 20.0;
constexpr double kBackdropDrop = 0.05;
// layout: the close-up's share of the width; the strip's height (fraction of the image, and
// bounds in pixels)
constexpr double kCloseupShare = 0.5;
constexpr double kStripShare = 0.09;
constexpr int kMinStrip_px = 30;
constexpr int kMaxStrip_px = 64;
// overlay colours: the strip and label backgrounds, text and bars
constexpr float kPaper[3] = {0.96f, 0.96f, 0.95f};
constexpr float kInk[3] = {0.08f, 0.08f, 0.10f};

// an OSMesa context made current on its own colour buffer; destroyed last
class OsMesaContext {
 public:
  OsMesaContext(int width, int height)
      : buffer_(static_cast<size_t>(width) * height * 4), width_(width), height_(height) {
    context_ = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, nullptr);
    if (!context_) throw InternalError("OSMesa could not create a rendering context");
    if (!OSMesaMakeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE, width, height)) {
      OSMesaDestroyContext(context_);
      throw InternalError("OSMesa could not make its rendering context current");
    }
  }
  // current on the calling thread (a renderer may be used from another thread than the one
  // that built it, one thread at a time); false when OSMesa refuses
  bool try_make_current() noexcept {
    return OSMesaMakeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE, width_, height_);
  }
  void make_current() {
    if (!try_make_current())
      throw InternalError("OSMesa could not make its rendering context current");
  }
  // no context current on the calling thread, so another thread may take this one
  void release() { OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0); }
  ~OsMesaContext() { OSMesaDestroyContext(context_); }
  OsMesaContext(const OsMesaContext&) = delete;
  OsMesaContext& operator=(const OsMesaContext&) = delete;

 private:
  std::vector<unsigned char> buffer_;
  int width_ = 0, height_ = 0;
  OSMesaContext context_ = nullptr;
};

// OSMesa's GL entry points, for the deposit mesh
void* osmesa_proc_address(const char* name) {
  return reinterpret_cast<void*>(OSMesaGetProcAddress(name));
}

// mjvScene / mjrContext owners (freed before the GL context goes)
struct SceneOwner {
  mjvScene scene;
  SceneOwner(const mjModel& model, int max_geoms) {
    mjv_defaultScene(&scene);
    mjv_makeScene(&model, &scene, max_geoms);
  }
  ~SceneOwner() { mjv_freeScene(&scene); }
  SceneOwner(const SceneOwner&) = delete;
  SceneOwner& operator=(const SceneOwner&) = delete;
};
struct RenderContextOwner {
  mjrContext context;
  // made from a copy of the model whose offscreen and shadow sizes are those of `shape`
  RenderContextOwner(const mjModel& model, int width, int height, int shadow_size, int font_scale) {
    const ModelPtr sized(mj_copyModel(nullptr, &model));
    if (!sized) throw InternalError("MuJoCo could not copy the model for its render context");
    sized->vis.global.offwidth = width;
    sized->vis.global.offheight = height;
    sized->vis.quality.offsamples = 0;  // anti-aliased by supersampling instead
    sized->vis.quality.shadowsize = shadow_size;
    mjr_defaultContext(&context);
    mjr_makeContext(sized.get(), &context, font_scale);
  }
  ~RenderContextOwner() { mjr_freeContext(&context); }
  RenderContextOwner(const RenderContextOwner&) = delete;
  RenderContextOwner& operator=(const RenderContextOwner&) = delete;
};

// what an mjrContext depends on: the model's shape (models of the same MJCF file have the
// same one) and the buffers and font it was made with
struct ContextShape {
  int ngeom, nmesh, nmeshvert, ntex, ntexdata, nmat, nskin, nhfield;
  int width, height, shadow_size, font_scale;
  bool operator==(const ContextShape& o) const {
    return ngeom == o.ngeom && nmesh == o.nmesh && nmeshvert == o.nmeshvert && ntex == o.ntex &&
           ntexdata == o.ntexdata && nmat == o.nmat && nskin == o.nskin && nhfield == o.nhfield &&
           width == o.width && height == o.height && shadow_size == o.shadow_size &&
           font_scale == o.font_scale;
  }
};
// MuJoCo's font scale for text of the usual size after downsampling by `factor`
int font_scale_for(int factor) {
  return std::min(300, 100 * factor);
}
// The offscreen buffer is the supersampled image's size, not the model's <global offwidth
// offheight>, without multisampling, and the shadow map is left out when shadows are off: in
// software GL a multisampled buffer costs its own shader compilation and a resolve pass, and
// a 2048-pixel shadow map is 16 MB of memory to clear.
ContextShape context_shape(const mjModel& m, const SceneRenderOptions& options) {
  return {m.ngeom,
          m.nmesh,
          m.nmeshvert,
          m.ntex,
          m.ntexdata,
          m.nmat,
          m.nskin,
          m.nhfield,
          options.width * options.supersampling,
          options.height * options.supersampling,
          options.shadows ? m.vis.quality.shadowsize : 0,
          font_scale_for(options.supersampling)};
}

// substrate-frame point (mm) -> world (m)
Vec3 substrate_to_world(const mjData& data, int body, const Vec3& local_mm) {
  const mjtNum* origin = data.xpos + 3 * body;
  const mjtNum* rotation = data.xmat + 9 * body;
  Vec3 world;
  for (int row = 0; row < 3; ++row) {
    world[row] = origin[row];
    for (int col = 0; col < 3; ++col)
      world[row] += rotation[3 * row + col] * mm_to_m(local_mm[col]);
  }
  return world;
}

// substrate frame (mm) <- world point (m)
Vec3 world_to_substrate(const mjData& data, int substrate, const Vec3& world) {
  const mjtNum* origin = data.xpos + 3 * substrate;
  const mjtNum* rotation = data.xmat + 9 * substrate;
  Vec3 local = Vec3::Zero();
  for (int col = 0; col < 3; ++col)
    for (int row = 0; row < 3; ++row)
      local[col] += rotation[3 * row + col] * (world[row] - origin[row]);
  return m_to_mm(1.0) * local;
}

// the 8 corners of a box
std::vector<Vec3> box_corners(const Vec3& lo, const Vec3& hi) {
  std::vector<Vec3> corners;
  for (int i = 0; i < 8; ++i)
    corners.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
  return corners;
}

// drawn by mjv_updateScene with the default options: groups 0 to 2, not fully transparent
bool geom_visible(const mjModel& model, int geom) {
  if (model.geom_group[geom] < 0 || model.geom_group[geom] > 2) return false;
  const int material = model.geom_matid[geom];
  const float alpha =
      material >= 0 ? model.mat_rgba[4 * material + 3] : model.geom_rgba[4 * geom + 3];
  return alpha > 0.0f;
}

// The world bounding box (m) of the model's visible geoms, planes left out: each geom's box in
// its own frame (a mesh's vertices' box) turned into the world. false when there is none.
bool machine_bounds(const mjModel& model, const mjData& data, Vec3& lo, Vec3& hi) {
  lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  hi = -lo;
  bool any = false;
  for (int geom = 0; geom < model.ngeom; ++geom) {
    if (model.geom_type[geom] == mjGEOM_PLANE || !geom_visible(model, geom)) continue;
    const mjtNum* size = model.geom_size + 3 * geom;
    Vec3 centre = Vec3::Zero(), half;
    switch (model.geom_type[geom]) {
      case mjGEOM_SPHERE:
        half = Vec3::Constant(size[0]);
        break;
      case mjGEOM_CAPSULE:
        half = Vec3(size[0], size[0], size[1] + size[0]);
        break;
      case mjGEOM_CYLINDER:
        half = Vec3(size[0], size[0], size[1]);
        break;
      case mjGEOM_BOX:
      case mjGEOM_ELLIPSOID:
        half = Vec3(size[0], size[1], size[2]);
        break;
      case mjGEOM_MESH: {
        const int mesh = model.geom_dataid[geom];
        Vec3 mesh_lo = Vec3::Constant(std::numeric_limits<double>::infinity()), mesh_hi = -mesh_lo;
        for (int v = 0; v < model.mesh_vertnum[mesh]; ++v) {
          const float* vertex = model.mesh_vert + 3 * (model.mesh_vertadr[mesh] + v);
          const Vec3 point(vertex[0], vertex[1], vertex[2]);
          mesh_lo = mesh_lo.cwiseMin(point);
          mesh_hi = mesh_hi.cwiseMax(point);
        }
        if (model.mesh_vertnum[mesh] == 0) continue;
        centre = 0.5 * (mesh_lo + mesh_hi);
        half = 0.5 * (mesh_hi - mesh_lo);
        break;
      }
      default:
        half = Vec3::Constant(model.geom_rbound[geom]);
    }
    const mjtNum* rotation = data.geom_xmat + 9 * geom;
    Vec3 world_centre, world_half;
    for (int row = 0; row < 3; ++row) {
      world_centre[row] = data.geom_xpos[3 * geom + row];
      world_half[row] = 0.0;
      for (int col = 0; col < 3; ++col) {
        world_centre[row] += rotation[3 * row + col] * centre[col];
        world_half[row] += std::abs(rotation[3 * row + col]) * half[col];
      }
    }
    lo = lo.cwiseMin(world_centre - world_half);
    hi = hi.cwiseMax(world_centre + world_half);
    any = true;
  }
  return any;
}

// a free camera's forward, up and right directions (MuJoCo's mjv_updateScene convention)
struct ViewBasis {
  Vec3 forward, up, right;
};
ViewBasis view_basis(double azimuth_deg, double elevation_deg) {
  const double ca = std::cos(deg_to_rad(azimuth_deg)), sa = std::sin(deg_to_rad(azimuth_deg));
  const double ce = std::cos(deg_to_rad(elevation_deg)), se = std::sin(deg_to_rad(elevation_deg));
  ViewBasis basis;
  basis.forward = Vec3(ce * ca, ce * sa, se);
  basis.up = Vec3(-se * ca, -se * sa, ce);
  basis.right = basis.forward.cross(basis.up);
  return basis;
}

// The free camera from this direction that shows every point inside kFill of a panel of
// `aspect` (width / height) with vertical field of view fovy: centred on the points' image
// (a few passes: the look-at point moves to the middle of their projected extent), then as
// close as that allows.
FreeCamera fit_camera(const std::vector<Vec3>& points, double azimuth_deg, double elevation_deg,
                      double fovy_deg, double aspect) {
  FreeCamera camera;
  camera.azimuth_deg = azimuth_deg;
  camera.elevation_deg = elevation_deg;
  if (points.empty()) return camera;
  const ViewBasis basis = view_basis(azimuth_deg, elevation_deg);
  const double tan_v = std::tan(deg_to_rad(0.5 * fovy_deg)) * kFill;
  const double tan_h = tan_v * aspect;
  Vec3 lo = points.front(), hi = points.front();
  for (const Vec3& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  Vec3 lookat = 0.5 * (lo + hi);
  // the nearest distance at which every point is inside the panel
  auto distance_for = [&](const Vec3& at) {
    double distance = 0.0;
    for (const Vec3& p : points) {
      const Vec3 d = p - at;
      const double depth = d.dot(basis.forward);
      distance = std::max({distance, std::abs(d.dot(basis.right)) / tan_h - depth,
                           std::abs(d.dot(basis.up)) / tan_v - depth});
    }
    return distance;
  };
  for (int pass = 0; pass < 4; ++pass) {
    const double distance = std::max(distance_for(lookat), 1e-6);
    double u_lo = std::numeric_limits<double>::infinity(), u_hi = -u_lo, v_lo = u_lo, v_hi = -u_lo;
    for (const Vec3& p : points) {
      const Vec3 d = p - lookat;
      const double depth = std::max(1e-9, distance + d.dot(basis.forward));
      const double u = d.dot(basis.right) / depth, v = d.dot(basis.up) / depth;
      u_lo = std::min(u_lo, u);
      u_hi = std::max(u_hi, u);
      v_lo = std::min(v_lo, v);
      v_hi = std::max(v_hi, v);
    }
    lookat += distance * (0.5 * (u_lo + u_hi) * basis.right + 0.5 * (v_lo + v_hi) * basis.up);
  }
  camera.lookat_m = lookat;
  camera.distance_m = std::max(distance_for(lookat), 1e-4);
  return camera;
}

// The view's azimuth (deg) for a machine that reaches the part through a chain of bodies (an
// arm), `towards_root` the horizontal direction from the deposit to the chain's root and
// `tool_lean` the tool's (horizontal, from the nozzle up to the tool body): an elongated
// deposit region is seen broadside (the view across its long side, from the side that has the
// tool leaning away, else the machine behind it, turned kChainTurn_deg towards the machine), a
// squarish one from opposite the machine, turned kChainTurn_deg towards render_cam's view
// (`camera_azimuth`): a three-quarter view of the part with the arm reaching in from behind.
double machine_side_azimuth(const mjData& data, int substrate, const Vec3& deposit_size_mm,
                            const Vec3& towards_root, const Vec3& tool_lean,
                            double camera_azimuth) {
  const double root = rad_to_deg(std::atan2(towards_root.y(), towards_root.x()));
  // the azimuth `from` turned by at most `by` towards `to`
  auto turned = [](double from, double to, double by) {
    return from + std::clamp(std::remainder(to - from, 360.0), -by, by);
  };
  const double ex = deposit_size_mm.x(), ey = deposit_size_mm.y();
  if (std::max(ex, ey) < kElongated * std::min(ex, ey))
    return turned(root, camera_azimuth, kChainTurn_deg);
  // the long side's direction in the world, and the two views across it
  const mjtNum* rotation = data.xmat + 9 * substrate;
  const int column = ex >= ey ? 0 : 1;
  const double long_side = rad_to_deg(std::atan2(rotation[3 + column], rotation[column]));
  const double across[2] = {long_side + 90.0, long_side - 90.0};
  auto offset = [](double a, double b) { return std::abs(std::remainder(a - b, 360.0)); };
  // the side with the tool leaning away from the view, the head then behind the nozzle
  // rather than over the deposit; without a lean, with the machine behind; then render_cam's
  const double view_x = std::cos(deg_to_rad(across[0])), view_y = std::sin(deg_to_rad(across[0]));
  const double lean_along = tool_lean.x() * view_x + tool_lean.y() * view_y;
  const double root_offsets[2] = {offset(across[0], root), offset(across[1], root)};
  int side = offset(across[0], camera_azimuth) <= offset(across[1], camera_azimuth) ? 0 : 1;
  if (std::abs(lean_along) > kToolLean * tool_lean.norm() && tool_lean.norm() > 0.0)
    side = lean_along > 0.0 ? 0 : 1;
  else if (std::abs(root_offsets[0] - root_offsets[1]) >= 1.0)
    side = root_offsets[0] < root_offsets[1] ? 0 : 1;
  return turned(across[side], root, kChainTurn_deg);
}

// The deposit's bead width (mm): the median length of the runs of cells thicker than half the
// peak, along the rows and along the columns, the smaller of the two (a line at any angle: its
// width to within 41 %; a covered area: its size). 0 without a deposit.
double bead_width_mm(const HeightMap& map) {
  const float half = 0.5f * map.max_value();
  if (!(half > 0.0f)) return 0.0;
  auto median_run = [&](int lines, int length, auto at) {
    std::vector<int> runs;
    for (int line = 0; line < lines; ++line) {
      int run = 0;
      for (int i = 0; i <= length; ++i) {
        if (i < length && at(line, i) >= half) {
          ++run;
        } else if (run > 0) {
          runs.push_back(run);
          run = 0;
        }
      }
    }
    if (runs.empty()) return std::numeric_limits<double>::infinity();
    std::nth_element(runs.begin(), runs.begin() + runs.size() / 2, runs.end());
    return static_cast<double>(runs[runs.size() / 2]);
  };
  const double along_rows =
      median_run(map.ny, map.nx, [&](int row, int i) { return map.at(i, row); });
  const double along_columns =
      median_run(map.nx, map.ny, [&](int column, int i) { return map.at(column, i); });
  return std::min(along_rows, along_columns) * map.cell_mm;
}

// the deposit mesh's colour top and relief for `deposit` (the framing's when given): the relief
// a fraction of the region's size, at most kReliefPerBeadWidth of the bead's width (a narrow
// line as a low mound, not a wall whose flanks hide its crest)
DepositMeshOptions mesh_options(const HeightMap& deposit, const SceneRenderOptions& options) {
  DepositMeshOptions mesh;
  if (options.framing) {
    mesh.colour_top_um = options.framing->colour_top_um;
    mesh.relief_mm = options.framing->relief_mm;
  } else {
    mesh.colour_top_um = deposit.thickness_um.empty() ? 0.0 : deposit.max_value();
    mesh.relief_mm =
        std::min(options.relief_fraction * std::max(deposit.nx, deposit.ny) * deposit.cell_mm,
                 kReliefPerBeadWidth * bead_width_mm(deposit));
  }
  mesh.surface_height_mm = options.surface_height_mm;
  mesh.along_normal = options.tilt_to_surface;
  mesh.max_vertices = options.max_mesh_vertices;
  mesh.min_relative_thickness = options.min_relative_thickness;
  mesh.lift_mm = options.surface_height_mm
                     ? std::max(kLift_mm, kSurfaceLiftFraction * mesh.relief_mm)
                     : kLift_mm;
  return mesh;
}

// panel aspect ratio (width / height)
double aspect_of(const PixelRect& rect) {
  return rect.height > 0 ? static_cast<double>(rect.width) / rect.height : 1.0;
}

// The views of frame_scene, from the mesh already built for the deposit (its bounds).
SceneFraming frame_views(const mjModel& model, const mjData& data, int camera, int substrate,
                         const DepositMesh& mesh, const SceneRenderOptions& options) {
  SceneFraming framing;
  framing.colour_top_um = mesh.colour_top_um;
  framing.relief_mm = mesh.relief_mm;
  framing.whole_from_render_cam = !options.frame_deposit;
  const SceneLayout layout = scene_layout(options);
  const double fovy = model.vis.global.fovy;
  const bool on_surface = static_cast<bool>(options.surface_height_mm);

  // the deposit's box in the substrate frame: the mesh's (on a flat plate down to z = 0), else
  // a few mm around the nozzle's point on the substrate
  const int nozzle = mj_name2id(&model, mjOBJ_SITE, kNozzleSite);
  Vec3 nozzle_world = Vec3::Zero();
  if (nozzle >= 0)
    nozzle_world = Vec3(data.site_xpos[3 * nozzle], data.site_xpos[3 * nozzle + 1],
                        data.site_xpos[3 * nozzle + 2]);
  Vec3 deposit_lo, deposit_hi;
  if (!mesh.empty()) {
    deposit_lo = mesh.lo_mm;
    deposit_hi = mesh.hi_mm;
    deposit_lo.z() = std::min(deposit_lo.z(), 0.0);
  } else {
    Vec3 centre = nozzle >= 0 ? world_to_substrate(data, substrate, nozzle_world) : Vec3::Zero();
    centre.z() = 0.0;
    deposit_lo = centre;
    deposit_hi = centre;
  }
  const Vec3 deposit_centre_mm = 0.5 * (deposit_lo + deposit_hi);
  const Vec3 min_half(kMinCloseupHalf_mm, kMinCloseupHalf_mm, 0.0);
  const Vec3 closeup_lo = deposit_lo.cwiseMin(deposit_centre_mm - min_half);
  const Vec3 closeup_hi = deposit_hi.cwiseMax(deposit_centre_mm + min_half);
  std::vector<Vec3> deposit_points;
  for (const Vec3& corner : box_corners(closeup_lo, closeup_hi))
    deposit_points.push_back(substrate_to_world(data, substrate, corner));

  // the direction: render_cam's (it looks along its -z axis)
  const mjtNum* axes = data.cam_xmat + 9 * camera;
  const Vec3 forward(-axes[2], -axes[5], -axes[8]);
  const double camera_azimuth = rad_to_deg(std::atan2(forward.y(), forward.x()));
  double azimuth = camera_azimuth;
  double elevation = rad_to_deg(std::asin(std::clamp(forward.z(), -1.0, 1.0)));
  // a nozzle carried on a chain of bodies (an arm): the part broadside, the arm behind it
  if (nozzle >= 0 && model.site_bodyid[nozzle] > 0) {
    const Vec3 deposit_world = substrate_to_world(data, substrate, deposit_centre_mm);
    Vec3 towards_root = Vec3::Zero();
    for (int body = model.site_bodyid[nozzle]; body > 0; body = model.body_parentid[body])
      towards_root = Vec3(data.xpos[3 * body] - deposit_world.x(),
                          data.xpos[3 * body + 1] - deposit_world.y(), 0.0);
    const int tool = model.site_bodyid[nozzle];
    const Vec3 tool_lean(data.xpos[3 * tool] - nozzle_world.x(),
                         data.xpos[3 * tool + 1] - nozzle_world.y(), 0.0);
    if (towards_root.norm() > 0.0)
      azimuth = machine_side_azimuth(data, substrate, closeup_hi - closeup_lo, towards_root,
                                     tool_lean, camera_azimuth);
  }
  // on a part, from at least this high: the deposit lies on top of it
  if (on_surface) elevation = std::min(elevation, -kPartElevation_deg);

  // the machine view: the visible geoms, the deposit and the nozzle
  std::vector<Vec3> machine_points = deposit_points;
  Vec3 machine_lo, machine_hi;
  if (machine_bounds(model, data, machine_lo, machine_hi))
    for (const Vec3& corner : box_corners(machine_lo, machine_hi)) machine_points.push_back(corner);
  if (nozzle >= 0) machine_points.push_back(nozzle_world);
  framing.whole = fit_camera(machine_points, azimuth, elevation, fovy, aspect_of(layout.whole));

  // the close-up: the deposit, more steeply
  const double closeup_elevation = std::min(elevation, -kCloseupElevation_deg);
  const PixelRect& closeup_panel = layout.closeup.width > 0 ? layout.closeup : layout.whole;
  framing.closeup =
      fit_camera(deposit_points, azimuth, closeup_elevation, fovy, aspect_of(closeup_panel));
  return framing;
}

// body `body` is `ancestor` or lies in its subtree
bool in_subtree(const mjModel& model, int body, int ancestor) {
  for (; body > 0; body = model.body_parentid[body])
    if (body == ancestor) return true;
  return body == ancestor;
}

// The close-up's ghosts: geoms outside the substrate's body tree whose centre is above the
// deposit's lowest point (the print head, a shutter, an arm's links) become see-through within
// `reach_mm` above it (the nozzle's tip, a shutter blade), and are left out higher up (they
// would loom over the panel).
void ghost_above_substrate(const mjModel& model, const mjData& data, int substrate, double above_mm,
                           double reach_mm, mjvScene& scene) {
  int kept = 0;
  for (int i = 0; i < scene.ngeom; ++i) {
    mjvGeom geom = scene.geoms[i];
    if (geom.objtype == mjOBJ_GEOM || geom.objtype == mjOBJ_SITE) {
      const int body = geom.objtype == mjOBJ_GEOM ? model.geom_bodyid[geom.objid]
                                                  : model.site_bodyid[geom.objid];
      const Vec3 centre(geom.pos[0], geom.pos[1], geom.pos[2]);
      const double height_mm = world_to_substrate(data, substrate, centre).z() - above_mm;
      if (!in_subtree(model, body, substrate) && height_mm > 0.0) {
        if (height_mm > reach_mm) continue;
        geom.rgba[3] = std::min(geom.rgba[3], kGhostAlpha);
      }
    }
    scene.geoms[kept++] = geom;
  }
  scene.ngeom = kept;
}

// the model's shadow-casting lights moved over the framed camera's shoulder: shadows then
// fall away from the viewer, behind the print head instead of across the deposit
void light_over_camera(const mjvCamera& view, mjvScene& scene) {
  const double azimuth_rad = deg_to_rad(view.azimuth);
  const Vec3 direction =
      Vec3(kShoulderLight * std::cos(azimuth_rad), kShoulderLight * std::sin(azimuth_rad), -1.0)
          .normalized();
  for (int i = 0; i < scene.nlight; ++i) {
    mjvLight& light = scene.lights[i];
    if (light.headlight || !light.castshadow) continue;
    for (int axis = 0; axis < 3; ++axis) {
      light.dir[axis] = static_cast<float>(direction[axis]);
      light.pos[axis] = static_cast<float>(view.lookat[axis] - kLightDistance_m * direction[axis]);
    }
  }
}

// The image from a render `factor` times its size: each pixel the mean of a factor x factor
// block (a box filter), rows flipped from OpenGL's bottom-up order to top-down.
std::vector<unsigned char> downsample_flipped(const std::vector<unsigned char>& bottom_up,
                                              int width, int height, int factor) {
  std::vector<unsigned char> rgb(static_cast<size_t>(width) * height * 3);
  const size_t source_row = static_cast<size_t>(width) * factor * 3;
  const unsigned block = static_cast<unsigned>(factor * factor);
  std::vector<unsigned> column_sums(source_row);  // the block's rows added, per source byte
  for (int row = 0; row < height; ++row) {
    // add the block's source rows (a plain loop the compiler vectorises), then each pixel's
    // `factor` neighbours in them
    std::fill(column_sums.begin(), column_sums.end(), 0u);
    for (int sub_row = 0; sub_row < factor; ++sub_row) {
      const unsigned char* source =
          bottom_up.data() + (static_cast<size_t>(row) * factor + sub_row) * source_row;
      for (size_t i = 0; i < source_row; ++i) column_sums[i] += source[i];
    }
    unsigned char* target = rgb.data() + static_cast<size_t>(height - 1 - row) * width * 3;
    for (int column = 0; column < width; ++column)
      for (int channel = 0; channel < 3; ++channel) {
        unsigned sum = 0;
        for (int sub_column = 0; sub_column < factor; ++sub_column)
          sum += column_sums[3 * (static_cast<size_t>(column) * factor + sub_column) + channel];
        target[3 * column + channel] = static_cast<unsigned char>((sum + block / 2) / block);
      }
  }
  return rgb;
}

void write_png(const std::string& path, int width, int height,
               const std::vector<unsigned char>& rgb) {
  write_file_atomically(path, encode_png(width, height, PngPixels::rgb8, rgb.data()));
}

// a round length near `target`: 1, 2 or 5 times a power of ten
double round_length(double target) {
  const double decade = std::pow(10.0, std::floor(std::log10(target)));
  for (const double step : {5.0, 2.0, 1.0})
    if (step * decade <= target) return step * decade;
  return decade;
}

// a round step at least `target`: 1, 2, 2.5 or 5 times a power of ten
double round_step(double target) {
  const double decade = std::pow(10.0, std::floor(std::log10(target)));
  for (const double step : {1.0, 2.0, 2.5, 5.0})
    if (step * decade >= target * (1.0 - 1e-12)) return step * decade;
  return 10.0 * decade;
}

// the width of a text in MuJoCo's normal font (pixels)
int text_width(const mjrContext& context, const char* text) {
  int width = 0;
  for (const char* c = text; *c; ++c)
    width += context.charWidth[static_cast<unsigned char>(*c) & 0x7f];
  return width;
}

// a number for a label: 3 significant digits, no trailing zeros
std::string label_number(double value) {
  char text[32];
  if (std::abs(value) >= 100.0)
    std::snprintf(text, sizeof text, "%.0f", value);
  else
    std::snprintf(text, sizeof text, "%.3g", std::abs(value) < 1e-12 ? 0.0 : value);
  return text;
}

}  // namespace

void ghost_over_deposit(const mjModel& model, const mjData& data, int substrate,
                        const Vec3& deposit_lo_mm, const Vec3& deposit_hi_mm, mjvScene& scene) {
  ghost_above_substrate(model, data, substrate, deposit_lo_mm.z(),
                        std::max(kMinCloseupHalf_mm, 0.5 * (deposit_hi_mm - deposit_lo_mm).norm()),
                        scene);
}

void add_backdrop(const mjModel& model, const mjData& data, mjvScene& scene) {
  double lowest_m = std::numeric_limits<double>::infinity();
  for (int geom = 0; geom < model.ngeom; ++geom) {
    if (model.geom_type[geom] == mjGEOM_PLANE) return;
    lowest_m = std::min(lowest_m, data.geom_xpos[3 * geom + 2] - model.geom_rbound[geom]);
  }
  if (!std::isfinite(lowest_m) || scene.ngeom >= scene.maxgeom) return;
  const double extent_m = model.stat.extent;
  const double half_thickness_m = 0.01 * extent_m;
  const mjtNum size[3] = {kBackdropHalfWidth * extent_m, kBackdropHalfWidth * extent_m,
                          half_thickness_m};
  const mjtNum position[3] = {model.stat.center[0], model.stat.center[1],
                              lowest_m - kBackdropDrop * extent_m - half_thickness_m};
  const mjtNum identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  mjv_initGeom(scene.geoms + scene.ngeom++, mjGEOM_BOX, size, position, identity, kBackdropColour);
}

SceneLayout scene_layout(const SceneRenderOptions& options) {
  SceneLayout layout;
  const int strip = options.overlays
                        ? std::clamp(static_cast<int>(std::lround(kStripShare * options.height)),
                                     kMinStrip_px, std::min(kMaxStrip_px, options.height / 3))
                        : 0;
  const int panels_height = options.height - strip;
  const int closeup =
      options.closeup ? static_cast<int>(std::lround(kCloseupShare * options.width)) : 0;
  layout.whole = {0, 0, options.width - closeup, panels_height};
  layout.closeup = {options.width - closeup, 0, closeup, closeup > 0 ? panels_height : 0};
  layout.strip = {0, panels_height, options.width, strip};
  return layout;
}

void set_free_camera(const FreeCamera& camera, mjvCamera& view) {
  view.type = mjCAMERA_FREE;
  for (int i = 0; i < 3; ++i) view.lookat[i] = camera.lookat_m[i];
  view.distance = camera.distance_m;
  view.azimuth = camera.azimuth_deg;
  view.elevation = camera.elevation_deg;
}

std::optional<Eigen::Vector2d> project_to_viewport(const mjvGLCamera& camera,
                                                   const mjrRect& viewport, const Vec3& world_m) {
  const Vec3 forward = Vec3(camera.forward[0], camera.forward[1], camera.forward[2]).normalized();
  const Vec3 right = forward.cross(Vec3(camera.up[0], camera.up[1], camera.up[2])).normalized();
  const Vec3 up = right.cross(forward);
  const Vec3 d = world_m - Vec3(camera.pos[0], camera.pos[1], camera.pos[2]);
  const double depth = d.dot(forward);
  if (!(depth > 0.0)) return std::nullopt;
  // glFrustum at the near plane, its half-width matched to the viewport (as mjr_render)
  const double half_height = 0.5 * (camera.frustum_top - camera.frustum_bottom);
  const double half_width = half_height * viewport.width / viewport.height;
  const double centre_y = 0.5 * (camera.frustum_top + camera.frustum_bottom);
  const double x = d.dot(right) / depth * camera.frustum_near;
  const double y = d.dot(up) / depth * camera.frustum_near;
  const double ndc_x = (x - camera.frustum_center) / half_width;
  const double ndc_y = (y - centre_y) / half_height;
  return Eigen::Vector2d(viewport.left + 0.5 * (ndc_x + 1.0) * viewport.width,
                         viewport.bottom + 0.5 * (ndc_y + 1.0) * viewport.height);
}

double pixels_per_mm(const mjvGLCamera& camera, const mjrRect& viewport, const Vec3& world_m) {
  const Vec3 forward = Vec3(camera.forward[0], camera.forward[1], camera.forward[2]).normalized();
  const double depth = (world_m - Vec3(camera.pos[0], camera.pos[1], camera.pos[2])).dot(forward);
  const double frustum_height = camera.frustum_top - camera.frustum_bottom;
  if (!(depth > 0.0) || !(frustum_height > 0.0)) return 0.0;
  const double visible_height_m = depth * frustum_height / camera.frustum_near;
  return viewport.height / m_to_mm(visible_height_m);
}

void draw_colour_bar(const mjrRect& strip, double colour_top_um, int pixel_scale,
                     const mjrContext& context, GlProcAddress gl_proc_address) {
  const int s = std::max(1, pixel_scale);
  mjr_rectangle(strip, kPaper[0], kPaper[1], kPaper[2], 1.0f);
  if (!(colour_top_um > 0.0)) {
    mjr_label(strip, mjFONT_NORMAL, "no deposit", kPaper[0], kPaper[1], kPaper[2], 0.0f, kInk[0],
              kInk[1], kInk[2], &context);
    return;
  }
  // the title (with the top value) on the left, the bar across the rest with round values
  // below it
  const std::string title = "thickness, um (top " + label_number(colour_top_um) + ")";
  const int title_width = text_width(context, title.c_str()) + 16 * s;
  mjr_label({strip.left, strip.bottom, title_width, strip.height}, mjFONT_NORMAL, title.c_str(), 0,
            0, 0, 0.0f, kInk[0], kInk[1], kInk[2], &context);
  const int label_height = context.charHeight + 2 * s;
  const int margin = 4 * s, tick = 3 * s;
  const int bar_left = strip.left + title_width;
  const int bar_width = strip.left + strip.width - bar_left - 24 * s;
  const int bar_bottom = strip.bottom + margin + label_height + tick;
  const int bar_height = std::max(s, strip.bottom + strip.height - margin - bar_bottom);
  if (bar_width <= 0) return;
  if (gl_proc_address) {
    draw_viridis_ramp({bar_left, bar_bottom, bar_width, bar_height}, gl_proc_address);
  } else {
    for (int column = 0; column < bar_width; ++column) {
      float rgb[3];
      viridis((column + 0.5) / bar_width, rgb);
      mjr_rectangle({bar_left + column, bar_bottom, 1, bar_height}, rgb[0], rgb[1], rgb[2], 1.0f);
    }
  }
  // ticks at round values (about 5 on a wide bar, 3 on a narrow one), labelled
  const double step = round_step(colour_top_um / (bar_width >= 240 * s ? 5.0 : 3.0));
  for (int i = 0; i * step <= colour_top_um * (1.0 + 1e-9); ++i) {
    const double value = i * step;
    const int x = bar_left + static_cast<int>(std::lround(value / colour_top_um * (bar_width - s)));
    mjr_rectangle({x, bar_bottom - tick, s, tick}, kInk[0], kInk[1], kInk[2], 1.0f);
    const std::string text = label_number(value);
    const int width = text_width(context, text.c_str()) + 4 * s;
    mjr_label({x - width / 2, strip.bottom + margin, width, label_height}, mjFONT_NORMAL,
              text.c_str(), 0, 0, 0, 0.0f, kInk[0], kInk[1], kInk[2], &context);
  }
}

void draw_scale_bar(const mjrRect& panel, double px_per_mm, int pixel_scale,
                    const mjrContext& context) {
  if (!(px_per_mm > 0.0) || panel.width <= 0) return;
  const int s = std::max(1, pixel_scale);
  const double length_mm = round_length(0.2 * panel.width / px_per_mm);
  const int length = std::max(s, static_cast<int>(std::lround(length_mm * px_per_mm)));
  char text[48];
  std::snprintf(text, sizeof text, "%g mm", length_mm);
  // a paper backing, the bar with end ticks, its length above it
  const int pad = 6 * s, bar = 3 * s, end = 5 * s;
  const int width = std::max(length, text_width(context, text)) + 2 * pad;
  const int height = context.charHeight + bar + end + 2 * pad;
  const mjrRect box = {panel.left + pad, panel.bottom + pad, width, height};
  mjr_rectangle(box, kPaper[0], kPaper[1], kPaper[2], 0.8f);
  const int bar_left = box.left + pad, bar_bottom = box.bottom + pad;
  mjr_rectangle({bar_left, bar_bottom, length, bar}, kInk[0], kInk[1], kInk[2], 1.0f);
  mjr_rectangle({bar_left, bar_bottom, s, bar + end}, kInk[0], kInk[1], kInk[2], 1.0f);
  mjr_rectangle({bar_left + length - s, bar_bottom, s, bar + end}, kInk[0], kInk[1], kInk[2], 1.0f);
  mjr_label({box.left, bar_bottom + bar + end, width, context.charHeight + pad}, mjFONT_NORMAL,
            text, 0, 0, 0, 0.0f, kInk[0], kInk[1], kInk[2], &context);
}

void draw_panel_title(const mjrRect& panel, const char* title, int pixel_scale,
                      const mjrContext& context) {
  const int s = std::max(1, pixel_scale);
  const int pad = 6 * s;
  const int width = text_width(context, title) + 2 * pad;
  const int height = context.charHeight + pad;
  mjr_label({panel.left + pad, panel.bottom + panel.height - pad - height, width, height},
            mjFONT_NORMAL, title, kPaper[0], kPaper[1], kPaper[2], 0.8f, kInk[0], kInk[1], kInk[2],
            &context);
}

SceneFraming frame_scene(const mjModel& model, const mjData& data, const HeightMap& deposit,
                         const SceneRenderOptions& options) {
  const int camera = require_id(model, mjOBJ_CAMERA, kCameraName, "model", "the scene camera");
  const int substrate =
      require_id(model, mjOBJ_BODY, kSubstrateBody, "model", "the frame of the deposit");
  SceneRenderOptions unframed = options;
  unframed.framing.reset();
  const DepositMesh mesh = build_deposit_mesh(deposit, mesh_options(deposit, unframed));
  return frame_views(model, data, camera, substrate, mesh, unframed);
}

// The GL and MuJoCo render contexts, kept between images. mjr_makeContext is most of an
// image's cost in software (buffers and shader compilation), so a run that renders one
// scene per planner builds it once.
struct SceneRenderer::Contexts {
  OsMesaContext gl;
  RenderContextOwner render;
  ContextShape shape;
  std::vector<unsigned char> readback;  // the rendered pixels, bottom row first
  Contexts(const mjModel& model, const ContextShape& sized)
      : gl(sized.width, sized.height),
        render(model, sized.width, sized.height, sized.shadow_size, sized.font_scale),
        shape(sized) {}
  // mjr_freeContext needs the GL context current on the thread that destroys them
  ~Contexts() { gl.try_make_current(); }
  Contexts(const Contexts&) = delete;
  Contexts& operator=(const Contexts&) = delete;
};

SceneRenderer::SceneRenderer() = default;
SceneRenderer::~SceneRenderer() {
  try {
    finish_preparation();
  } catch (...) {  // a preparation that failed and was never used
  }
}

void SceneRenderer::prepare(const std::string& model_path, const SceneRenderOptions& options,
                            const std::string& model_text) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (contexts_ || preparing_.valid()) return;
  install_mujoco_handlers();  // before the thread: the handlers are process-wide
  preparing_ = std::async(std::launch::async, [model_path, options, model_text] {
    const ModelPtr model = model_text.empty() ? load_model(model_path)
                                              : load_model_from_string(model_text, model_path);
    auto contexts = std::make_unique<Contexts>(*model, context_shape(*model, options));
    contexts->gl.release();  // the rendering thread makes it current
    return contexts;
  });
}

void SceneRenderer::finish_preparation() {
  if (!preparing_.valid()) return;
  std::unique_ptr<Contexts> prepared = preparing_.get();
  if (!contexts_) contexts_ = std::move(prepared);
}

std::vector<unsigned char> SceneRenderer::render_rgb(const Simulation& simulation,
                                                     const HeightMap& deposit,
                                                     const SceneRenderOptions& options) {
  return render_rgb(SimulationAccess::model(simulation), SimulationAccess::data(simulation),
                    deposit, options);
}

std::vector<unsigned char> SceneRenderer::render_rgb(const mjModel& model, const mjData& data,
                                                     const HeightMap& deposit,
                                                     const SceneRenderOptions& options) {
  install_mujoco_handlers();
  // the image needs no room in the model's <global offwidth offheight>: the render context is
  // made from a copy of the model sized to the image (RenderContextOwner)
  if (options.width <= 0 || options.height <= 0)
    throw InternalError("render: the image must be at least 1 x 1 pixels");
  if (options.supersampling < 1 || options.supersampling > kMaxSupersampling)
    throw InternalError("render: supersampling must be between 1 and " +
                        std::to_string(kMaxSupersampling));
  if (deposit.nx < 0 || deposit.ny < 0 ||
      deposit.thickness_um.size() != static_cast<size_t>(deposit.nx) * deposit.ny ||
      (deposit.nx > 0 && !(deposit.cell_mm > 0.0)))
    throw InternalError("render: the height map's size does not match its grid");
  const int camera = require_id(model, mjOBJ_CAMERA, kCameraName, "model", "the scene camera");
  const int substrate =
      require_id(model, mjOBJ_BODY, kSubstrateBody, "model", "the frame of the deposit");
  const int width = options.width, height = options.height;

  // the deposit mesh and the views (before the lock: no GL yet)
  DataPtr state = copy_data(model, data);
  const DepositMesh mesh = build_deposit_mesh(deposit, mesh_options(deposit, options));
  const SceneFraming framing = options.framing
                                   ? *options.framing
                                   : frame_views(model, *state, camera, substrate, mesh, options);
  const SceneLayout layout = scene_layout(options);

  // set up: GL context, MuJoCo render context on the offscreen buffer, scene
  const std::lock_guard<std::mutex> lock(mutex_);
  // the prepared contexts, or those of the previous image, when the model has the same shape
  // (the same MJCF)
  try {
    finish_preparation();
  } catch (const std::exception&) {  // built again below, where an error names this model
  }
  const ContextShape shape = context_shape(model, options);
  if (!contexts_ || !(contexts_->shape == shape)) {
    contexts_.reset();
    contexts_ = std::make_unique<Contexts>(model, shape);
  }
  // current for this render only, so that the next may come from another thread
  contexts_->gl.make_current();
  struct ReleaseAtExit {
    OsMesaContext& gl;
    ~ReleaseAtExit() { gl.release(); }
  } release_at_exit{contexts_->gl};
  mjrContext& context = contexts_->render.context;
  mjr_setBuffer(mjFB_OFFSCREEN, &context);
  if (context.currentBuffer != mjFB_OFFSCREEN)
    throw InternalError("MuJoCo could not select its offscreen buffer");
  SceneOwner scene(model, 4 * model.ngeom + 64);
  mjvOption visual_options;
  mjv_defaultOption(&visual_options);
  mjvPerturb perturb;
  mjv_defaultPerturb(&perturb);

  // panels in framebuffer pixels (bottom-up, supersampled)
  const int factor = options.supersampling;
  auto framebuffer_rect = [&](const PixelRect& r) {
    return mjrRect{r.x * factor, (height - r.y - r.height) * factor, r.width * factor,
                   r.height * factor};
  };
  const mjrRect full = {0, 0, width * factor, height * factor};
  const mjrRect whole_rect = framebuffer_rect(layout.whole);
  const mjrRect closeup_rect = framebuffer_rect(layout.closeup);
  mjr_rectangle(full, kPaper[0], kPaper[1], kPaper[2], 1.0f);
  const Vec3 deposit_centre = substrate_to_world(
      *state, substrate, mesh.empty() ? Vec3::Zero() : Vec3(0.5 * (mesh.lo_mm + mesh.hi_mm)));

  // one panel: update the scene from `view`, add the floor, render, draw the deposit on it;
  // returns the panel's pixels per mm at the deposit
  auto render_panel = [&](mjvCamera& view, const mjrRect& rect, bool ghosts) {
    mjv_updateScene(&model, state.get(), &visual_options, &perturb, &view, mjCAT_ALL, &scene.scene);
    if (view.type == mjCAMERA_FREE) light_over_camera(view, scene.scene);
    scene.scene.flags[mjRND_SHADOW] = options.shadows ? 1 : 0;
    if (ghosts && !mesh.empty())
      ghost_over_deposit(model, *state, substrate, mesh.lo_mm, mesh.hi_mm, scene.scene);
    else if (ghosts)
      ghost_over_deposit(model, *state, substrate, Vec3::Zero(), Vec3::Zero(), scene.scene);
    add_backdrop(model, *state, scene.scene);
    mjr_render(rect, &scene.scene, &context);
    draw_deposit_mesh(mesh, scene.scene, rect, state->xpos + 3 * substrate,
                      state->xmat + 9 * substrate, osmesa_proc_address);
    const mjvGLCamera gl_camera = mjv_averageCamera(scene.scene.camera, scene.scene.camera + 1);
    return pixels_per_mm(gl_camera, rect, deposit_centre);
  };

  // the machine: render_cam itself, or framed
  mjvCamera view;
  mjv_defaultCamera(&view);
  if (framing.whole_from_render_cam) {
    view.type = mjCAMERA_FIXED;
    view.fixedcamid = camera;
  } else {
    set_free_camera(framing.whole, view);
  }
  const double whole_px_per_mm = render_panel(view, whole_rect, false);
  // the close-up of the deposit
  double closeup_px_per_mm = 0.0;
  if (layout.closeup.width > 0) {
    mjv_defaultCamera(&view);
    set_free_camera(framing.closeup, view);
    closeup_px_per_mm = render_panel(view, closeup_rect, true);
  }

  // the overlays: colour bar, scale bars, titles
  if (layout.strip.height > 0) {
    draw_colour_bar(framebuffer_rect(layout.strip), framing.colour_top_um, factor, context,
                    osmesa_proc_address);
    draw_scale_bar(whole_rect, whole_px_per_mm, factor, context);
    if (layout.closeup.width > 0) {
      draw_scale_bar(closeup_rect, closeup_px_per_mm, factor, context);
      draw_panel_title(whole_rect, "machine", factor, context);
      draw_panel_title(closeup_rect, "deposit (close-up)", factor, context);
      // a thin rule between the panels
      mjr_rectangle({closeup_rect.left - factor, closeup_rect.bottom, factor, closeup_rect.height},
                    kPaper[0], kPaper[1], kPaper[2], 1.0f);
    }
  }

  // read back into a buffer kept with the contexts: a fresh one of this size is several
  // MB of memory to fault in and clear per image
  std::vector<unsigned char>& bottom_up = contexts_->readback;
  bottom_up.resize(static_cast<size_t>(full.width) * full.height * 3);
  mjr_readPixels(bottom_up.data(), nullptr, full, &context);
  check_warnings(*state, "while rendering");
  return downsample_flipped(bottom_up, width, height, factor);
}

void SceneRenderer::render_png(const Simulation& simulation, const HeightMap& deposit,
                               const std::string& png_path, const SceneRenderOptions& options) {
  const std::vector<unsigned char> rgb = render_rgb(simulation, deposit, options);
  write_png(png_path, options.width, options.height, rgb);
}

std::vector<unsigned char> render_scene_rgb(const Simulation& simulation, const HeightMap& deposit,
                                            const SceneRenderOptions& options) {
  SceneRenderer renderer;
  return renderer.render_rgb(simulation, deposit, options);
}

void render_scene_png(const Simulation& simulation, const HeightMap& deposit,
                      const std::string& png_path, const SceneRenderOptions& options) {
  const std::vector<unsigned char> rgb = render_scene_rgb(simulation, deposit, options);
  write_png(png_path, options.width, options.height, rgb);
}

}  // namespace depotwin
