#include "render/deposit_mesh.hpp"

#include <GL/gl.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"

namespace depotwin {

namespace {

// the key light over the deposit: from above the substrate, tilted this far (deg) towards the
// camera, so that a flat deposit shows nearly its colour bar's colours and slopes shade
constexpr double kLightTilt_deg = 30.0;
constexpr float kLightAmbient = 0.7f;
constexpr float kLightDiffuse = 0.3f;
// a grid square whose surface heights differ by more than this many grid steps is a cliff (a
// part's wall, steeper than atan(10 / sqrt(2)) = 82 deg across its diagonal): not meshed
constexpr double kCliffRise = 10.0;

// the resampled grid: block maxima over stride x stride cells
struct BlockGrid {
  int stride = 1;
  int nx = 0, ny = 0;
  std::vector<float> value;  // row-major, nx * ny
  float at(int bx, int by) const { return value[static_cast<size_t>(by) * nx + bx]; }
};

BlockGrid block_maxima(const HeightMap& map, int stride) {
  BlockGrid grid;
  grid.stride = stride;
  grid.nx = (map.nx + stride - 1) / stride;
  grid.ny = (map.ny + stride - 1) / stride;
  grid.value.assign(static_cast<size_t>(grid.nx) * grid.ny, 0.0f);
  for (int iy = 0; iy < map.ny; ++iy) {
    float* row = grid.value.data() + static_cast<size_t>(iy / stride) * grid.nx;
    const float* source = map.thickness_um.data() + static_cast<size_t>(iy) * map.nx;
    for (int ix = 0; ix < map.nx; ++ix) row[ix / stride] = std::max(row[ix / stride], source[ix]);
  }
  return grid;
}

// which blocks carry a vertex: those reaching the threshold and their 8 neighbours
std::vector<char> active_blocks(const BlockGrid& grid, float threshold, long& count) {
  std::vector<char> active(grid.value.size(), 0);
  count = 0;
  for (int by = 0; by < grid.ny; ++by)
    for (int bx = 0; bx < grid.nx; ++bx) {
      if (grid.at(bx, by) < threshold) continue;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = bx + dx, y = by + dy;
          if (x < 0 || y < 0 || x >= grid.nx || y >= grid.ny) continue;
          char& flag = active[static_cast<size_t>(y) * grid.nx + x];
          count += flag == 0;
          flag = 1;
        }
    }
  return active;
}

// the derivative along one grid direction from the values of the neighbours before and after
// (central difference, one-sided at an edge, 0 without neighbours); `step` apart
template <typename Value>
Value grid_difference(const Value* before, const Value& here, const Value* after, double step,
                      const Value& none) {
  if (before && after) return (*after - *before) / (2.0 * step);
  if (after) return (*after - here) / step;
  if (before) return (here - *before) / step;
  return none;
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

DepositMesh build_deposit_mesh(const HeightMap& map, const DepositMeshOptions& options) {
  DepositMesh mesh;
  mesh.relief_mm = options.relief_mm;
  if (map.nx <= 0 || map.ny <= 0 ||
      map.thickness_um.size() != static_cast<size_t>(map.nx) * map.ny || !(map.cell_mm > 0.0))
    return mesh;
  const double top_um = options.colour_top_um > 0.0 ? options.colour_top_um : map.max_value();
  mesh.colour_top_um = top_um;
  if (!(top_um > 0.0)) return mesh;
  const float threshold = static_cast<float>(options.min_relative_thickness * top_um);

  // the smallest block stride whose active vertices fit the budget: a first guess from the
  // full grid's count (area scales with the stride squared), then larger until it fits
  const long budget = std::max(4, options.max_vertices);
  BlockGrid grid = block_maxima(map, 1);
  long count = 0;
  std::vector<char> active = active_blocks(grid, threshold, count);
  while (count > budget) {
    const int guess = static_cast<int>(std::ceil(
        grid.stride * std::sqrt(static_cast<double>(count) / static_cast<double>(budget))));
    grid = block_maxima(map, std::max(grid.stride + 1, guess));
    active = active_blocks(grid, threshold, count);
  }
  mesh.stride = grid.stride;
  if (count == 0) return mesh;

  // vertex indices, block centres (the middle of the cells a full block covers) and the surface
  const double step_mm = grid.stride * map.cell_mm;
  const double centre_offset = 0.5 * (grid.stride - 1) * map.cell_mm;
  std::vector<int> index(active.size(), -1);
  std::vector<Vec3> base;     // on the surface (or z = 0)
  std::vector<char> on_part;  // the surface function had a height there
  std::vector<int> block_of;  // the vertex's block (row-major)
  base.reserve(static_cast<size_t>(count));
  for (int by = 0; by < grid.ny; ++by)
    for (int bx = 0; bx < grid.nx; ++bx) {
      const size_t b = static_cast<size_t>(by) * grid.nx + bx;
      if (!active[b]) continue;
      index[b] = static_cast<int>(base.size());
      const double x_mm = map.origin_x_mm + bx * step_mm + centre_offset;
      const double y_mm = map.origin_y_mm + by * step_mm + centre_offset;
      std::optional<double> z_mm;
      if (options.surface_height_mm) z_mm = options.surface_height_mm(x_mm, y_mm);
      base.emplace_back(x_mm, y_mm, z_mm.value_or(0.0));
      on_part.push_back(z_mm.has_value());
      block_of.push_back(static_cast<int>(b));
    }
  const size_t vertices = base.size();
  // the vertex of the neighbouring block (dx, dy), or -1
  auto neighbour = [&](size_t v, int dx, int dy) {
    const int b = block_of[v];
    const int x = b % grid.nx + dx, y = b / grid.nx + dy;
    if (x < 0 || y < 0 || x >= grid.nx || y >= grid.ny) return -1;
    return index[static_cast<size_t>(y) * grid.nx + x];
  };

  // each vertex lifted off its surface along the surface's normal (on the part: its heights at
  // the neighbouring vertices on the part, central differences; elsewhere +z)
  std::vector<Vec3> position(vertices);
  mesh.thickness_um.resize(vertices);
  mesh.colours.resize(3 * vertices);
  for (size_t v = 0; v < vertices; ++v) {
    Vec3 axis = Vec3::UnitZ();
    if (on_part[v] && options.along_normal) {
      auto height = [&](int dx, int dy) -> const double* {
        const int n = neighbour(v, dx, dy);
        return n >= 0 && on_part[static_cast<size_t>(n)] ? &base[static_cast<size_t>(n)].z()
                                                         : nullptr;
      };
      const double slope_x =
          grid_difference(height(-1, 0), base[v].z(), height(1, 0), step_mm, 0.0);
      const double slope_y =
          grid_difference(height(0, -1), base[v].z(), height(0, 1), step_mm, 0.0);
      axis = Vec3(-slope_x, -slope_y, 1.0).normalized();
    }
    const float thickness = grid.value[static_cast<size_t>(block_of[v])];
    const double relative = std::min(1.0, thickness / top_um);
    position[v] = base[v] + (options.lift_mm + options.relief_mm * relative) * axis;
    mesh.thickness_um[v] = thickness;
    viridis(relative, &mesh.colours[3 * v]);
  }

  // shading normals of the drawn surface: the cross product of its tangents along x and y
  mesh.positions_mm.resize(3 * vertices);
  mesh.normals.resize(3 * vertices);
  mesh.lo_mm = position.front();
  mesh.hi_mm = position.front();
  for (size_t v = 0; v < vertices; ++v) {
    auto point = [&](int dx, int dy) -> const Vec3* {
      const int n = neighbour(v, dx, dy);
      return n >= 0 ? &position[static_cast<size_t>(n)] : nullptr;
    };
    const Vec3 along_x =
        grid_difference(point(-1, 0), position[v], point(1, 0), step_mm, Vec3(Vec3::UnitX()));
    const Vec3 along_y =
        grid_difference(point(0, -1), position[v], point(0, 1), step_mm, Vec3(Vec3::UnitY()));
    Vec3 normal = along_x.cross(along_y);
    normal = normal.norm() > 0.0 ? normal.normalized() : Vec3(Vec3::UnitZ());
    for (int c = 0; c < 3; ++c) {
      mesh.positions_mm[3 * v + c] = static_cast<float>(position[v][c]);
      mesh.normals[3 * v + c] = static_cast<float>(normal[c]);
    }
    mesh.lo_mm = mesh.lo_mm.cwiseMin(position[v]);
    mesh.hi_mm = mesh.hi_mm.cwiseMax(position[v]);
  }

  // two triangles per grid square whose corners all exist and one reaches the threshold,
  // split along the diagonal whose ends differ less (a ridge stays connected). Not across a
  // cliff: a square whose surface heights differ by more than kCliffRise steps (a part's
  // wall down to the table) would hang a curtain of deposit down it
  const double cliff_mm = kCliffRise * step_mm;
  for (int by = 0; by + 1 < grid.ny; ++by)
    for (int bx = 0; bx + 1 < grid.nx; ++bx) {
      const size_t b00 = static_cast<size_t>(by) * grid.nx + bx, b10 = b00 + 1, b01 = b00 + grid.nx,
                   b11 = b01 + 1;
      if (index[b00] < 0 || index[b10] < 0 || index[b01] < 0 || index[b11] < 0) continue;
      const float t00 = grid.value[b00], t10 = grid.value[b10], t01 = grid.value[b01],
                  t11 = grid.value[b11];
      if (std::max({t00, t10, t01, t11}) < threshold) continue;
      const unsigned v00 = index[b00], v10 = index[b10], v01 = index[b01], v11 = index[b11];
      const auto [low, high] =
          std::minmax({base[v00].z(), base[v10].z(), base[v01].z(), base[v11].z()});
      if (high - low > cliff_mm) continue;
      if (std::abs(t00 - t11) <= std::abs(t10 - t01))
        mesh.triangles.insert(mesh.triangles.end(), {v00, v10, v11, v00, v11, v01});
      else
        mesh.triangles.insert(mesh.triangles.end(), {v00, v10, v01, v10, v11, v01});
    }
  return mesh;
}

namespace {

// the legacy GL entry points the mesh is drawn with, resolved by name
struct GlFunctions {
  void (*PushAttrib)(GLbitfield);
  void (*PopAttrib)();
  void (*PushClientAttrib)(GLbitfield);
  void (*PopClientAttrib)();
  void (*MatrixMode)(GLenum);
  void (*PushMatrix)();
  void (*PopMatrix)();
  void (*LoadIdentity)();
  void (*LoadMatrixd)(const GLdouble*);
  void (*MultMatrixd)(const GLdouble*);
  void (*Scaled)(GLdouble, GLdouble, GLdouble);
  void (*Frustum)(GLdouble, GLdouble, GLdouble, GLdouble, GLdouble, GLdouble);
  void (*Viewport)(GLint, GLint, GLsizei, GLsizei);
  void (*GetIntegerv)(GLenum, GLint*);
  void (*Enable)(GLenum);
  void (*Disable)(GLenum);
  void (*Lightfv)(GLenum, GLenum, const GLfloat*);
  void (*LightModelfv)(GLenum, const GLfloat*);
  void (*LightModeli)(GLenum, GLint);
  void (*ColorMaterial)(GLenum, GLenum);
  void (*Materialfv)(GLenum, GLenum, const GLfloat*);
  void (*ShadeModel)(GLenum);
  void (*PolygonOffset)(GLfloat, GLfloat);
  void (*PolygonMode)(GLenum, GLenum);
  void (*DepthMask)(GLboolean);
  void (*EnableClientState)(GLenum);
  void (*DisableClientState)(GLenum);
  void (*VertexPointer)(GLint, GLenum, GLsizei, const void*);
  void (*NormalPointer)(GLenum, GLsizei, const void*);
  void (*ColorPointer)(GLint, GLenum, GLsizei, const void*);
  void (*DrawElements)(GLenum, GLsizei, GLenum, const void*);
  void (*BindBuffer)(GLenum, GLuint);
  void (*Ortho)(GLdouble, GLdouble, GLdouble, GLdouble, GLdouble, GLdouble);
  void (*Begin)(GLenum);
  void (*End)();
  void (*Color3fv)(const GLfloat*);
  void (*Vertex2d)(GLdouble, GLdouble);

  explicit GlFunctions(GlProcAddress resolve) {
    load(resolve, PushAttrib, "glPushAttrib");
    load(resolve, PopAttrib, "glPopAttrib");
    load(resolve, PushClientAttrib, "glPushClientAttrib");
    load(resolve, PopClientAttrib, "glPopClientAttrib");
    load(resolve, MatrixMode, "glMatrixMode");
    load(resolve, PushMatrix, "glPushMatrix");
    load(resolve, PopMatrix, "glPopMatrix");
    load(resolve, LoadIdentity, "glLoadIdentity");
    load(resolve, LoadMatrixd, "glLoadMatrixd");
    load(resolve, MultMatrixd, "glMultMatrixd");
    load(resolve, Scaled, "glScaled");
    load(resolve, Frustum, "glFrustum");
    load(resolve, Viewport, "glViewport");
    load(resolve, GetIntegerv, "glGetIntegerv");
    load(resolve, Enable, "glEnable");
    load(resolve, Disable, "glDisable");
    load(resolve, Lightfv, "glLightfv");
    load(resolve, LightModelfv, "glLightModelfv");
    load(resolve, LightModeli, "glLightModeli");
    load(resolve, ColorMaterial, "glColorMaterial");
    load(resolve, Materialfv, "glMaterialfv");
    load(resolve, ShadeModel, "glShadeModel");
    load(resolve, PolygonOffset, "glPolygonOffset");
    load(resolve, PolygonMode, "glPolygonMode");
    load(resolve, DepthMask, "glDepthMask");
    load(resolve, EnableClientState, "glEnableClientState");
    load(resolve, DisableClientState, "glDisableClientState");
    load(resolve, VertexPointer, "glVertexPointer");
    load(resolve, NormalPointer, "glNormalPointer");
    load(resolve, ColorPointer, "glColorPointer");
    load(resolve, DrawElements, "glDrawElements");
    load(resolve, BindBuffer, "glBindBuffer");
    load(resolve, Ortho, "glOrtho");
    load(resolve, Begin, "glBegin");
    load(resolve, End, "glEnd");
    load(resolve, Color3fv, "glColor3fv");
    load(resolve, Vertex2d, "glVertex2d");
  }

 private:
  template <typename Function>
  static void load(GlProcAddress resolve, Function& function, const char* name) {
    void* address = resolve ? resolve(name) : nullptr;
    if (!address)
      throw InternalError(std::string("render: the GL function ") + name + " is not available");
    function = reinterpret_cast<Function>(address);
  }
};

}  // namespace

void draw_deposit_mesh(const DepositMesh& mesh, const mjvScene& scene, const mjrRect& viewport,
                       const mjtNum substrate_pos[3], const mjtNum substrate_mat[9],
                       GlProcAddress gl_proc_address) {
  if (mesh.empty() || viewport.width <= 0 || viewport.height <= 0) return;
  const GlFunctions gl(gl_proc_address);
  const mjvGLCamera camera = mjv_averageCamera(scene.camera, scene.camera + 1);

  gl.PushAttrib(GL_ALL_ATTRIB_BITS);
  gl.PushClientAttrib(GL_CLIENT_ALL_ATTRIB_BITS);
  gl.Viewport(viewport.left, viewport.bottom, viewport.width, viewport.height);
  // MuJoCo's depth convention: the usual one (LEQUAL), or reversed (GEQUAL: the projection
  // maps far to -1), as mjr_render's own projection
  GLint depth_function = GL_LEQUAL;
  gl.GetIntegerv(GL_DEPTH_FUNC, &depth_function);
  const bool reversed = depth_function == GL_GEQUAL || depth_function == GL_GREATER;

  // projection: the scene camera's frustum, its width matched to the viewport (as mjr_render)
  gl.MatrixMode(GL_PROJECTION);
  gl.PushMatrix();
  gl.LoadIdentity();
  if (reversed) gl.Scaled(1.0, 1.0, -1.0);
  const double half_width =
      0.5 * viewport.width / viewport.height * (camera.frustum_top - camera.frustum_bottom);
  gl.Frustum(camera.frustum_center - half_width, camera.frustum_center + half_width,
             camera.frustum_bottom, camera.frustum_top, camera.frustum_near, camera.frustum_far);

  // modelview: the camera's look-at (side, up, -forward rows), then the substrate frame (mm)
  const Vec3 forward = Vec3(camera.forward[0], camera.forward[1], camera.forward[2]).normalized();
  const Vec3 side = forward.cross(Vec3(camera.up[0], camera.up[1], camera.up[2])).normalized();
  const Vec3 up = side.cross(forward);
  const Vec3 eye(camera.pos[0], camera.pos[1], camera.pos[2]);
  GLdouble view[16] = {0};  // column-major
  for (int c = 0; c < 3; ++c) {
    view[4 * c + 0] = side[c];
    view[4 * c + 1] = up[c];
    view[4 * c + 2] = -forward[c];
  }
  view[12] = -side.dot(eye);
  view[13] = -up.dot(eye);
  view[14] = forward.dot(eye);
  view[15] = 1.0;
  GLdouble placement[16] = {0};
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col)
      placement[4 * col + row] = 1e-3 * substrate_mat[3 * row + col];
    placement[12 + row] = substrate_pos[row];
  }
  placement[15] = 1.0;
  gl.MatrixMode(GL_MODELVIEW);
  gl.PushMatrix();
  gl.LoadMatrixd(view);

