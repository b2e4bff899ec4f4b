// Fuzz target: the STL reader (toolpath/stl.hpp, assimp underneath) on arbitrary bytes, as a
// scenario's `surface: {file: ...}` part goes through it. Bad input must be an InputError; a
// mesh read must have finite vertices and triangles that index them.
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.hpp"
#include "fuzz/fuzz_check.hpp"
#include "toolpath/stl.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using depotwin::fuzz::require;
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  // mm and inches (a scale can overflow what a float held)
  for (const double mm_per_unit : {1.0, 25.4}) {
    try {
      const depotwin::TriangleMesh mesh = depotwin::read_stl_bytes(bytes, "fuzz.stl", mm_per_unit);
      require(!mesh.empty(), "a mesh read has triangles");
      for (const depotwin::Vec3& v : mesh.vertices) require(v.allFinite(), "finite vertices");
      for (const auto& triangle : mesh.triangles)
        for (const int corner : triangle)
          require(corner >= 0 && static_cast<std::size_t>(corner) < mesh.vertices.size(),
                  "triangles index the vertices");
      // what the hatching asks of the part first
      depotwin::Vec3 lo, hi;
      mesh.bounds(lo, hi);
      require(lo.allFinite() && hi.allFinite(), "finite bounds");
      for (const depotwin::Vec3& normal : mesh.vertex_normals())
        require(normal.allFinite(), "finite vertex normals");
    } catch (const depotwin::InputError&) {
      // rejected with a message: expected
    }
  }
  return 0;
}
