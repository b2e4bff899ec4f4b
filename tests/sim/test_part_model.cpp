// The part added to a machine's MJCF (sim/part_model): the mesh compiles in the substrate
// body exactly where the work frame puts it, visual only; an open surface is closed into a
// thin shell (MuJoCo refuses a mesh without volume); a model without a substrate is refused.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "sim/mujoco_boundary.hpp"
#include "sim/part_model.hpp"

namespace depotwin {
namespace {

// a 10 x 8 mm patch of z = 0.02 (x^2 + y^2) mm: open, curved, n x n vertices
TriangleMesh curved_patch(int n) {
  TriangleMesh mesh;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double x = -5.0 + 10.0 * i / (n - 1), y = -4.0 + 8.0 * j / (n - 1);
      mesh.vertices.emplace_back(x, y, 0.02 * (x * x + y * y));
    }
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const int a = j * n + i, b = a + 1, c = a + n, d = c + 1;
      mesh.triangles.push_back({a, b, d});
      mesh.triangles.push_back({a, d, c});
    }
  return mesh;
}

// a closed tetrahedron, outward winding
TriangleMesh tetrahedron() {
  TriangleMesh mesh;
  mesh.vertices = {Vec3(0, 0, 0), Vec3(10, 0, 0), Vec3(0, 10, 0), Vec3(0, 0, 10)};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return mesh;
}

const char* kModel = R"(<mujoco model="probe">
  <worldbody>
    <body name="substrate" pos="0.4 0.1 0.05" euler="0 0 30">
      <geom type="box" size="0.05 0.05 0.005" pos="0 0 -0.005"/>
    </body>
  </worldbody>
</mujoco>)";

// the compiled part's vertices in the substrate frame (mm), bounds only
void compiled_bounds(const mjModel& m, Vec3& lo, Vec3& hi) {
  mjData* d = mj_makeData(&m);
  mj_forward(&m, d);
  const int geom = mj_name2id(&m, mjOBJ_GEOM, kPartGeomName);
  const int body = mj_name2id(&m, mjOBJ_BODY, "substrate");
  const int mesh = m.geom_dataid[geom];
  lo = Vec3::Constant(1e300);
  hi = Vec3::Constant(-1e300);
  for (int v = 0; v < m.mesh_vertnum[mesh]; ++v) {
    const float* local = m.mesh_vert + 3 * (m.mesh_vertadr[mesh] + v);
    Vec3 world;
    for (int r = 0; r < 3; ++r) {
      world[r] = d->geom_xpos[3 * geom + r];
      for (int c = 0; c < 3; ++c) world[r] += d->geom_xmat[9 * geom + 3 * r + c] * local[c];
    }
    // back into the substrate frame
    Vec3 in_body = Vec3::Zero();
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r)
        in_body[c] += d->xmat[9 * body + 3 * r + c] * (world[r] - d->xpos[3 * body + r]);
    lo = lo.cwiseMin(in_body * 1000.0);
    hi = hi.cwiseMax(in_body * 1000.0);
  }
  mj_deleteData(d);
}

TEST(PartModel, OpenSurfaceCompilesAsAShellWhereTheWorkFramePutsIt) {
  const TriangleMesh patch = curved_patch(9);
  EXPECT_FALSE(mesh_is_closed(patch));
  const std::string text = mjcf_with_part(kModel, "probe.xml", patch, 1.0);
  const ModelPtr model = load_model_from_string(text, "probe.xml");
  const int geom = mj_name2id(model.get(), mjOBJ_GEOM, kPartGeomName);
  ASSERT_GE(geom, 0);
  EXPECT_EQ(model->geom_contype[geom], 0);
  EXPECT_EQ(model->geom_conaffinity[geom], 0);
  // the surface and its copy 1 mm below
  EXPECT_EQ(model->mesh_vertnum[model->geom_dataid[geom]], 2 * 81);
  Vec3 lo, hi;
  compiled_bounds(*model, lo, hi);
  // x, y span the patch; z from 1 mm below its lowest point (0) to its highest (0.02 * 41)
  // (mesh vertices are stored as floats: micrometre agreement)
  EXPECT_NEAR(lo.x(), -5.0, 1e-3);
  EXPECT_NEAR(hi.x(), 5.0, 1e-3);
  EXPECT_NEAR(lo.y(), -4.0, 1e-3);
  EXPECT_NEAR(hi.y(), 4.0, 1e-3);
  EXPECT_NEAR(lo.z(), -1.0, 1e-3);
  EXPECT_NEAR(hi.z(), 0.02 * 41.0, 1e-3);
}