  // one light over the substrate, tilted towards the camera (set in world coordinates)
  const Vec3 substrate_up(substrate_mat[2], substrate_mat[5], substrate_mat[8]);
  Vec3 towards_camera = -forward - (-forward).dot(substrate_up) * substrate_up;
  towards_camera = towards_camera.norm() > 0.0 ? towards_camera.normalized() : Vec3::Zero();
  const double tilt = deg_to_rad(kLightTilt_deg);
  const Vec3 light = std::cos(tilt) * substrate_up + std::sin(tilt) * towards_camera;
  const GLfloat light_position[4] = {static_cast<float>(light.x()), static_cast<float>(light.y()),
                                     static_cast<float>(light.z()), 0.0f};
  const GLfloat ambient[4] = {kLightAmbient, kLightAmbient, kLightAmbient, 1.0f};
  const GLfloat diffuse[4] = {kLightDiffuse, kLightDiffuse, kLightDiffuse, 1.0f};
  const GLfloat none[4] = {0.0f, 0.0f, 0.0f, 1.0f};
  gl.Enable(GL_LIGHTING);
  for (GLenum i = 1; i < 8; ++i) gl.Disable(GL_LIGHT0 + i);
  gl.Enable(GL_LIGHT0);
  gl.Lightfv(GL_LIGHT0, GL_POSITION, light_position);
  gl.Lightfv(GL_LIGHT0, GL_AMBIENT, ambient);
  gl.Lightfv(GL_LIGHT0, GL_DIFFUSE, diffuse);
  gl.Lightfv(GL_LIGHT0, GL_SPECULAR, none);
  gl.LightModelfv(GL_LIGHT_MODEL_AMBIENT, none);
  gl.LightModeli(GL_LIGHT_MODEL_TWO_SIDE, 1);
  gl.Enable(GL_COLOR_MATERIAL);
  gl.ColorMaterial(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE);
  gl.Materialfv(GL_FRONT_AND_BACK, GL_SPECULAR, none);
  gl.Materialfv(GL_FRONT_AND_BACK, GL_EMISSION, none);
  gl.Enable(GL_NORMALIZE);  // the millimetre scale shrinks the normals
  gl.ShadeModel(GL_SMOOTH);
  gl.MultMatrixd(placement);

