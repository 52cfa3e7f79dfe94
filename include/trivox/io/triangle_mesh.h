// Triangle meshes read from files, for mesh trims (trivox/trim/trim.h): binary and ASCII STL,
// Wavefront OBJ and PLY through the Open Asset Import Library (assimp), 3MF through lib3mf,
// the 3MF Consortium's reference library (assimp's 3MF importer returns an empty scene for
// files that use the production extension, as lib3mf itself writes them; FORMATS.md).
//
// What a file gives: every triangle of every mesh the file places (OBJ and PLY polygons are
// split into triangles by assimp; a 3MF file's build items with their components, each with
// its transform), in the file's order, in millimetres (3MF files state their unit and are
// converted; the other formats have none and are taken as millimetres). Vertices that are
// equal in all three coordinates are merged into one, so that triangles sharing an edge in
// the file share its two vertex indices (the mesh layer's tie rule, trivox/mesh/sliced_mesh.h,
// rests on that); nothing else is moved or merged. A triangle that repeats a vertex (zero
// area by construction) is dropped and counted; points and lines are ignored and counted.
//
// Sizes are checked before they are allocated: a binary STL's triangle count against the file
// size, a PLY header's element counts against the file size, every count against
// kMaxMeshTriangles (trivox/limits.h). Errors are InputError naming the file and the rule
// (UnsupportedError for a format not read), IoError for a file that cannot be read.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "trivox/math.h"

namespace trivox {

struct TriangleMeshFile {
  std::string source;  // the file it was read from (as given)
  std::string format;  // "binary STL", "ASCII STL", "OBJ", "PLY" or "3MF"
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;  // indices into vertices, in the file's order and orientation
  std::size_t dropped_degenerate = 0;         // triangles that repeated a vertex
  std::size_t ignored_primitives = 0;         // points and lines
};

// The mesh formats, by file extension (lower case, with the dot): ".stl", ".obj", ".ply",
// ".3mf".
bool is_triangle_mesh_extension(std::string_view extension) noexcept;

// Reads a mesh file by its extension (any case). Throws InputError for malformed content or
// a file with no triangle, UnsupportedError for another extension, IoError when the file
// cannot be read. `stop` (optional, may be set from a signal handler) is read while the file
// is read, checked and welded: once it is raised, CancelledError (error.h). The one step that
// does not read it is the third-party parser (assimp, lib3mf), bounded by the file's size.
TriangleMeshFile read_triangle_mesh(const std::filesystem::path& path, const std::atomic<bool>* stop = nullptr);

// The same from bytes in memory; `extension` names the format as above and `source` the
// input in messages.
TriangleMeshFile read_triangle_mesh(std::span<const std::uint8_t> bytes, std::string_view extension,
                                    const std::string& source, const std::atomic<bool>* stop = nullptr);

}  // namespace trivox
