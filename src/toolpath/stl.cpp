#include "toolpath/stl.hpp"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <array>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <locale>
#include <sstream>
#include <string_view>
#include <unordered_map>

#include "core/error.hpp"
#include "core/file_io.hpp"
#include "core/number_text.hpp"

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

// A strict reader of ASCII STL, the grammar every exporter writes:
//   solid [name]
//     facet normal ni nj nk / outer loop / vertex x y z (three) / endloop / endfacet  (any number)
//   endsolid [name]
// one solid or several in a row; keywords in any case, words separated by any white space.
// Every departure from it (a facet of two or four vertices, a coordinate that is not a number
// such as a decimal comma, a fourth coordinate, no `endsolid`) is an InputError naming the
// line: a general reader's guess would be a silently different part. Coordinates are 32-bit
// floats, as in a binary STL, and identical ones are joined across the solids.
class AsciiStlReader {
 public:
  AsciiStlReader(const std::string& text, const std::string& path, double mm_per_unit,
                 const std::string& key)
      : text_(text), path_(path), key_(key), mm_per_unit_(mm_per_unit) {}

  TriangleMesh read() {
    std::string_view word;
    while (next(word)) {
      // "solid", or "solid" and the name with no space between (as begins_with_solid allows)
      if (!is(word.substr(0, 5), "solid"))
        fail("expected 'solid' (or the end of the file), got " + shown(word));
      skip_name();
      ++solids_;
      read_facets();
    }
    if (mesh_.triangles.empty()) fail_at(0, "ASCII STL without triangles");
    return std::move(mesh_);
  }

 private:
  // the facets of one solid, through its `endsolid`
  void read_facets() {
    std::string_view word;
    for (;;) {
      if (!next(word))
        fail_at(line_, "the file ends without 'endsolid' (solid " + std::to_string(solids_ - 1) +
                           " is not closed: a truncated file?)");
      if (is(word, "endsolid")) {
        skip_line();
        return;
      }
      if (!is(word, "facet")) fail("expected 'facet' or 'endsolid', got " + shown(word));
      const int facet_line = word_line_;
      ++facets_;
      expect("normal", "after 'facet'");
      // the normal is read, not used: the winding decides which way the facet faces
      for (int i = 0; i < 3; ++i) number("the facet's normal");
      expect("outer", "after the facet's normal");
      expect("loop", "after 'outer'");
      std::array<int, 3> corners{};
      int vertices = 0;
      for (;;) {
        if (!next(word)) ends_inside_facet();
        if (is(word, "endloop")) break;
        if (!is(word, "vertex"))
          fail("expected 'vertex' or 'endloop', got " + shown(word) +
               (parse_double(std::string(word)) ? " (a vertex has three coordinates)" : ""));
        const int index = vertex();
        if (vertices < 3) corners[static_cast<std::size_t>(vertices)] = index;
        ++vertices;
      }
      if (vertices != 3)
        fail_at(facet_line, "facet " + std::to_string(facets_ - 1) + " has " +
                                std::to_string(vertices) +
                                " vertices: an STL facet is a triangle, with 3");
      expect("endfacet", "after 'endloop'");
      mesh_.triangles.push_back(corners);
    }
  }

  // `vertex x y z`: the joined vertex's index
  int vertex() {
    std::array<uint32_t, 3> bits{};
    Vec3 mm;
    for (int i = 0; i < 3; ++i) {
      const double value = number("a vertex");
      if (!std::isfinite(value))
        fail("non-finite coordinate in facet " + std::to_string(facets_ - 1));
      if (std::abs(value) > std::numeric_limits<float>::max())
        fail("coordinate " + message_number(value) + " in facet " + std::to_string(facets_ - 1) +
             " is beyond STL's 32-bit floats");
      const float f = static_cast<float>(value) + 0.0f;  // -0 as +0
      std::memcpy(&bits[static_cast<std::size_t>(i)], &f, 4);
      mm[i] = mm_per_unit_ * static_cast<double>(f);
    }
    const auto [it, inserted] = index_of_.emplace(bits, static_cast<int>(mesh_.vertices.size()));
    if (inserted) mesh_.vertices.push_back(mm);
    return it->second;
  }

  // the next word as a number (nan and inf included: the caller decides); a problem at the
  // line of the word the numbers follow (`vertex`, `normal`)
  double number(const std::string& what) {
    const int statement_line = word_line_;
    std::string_view word;
    if (!next(word)) ends_inside_facet();
    const std::optional<double> value = parse_double(std::string(word));
    if (!value)
      fail_at(statement_line, what + " needs three numbers, got " + shown(word) +
                                  (word.find(',') != std::string_view::npos
                                       ? " (STL writes '.' for the decimal point)"
                                       : ""));
    return *value;
  }

  void expect(const char* keyword, const std::string& where) {
    std::string_view word;
    if (!next(word)) ends_inside_facet();
    if (!is(word, keyword))
      fail(std::string("expected '") + keyword + "' " + where + ", got " + shown(word));
  }

  // the next white-space separated word, and its line in word_line_; false at the end
  bool next(std::string_view& word) {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) {
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
    if (pos_ == text_.size()) return false;
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    word = std::string_view(text_).substr(start, pos_ - start);
    word_line_ = line_;
    return true;
  }

