// read_triangle_mesh (trivox/io/triangle_mesh.h): the sizes a file declares checked first,
// then STL, OBJ and PLY through assimp and 3MF through lib3mf (threemf_reader.cpp), every
// triangle welded by MeshBuilder.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <new>
#include <sstream>
#include <string>
#include <system_error>

#include <assimp/IOStream.hpp>
#include <assimp/IOSystem.hpp>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#include "io/mesh_builder.h"
#include "io/text_number.h"
#include "trivox/cancel.h"
#include "trivox/error.h"
#include "trivox/io/detail/regular_file.h"
#include "trivox/io/triangle_mesh.h"
#include "trivox/limits.h"

namespace trivox {

namespace io_detail {

bool MeshTransform::identity() const noexcept {
  for (int i = 0; i < 3; ++i) {
    if (t[i] != 0) return false;
    for (int j = 0; j < 3; ++j)
      if (m[i][j] != (i == j ? 1.0 : 0.0)) return false;
  }
  return true;
}

Vec3 MeshTransform::apply(Vec3 p) const noexcept {
  return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + t[0], m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + t[1],
          m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + t[2]};
}

MeshTransform MeshTransform::after(const MeshTransform& inner) const noexcept {
  MeshTransform r;
  for (int i = 0; i < 3; ++i) {
    r.t[i] = t[i];
    for (int j = 0; j < 3; ++j) {
      r.m[i][j] = 0;
      for (int k = 0; k < 3; ++k) r.m[i][j] += m[i][k] * inner.m[k][j];
      r.t[i] += m[i][j] * inner.t[j];
    }
  }
  return r;
}

MeshTransform MeshTransform::scaled(double s) const noexcept {
  MeshTransform r = *this;
  for (int i = 0; i < 3; ++i) {
    r.t[i] *= s;
    for (int j = 0; j < 3; ++j) r.m[i][j] *= s;
  }
  return r;
}

void MeshBuilder::expect(std::int64_t triangles, std::int64_t vertices, const std::string& what) {
  // Derived from the memory budget (limits.h), so that a small file instancing many triangles
  // (a 3MF's components) is refused before they are allocated.
  static const std::int64_t max_triangles = mesh_triangle_limit();
  const std::int64_t max_vertices = *product_within(max_triangles, 3, INT64_MAX);
  if (triangles < 0 || vertices < 0 || triangles > max_triangles - triangles_expected_ ||
      vertices > max_vertices - vertices_expected_)
    throw InputError(out_.source, 0, what,
                     fmt::format("{} triangles and {} vertices more than the {} and {} before would pass the limit of "
                                 "{} triangles (and three vertices a triangle) a mesh may have: {} bytes a triangle "
                                 "while it is checked, within half of the memory this process may use",
                                 triangles, vertices, triangles_expected_, vertices_expected_, max_triangles,
                                 kMeshTrimBytesPerTriangle));
  triangles_expected_ += triangles;
  vertices_expected_ += vertices;
  out_.triangles.reserve(static_cast<std::size_t>(triangles_expected_));
}

std::size_t MeshBuilder::KeyHash::operator()(const Key& k) const noexcept {
  std::uint64_t h = k.x * 0x9E3779B97F4A7C15ULL;
  h ^= (k.y + 0x632BE59BD9B4E019ULL + (h << 6) + (h >> 2));
  h ^= (k.z * 0xC2B2AE3D27D4EB4FULL + (h << 6) + (h >> 2));
  return static_cast<std::size_t>(h ^ (h >> 29));
}

int MeshBuilder::vertex(Vec3 p, const std::string& what) {
  stop_.step();
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
    throw InputError(out_.source, 0, what, fmt::format("a vertex is not finite ({}, {}, {})", p.x, p.y, p.z));
  // -0 and 0 are one coordinate: adding 0.0 turns -0 into +0 and leaves every other value.
  const Key key{std::bit_cast<std::uint64_t>(p.x + 0.0), std::bit_cast<std::uint64_t>(p.y + 0.0),
                std::bit_cast<std::uint64_t>(p.z + 0.0)};
  const auto [it, added] = index_.try_emplace(key, static_cast<int>(out_.vertices.size()));
  if (added) out_.vertices.push_back({p.x + 0.0, p.y + 0.0, p.z + 0.0});
  return it->second;
}

void MeshBuilder::triangle(int a, int b, int c) {
  if (a == b || b == c || a == c) {
    ++out_.dropped_degenerate;
    return;
  }
  out_.triangles.push_back({a, b, c});
}

}  // namespace io_detail

