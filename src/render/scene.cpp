#include "render/scene.hpp"

#include <GL/osmesa.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
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
// margin around the framed region, and the smallest region framed (mm)
constexpr double kFrameMargin = 1.25;
constexpr double kMinFrameRadius_mm = 3.0;
// framed renders: the key light comes from above, tilted this much towards the view
// direction, from this far away
constexpr double kShoulderLight = 0.35;
constexpr double kLightDistance_m = 0.6;
// the nozzle counts as apart from the deposit beyond this fraction of the deposit's radius
constexpr double kNozzleApartFraction = 0.2;
// the bodies carrying the nozzle are framed while the region's radius stays within this
// multiple of the deposit-and-nozzle radius (frame_camera)
constexpr double kChainFrameFactor = 3.5;
// ... seen broadside when its deposit region is this much longer than wide, the view turned
// this much towards the machine (deg) (machine_side_azimuth)
constexpr double kElongated = 1.5;
constexpr double kChainTurn_deg = 25.0;
// the tool leans across the long side when this fraction of its lean is (machine_side_azimuth)
constexpr double kToolLean = 0.3;
// on a part the view looks down at least this steeply (deg)
constexpr double kPartElevation_deg = 40.0;
// deposit boxes float this far above the plate so they never z-fight with it (mm); on a part
// (a mesh seen from farther away, an arm's scale) this fraction of the relief, if more
constexpr double kLift_mm = 0.005;
constexpr double kSurfaceLiftFraction = 0.02;
// the floor drawn under the machine: colour, half-width and drop below the lowest geom (in
// model extents)
constexpr float kBackdropColour[4] = {0.78f, 0.80f, 0.83f, 1.0f};
constexpr double kBackdropHalfWidth = 20.0;
constexpr double kBackdropDrop = 0.05;

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
  RenderContextOwner(const mjModel& model, int width, int height, int shadow_size) {
    const ModelPtr sized(mj_copyModel(nullptr, &model));
    if (!sized) throw InternalError("MuJoCo could not copy the model for its render context");
    sized->vis.global.offwidth = width;
    sized->vis.global.offheight = height;
    sized->vis.quality.offsamples = 0;  // anti-aliased by supersampling instead
    sized->vis.quality.shadowsize = shadow_size;
    mjr_defaultContext(&context);
    mjr_makeContext(sized.get(), &context, mjFONTSCALE_100);
  }
  ~RenderContextOwner() { mjr_freeContext(&context); }
  RenderContextOwner(const RenderContextOwner&) = delete;
  RenderContextOwner& operator=(const RenderContextOwner&) = delete;
};

// what an mjrContext depends on: the model's shape (models of the same MJCF file have the
// same one) and the buffers it was made with
struct ContextShape {
  int ngeom, nmesh, nmeshvert, ntex, ntexdata, nmat, nskin, nhfield;
  int width, height, shadow_size;
  bool operator==(const ContextShape& o) const {
    return ngeom == o.ngeom && nmesh == o.nmesh && nmeshvert == o.nmeshvert && ntex == o.ntex &&
           ntexdata == o.ntexdata && nmat == o.nmat && nskin == o.nskin && nhfield == o.nhfield &&
           width == o.width && height == o.height && shadow_size == o.shadow_size;
  }
};
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
          options.shadows ? m.vis.quality.shadowsize : 0};
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

// the surface's unit normal at (x, y) from its heights `step_mm` either side (central
// differences, one-sided at an edge; +z where there are no neighbours)
Vec3 surface_normal(const SceneRenderOptions& options, double x_mm, double y_mm, double z_mm,
                    double step_mm) {
  auto slope = [&](double dx, double dy) {
    const std::optional<double> ahead = options.surface_height_mm(x_mm + dx, y_mm + dy);
    const std::optional<double> behind = options.surface_height_mm(x_mm - dx, y_mm - dy);
    if (ahead && behind) return (*ahead - *behind) / (2.0 * step_mm);
    if (ahead) return (*ahead - z_mm) / step_mm;
    if (behind) return (z_mm - *behind) / step_mm;
    return 0.0;
  };
  return Vec3(-slope(step_mm, 0.0), -slope(0.0, step_mm), 1.0).normalized();
}

