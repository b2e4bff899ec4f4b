// A machine's MJCF with the job's part added (conformal work): the part's mesh, placed in the
// work frame, becomes a visual geom of the `substrate` body, so the scene shows it and it
// moves with the substrate. MuJoCo 2.2.2 has no model-editing API (no mjSpec): the MJCF text
// is edited and compiled from memory (an mjVFS under the model file's own name, so its
// relative asset paths still resolve against its directory).
//
// The geom is visual only (contype = conaffinity = 0): MuJoCo collides meshes by their convex
// hull, wrong for a concave part; the arm's clearance to the part is an exact distance query
// (collision/part_clearance.hpp).
#pragma once

#include <string>

#include "core/triangle_mesh.hpp"

namespace depotwin {

// The name of the part's mesh asset and geom in the edited model.
constexpr const char* kPartGeomName = "depotwin_part";

// `mjcf` (the text of the model at `model_path`, for messages) with the part added: a
// <mesh> asset with the vertices in metres and a geom in the `substrate` body. An open
// surface (edges with one triangle) is closed into a thin shell `shell_mm` thick below it
// (MuJoCo refuses a mesh without volume). A mesh whose triangles run along an edge in the same
// direction (MuJoCo refuses it too: a corner where two patches touch, a triangle turned over)
// is added with every triangle on vertices of its own. InputError naming the model file when it has
// no <mujoco> root or no body named `substrate`.
std::string mjcf_with_part(const std::string& mjcf, const std::string& model_path,
                           const TriangleMesh& part_mm, double shell_mm = 1.0);

// true when every edge of the mesh is shared by exactly two triangles
bool mesh_is_closed(const TriangleMesh& mesh);

}  // namespace depotwin