namespace {

using io_detail::MeshBuilder;
using io_detail::MeshTransform;

std::string lowercase(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return out;
}

std::uint32_t read_le32(const std::uint8_t* p) noexcept {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

// A binary STL is 80 header bytes, a 32-bit triangle count and 50 bytes a triangle; this is
// also the test assimp applies. Anything else must be ASCII ("solid" first).
std::string check_stl(std::span<const std::uint8_t> bytes, const std::string& source) {
  const auto size = static_cast<std::int64_t>(bytes.size());
  if (size >= 84) {
    const std::int64_t count = read_le32(bytes.data() + 80);
    if (84 + 50 * count == size) {
      if (count > mesh_triangle_limit())
        throw InputError(source, 0, "binary STL",
                         fmt::format("{} triangles, more than the {} a mesh may have (limits.h, "
                                     "mesh_triangle_limit)",
                                     count, mesh_triangle_limit()));
      return "binary STL";
    }
  }
  std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  const std::size_t first = text.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos || lowercase(text.substr(first, 5)) != "solid") {
    const std::string said = size >= 84 ? fmt::format("its header counts {} triangles, which would be {} bytes",
                                                      read_le32(bytes.data() + 80),
                                                      84 + 50 * static_cast<std::int64_t>(read_le32(bytes.data() + 80)))
                                        : std::string("it is shorter than the 84 bytes of a binary header");
    throw InputError(source, 0, "STL",
                     fmt::format("neither a binary STL ({} bytes, but {}) nor an ASCII STL (which starts with "
                                 "\"solid\")",
                                 size, said));
  }
  return "ASCII STL";
}

// The lines of an ASCII STL that carry numbers, checked before assimp reads the file: assimp
// reads a vertex of two numbers by taking the next word as the third and reports a character
// the file does not hold, on no line. Here "vertex" takes exactly three numbers and "facet
// normal" three, the vertex's finite, and a problem names its line.
void check_ascii_stl(std::span<const std::uint8_t> bytes, const std::string& source, const std::atomic<bool>* stop) {
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  StopPoll poll(stop, "checking an ASCII STL file");
  int line = 0;
  for (std::size_t at = 0; at < text.size();) {
    poll.step();
    std::size_t end = text.find('\n', at);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view row = text.substr(at, end - at);
    at = end + 1;
    ++line;
    std::vector<std::string_view> words;
    for (std::size_t i = 0; i < row.size();) {
      while (i < row.size() && (row[i] == ' ' || row[i] == '\t' || row[i] == '\r')) ++i;
      std::size_t j = i;
      while (j < row.size() && row[j] != ' ' && row[j] != '\t' && row[j] != '\r') ++j;
      if (j > i) words.push_back(row.substr(i, j - i));
      i = j;
    }
    if (words.empty()) continue;
    const std::string first = lowercase(std::string(words[0]));
    std::size_t from = 1;
    if (first == "facet" && words.size() > 1 && lowercase(std::string(words[1])) == "normal")
      from = 2;
    else if (first != "vertex")
      continue;
    const std::string what = from == 2 ? "a facet normal" : "a vertex";
    if (words.size() - from != 3)
      throw InputError(source, line, "ASCII STL",
                       fmt::format("{} has {} numbers; it needs three (x, y and z)", what, words.size() - from));
    for (std::size_t w = from; w < words.size(); ++w) {
      // A normal is not used (the corners give the triangle), so only a vertex must be finite.
      const auto v = io_detail::parse_double(words[w]);
      if (!v || (from == 1 && !std::isfinite(*v)))
        throw InputError(source, line, "ASCII STL",
                         fmt::format("{} has \"{}\" where a finite number belongs", what,
                                     words[w].substr(0, std::min<std::size_t>(words[w].size(), 40))));
    }
  }
}

// The element counts of a PLY header, each at most what the file's bytes can hold (one byte
// an entry at least), so that no count makes the parser allocate beyond the file's size.
void check_ply_header(std::span<const std::uint8_t> bytes, const std::string& source) {
  std::string_view text(reinterpret_cast<const char*>(bytes.data()), std::min<std::size_t>(bytes.size(), 1 << 16));
  const std::size_t end = text.find("end_header");
  if (end == std::string_view::npos) return;  // not a PLY header: the parser says what is wrong
  std::istringstream header{std::string(text.substr(0, end))};
  std::string line;
  int number = 0;
  std::int64_t entries = 0;
  while (std::getline(header, line)) {
    ++number;
    std::istringstream words(line);
    std::string keyword, name, count_text;
    words >> keyword;
    if (keyword != "element") continue;
    words >> name >> count_text;
    std::int64_t count = 0;
    bool digits = !count_text.empty() && count_text.size() <= 18;
    for (char c : count_text) digits = digits && c >= '0' && c <= '9';
    if (!digits)
      throw InputError(source, number, "PLY header",
                       fmt::format("element \"{}\" has count \"{}\", not a non-negative integer", name, count_text));
    count = std::stoll(count_text);
    entries += count;
    if (count > static_cast<std::int64_t>(bytes.size()) || entries > 4 * kMaxMeshTriangles)
      throw InputError(source, number, "PLY header",
                       fmt::format("element \"{}\" declares {} entries, more than the file's {} bytes can hold or the "
                                   "limit of {} triangles a mesh may have allows",
                                   name, count, bytes.size(), kMaxMeshTriangles));
  }
}

MeshTransform to_transform(const aiMatrix4x4& a) {
  MeshTransform t;
  const float* r[3] = {a[0], a[1], a[2]};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) t.m[i][j] = r[i][j];
    t.t[i] = r[i][3];
  }
  return t;
}

