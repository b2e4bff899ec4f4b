// STL import and export: binary through assimp, ASCII by its own strict reader, a binary file
// whose header begins with "solid" (decided by its size), identical vertices joined (across
// solids too), units, round trips, and every kind of broken file an InputError naming the file
// (an ASCII one also its line).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "core/error.hpp"
#include "toolpath/analytic_surfaces.hpp"
#include "toolpath/stl.hpp"

namespace depotwin {
namespace {

namespace fs = std::filesystem;

const std::string kData = std::string(DEPOTWIN_SOURCE_DIR) + "/tests/toolpath/data/";
const std::string kTorus = kData + "torus.STL";  // mikedh/trimesh's, see data/README.md
const std::string kTwoSolids = kData + "two_solids.stl";

// a scratch directory for this test program's files
std::string scratch(const std::string& name) {
  const fs::path dir = fs::path(DEPOTWIN_BINARY_DIR) / "test_surface_scratch";
  fs::create_directories(dir);
  return (dir / name).string();
}

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << bytes;
}

// a closed tetrahedron, outward normals
TriangleMesh tetrahedron() {
  TriangleMesh mesh;
  mesh.vertices = {Vec3(0, 0, 0), Vec3(10, 0, 0), Vec3(0, 10, 0), Vec3(0, 0, 10)};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return mesh;
}

// the problem of reading a broken file (fails the test if it reads)
Problem problem_of(const std::string& path) {
  try {
    read_stl(path, 1.0);
  } catch (const InputError& e) {
    EXPECT_EQ(e.problems().size(), 1u);
    return e.problems().front();
  }
  ADD_FAILURE() << "expected an InputError for " << path;
  return {};
}

void expect_problem(const std::string& path, const std::string& words) {
  const Problem p = problem_of(path);
  EXPECT_EQ(p.file, path);
  EXPECT_EQ(p.key, "toolpath.surface.file");
  EXPECT_NE(p.message.find(words), std::string::npos) << p.message;
}

TEST(Stl, AsciiTetrahedronJoinsVertices) {
  const std::string path = scratch("tetra_ascii.stl");
  write_stl_ascii(tetrahedron(), path, "tetra");
  const TriangleMesh mesh = read_stl(path, 1.0);
  ASSERT_EQ(mesh.triangle_count(), 4u);
  EXPECT_EQ(mesh.vertices.size(), 4u);  // 12 facet corners, 4 distinct points
  Vec3 lo, hi;
  mesh.bounds(lo, hi);
  EXPECT_EQ(lo, Vec3(0, 0, 0));
  EXPECT_EQ(hi, Vec3(10, 10, 10));
  // orientation kept: the facet normal of the slanted face points away from the origin
  for (std::size_t t = 0; t < 4; ++t) {
    const std::array<int, 3>& f = mesh.triangles[t];
    const Vec3 centroid = (mesh.vertices[f[0]] + mesh.vertices[f[1]] + mesh.vertices[f[2]]) / 3;
    EXPECT_GT(mesh.facet_normal(t).dot(centroid - Vec3(2.5, 2.5, 2.5)), 0.0) << "triangle " << t;
  }
}

TEST(Stl, BinaryTetrahedronInInches) {
  const std::string path = scratch("tetra_binary.stl");
  write_stl_binary(tetrahedron(), path, "binary tetrahedron");
  EXPECT_EQ(fs::file_size(path), 84u + 4u * 50u);
  const TriangleMesh mesh = read_stl(path, 25.4);
  ASSERT_EQ(mesh.triangle_count(), 4u);
  EXPECT_EQ(mesh.vertices.size(), 4u);
  Vec3 lo, hi;
  mesh.bounds(lo, hi);
  EXPECT_EQ(hi, Vec3(254, 254, 254));
}

TEST(Stl, SeveralAsciiSolidsShareVertices) {
  // two solids, each one triangle of a unit square, sharing the diagonal's two vertices
  const TriangleMesh mesh = read_stl(kTwoSolids, 1.0);
  EXPECT_EQ(mesh.triangle_count(), 2u);
  EXPECT_EQ(mesh.vertices.size(), 4u);
}

TEST(Stl, BinaryWithSolidHeaderIsDecidedBySize) {
  // torus.STL: binary, its header begins "solid torus"; the count at offset 80 is 8700
  std::ifstream in(kTorus, std::ios::binary);
  char head[84];
  in.read(head, 84);
  ASSERT_TRUE(in) << "missing " << kTorus;
  ASSERT_EQ(std::string(head, 5), "solid");
  uint32_t count = 0;
  std::memcpy(&count, head + 80, 4);
  ASSERT_EQ(count, 8700u);
  ASSERT_EQ(fs::file_size(kTorus), 84u + 50u * count);

  const TriangleMesh inches = read_stl(kTorus, 1.0);
  EXPECT_EQ(inches.triangle_count(), count);
  // a closed torus (genus 1): V - E + F = 0 with E = 3F / 2, so V = F / 2 once joined
  EXPECT_EQ(inches.vertices.size(), count / 2);
  Vec3 lo, hi;
  inches.bounds(lo, hi);
  EXPECT_NEAR(hi.x() - lo.x(), 3.0, 0.01);  // ~3 inches across, 1 inch thick
  EXPECT_NEAR(hi.y() - lo.y(), 3.0, 0.01);
  EXPECT_NEAR(hi.z() - lo.z(), 1.0, 0.01);

  const TriangleMesh mm = read_stl(kTorus, 25.4);
  ASSERT_EQ(mm.vertices.size(), inches.vertices.size());
  for (std::size_t v = 0; v < mm.vertices.size(); ++v)
    ASSERT_EQ(mm.vertices[v], 25.4 * inches.vertices[v]);
  mm.bounds(lo, hi);
  EXPECT_NEAR(hi.x() - lo.x(), 76.2, 0.3);
}

TEST(Stl, SolidHeaderOnASmallBinaryFile) {
  std::string bytes = stl_binary_bytes(tetrahedron(), "x");
  bytes.replace(0, 11, "solid tetra");  // what some CAD exporters write
  const std::string path = scratch("tetra_solid_header.stl");
  write_bytes(path, bytes);
  const TriangleMesh mesh = read_stl(path, 1.0);
  EXPECT_EQ(mesh.triangle_count(), 4u);
  EXPECT_EQ(mesh.vertices.size(), 4u);
}

TEST(Stl, RoundTripBinaryAndAscii) {
  SphereCapParams params;
  params.mesh.cell_mm = 2.0;
  const TriangleMesh original = sphere_cap(params);
  for (bool binary : {true, false}) {
    const std::string path = scratch(binary ? "cap_binary.stl" : "cap_ascii.stl");
    if (binary)
      write_stl_binary(original, path, "sphere cap");
    else
      write_stl_ascii(original, path, "cap");
    const TriangleMesh back = read_stl(path, 1.0);
    ASSERT_EQ(back.triangle_count(), original.triangle_count());
    // every vertex is joined again (the reader recovers the shared vertices exactly)
    ASSERT_EQ(back.vertices.size(), original.vertices.size());
    for (std::size_t t = 0; t < original.triangle_count(); ++t)
      for (int c = 0; c < 3; ++c) {
        const Vec3& a = original.vertices[original.triangles[t][c]];
        const Vec3& b = back.vertices[back.triangles[t][c]];
        ASSERT_LT((a - b).norm(), 1e-5) << "triangle " << t;  // float precision at 20 mm
      }
  }
  // the binary bytes are deterministic
  EXPECT_EQ(stl_binary_bytes(original, "x"), stl_binary_bytes(original, "x"));
}

TEST(Stl, WriterRefusesASolidHeader) {
  EXPECT_THROW(stl_binary_bytes(tetrahedron(), "solid part"), InternalError);
}

TEST(Stl, BrokenFilesNameTheFile) {
  expect_problem(scratch("does_not_exist.stl"), "cannot open");

  const std::string empty = scratch("empty.stl");
  write_bytes(empty, "");
  expect_problem(empty, "empty");

  const std::string good = stl_binary_bytes(tetrahedron(), "tetra");
  const std::string truncated = scratch("truncated.stl");
  write_bytes(truncated, good.substr(0, good.size() - 7));
  expect_problem(truncated, "counts 4 triangles (284 bytes) but the file has 277 bytes");

  std::string miscounted_bytes = good;
  miscounted_bytes[80] = 5;  // says 5 triangles, holds 4
  const std::string miscounted = scratch("miscounted.stl");
  write_bytes(miscounted, miscounted_bytes);
  expect_problem(miscounted, "counts 5 triangles");

  // the torus's bytes cut short: the header says "solid" but the file holds binary data
  std::ifstream in(kTorus, std::ios::binary);
  std::string torus((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string torus_cut = scratch("torus_cut.stl");
  write_bytes(torus_cut, torus.substr(0, 1000));
  expect_problem(torus_cut, "binary data");

  std::string nan_bytes = good;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(&nan_bytes[84 + 12 + 4], &nan, 4);  // first triangle, first vertex, y
  const std::string nan_binary = scratch("nan_binary.stl");
  write_bytes(nan_binary, nan_bytes);
  expect_problem(nan_binary, "non-finite coordinate in triangle 0");

  const std::string nan_ascii = scratch("nan_ascii.stl");
  write_bytes(nan_ascii,
              "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
              "vertex 0 1 inf\nendloop\nendfacet\nendsolid t\n");
  expect_problem(nan_ascii, "non-finite");

  const std::string ascii = stl_ascii_text(tetrahedron(), "tetra");
  const std::string ascii_cut = scratch("ascii_cut.stl");
  write_bytes(ascii_cut, ascii.substr(0, 200));  // in the middle of the second facet
  expect_problem(ascii_cut, "the file ends inside facet 1");

  const std::string zero = scratch("zero_triangles.stl");
  write_bytes(zero, stl_binary_bytes(TriangleMesh{}, "nothing"));
  expect_problem(zero, "without triangles");

  const std::string no_facets = scratch("no_facets.stl");
  write_bytes(no_facets, "solid nothing\nendsolid nothing\n");
  expect_problem(no_facets, "without triangles");

  const std::string text = scratch("not_stl.stl");
  write_bytes(text, "hello, world\n");
  expect_problem(text, "not an STL file");

  const std::string noise = scratch("noise.stl");
  write_bytes(noise, std::string(300, '\x7f'));
  expect_problem(noise, "not an STL file");

  EXPECT_THROW(read_stl(kTorus, 0.0), InputError);

  // bytes beyond the counted triangles: named as such, not as a truncation
  const std::string appended = scratch("appended.stl");
  write_bytes(appended, good + "tail!!!");
  expect_problem(appended, "a binary one with bytes beyond its triangles");
  expect_problem(appended, "counts 4 triangles (284 bytes) but the file has 291 bytes");

  // a stray vertex far beyond any machine (a CAD leftover, or metres read as mm): refused
  // rather than stretching the part's bounds; at 1e6 mm still read
  for (const double z : {1e20, 2e6}) {
    TriangleMesh stray = tetrahedron();
    stray.vertices[3].z() = z;
    const std::string far = scratch("stray.stl");
    write_bytes(far, stl_binary_bytes(stray, "stray"));
    expect_problem(far, "lies beyond ±1e+06 mm: check units, or remove the stray triangles");
  }
  TriangleMesh at_limit = tetrahedron();
  at_limit.vertices[3].z() = 1e6;
  EXPECT_EQ(read_stl_bytes(stl_binary_bytes(at_limit, "t"), "t.stl", 1.0).triangle_count(), 4u);
}

// an ASCII STL saved with a UTF-8 byte order mark reads as the same ASCII STL
TEST(Stl, AsciiWithAByteOrderMarkReads) {
  const std::string ascii = stl_ascii_text(tetrahedron(), "tetra");
  const TriangleMesh plain = read_stl_bytes(ascii, "plain.stl", 1.0);
  const TriangleMesh marked = read_stl_bytes("\xEF\xBB\xBF" + ascii, "marked.stl", 1.0);
  ASSERT_EQ(marked.triangle_count(), plain.triangle_count());
  ASSERT_EQ(marked.vertices.size(), plain.vertices.size());
  for (std::size_t i = 0; i < plain.vertices.size(); ++i)
    EXPECT_EQ(marked.vertices[i], plain.vertices[i]);
}

// an ASCII STL of two facets (a 10 mm square at z = 1), its first facet's third vertex line
// (line 6) as given
std::string square_with_third_vertex(const std::string& third_vertex) {
  return "solid x\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 1\n  vertex 10 0 1\n" +
         third_vertex +
         "\n endloop\nendfacet\nfacet normal 0 0 1\n outer loop\n  vertex 10 0 1\n"
         "  vertex 10 10 1\n  vertex 0 10 1\n endloop\nendfacet\nendsolid x\n";
}

// the problem of reading these ASCII bytes (fails the test if they read)
Problem ascii_problem(const std::string& text) {
  try {
    read_stl_bytes(text, "part.stl", 1.0);
  } catch (const InputError& e) {
    EXPECT_EQ(e.problems().size(), 1u);
    return e.problems().front();
  }
  ADD_FAILURE() << "expected an InputError for:\n" << text;
  return {};
}

TEST(Stl, AsciiDeparturesFromTheGrammarNameTheirLine) {
  const auto expect_at = [](const std::string& text, int line, const std::string& message) {
    const Problem p = ascii_problem(text);
    EXPECT_EQ(p.file, "part.stl");
    EXPECT_EQ(p.line, line) << p.message;
    EXPECT_EQ(p.message, message);
  };
  // a decimal comma (what a German locale's exporter writes): not read as 10
  expect_at(square_with_third_vertex("  vertex 0 10,5 1"), 6,
            "a vertex needs three numbers, got '10,5' (STL writes '.' for the decimal point)");
  expect_at(square_with_third_vertex("  vertex 0 10"), 6,
            "a vertex needs three numbers, got 'endloop'");
  expect_at(square_with_third_vertex("  vertex 0 10 1 7"), 6,
            "expected 'vertex' or 'endloop', got '7' (a vertex has three coordinates)");
  expect_at(square_with_third_vertex("  vertex 0 10 1\n  vertex 5 5 1"), 2,
            "facet 0 has 4 vertices: an STL facet is a triangle, with 3");
  expect_at(square_with_third_vertex("  vertex 0 1e50 1"), 6,
            "coordinate 1e+50 in facet 0 is beyond STL's 32-bit floats");
  expect_at(square_with_third_vertex("  vertex 0 nan 1"), 6, "non-finite coordinate in facet 0");
  expect_at(square_with_third_vertex("  vertex 0 10 1\n  endlop"), 7,
            "expected 'vertex' or 'endloop', got 'endlop'");
  // a file cut after a whole facet: no `endsolid`, not a smaller part
  const std::string whole = square_with_third_vertex("  vertex 0 10 1");
  expect_at(whole.substr(0, whole.find("endsolid")), 16,
            "the file ends without 'endsolid' (solid 0 is not closed: a truncated file?)");
  expect_at(whole + "garbage\n", 17, "expected 'solid' (or the end of the file), got 'garbage'");
}

TEST(Stl, AsciiAsExportersWriteItReads) {
  // the grammar in capitals, CRLF line ends, tabs, a degenerate facet's NaN normal (some
  // exporters write one) and no name: the same two triangles as the plain file
  const TriangleMesh plain =
      read_stl_bytes(square_with_third_vertex("  vertex 0 10 1"), "plain.stl", 1.0);
  const std::string shouted =
      "SOLID\r\nFACET NORMAL nan nan nan\r\n\tOUTER LOOP\r\n\t\tVERTEX 0 0 1\r\n"
      "\t\tVERTEX 1e1 0 1\r\n\t\tVERTEX 0 10 +1\r\n\tENDLOOP\r\nENDFACET\r\n"
      "FACET NORMAL 0 0 1 OUTER LOOP VERTEX 10 0 1 VERTEX 10 10 1 VERTEX 0 10 1 ENDLOOP "
      "ENDFACET\r\nENDSOLID\r\n";
  const TriangleMesh read = read_stl_bytes(shouted, "shouted.stl", 1.0);
  ASSERT_EQ(read.triangle_count(), 2u);
  ASSERT_EQ(read.vertices.size(), 4u);  // the diagonal's two vertices shared
  EXPECT_EQ(read.vertices, plain.vertices);
  EXPECT_EQ(read.triangles, plain.triangles);

  // the whole file on one line, a name of several words (one of them `facet`, not followed by
  // `normal`), and a name with the first facet on its line: the same two triangles
  std::string one_line = square_with_third_vertex("  vertex 0 10 1");
  std::replace(one_line.begin(), one_line.end(), '\n', ' ');
  const std::string many_words = "solid Exported from a facet modeller 2.9\n" +
                                 square_with_third_vertex("  vertex 0 10 1").substr(8);
  const std::string name_then_facet =
      "solid part " + square_with_third_vertex("  vertex 0 10 1").substr(8);
  for (const std::string& text : {one_line, many_words, name_then_facet}) {
    const TriangleMesh same = read_stl_bytes(text, "same.stl", 1.0);
    EXPECT_EQ(same.vertices, plain.vertices) << text;
    EXPECT_EQ(same.triangles, plain.triangles) << text;
  }
}

}  // namespace
}  // namespace depotwin
