#include "toolpath/stl.hpp"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <array>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <locale>
#include <sstream>
#include <unordered_map>

#include "core/error.hpp"
#include "core/file_io.hpp"

namespace depotwin {

namespace {

constexpr std::size_t kHeaderBytes = 80;
constexpr std::size_t kBinaryPreambleBytes = 84;  // header + uint32 triangle count
constexpr std::size_t kBinaryFacetBytes = 50;     // 12 floats + uint16 attribute

uint32_t read_u32_le(const std::string& bytes, std::size_t offset) {
  uint32_t value = 0;
  for (int i = 3; i >= 0; --i)
    value = (value << 8) | static_cast<unsigned char>(bytes[offset + static_cast<std::size_t>(i)]);
  return value;
}

void append_u32_le(std::string& bytes, uint32_t value) {
  for (int i = 0; i < 4; ++i) bytes += static_cast<char>((value >> (8 * i)) & 0xffu);
}

void append_f32_le(std::string& bytes, double value) {
  const float f = static_cast<float>(value);
  uint32_t bits = 0;
  std::memcpy(&bits, &f, sizeof bits);
  append_u32_le(bytes, bits);
}

// the text begins with "solid" after optional white space (case-insensitive, as assimp)
bool begins_with_solid(const std::string& bytes) {
  std::size_t i = 0;
  while (i < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[i]))) ++i;
  if (bytes.size() - i < 5) return false;
  for (std::size_t k = 0; k < 5; ++k)
    if (std::tolower(static_cast<unsigned char>(bytes[i + k])) != "solid"[k]) return false;
  return true;
}

std::string read_bytes(const std::string& path, const std::string& key) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, key, "cannot open the STL file (missing or unreadable)");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(path, 0, key, "cannot read the STL file");
  return bytes;
}

// Exact join across assimp's meshes (an ASCII file may hold several solids; assimp joins
// identical vertices within each). Vertices are keyed by their float bits (-0 as +0).
struct FloatTripleHash {
  std::size_t operator()(const std::array<uint32_t, 3>& k) const {
    uint64_t h = 1469598103934665603ull;
    for (uint32_t v : k) h = (h ^ v) * 1099511628211ull;
    return static_cast<std::size_t>(h);
  }
};

std::array<uint32_t, 3> key_of(const aiVector3D& v) {
  std::array<uint32_t, 3> key{};
  const float c[3] = {v.x + 0.0f, v.y + 0.0f, v.z + 0.0f};
  for (int i = 0; i < 3; ++i) std::memcpy(&key[static_cast<std::size_t>(i)], &c[i], 4);
  return key;
}

std::string format_count(std::size_t n) {
  return std::to_string(n);
}

}  // namespace

TriangleMesh read_stl(const std::string& path, double mm_per_unit, const std::string& key) {
  if (!std::isfinite(mm_per_unit) || mm_per_unit <= 0.0)
    throw InputError(path, 0, key, "the unit scale (mm per unit) must be positive and finite");
  return read_stl_bytes(read_bytes(path, key), path, mm_per_unit, key);
}

