#include "core/triangle_mesh.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

namespace depotwin {

namespace {

// a mesh whose facets' signed projected areas cancel to within this share of their absolute
// sum is judged closed (a solid; one with a few holes too), by its signed volume. An open
// surface that is a height field has the ratio 1
constexpr double kClosedAreaRatio = 0.1;

// A mesh's T-junctions (see corner_normals): for each vertex, the facets whose edge it lies on
// without being their corner (empty when the mesh has none); and at each end of such an edge,
// the facet and the one whose boundary edge runs along it from there, which share a fan.
// Only facets with a normal, each once (a duplicate: original[t] != t), have edges here; an
// edge of one of them is a boundary edge.
struct TJunctions {
  std::vector<std::vector<int>> across;
  std::vector<std::array<int, 3>> joins;  // (vertex, facet, facet), sorted
};
TJunctions find_t_junctions(const TriangleMesh& mesh, const std::vector<int>& original,
                            const std::vector<Vec3>& facet) {
  const auto& vertices = mesh.vertices;
  struct Edge {
    int low, high, triangle;
  };
  std::vector<Edge> edges;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (original[t] != static_cast<int>(t) || facet[t].isZero()) continue;
    for (int c = 0; c < 3; ++c) {
      const int a = mesh.triangles[t][c], b = mesh.triangles[t][(c + 1) % 3];
      edges.push_back({std::min(a, b), std::max(a, b), static_cast<int>(t)});
    }
  }
  std::sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) {
    return x.low != y.low ? x.low < y.low : x.high < y.high;
  });
  // the boundary edges, and each vertex's neighbours along them (pairs sorted by vertex)
  std::vector<Edge> boundary;
  std::vector<std::array<int, 3>> along;  // (vertex, neighbour, the edge's facet)
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j].low == edges[i].low && edges[j].high == edges[i].high) ++j;
    if (j - i == 1) {
      boundary.push_back(edges[i]);
      along.push_back({edges[i].low, edges[i].high, edges[i].triangle});
      along.push_back({edges[i].high, edges[i].low, edges[i].triangle});
    }
    i = j;
  }
  std::sort(along.begin(), along.end());
  TJunctions found;
  // from a to b along boundary edges, each step to the next vertex on the segment a-b (within
  // a float STL's rounding of it); the vertices passed are the facet's T-junctions
  constexpr int kMaxJunctionsPerEdge = 64;
  // a vertex with more boundary edges than this is no T-junction's (the hub of facets that
  // meet only there): a walk stops at it, so that walks from it do not scan all of them each
  constexpr std::ptrdiff_t kMaxBoundaryEdgesAtVertex = 16;
  std::vector<int> chain;
  for (const Edge& edge : boundary) {
    const Vec3 a = vertices[edge.low], b = vertices[edge.high];
    const Vec3 ab = b - a;
    const double length_squared = ab.squaredNorm();
    if (!(length_squared > 0.0)) continue;
    const double tolerance = 1e-6 * (std::sqrt(length_squared) +
                                     std::max(a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff()));
    chain.clear();
    int at = edge.low, first_facet = -1, last_facet = -1;
    double at_fraction = 0.0;
    bool reached = false;
    for (int step = 0; step <= kMaxJunctionsPerEdge && !reached; ++step) {
      int next = -1, next_facet = -1;
      double next_fraction = 1.0;
      const auto from =
          std::lower_bound(along.begin(), along.end(), std::array<int, 3>{at, -1, -1});
      const auto to = std::upper_bound(from, along.end(), std::array<int, 3>{at + 1, -1, -1});
      if (to - from > kMaxBoundaryEdgesAtVertex) break;
      for (auto it = from; it != to; ++it) {
        const int w = (*it)[1];
        if (w == edge.high) {
          if (at != edge.low) {
            reached = true;
            last_facet = (*it)[2];
          }
          continue;
        }
        const Vec3 aw = vertices[w] - a;
        const double fraction = aw.dot(ab) / length_squared;
        if (!(fraction > at_fraction && fraction < next_fraction)) continue;
        if ((aw - fraction * ab).norm() > tolerance) continue;
        next = w;
        next_facet = (*it)[2];
        next_fraction = fraction;
      }
      if (reached || next < 0) break;
      if (chain.empty()) first_facet = next_facet;
      chain.push_back(next);
      at = next;
      at_fraction = next_fraction;
    }
    if (!reached || chain.empty()) continue;
    if (found.across.empty()) found.across.resize(vertices.size());
    for (const int v : chain) found.across[static_cast<size_t>(v)].push_back(edge.triangle);
    found.joins.push_back({edge.low, edge.triangle, first_facet});
    found.joins.push_back({edge.high, edge.triangle, last_facet});
  }
  std::sort(found.joins.begin(), found.joins.end());
  return found;
}

}  // namespace