  // nothing else of MuJoCo's state: no textures, fog, blending, culling, clipping
  for (GLenum capability : {GL_TEXTURE_2D, GL_TEXTURE_CUBE_MAP, GL_TEXTURE_GEN_S, GL_TEXTURE_GEN_T,
                            GL_TEXTURE_GEN_R, GL_TEXTURE_GEN_Q, GL_FOG, GL_BLEND, GL_CULL_FACE,
                            GL_ALPHA_TEST, GL_STENCIL_TEST, GL_SCISSOR_TEST, GL_CLIP_PLANE0})
    gl.Disable(capability);
  gl.PolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  // depth-tested against the scene, pulled slightly towards the camera so that the thin edges
  // of the deposit never z-fight with the substrate under them
  gl.Enable(GL_DEPTH_TEST);
  gl.DepthMask(GL_TRUE);
  gl.Enable(GL_POLYGON_OFFSET_FILL);
  gl.PolygonOffset(reversed ? 1.0f : -1.0f, reversed ? 4.0f : -4.0f);

  // the triangles from client arrays
  gl.BindBuffer(GL_ARRAY_BUFFER, 0);
  gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, 0);
  gl.EnableClientState(GL_VERTEX_ARRAY);
  gl.EnableClientState(GL_NORMAL_ARRAY);
  gl.EnableClientState(GL_COLOR_ARRAY);
  gl.DisableClientState(GL_TEXTURE_COORD_ARRAY);
  gl.VertexPointer(3, GL_FLOAT, 0, mesh.positions_mm.data());
  gl.NormalPointer(GL_FLOAT, 0, mesh.normals.data());
  gl.ColorPointer(3, GL_FLOAT, 0, mesh.colours.data());
  gl.DrawElements(GL_TRIANGLES, static_cast<GLsizei>(mesh.triangles.size()), GL_UNSIGNED_INT,
                  mesh.triangles.data());

  // restore
  gl.PopMatrix();  // modelview
  gl.MatrixMode(GL_PROJECTION);
  gl.PopMatrix();
  gl.PopClientAttrib();
  gl.PopAttrib();
}