// Every mesh each node places, with the node's transform composed from the root.
void add_node(const aiScene& scene, const aiNode& node, const MeshTransform& parent, MeshBuilder& builder,
              TriangleMeshFile& out, int depth) {
  if (depth > 64) throw InputError(out.source, 0, out.format, "the scene's nodes nest more than 64 deep");
  const aiMatrix4x4& a = node.mTransformation;
  if (a.d1 != 0 || a.d2 != 0 || a.d3 != 0 || a.d4 != 1)
    throw InputError(out.source, 0, out.format, "a node's transform is projective; meshes are placed by affine maps");
  const MeshTransform here = parent.after(to_transform(a));
  const bool identity = here.identity();
  std::vector<int> index;
  for (unsigned k = 0; k < node.mNumMeshes; ++k) {
    if (node.mMeshes == nullptr || node.mMeshes[k] >= scene.mNumMeshes) continue;
    const aiMesh* mesh = scene.mMeshes[node.mMeshes[k]];
    if (mesh == nullptr) continue;
    const std::string what = fmt::format("{} mesh {}", out.format, node.mMeshes[k]);
    builder.expect(mesh->mNumFaces, mesh->mNumVertices, what);
    index.assign(mesh->mNumVertices, -1);
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3 || face.mIndices == nullptr) {
        ++out.ignored_primitives;
        continue;
      }
      int v[3];
      for (int c = 0; c < 3; ++c) {
        const unsigned i = face.mIndices[c];
        if (i >= mesh->mNumVertices)
          throw InputError(out.source, 0, what, fmt::format("face {} names vertex {} of {}", f, i, mesh->mNumVertices));
        if (index[i] < 0) {
          const aiVector3D& p = mesh->mVertices[i];
          const Vec3 q{p.x, p.y, p.z};
          index[i] = builder.vertex(identity ? q : here.apply(q), what);
        }
        v[c] = index[i];
      }
      builder.triangle(v[0], v[1], v[2]);
    }
  }
  for (unsigned c = 0; c < node.mNumChildren; ++c)
    if (node.mChildren != nullptr && node.mChildren[c] != nullptr)
      add_node(scene, *node.mChildren[c], here, builder, out, depth + 1);
}

// The file system as assimp sees it while it reads from memory: nothing but the bytes given.
// An OBJ's "mtllib" then names a file that is not there, and the geometry reads the same
// wherever the program runs.
class NoFiles : public Assimp::IOSystem {
 public:
  bool Exists(const char*) const override { return false; }
  char getOsSeparator() const override { return '/'; }
  Assimp::IOStream* Open(const char*, const char*) override { return nullptr; }
  void Close(Assimp::IOStream* stream) override { delete stream; }
};

void read_with_assimp(std::span<const std::uint8_t> bytes, const char* hint, MeshBuilder& builder,
                      TriangleMeshFile& out) {
  if (bytes.empty()) throw InputError(out.source, 0, out.format, "the file is empty");
  Assimp::Importer importer;
  importer.SetIOHandler(new NoFiles);  // the importer owns it
  // Polygons (OBJ, PLY) are split into triangles; nothing else is changed: no weld (ours is
  // exact), no normals, no reordering.
  const aiScene* scene = nullptr;
  try {
    scene = importer.ReadFileFromMemory(bytes.data(), bytes.size(), aiProcess_Triangulate, hint);
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(out.source, 0, out.format, e.what());
  }
  if (scene == nullptr || scene->mRootNode == nullptr) {
    const std::string why = importer.GetErrorString();
    throw InputError(out.source, 0, out.format, why.empty() ? "the file holds no scene" : why);
  }
  add_node(*scene, *scene->mRootNode, MeshTransform{}, builder, out, 0);
}