Vec3 TriangleMesh::facet_normal(size_t t) const {
  const std::array<int, 3>& f = triangles[t];
  const Vec3 n = (vertices[f[1]] - vertices[f[0]]).cross(vertices[f[2]] - vertices[f[0]]);
  const double length = n.norm();
  return length > 0.0 ? Vec3(n / length) : Vec3::Zero();
}

double TriangleMesh::facet_area_mm2(size_t t) const {
  const std::array<int, 3>& f = triangles[t];
  return 0.5 * (vertices[f[1]] - vertices[f[0]]).cross(vertices[f[2]] - vertices[f[0]]).norm();
}

void TriangleMesh::bounds(Vec3& lo, Vec3& hi) const {
  if (vertices.empty()) {
    lo = hi = Vec3::Zero();
    return;
  }
  lo = hi = vertices.front();
  for (const Vec3& v : vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
}

std::vector<Vec3> TriangleMesh::vertex_normals() const {
  std::vector<Vec3> normals(vertices.size(), Vec3::Zero());
  for (size_t t = 0; t < triangles.size(); ++t) {
    const Vec3 n = facet_normal(t);
    if (n.isZero()) continue;
    // each corner adds the facet normal weighted by the triangle's angle there
    for (int corner = 0; corner < 3; ++corner) {
      const Vec3& p = vertices[triangles[t][corner]];
      const Vec3 a = vertices[triangles[t][(corner + 1) % 3]] - p;
      const Vec3 b = vertices[triangles[t][(corner + 2) % 3]] - p;
      const double angle = std::atan2(a.cross(b).norm(), a.dot(b));
      normals[triangles[t][corner]] += angle * n;
    }
  }
  for (Vec3& n : normals) {
    const double length = n.norm();
    if (length > 0.0) n /= length;
  }
  return normals;
}

std::vector<std::array<Vec3, 3>> TriangleMesh::corner_normals(double crease_angle_rad) const {
  const size_t n_triangles = triangles.size();
  std::vector<Vec3> facet(n_triangles);
  std::vector<std::array<double, 3>> angle(n_triangles);
  // the triangles around each vertex (compressed rows: first[v] .. first[v + 1])
  std::vector<int> first(vertices.size() + 1, 0);
  for (size_t t = 0; t < n_triangles; ++t) {
    facet[t] = facet_normal(t);
    for (int corner = 0; corner < 3; ++corner) {
      const Vec3& p = vertices[triangles[t][corner]];
      const Vec3 a = vertices[triangles[t][(corner + 1) % 3]] - p;
      const Vec3 b = vertices[triangles[t][(corner + 2) % 3]] - p;
      angle[t][corner] = std::atan2(a.cross(b).norm(), a.dot(b));
      ++first[triangles[t][corner] + 1];
    }
  }
  for (size_t v = 0; v < vertices.size(); ++v) first[v + 1] += first[v];
  std::vector<int> fill(first.begin(), first.end() - 1);
  std::vector<std::pair<int, int>> around(static_cast<size_t>(first.back()));  // (t, corner)
  for (size_t t = 0; t < n_triangles; ++t)
    for (int corner = 0; corner < 3; ++corner)
      around[fill[triangles[t][corner]]++] = {static_cast<int>(t), corner};

  // the triangles around a vertex form fans: two are in one fan where they share an edge
  // from the vertex that no other triangle has (a manifold edge). A triangle sharing only a
  // non-manifold edge (three or more triangles on it: a hidden facet hung on the top's
  // diagonal) or only the vertex (two cones tip to tip) is another surface there, and its
  // normal is not averaged in. A facet's duplicate (the same three vertices) stands for its
  // original: it counts once on the edges and shares the original's fan.
  std::vector<std::pair<std::array<int, 3>, int>> sorted_facets(n_triangles);
  for (size_t t = 0; t < n_triangles; ++t) {
    sorted_facets[t] = {triangles[t], static_cast<int>(t)};
    std::sort(sorted_facets[t].first.begin(), sorted_facets[t].first.end());
  }
  std::sort(sorted_facets.begin(), sorted_facets.end());
  std::vector<int> original(n_triangles);  // the first triangle with the same three vertices
  for (size_t i = 0; i < n_triangles; ++i)
    original[static_cast<size_t>(sorted_facets[i].second)] =
        i > 0 && sorted_facets[i].first == sorted_facets[i - 1].first
            ? original[static_cast<size_t>(sorted_facets[i - 1].second)]
            : sorted_facets[i].second;

  // T-junctions: a vertex v that lies on another facet's edge (a, b) without being its corner
  // (a facet split on one side of an edge only, as CAD exporters and mesh repairs leave them)
  // has the facets of that side only around it, a half fan; and at a and b the edge, held by
  // one facet on each side, splits the fan in two. Each leaned the normals by half the turn
  // between the two sides (4 deg on a 0.5 mm sine sheet: the offset layer bent 0.03 mm and
  // the tool turned at every such vertex). The facet across counts as a corner of angle pi at
  // v, as it would had it been split there too, and at a and b it joins the fan of the facet
  // along its edge. Found along boundary edges (one original facet): the facet's edge (a, b)
  // and a chain of boundary edges from a to b through vertices on the segment a-b.
  const TJunctions t_junctions = find_t_junctions(*this, original, facet);

  // fan[k]: the fan of the corner at around[k], as a row of its vertex's rows
  std::vector<int> fan(around.size());
  std::vector<int> parent;
  std::vector<std::pair<int, int>> rows_by_original, rows_by_edge;  // (key, row)
  const auto root_of = [&parent](int i) {
    while (parent[static_cast<size_t>(i)] != i)
      i = parent[static_cast<size_t>(i)] = parent[static_cast<size_t>(parent[i])];
    return i;
  };
  const auto join = [&](int a, int b) { parent[static_cast<size_t>(root_of(a))] = root_of(b); };
  for (size_t v = 0; v < vertices.size(); ++v) {
    const int begin = first[v], count = first[v + 1] - first[v];
    parent.resize(static_cast<size_t>(count));
    rows_by_original.clear();
    for (int i = 0; i < count; ++i) {
      parent[static_cast<size_t>(i)] = i;
      rows_by_original.emplace_back(original[static_cast<size_t>(around[begin + i].first)], i);
    }
    std::sort(rows_by_original.begin(), rows_by_original.end());
    // a duplicate joins its original's fan; each original's two edges from v are counted
    rows_by_edge.clear();
    for (size_t i = 0; i < rows_by_original.size(); ++i) {
      const int row = rows_by_original[i].second;
      if (i > 0 && rows_by_original[i].first == rows_by_original[i - 1].first) {
        join(row, rows_by_original[i - 1].second);
        continue;
      }
      const auto [t, corner] = around[begin + row];
      const std::array<int, 3>& f = triangles[static_cast<size_t>(t)];
      if (f[0] == f[1] || f[1] == f[2] || f[2] == f[0]) continue;  // a vertex twice: no edges
      for (int step = 1; step <= 2; ++step) rows_by_edge.emplace_back(f[(corner + step) % 3], row);
    }
    // an edge exactly two originals share joins their fans
    std::sort(rows_by_edge.begin(), rows_by_edge.end());
    for (size_t i = 0; i < rows_by_edge.size();) {
      size_t j = i;
      while (j < rows_by_edge.size() && rows_by_edge[j].first == rows_by_edge[i].first) ++j;
      if (j - i == 2) join(rows_by_edge[i].second, rows_by_edge[i + 1].second);
      i = j;
    }
    // the facets on either side of a T-junction's edge, at its ends
    for (auto it = std::lower_bound(t_junctions.joins.begin(), t_junctions.joins.end(),
                                    std::array<int, 3>{static_cast<int>(v), -1, -1});
         it != t_junctions.joins.end() && (*it)[0] == static_cast<int>(v); ++it) {
      int one = -1, other = -1;
      for (int i = 0; i < count; ++i) {
        const int t = around[begin + i].first;
        if (t == (*it)[1]) one = i;
        if (t == (*it)[2]) other = i;
      }
      if (one >= 0 && other >= 0) join(one, other);
    }
    for (int i = 0; i < count; ++i) fan[static_cast<size_t>(begin + i)] = root_of(i);
  }

  const double cos_crease = std::cos(crease_angle_rad);
  std::vector<std::array<Vec3, 3>> normals(n_triangles);
  std::vector<int> row_of_corner(3 * n_triangles);  // around's row of each (t, corner)
  for (size_t k = 0; k < around.size(); ++k)
    row_of_corner[3 * around[k].first + around[k].second] = static_cast<int>(k);
  for (size_t t = 0; t < n_triangles; ++t) {
    for (int corner = 0; corner < 3; ++corner) {
      const int v = triangles[t][corner];
      const int own_fan = fan[row_of_corner[3 * t + corner]];
      Vec3 sum = Vec3::Zero();
      for (int k = first[v]; k < first[v + 1]; ++k) {
        const auto [u, u_corner] = around[k];
        // the fan's facets, each once: a duplicate facing as its original does adds nothing
        const int first_copy = original[static_cast<size_t>(u)];
        if (fan[k] != own_fan || (first_copy != u && facet[u].dot(facet[first_copy]) > 0.0))
          continue;
        if (facet[u].isZero() || facet[u].dot(facet[t]) < cos_crease) continue;
        sum += angle[u][u_corner] * facet[u];
      }
      if (!t_junctions.across.empty())
        for (const int across : t_junctions.across[static_cast<size_t>(v)])
          if (facet[across].dot(facet[t]) >= cos_crease) sum += M_PI * facet[across];
      const double length = sum.norm();
      normals[t][corner] = length > 0.0 ? Vec3(sum / length) : facet[t];
    }
  }
  return normals;
}

void TriangleMesh::transform(const Eigen::Matrix3d& rotation, const Vec3& offset) {
  for (Vec3& v : vertices) v = rotation * v + offset;
}

double TriangleMesh::signed_volume_mm3() const {
  // the sum of v0 . (v1 x v2) / 6 over the triangles
  Vec3 lo, hi;
  bounds(lo, hi);
  const Vec3 centre = 0.5 * (lo + hi);
  double volume = 0.0;
  for (const auto& t : triangles)
    volume +=
        (vertices[t[0]] - centre).dot((vertices[t[1]] - centre).cross(vertices[t[2]] - centre));
  return volume / 6.0;
}

bool TriangleMesh::face_outward_and_up() {
  // the signed area projected on xy (n_z A per facet) and its absolute sum
  double signed_area = 0.0, absolute_area = 0.0;
  for (const auto& t : triangles) {
    const Vec3& a = vertices[t[0]];
    const double projected = 0.5 * (vertices[t[1]] - a).cross(vertices[t[2]] - a).z();
    signed_area += projected;
    absolute_area += std::abs(projected);
  }
  // a closed solid's projected areas cancel (up to rounding): judge it by its volume
  const bool closed = std::abs(signed_area) <= kClosedAreaRatio * absolute_area;
  const bool reversed = closed ? signed_volume_mm3() < 0.0 : signed_area < 0.0;
  if (!reversed) return false;
  for (auto& t : triangles) std::swap(t[1], t[2]);
  return true;
}

TriangleMesh::Orientation TriangleMesh::orient_consistently() {
  // every directed edge of every triangle with two distinct corners: (undirected key, triangle,
  // whether it runs from the lower vertex index to the higher)
  struct EdgeUse {
    uint64_t key;
    uint32_t triangle;
    bool ascending;
  };
  std::vector<EdgeUse> uses;
  uses.reserve(3 * triangles.size());
  for (size_t t = 0; t < triangles.size(); ++t)
    for (int c = 0; c < 3; ++c) {
      const int a = triangles[t][c], b = triangles[t][(c + 1) % 3];
      if (a == b) continue;
      const uint64_t low = static_cast<uint32_t>(std::min(a, b));
      const uint64_t high = static_cast<uint32_t>(std::max(a, b));
      uses.push_back({(low << 32) | high, static_cast<uint32_t>(t), a < b});
    }
  std::sort(uses.begin(), uses.end(), [](const EdgeUse& x, const EdgeUse& y) {
    return x.key != y.key ? x.key < y.key : x.triangle < y.triangle;
  });

  // the neighbours across manifold edges, and whether each pair must differ in winding from
  // the other's current one (they run the edge the same way) or not
  std::vector<std::vector<std::pair<uint32_t, bool>>> neighbours(triangles.size());
  for (size_t i = 0; i < uses.size();) {
    size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key) ++j;
    // (a facet given twice, as in an STL holding a copy of its own surface, is no neighbour
    // of its copy: the two run every edge the same way and neither is wound wrong)
    const auto corners = [&](uint32_t t) {
      std::array<int, 3> c = triangles[t];
      std::sort(c.begin(), c.end());
      return c;
    };
    if (j - i == 2 && uses[i].triangle != uses[i + 1].triangle &&
        corners(uses[i].triangle) != corners(uses[i + 1].triangle)) {
      const bool same_way = uses[i].ascending == uses[i + 1].ascending;
      neighbours[uses[i].triangle].push_back({uses[i + 1].triangle, same_way});
      neighbours[uses[i + 1].triangle].push_back({uses[i].triangle, same_way});
    }
    i = j;
  }

  // each piece by breadth-first search: a triangle's turn relative to the piece's first, then
  // the turn of the smaller area applied
  std::vector<int8_t> relative(triangles.size(), -1);
  std::vector<uint32_t> piece;
  Orientation result;
  const auto turn_over = [&](uint32_t t) {
    std::swap(triangles[t][1], triangles[t][2]);
    ++result.turned;
  };
  for (size_t seed = 0; seed < triangles.size(); ++seed) {
    if (relative[seed] >= 0) continue;
    piece.assign(1, static_cast<uint32_t>(seed));
    relative[seed] = 0;
    bool orientable = true;
    for (size_t k = 0; k < piece.size(); ++k)
      for (const auto& [other, same_way] : neighbours[piece[k]]) {
        const int8_t wanted = static_cast<int8_t>(relative[piece[k]] ^ (same_way ? 1 : 0));
        if (relative[other] >= 0) {
          // reached already: by a loop that asks the other winding, the piece has no outside
          orientable = orientable && relative[other] == wanted;
          continue;
        }
        relative[other] = wanted;
        piece.push_back(other);
      }
    if (!orientable) {
      // no winding fits: each triangle faces up on its own (a vertical one is left)
      ++result.unorientable_pieces;
      result.unorientable_triangles += piece.size();
      for (const uint32_t t : piece)
        if (facet_normal(t).z() < 0.0) turn_over(t);
      continue;
    }
    double area[2] = {0.0, 0.0};
    for (const uint32_t t : piece) area[relative[t]] += facet_area_mm2(t);
    const int8_t turn = area[1] > area[0] ? 0 : 1;
    for (const uint32_t t : piece)
      if (relative[t] == turn) turn_over(t);
  }
  return result;
}

}  // namespace depotwin