void draw_viridis_ramp(const mjrRect& rect, GlProcAddress gl_proc_address) {
  if (rect.width <= 0 || rect.height <= 0) return;
  const GlFunctions gl(gl_proc_address);
  gl.PushAttrib(GL_ALL_ATTRIB_BITS);
  gl.Viewport(rect.left, rect.bottom, rect.width, rect.height);
  gl.MatrixMode(GL_PROJECTION);
  gl.PushMatrix();
  gl.LoadIdentity();
  gl.Ortho(0.0, 1.0, 0.0, 1.0, -1.0, 1.0);
  gl.MatrixMode(GL_MODELVIEW);
  gl.PushMatrix();
  gl.LoadIdentity();
  for (GLenum capability : {GL_LIGHTING, GL_DEPTH_TEST, GL_BLEND, GL_TEXTURE_2D, GL_CULL_FACE,
                            GL_FOG, GL_SCISSOR_TEST, GL_STENCIL_TEST})
    gl.Disable(capability);
  gl.ShadeModel(GL_SMOOTH);
  gl.PolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  // viridis is linear between its 9 stops: smooth shading between them draws it exactly
  gl.Begin(GL_QUAD_STRIP);
  for (int stop = 0; stop <= 8; ++stop) {
    float rgb[3];
    viridis(stop / 8.0, rgb);
    gl.Color3fv(rgb);
    gl.Vertex2d(stop / 8.0, 0.0);
    gl.Vertex2d(stop / 8.0, 1.0);
  }
  gl.End();
  gl.PopMatrix();
  gl.MatrixMode(GL_PROJECTION);
  gl.PopMatrix();
  gl.PopAttrib();
}

void draw_deposit_mesh(const DepositMesh& mesh, const mjvScene& scene, const mjrRect& viewport,
                       const mjModel& model, const mjData& data, GlProcAddress gl_proc_address) {
  const int substrate = mj_name2id(&model, mjOBJ_BODY, "substrate");
  if (substrate < 0) throw InternalError("render: the model has no body 'substrate'");
  draw_deposit_mesh(mesh, scene, viewport, data.xpos + 3 * substrate, data.xmat + 9 * substrate,
                    gl_proc_address);
}

}  // namespace depotwin
