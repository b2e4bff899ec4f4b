#include "sim/part_model.hpp"

#include <cctype>
#include <cstdio>
#include <map>
#include <set>
#include <utility>

#include "core/error.hpp"

namespace depotwin {

namespace {

// the mesh as MuJoCo reads it: vertices in metres, faces as vertex indices
std::string mesh_asset(const TriangleMesh& mesh) {
  std::string vertices, faces;
  vertices.reserve(mesh.vertices.size() * 3 * 14);
  faces.reserve(mesh.triangles.size() * 3 * 7);
  char number[32];
  for (const Vec3& v : mesh.vertices) {
    for (int axis = 0; axis < 3; ++axis) {
      std::snprintf(number, sizeof number, "%.10g ", mm_to_m(v[axis]));
      vertices += number;
    }
  }
  for (const std::array<int, 3>& t : mesh.triangles) {
    std::snprintf(number, sizeof number, "%d %d %d ", t[0], t[1], t[2]);
    faces += number;
  }
  return std::string("<asset><mesh name=\"") + kPartGeomName + "\" vertex=\"" + vertices +
         "\" face=\"" + faces + "\"/></asset>";
}

// An open surface closed into a shell: the surface, a copy `thickness` below with the winding
// reversed, and a wall along every boundary edge.
TriangleMesh closed_shell(const TriangleMesh& surface, double thickness_mm) {
  TriangleMesh shell = surface;
  const int count = static_cast<int>(surface.vertices.size());
  for (const Vec3& v : surface.vertices) shell.vertices.push_back(v - Vec3(0, 0, thickness_mm));
  for (const std::array<int, 3>& t : surface.triangles)
    shell.triangles.push_back({t[0] + count, t[2] + count, t[1] + count});
  // boundary edges: used once; the wall keeps the outward winding of the edge's triangle
  std::map<std::pair<int, int>, int> uses;
  for (const std::array<int, 3>& t : surface.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  for (const std::array<int, 3>& t : surface.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      if (uses[{std::min(a, b), std::max(a, b)}] != 1) continue;
      shell.triangles.push_back({b, a, a + count});
      shell.triangles.push_back({b, a + count, b + count});
    }
  return shell;
}

// true when two triangles run along an edge in the same direction: MuJoCo 2.2.2 refuses such a
// mesh ("faces have inconsistent orientation"), and the shell gives one where a surface's
// boundary passes a vertex twice (two patches touching at a corner, a T-junction between
// pieces that share no edge, each boundary adding a wall edge down from that vertex) or a
// closed mesh has a triangle turned over
bool repeats_directed_edge(const TriangleMesh& mesh) {
  std::set<std::pair<int, int>> directed;
  for (const std::array<int, 3>& t : mesh.triangles)
    for (int k = 0; k < 3; ++k)
      if (!directed.insert({t[k], t[(k + 1) % 3]}).second) return true;
  return false;
}

// the same triangles, each on three vertices of its own: no edge is shared, so none repeats
// (the part is only drawn: MuJoCo's shading of it is its faces' own, not blended across
// edges)
TriangleMesh unshared_vertices(const TriangleMesh& mesh) {
  TriangleMesh separate;
  separate.vertices.reserve(3 * mesh.triangles.size());
  separate.triangles.reserve(mesh.triangles.size());
  for (const std::array<int, 3>& t : mesh.triangles) {
    const int first = static_cast<int>(separate.vertices.size());
    for (int k = 0; k < 3; ++k) separate.vertices.push_back(mesh.vertices[t[k]]);
    separate.triangles.push_back({first, first + 1, first + 2});
  }
  return separate;
}

}  // namespace

bool mesh_is_closed(const TriangleMesh& mesh) {
  std::map<std::pair<int, int>, int> uses;
  for (const std::array<int, 3>& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  for (const auto& [edge, count] : uses)
    if (count != 2) return false;
  return !uses.empty();
}

std::string mjcf_with_part(const std::string& mjcf, const std::string& model_path,
                           const TriangleMesh& part_mm, double shell_mm) {
  // the <mujoco ...> root: the asset goes right after its opening tag
  const size_t root = mjcf.find("<mujoco");
  const size_t root_end = root == std::string::npos ? root : mjcf.find('>', root);
  if (root_end == std::string::npos)
    throw InputError(model_path, 0, "model", "no <mujoco> root element to add the part to");
  // the substrate body's opening tag (either quote style; not a material or a geom of that
  // name, nor anything inside a comment)
  size_t body = std::string::npos, tag_end = std::string::npos;
  for (const char* quoted : {"name=\"substrate\"", "name='substrate'"}) {
    for (size_t name = mjcf.find(quoted); name != std::string::npos && body == std::string::npos;
         name = mjcf.find(quoted, name + 1)) {
      const size_t open = mjcf.rfind('<', name);
      const size_t comment_open = mjcf.rfind("<!--", name);
      const size_t comment_close =
          comment_open == std::string::npos ? std::string::npos : mjcf.find("-->", comment_open);
      const bool in_comment = comment_open != std::string::npos &&
                              (comment_close == std::string::npos || comment_close > name);
      if (in_comment || open == std::string::npos || mjcf.compare(open, 5, "<body") != 0 ||
          !std::isspace(static_cast<unsigned char>(mjcf[open + 5])))
        continue;
      body = open;
      tag_end = mjcf.find('>', name);
    }
  }
  if (tag_end == std::string::npos)
    throw InputError(model_path, 0, "body substrate",
                     "the model has no <body name=\"substrate\"> to carry the part");
  TriangleMesh mesh = mesh_is_closed(part_mm) ? part_mm : closed_shell(part_mm, shell_mm);
  if (repeats_directed_edge(mesh)) mesh = unshared_vertices(mesh);
  const std::string geom = std::string("<geom name=\"") + kPartGeomName +
                           "\" type=\"mesh\" mesh=\"" + kPartGeomName +
                           "\" contype=\"0\" conaffinity=\"0\" group=\"1\" "
                           "rgba=\"0.78 0.76 0.72 1\"/>";
  // a self-closing <body .../> becomes <body ...> geom </body>
  std::string edited = mjcf;
  if (mjcf[tag_end - 1] == '/')
    edited.replace(tag_end - 1, 2, ">" + geom + "</body>");
  else
    edited.insert(tag_end + 1, geom);
  edited.insert(root_end + 1, mesh_asset(mesh));
  return edited;
}

}  // namespace depotwin
