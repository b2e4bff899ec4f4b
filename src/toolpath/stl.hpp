// STL import and export for the part a conformal toolpath is printed on.
//
// The storage format is decided here first: a file is binary when its size is exactly
// 84 + 50 n bytes with n the little-endian uint32 at offset 80, whatever its first bytes say
// (CAD exporters write binary files whose 80-byte header begins with "solid"), and ASCII when
// it is not and begins with "solid". A binary file goes through assimp (5.2), with the "stl"
// hint (it checks the binary size first too). An ASCII file is read here, strictly: its
// grammar (solid, facet normal, outer loop, three vertices, endloop, endfacet, endsolid) and
// nothing else, every departure an error naming its line (assimp reads "10,5" as 10 and a
// facet of four vertices without a word). Identical vertices are joined (after the facet
// normals are dropped: assimp would otherwise keep one vertex per facet), so vertex normals
// are smooth over the surface.
#pragma once

#include <string>

#include "core/triangle_mesh.hpp"

namespace depotwin {

// Read an STL file (ASCII or binary); coordinates are multiplied by mm_per_unit (1 for a file
// in mm, 25.4 for inches). Bad input is an InputError naming the file and `key`: a missing
// or unreadable file, an empty or truncated file, a binary header whose triangle count does
// not match the file's size, a file that is not STL, non-finite coordinates, no triangles, a
// non-positive or non-finite mm_per_unit; in an ASCII file also its line (Problem::line) and
// what it found there: a word out of the grammar, a facet of other than 3 vertices, a
// coordinate that is not a number or beyond 32-bit floats, a solid without `endsolid`.
TriangleMesh read_stl(const std::string& path, double mm_per_unit,
                      const std::string& key = "toolpath.surface.file");
// The same for a file's bytes already in memory; `label` names the file in messages.
TriangleMesh read_stl_bytes(const std::string& bytes, const std::string& label, double mm_per_unit,
                            const std::string& key = "toolpath.surface.file");

// The bytes of a binary STL of the mesh (little-endian floats, facet normals by the right-hand
// rule, attribute 0): deterministic, for files committed with scenarios. The header is cut or
// padded with spaces to 80 bytes; it must not begin with "solid" (InternalError: many
// readers would take the file for ASCII).
std::string stl_binary_bytes(const TriangleMesh& mesh, const std::string& header);
// ... written to `path` atomically (InternalError on I/O failure).
void write_stl_binary(const TriangleMesh& mesh, const std::string& path, const std::string& header);

// An ASCII STL ("solid <name>" ... "endsolid <name>") with coordinates printed to round-trip
// floats (9 significant digits); for tests and inspection.
std::string stl_ascii_text(const TriangleMesh& mesh, const std::string& name);
void write_stl_ascii(const TriangleMesh& mesh, const std::string& path, const std::string& name);

}  // namespace depotwin