// a rotation (row-major, MuJoCo's geom frame) whose z axis is `axis` in the substrate frame and
// whose x axis is the substrate's x tilted with it, composed with the substrate's orientation
void box_rotation(const mjData& data, int substrate, const Vec3& axis, mjtNum out[9]) {
  const Vec3 x_axis = (Vec3::UnitX() - Vec3::UnitX().dot(axis) * axis).normalized();
  const Vec3 y_axis = axis.cross(x_axis);
  const mjtNum* rotation = data.xmat + 9 * substrate;
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) {
      const Vec3& column = col == 0 ? x_axis : (col == 1 ? y_axis : axis);
      out[3 * row + col] = rotation[3 * row] * column.x() + rotation[3 * row + 1] * column.y() +
                           rotation[3 * row + 2] * column.z();
    }
}

// the boxes as scene geoms, coloured by their relative thickness
void add_deposit_boxes(const mjData& data, int substrate, const std::vector<DepositBox>& boxes,
                       mjvScene& scene) {
  for (const DepositBox& box : boxes) {
    if (scene.ngeom >= scene.maxgeom) return;
    const Vec3 centre = substrate_to_world(
        data, substrate, box.base_mm + (box.lift_mm + box.half_height_mm) * box.axis);
    const mjtNum size[3] = {mm_to_m(box.half_width_mm), mm_to_m(box.half_width_mm),
                            mm_to_m(box.half_height_mm)};
    const mjtNum position[3] = {centre.x(), centre.y(), centre.z()};
    mjtNum rotation[9];
    box_rotation(data, substrate, box.axis, rotation);
    float rgba[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    viridis(box.relative, rgba);
    mjvGeom* geom = scene.geoms + scene.ngeom++;
    mjv_initGeom(geom, mjGEOM_BOX, size, position, rotation, rgba);
    geom->emission = 0.25f;
    geom->specular = 0.2f;
  }
}

// A floor under the machine, so that no view shows the empty background (the models have
// no skybox: in software GL each texture costs a shader compilation per process). Left out
// when the model has a plane of its own.
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

// The view's azimuth (deg) for a machine that reaches the part through a chain of bodies (an
// arm), `towards_root` the horizontal direction from the deposit to the chain's root and
// `tool_lean` the tool's (horizontal, from the nozzle up to the tool body): an elongated
// deposit region is seen broadside (the view across its long side, from the side that has the
// tool leaning away, else the machine behind it, turned kChainTurn_deg towards the machine), a
// squarish one from opposite the machine, turned kChainTurn_deg towards render_cam's view
// (`camera_azimuth`): a three-quarter view of the part with the arm reaching in from behind.
double machine_side_azimuth(const mjData& data, int substrate, const HeightMap& deposit,
                            const Vec3& towards_root, const Vec3& tool_lean,
                            double camera_azimuth) {
  const double root = rad_to_deg(std::atan2(towards_root.y(), towards_root.x()));
  // the azimuth `from` turned by at most `by` towards `to`
  auto turned = [](double from, double to, double by) {
    return from + std::clamp(std::remainder(to - from, 360.0), -by, by);
  };
  const double ex = deposit.nx * deposit.cell_mm, ey = deposit.ny * deposit.cell_mm;
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

// The free camera that frames the deposit region and the nozzle from render_cam's elevation.
// Its azimuth points from the deposit towards the nozzle when they are apart, so the print
// head stands behind the deposit rather than in front of it; otherwise render_cam's azimuth.
//
// A machine that carries the nozzle on a chain of bodies (an arm: tool, wrist, forearm, ...)
// is framed with its tool, and with the tool's ancestors as long as their origins stay within
// kChainFrameFactor times the deposit-and-nozzle radius of that region's centre. Why: an arm
// is ten times the size of its part. render_cam's own pose shows all of it, with the part and
// its deposit a few pixels wide; the deposit and the nozzle alone show a nozzle tip over a
// strip, the machine cut off. Framed with the tool (and on a larger part the wrist, which
// then stays within the factor), the deposit is the subject in the lower middle, the head
// stands over it, the arm reaches in from behind, and the picture says what machine it is.
// The azimuth then comes from machine_side_azimuth (the part broadside, the arm behind it),
// and on a part the view looks down at least kPartElevation_deg (see below). A nozzle fixed in
// the world (the delta, the XY stage) has no chain: their framing is as it was. On a part (a
// surface) the region also spans the deposit's heights and the nozzle's.
void frame_camera(const mjModel& model, const mjData& data, int camera, int substrate,
                  const HeightMap& deposit, const std::vector<DepositBox>& boxes, bool on_surface,
                  mjvCamera& view) {
  // region in the substrate frame: the grid's cells (and on a part the boxes' heights), then
  // the nozzle point
  Vec3 lo(deposit.origin_x_mm - 0.5 * deposit.cell_mm, deposit.origin_y_mm - 0.5 * deposit.cell_mm,
          0.0);
  Vec3 hi(lo.x() + deposit.nx * deposit.cell_mm, lo.y() + deposit.ny * deposit.cell_mm, 0.0);
  if (on_surface)
    for (const DepositBox& box : boxes) {
      const Vec3 top = box.base_mm + (box.lift_mm + 2.0 * box.half_height_mm) * box.axis;
      lo.z() = std::min({lo.z(), box.base_mm.z(), top.z()});
      hi.z() = std::max({hi.z(), box.base_mm.z(), top.z()});
    }
  const Vec3 deposit_centre = substrate_to_world(data, substrate, 0.5 * (lo + hi));
  const double deposit_radius_mm = 0.5 * (hi - lo).norm();
  Vec3 towards_nozzle = Vec3::Zero(), chain_towards = Vec3::Zero(), tool_lean = Vec3::Zero();
  bool chain_framed = false;
  const int nozzle = mj_name2id(&model, mjOBJ_SITE, "nozzle");
  if (nozzle >= 0) {
    const Vec3 nozzle_world(data.site_xpos[3 * nozzle], data.site_xpos[3 * nozzle + 1],
                            data.site_xpos[3 * nozzle + 2]);
    Vec3 local = world_to_substrate(data, substrate, nozzle_world);
    if (!on_surface) local.z() = 0.0;
    lo = lo.cwiseMin(local);
    hi = hi.cwiseMax(local);
    towards_nozzle = nozzle_world - deposit_centre;
    towards_nozzle.z() = 0.0;

    // the chain that carries the nozzle: the nozzle's own body (the tool) and its ancestors
    // as far as they stay near are framed; the direction towards the chain's root (an arm's
    // base) sets the azimuth
    const Vec3 base_centre = 0.5 * (lo + hi);
    const double base_radius_mm = std::max(kMinFrameRadius_mm, 0.5 * (hi - lo).norm());
    bool near = true;
    for (int body = model.site_bodyid[nozzle]; body > 0; body = model.body_parentid[body]) {
      const Vec3 world(data.xpos[3 * body], data.xpos[3 * body + 1], data.xpos[3 * body + 2]);
      const Vec3 point = world_to_substrate(data, substrate, world);
      near = near &&
             (!chain_framed || (point - base_centre).norm() <= kChainFrameFactor * base_radius_mm);
      if (!near) break;
      lo = lo.cwiseMin(point);
      hi = hi.cwiseMax(point);
      chain_framed = true;
    }
    // the direction from the deposit to the chain's root (an arm's base), the tool's lean
    for (int body = model.site_bodyid[nozzle]; body > 0; body = model.body_parentid[body])
      chain_towards = Vec3(data.xpos[3 * body] - deposit_centre.x(),
                           data.xpos[3 * body + 1] - deposit_centre.y(), 0.0);
    const int tool = model.site_bodyid[nozzle];
    tool_lean = Vec3(data.xpos[3 * tool] - nozzle_world.x(),
                     data.xpos[3 * tool + 1] - nozzle_world.y(), 0.0);
  }
  const double radius_mm = std::max(kMinFrameRadius_mm, 0.5 * (hi - lo).norm()) * kFrameMargin;
  const Vec3 centre = substrate_to_world(data, substrate, 0.5 * (lo + hi));

  // render_cam looks along its -z axis
  const mjtNum* axes = data.cam_xmat + 9 * camera;
  const Vec3 forward(-axes[2], -axes[5], -axes[8]);
  view.type = mjCAMERA_FREE;
  for (int i = 0; i < 3; ++i) view.lookat[i] = centre[i];
  const double camera_azimuth = rad_to_deg(std::atan2(forward.y(), forward.x()));
  view.azimuth = camera_azimuth;
  view.elevation = rad_to_deg(std::asin(std::clamp(forward.z(), -1.0, 1.0)));
  if (chain_framed && m_to_mm(chain_towards.norm()) > kNozzleApartFraction * deposit_radius_mm) {
    view.azimuth =
        machine_side_azimuth(data, substrate, deposit, chain_towards, tool_lean, camera_azimuth);
  } else if (m_to_mm(towards_nozzle.norm()) > kNozzleApartFraction * deposit_radius_mm) {
    view.azimuth = rad_to_deg(std::atan2(towards_nozzle.y(), towards_nozzle.x()));
  }
  // on a part, from at least this high: the deposit lies on top of it, and a low view would
  // look past the floor into the empty background
  if (on_surface) view.elevation = std::min(view.elevation, -kPartElevation_deg);
  const double half_fovy_rad = deg_to_rad(0.5 * model.vis.global.fovy);
  view.distance = mm_to_m(radius_mm) / std::tan(half_fovy_rad);
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

}  // namespace

void viridis(double value, float rgb[3]) {
  // matplotlib's viridis at 0, 1/8, ..., 1 (8-bit), linearly interpolated
  static const unsigned char kStops[9][3] = {{68, 1, 84},    {71, 44, 122},  {59, 81, 139},
                                             {44, 113, 142}, {33, 144, 141}, {39, 173, 129},
                                             {92, 200, 99},  {170, 220, 50}, {253, 231, 37}};
  const double position = std::clamp(value, 0.0, 1.0) * 8.0;
  const int index = std::min(7, static_cast<int>(position));
  const double fraction = position - index;
  for (int c = 0; c < 3; ++c)
    rgb[c] = static_cast<float>(
        ((1.0 - fraction) * kStops[index][c] + fraction * kStops[index + 1][c]) / 255.0);
}

std::vector<DepositBox> deposit_boxes(const HeightMap& deposit, double relief_mm,
                                      const SceneRenderOptions& options) {
  std::vector<DepositBox> boxes;
  if (deposit.nx <= 0 || deposit.ny <= 0 || !(deposit.max_value() > 0.0f)) return boxes;
  int block = 1;
  while ((static_cast<long>(deposit.nx + block - 1) / block) * ((deposit.ny + block - 1) / block) >
         options.max_boxes)
    ++block;

  // block means, normalised by the largest block mean (the colour scale's top)
  const int blocks_x = (deposit.nx + block - 1) / block,
            blocks_y = (deposit.ny + block - 1) / block;
  std::vector<float> block_mean(static_cast<size_t>(blocks_x) * blocks_y, 0.0f);
  float block_peak = 0.0f;
  for (int by = 0; by < blocks_y; ++by)
    for (int bx = 0; bx < blocks_x; ++bx) {
      double sum = 0.0;
      int count = 0;
      for (int iy = by * block; iy < std::min((by + 1) * block, deposit.ny); ++iy)
        for (int ix = bx * block; ix < std::min((bx + 1) * block, deposit.nx); ++ix) {
          sum += deposit.at(ix, iy);
          ++count;
        }
      const float mean = static_cast<float>(sum / count);
      block_mean[static_cast<size_t>(by) * blocks_x + bx] = mean;
      block_peak = std::max(block_peak, mean);
    }
  if (!(block_peak > 0.0f)) return boxes;

  const bool on_surface = static_cast<bool>(options.surface_height_mm);
  const double lift_mm =
      on_surface ? std::max(kLift_mm, kSurfaceLiftFraction * relief_mm) : kLift_mm;
  const double half_width_mm = 0.5 * block * deposit.cell_mm;
  for (int by = 0; by < blocks_y; ++by) {
    for (int bx = 0; bx < blocks_x; ++bx) {
      const double relative = block_mean[static_cast<size_t>(by) * blocks_x + bx] / block_peak;
      if (relative < options.min_relative_thickness) continue;
      // centre of the block's covered area, height proportional to the thickness
      DepositBox box;
      const double x_mm = deposit.origin_x_mm + (bx * block + 0.5 * (block - 1)) * deposit.cell_mm;
      const double y_mm = deposit.origin_y_mm + (by * block + 0.5 * (block - 1)) * deposit.cell_mm;
      box.base_mm = Vec3(x_mm, y_mm, 0.0);
      if (on_surface) {
        if (const std::optional<double> z_mm = options.surface_height_mm(x_mm, y_mm)) {
          box.base_mm.z() = *z_mm;
          if (options.tilt_to_surface)
            box.axis = surface_normal(options, x_mm, y_mm, *z_mm, half_width_mm);
        }
      }
      box.half_width_mm = half_width_mm;
      box.half_height_mm = 0.5 * relative * relief_mm;
      box.lift_mm = lift_mm;
      box.relative = relative;
      boxes.push_back(box);
    }
  }
  return boxes;
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
        render(model, sized.width, sized.height, sized.shadow_size),
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
  const mjModel& model = SimulationAccess::model(simulation);
  const mjData& data = SimulationAccess::data(simulation);
  install_mujoco_handlers();
  // the image must fit the model's offscreen buffer
  if (options.width <= 0 || options.width > model.vis.global.offwidth)
    throw InputError("outputs.image_width", "must be between 1 and " +
                                                std::to_string(model.vis.global.offwidth) +
                                                " (the model's <visual><global offwidth>), got " +
                                                std::to_string(options.width));
  if (options.height <= 0 || options.height > model.vis.global.offheight)
    throw InputError("outputs.image_height", "must be between 1 and " +
                                                 std::to_string(model.vis.global.offheight) +
                                                 " (the model's <visual><global offheight>), got " +
                                                 std::to_string(options.height));
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

  // set up: GL context, MuJoCo render context on the offscreen buffer, scene
  const std::lock_guard<std::mutex> lock(mutex_);
  DataPtr state = copy_data(model, data);
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
  SceneOwner scene(model, 4 * model.ngeom + options.max_boxes + 64);

  // camera: render_cam itself, or its direction aimed at the deposit
  mjvCamera view;
  mjv_defaultCamera(&view);
  view.type = mjCAMERA_FIXED;
  view.fixedcamid = camera;
  std::vector<DepositBox> boxes;
  const bool has_grid = deposit.nx > 0 && deposit.ny > 0;
  if (has_grid) {
    const double region_mm = std::max(deposit.nx, deposit.ny) * deposit.cell_mm;
    boxes = deposit_boxes(deposit, options.relief_fraction * region_mm, options);
    if (options.frame_deposit)
      frame_camera(model, *state, camera, substrate, deposit, boxes,
                   static_cast<bool>(options.surface_height_mm), view);
  }

  // update the scene, append the deposit, render, read back
  mjvOption visual_options;
  mjv_defaultOption(&visual_options);
  mjvPerturb perturb;
  mjv_defaultPerturb(&perturb);
  mjv_updateScene(&model, state.get(), &visual_options, &perturb, &view, mjCAT_ALL, &scene.scene);
  if (view.type == mjCAMERA_FREE) light_over_camera(view, scene.scene);
  scene.scene.flags[mjRND_SHADOW] = options.shadows ? 1 : 0;
  add_backdrop(model, *state, scene.scene);
  add_deposit_boxes(*state, substrate, boxes, scene.scene);
  const int factor = options.supersampling;
  const mjrRect viewport = {0, 0, width * factor, height * factor};
  mjr_render(viewport, &scene.scene, &context);
  // read back into a buffer kept with the contexts: a fresh one of this size is several
  // MB of memory to fault in and clear per image
  std::vector<unsigned char>& bottom_up = contexts_->readback;
  bottom_up.resize(static_cast<size_t>(viewport.width) * viewport.height * 3);
  mjr_readPixels(bottom_up.data(), nullptr, viewport, &context);
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