TriangleMesh read_stl_bytes(const std::string& bytes, const std::string& path, double mm_per_unit,
                            const std::string& key) {
  if (!std::isfinite(mm_per_unit) || mm_per_unit <= 0.0)
    throw InputError(path, 0, key, "the unit scale (mm per unit) must be positive and finite");
  if (bytes.empty()) throw InputError(path, 0, key, "the STL file is empty");

  // binary by its size, whatever the header says
  bool binary = false;
  if (bytes.size() >= kBinaryPreambleBytes) {
    const uint64_t count = read_u32_le(bytes, kHeaderBytes);
    binary = bytes.size() == kBinaryPreambleBytes + kBinaryFacetBytes * count;
    if (binary && count == 0)
      throw InputError(path, 0, key, "binary STL without triangles (its header counts 0)");
    if (!binary && !begins_with_solid(bytes)) {
      throw InputError(path, 0, key,
                       "not an STL file, or a truncated binary one: the binary header counts " +
                           format_count(count) + " triangles (" +
                           format_count(kBinaryPreambleBytes + kBinaryFacetBytes * count) +
                           " bytes) but the file has " + format_count(bytes.size()) +
                           " bytes, and it does not begin with \"solid\" as ASCII STL does");
    }
  } else if (!begins_with_solid(bytes)) {
    throw InputError(path, 0, key,
                     "not an STL file: " + format_count(bytes.size()) +
                         " bytes, too short for binary STL (84 bytes at least) and not "
                         "beginning with \"solid\" as ASCII STL does");
  }
  if (!binary && std::memchr(bytes.data(), '\0', bytes.size()) != nullptr) {
    throw InputError(path, 0, key,
                     "not a valid STL file: it begins with \"solid\" but holds binary data and "
                     "its size (" +
                         format_count(bytes.size()) +
                         " bytes) does not match a binary STL's triangle count (truncated?)");
  }

  // assimp decides binary vs ASCII by the same size rule, so the hint is unambiguous here
  Assimp::Importer importer;
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS);
  const aiScene* scene =
      importer.ReadFileFromMemory(bytes.data(), bytes.size(), aiProcess_RemoveComponent, "stl");
  if (scene == nullptr) {
    throw InputError(path, 0, key,
                     std::string(binary ? "binary" : "ASCII") +
                         " STL that cannot be read: " + importer.GetErrorString());
  }
  // coordinates must be finite before vertices are joined (assimp's join is not NaN-safe)
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D& p = mesh->mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        throw InputError(path, 0, key,
                         "non-finite coordinate in triangle " + std::to_string(v / 3 + 1) +
                             (scene->mNumMeshes > 1 ? " of solid " + std::to_string(m + 1) : ""));
      }
    }
  }
  scene = importer.ApplyPostProcessing(aiProcess_JoinIdenticalVertices);
  if (scene == nullptr)
    throw InputError(path, 0, key,
                     std::string("STL that cannot be read: ") + importer.GetErrorString());

  TriangleMesh result;
  std::unordered_map<std::array<uint32_t, 3>, int, FloatTripleHash> index_of;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    std::vector<int> joined(mesh->mNumVertices);
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D& p = mesh->mVertices[v];
      const auto [it, inserted] =
          index_of.emplace(key_of(p), static_cast<int>(result.vertices.size()));
      if (inserted) {
        result.vertices.emplace_back(mm_per_unit * static_cast<double>(p.x),
                                     mm_per_unit * static_cast<double>(p.y),
                                     mm_per_unit * static_cast<double>(p.z));
      }
      joined[v] = it->second;
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;  // STL holds triangles only
      result.triangles.push_back(
          {joined[face.mIndices[0]], joined[face.mIndices[1]], joined[face.mIndices[2]]});
    }
  }
  if (result.triangles.empty())
    throw InputError(path, 0, key,
                     std::string(binary ? "binary" : "ASCII") + " STL without triangles");
  for (const Vec3& v : result.vertices)
    if (!v.allFinite())  // finite floats times a finite scale may still overflow
      throw InputError(path, 0, key, "coordinates overflow when scaled to mm");
  return result;
}

std::string stl_binary_bytes(const TriangleMesh& mesh, const std::string& header) {
  std::string head = header.substr(0, kHeaderBytes);
  if (begins_with_solid(head))
    throw InternalError("binary STL header \"" + head +
                        "\" begins with \"solid\": readers would take the file for ASCII");
  head.resize(kHeaderBytes, ' ');
  std::string bytes = head;
  bytes.reserve(kBinaryPreambleBytes + kBinaryFacetBytes * mesh.triangle_count());
  append_u32_le(bytes, static_cast<uint32_t>(mesh.triangle_count()));
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const Vec3 n = mesh.facet_normal(t);
    for (int i = 0; i < 3; ++i) append_f32_le(bytes, n[i]);
    for (int corner : mesh.triangles[t])
      for (int i = 0; i < 3; ++i) append_f32_le(bytes, mesh.vertices[corner][i]);
    bytes += '\0';
    bytes += '\0';
  }
  return bytes;
}

void write_stl_binary(const TriangleMesh& mesh, const std::string& path,
                      const std::string& header) {
  write_file_atomically(path, stl_binary_bytes(mesh, header));
}

std::string stl_ascii_text(const TriangleMesh& mesh, const std::string& name) {
  std::ostringstream out;
  out.imbue(std::locale::classic());
  out.precision(9);
  out << "solid " << name << '\n';
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const Vec3 n = mesh.facet_normal(t);
    out << "  facet normal " << n.x() << ' ' << n.y() << ' ' << n.z() << "\n    outer loop\n";
    for (int corner : mesh.triangles[t]) {
      const Vec3& v = mesh.vertices[corner];
      out << "      vertex " << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
    }
    out << "    endloop\n  endfacet\n";
  }
  out << "endsolid " << name << '\n';
  return out.str();
}

void write_stl_ascii(const TriangleMesh& mesh, const std::string& path, const std::string& name) {
  write_file_atomically(path, stl_ascii_text(mesh, name));
}

}  // namespace depotwin