TEST(PartModel, ClosedMeshIsAddedAsItIs) {
  const TriangleMesh solid = tetrahedron();
  EXPECT_TRUE(mesh_is_closed(solid));
  const ModelPtr model =
      load_model_from_string(mjcf_with_part(kModel, "probe.xml", solid), "probe.xml");
  const int geom = mj_name2id(model.get(), mjOBJ_GEOM, kPartGeomName);
  ASSERT_GE(geom, 0);
  EXPECT_EQ(model->mesh_vertnum[model->geom_dataid[geom]], 4);
  Vec3 lo, hi;
  compiled_bounds(*model, lo, hi);
  EXPECT_LT((lo - Vec3::Zero()).norm(), 1e-3);
  EXPECT_LT((hi - Vec3(10, 10, 10)).norm(), 1e-3);
}

// MuJoCo 2.2.2 refuses a mesh whose triangles run along an edge in the same direction: two
// patches touching at a corner (their shell's walls both leave that vertex downwards) and a
// closed mesh with a triangle turned over; both are added with every triangle on its own
// vertices, and compile where the work frame puts them
TEST(PartModel, PatchesTouchingAtACornerAndATurnedTriangleStillCompile) {
  TriangleMesh touching;
  touching.vertices = {Vec3(0, 0, 0),  Vec3(5, 0, 0),   Vec3(5, 5, 0), Vec3(0, 5, 0),
                       Vec3(10, 5, 0), Vec3(10, 10, 0), Vec3(5, 10, 0)};
  touching.triangles = {{0, 1, 2}, {0, 2, 3}, {2, 4, 5}, {2, 5, 6}};
  EXPECT_FALSE(mesh_is_closed(touching));
  TriangleMesh turned = tetrahedron();
  turned.triangles[3] = {1, 3, 2};
  EXPECT_TRUE(mesh_is_closed(turned));
  for (const TriangleMesh* part : {&touching, &turned}) {
    const ModelPtr model =
        load_model_from_string(mjcf_with_part(kModel, "probe.xml", *part), "probe.xml");
    const int geom = mj_name2id(model.get(), mjOBJ_GEOM, kPartGeomName);
    ASSERT_GE(geom, 0);
    Vec3 lo, hi;
    compiled_bounds(*model, lo, hi);
    const Vec3 expected_hi = part == &touching ? Vec3(10, 10, 0) : Vec3(10, 10, 10);
    const Vec3 expected_lo = part == &touching ? Vec3(0, 0, -1) : Vec3(0, 0, 0);
    EXPECT_LT((lo - expected_lo).norm(), 1e-3);
    EXPECT_LT((hi - expected_hi).norm(), 1e-3);
  }
}

// the body named substrate, not a material or a commented-out body of that name
TEST(PartModel, TheSubstrateBodyNotAnythingElseOfThatName) {
  const std::string mjcf = R"(<mujoco>
  <asset><material name="substrate" rgba="1 1 1 1"/></asset>
  <!-- <body name="substrate"> was here -->
  <worldbody>
    <geom name='substrate' type="plane" size="1 1 0.1"/>
    <body name="substrate" pos="0.1 0 0"><geom type="sphere" size="0.01"/></body>
  </worldbody>
</mujoco>)";
  const ModelPtr model =
      load_model_from_string(mjcf_with_part(mjcf, "probe.xml", tetrahedron()), "probe.xml");
  const int geom = mj_name2id(model.get(), mjOBJ_GEOM, kPartGeomName);
  ASSERT_GE(geom, 0);
  EXPECT_EQ(model->geom_bodyid[geom], mj_name2id(model.get(), mjOBJ_BODY, "substrate"));
}

TEST(PartModel, SelfClosingSubstrateAndErrors) {
  const std::string self_closing =
      "<mujoco><worldbody><body name='substrate' pos='0 0 0'/></worldbody></mujoco>";
  const ModelPtr model =
      load_model_from_string(mjcf_with_part(self_closing, "probe.xml", tetrahedron()), "probe.xml");
  EXPECT_GE(mj_name2id(model.get(), mjOBJ_GEOM, kPartGeomName), 0);
  EXPECT_THROW(mjcf_with_part("<mujoco><worldbody/></mujoco>", "probe.xml", tetrahedron()),
               InputError);
  EXPECT_THROW(mjcf_with_part("<robot/>", "probe.xml", tetrahedron()), InputError);
}

}  // namespace
}  // namespace depotwin