  void skip_line() {
    while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
  }

  // a solid's name (any number of words, or none): the rest of its line, up to a `facet
  // normal` or an `endsolid` on that line (a file written on one line)
  void skip_name() {
    const auto blank = [&](std::size_t i) {
      return text_[i] != '\n' && std::isspace(static_cast<unsigned char>(text_[i]));
    };
    const auto word_at = [&](std::size_t i) {
      std::size_t end = i;
      while (end < text_.size() && !std::isspace(static_cast<unsigned char>(text_[end]))) ++end;
      return std::string_view(text_).substr(i, end - i);
    };
    for (;;) {
      while (pos_ < text_.size() && blank(pos_)) ++pos_;
      if (pos_ == text_.size() || text_[pos_] == '\n') return;
      const std::string_view word = word_at(pos_);
      std::size_t after = pos_ + word.size();
      while (after < text_.size() && blank(after)) ++after;
      if (is(word, "endsolid") ||
          (is(word, "facet") && after < text_.size() && is(word_at(after), "normal")))
        return;
      pos_ += word.size();
    }
  }

  static bool is(std::string_view word, const char* keyword) {
    const std::size_t n = std::strlen(keyword);
    if (word.size() != n) return false;
    for (std::size_t i = 0; i < n; ++i)
      if (std::tolower(static_cast<unsigned char>(word[i])) != keyword[i]) return false;
    return true;
  }

  static std::string shown(std::string_view word) {
    return "'" + printable_text(std::string(word)) + "'";
  }

  [[noreturn]] void ends_inside_facet() const {
    fail_at(line_,
            "the file ends inside facet " + std::to_string(facets_ - 1) + " (a truncated file?)");
  }
  [[noreturn]] void fail(const std::string& message) const { fail_at(word_line_, message); }
  [[noreturn]] void fail_at(int line, const std::string& message) const {
    throw InputError(path_, line, key_, message);
  }

  const std::string& text_;
  const std::string& path_;
  const std::string& key_;
  double mm_per_unit_;
  std::size_t pos_ = 0;
  int line_ = 1, word_line_ = 1;
  int solids_ = 0, facets_ = 0;
  TriangleMesh mesh_;
  std::unordered_map<std::array<uint32_t, 3>, int, FloatTripleHash> index_of_;
};

// the largest coordinate a part may have, mm (a scenario's coordinates are within it)
constexpr double kMaxCoordinate_mm = 1e6;

// every vertex finite and within the coordinate range once scaled to mm: a stray triangle far
// away (a CAD export's leftover) would otherwise stretch the part's bounds and hide it
void check_coordinates(const TriangleMesh& mesh, const std::string& path, const std::string& key) {
  for (const Vec3& v : mesh.vertices) {
    if (!v.allFinite())  // finite floats times a finite scale may still overflow
      throw InputError(path, 0, key, "coordinates overflow when scaled to mm");
    if (v.cwiseAbs().maxCoeff() > kMaxCoordinate_mm) {
      char text[160];
      std::snprintf(text, sizeof text, "a vertex at (%.6g, %.6g, %.6g) mm lies beyond ±%g mm",
                    v.x(), v.y(), v.z(), kMaxCoordinate_mm);
      throw InputError(path, 0, key,
                       std::string(text) + ": check units, or remove the stray triangles");
    }
  }
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
  // an ASCII STL saved with a UTF-8 byte order mark is ASCII STL
  if (bytes.compare(0, 3, "\xEF\xBB\xBF") == 0 && begins_with_solid(bytes.substr(3)))
    return read_stl_bytes(bytes.substr(3), path, mm_per_unit, key);

  // binary by its size, whatever the header says
  bool binary = false;
  if (bytes.size() >= kBinaryPreambleBytes) {
    const uint64_t count = read_u32_le(bytes, kHeaderBytes);
    binary = bytes.size() == kBinaryPreambleBytes + kBinaryFacetBytes * count;
    if (binary && count == 0)
      throw InputError(path, 0, key, "binary STL without triangles (its header counts 0)");
    if (!binary && !begins_with_solid(bytes)) {
      const uint64_t expected = kBinaryPreambleBytes + kBinaryFacetBytes * count;
      throw InputError(path, 0, key,
                       std::string(bytes.size() < expected
                                       ? "not an STL file, or a truncated binary one"
                                       : "not an STL file, or a binary one with bytes beyond its "
                                         "triangles (a wrong count, or data appended)") +
                           ": the binary header counts " + format_count(count) + " triangles (" +
                           format_count(expected) + " bytes) but the file has " +
                           format_count(bytes.size()) +
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

  if (!binary) {
    TriangleMesh mesh = AsciiStlReader(bytes, path, mm_per_unit, key).read();
    check_coordinates(mesh, path, key);
    return mesh;
  }

  // a binary file through assimp, which decides binary vs ASCII by the same size rule
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
                         "non-finite coordinate in triangle " + std::to_string(v / 3) +
                             (scene->mNumMeshes > 1 ? " of solid " + std::to_string(m) : ""));
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
  check_coordinates(result, path, key);
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