// A binary STL read here rather than by assimp (check_stl has matched its size to its count):
// 80 header bytes, a count, then per triangle a normal (unused: the corners give the
// triangle), three corners of three little-endian floats, two attribute bytes. The vertices
// and triangles are assimp's, in its order; the stop flag is read as they are welded, where
// assimp's parse of a large file could not be stopped.
void read_binary_stl(std::span<const std::uint8_t> bytes, MeshBuilder& builder, TriangleMeshFile& out) {
  const std::int64_t count = read_le32(bytes.data() + 80);
  const std::string what = fmt::format("{} mesh 0", out.format);
  builder.expect(count, 3 * count, what);
  const auto coordinate = [](const std::uint8_t* p) { return static_cast<double>(std::bit_cast<float>(read_le32(p))); };
  for (std::int64_t t = 0; t < count; ++t) {
    const std::uint8_t* corners = bytes.data() + 84 + 50 * t + 12;
    int v[3];
    for (int c = 0; c < 3; ++c) {
      const std::uint8_t* p = corners + 12 * c;
      v[c] = builder.vertex({coordinate(p), coordinate(p + 4), coordinate(p + 8)}, what);
    }
    builder.triangle(v[0], v[1], v[2]);
  }
}

std::vector<std::uint8_t> read_bytes(const std::filesystem::path& path, const std::atomic<bool>* stop) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw IoError(fmt::format("cannot read mesh '{}': it is a directory", path.string()));
  // A device or a FIFO is refused by what it is (io/detail/regular_file.h).
  try {
    const std::string bytes = read_regular_file(path, input_file_byte_limit(), stop);
    return std::vector<std::uint8_t>(bytes.begin(), bytes.end());
  } catch (const IoError& e) {
    throw IoError(fmt::format("cannot read mesh: {}", e.what()));
  }
}

}  // namespace

bool is_triangle_mesh_extension(std::string_view extension) noexcept {
  return extension == ".stl" || extension == ".obj" || extension == ".ply" || extension == ".3mf";
}

TriangleMeshFile read_triangle_mesh(std::span<const std::uint8_t> bytes, std::string_view extension,
                                    const std::string& source, const std::atomic<bool>* stop) {
  const std::string ext = lowercase(extension);
  if (!is_triangle_mesh_extension(ext))
    throw UnsupportedError(
        source, 0, "",
        fmt::format("unknown mesh format '{}': trivox reads .stl, .obj, .ply and .3mf meshes", extension));
  TriangleMeshFile out;
  out.source = source;
  MeshBuilder builder(out, stop);
  throw_if_stopped(stop, "reading a mesh");
  if (ext == ".3mf") {
    out.format = "3MF";
    io_detail::read_3mf(std::vector<std::uint8_t>(bytes.begin(), bytes.end()), builder, source);
  } else if (ext == ".stl") {
    out.format = check_stl(bytes, source);
    if (out.format == "ASCII STL") {
      check_ascii_stl(bytes, source, stop);
      read_with_assimp(bytes, "stl", builder, out);
    } else {
      read_binary_stl(bytes, builder, out);
    }
  } else if (ext == ".ply") {
    out.format = "PLY";
    check_ply_header(bytes, source);
    read_with_assimp(bytes, "ply", builder, out);
  } else {
    out.format = "OBJ";
    read_with_assimp(bytes, "obj", builder, out);
  }
  throw_if_stopped(stop, "reading a mesh");
  if (out.triangles.empty())
    throw InputError(source, 0, out.format,
                     fmt::format("the file holds no triangle ({} with a repeated vertex, {} points or lines)",
                                 out.dropped_degenerate, out.ignored_primitives));
  return out;
}

TriangleMeshFile read_triangle_mesh(const std::filesystem::path& path, const std::atomic<bool>* stop) {
  const std::string ext = lowercase(path.extension().string());
  if (!is_triangle_mesh_extension(ext))
    throw UnsupportedError(path.string(), 0, "",
                           fmt::format("unknown mesh format '{}': trivox reads .stl, .obj, .ply and .3mf meshes",
                                       path.extension().string()));
  const std::vector<std::uint8_t> bytes = read_bytes(path, stop);
  return read_triangle_mesh(bytes, ext, path.string(), stop);
}

}  // namespace trivox
