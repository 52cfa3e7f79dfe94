// The part of reading a triangle mesh that every format shares (trivox/io/triangle_mesh.h):
// the budget of triangles, the exact weld of equal vertices, degenerate triangles dropped.
// Private to the io layer.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "trivox/cancel.h"
#include "trivox/io/triangle_mesh.h"
#include "trivox/math.h"

namespace trivox::io_detail {

// A 4x3 affine map (column vectors: p' = m p + t) in doubles, so that a file's float
// transforms compose without rounding beyond one product per vertex.
struct MeshTransform {
  double m[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  double t[3] = {0, 0, 0};

  bool identity() const noexcept;
  Vec3 apply(Vec3 p) const noexcept;
  // This map after `inner`: p -> this(inner(p)).
  MeshTransform after(const MeshTransform& inner) const noexcept;
  MeshTransform scaled(double s) const noexcept;
};

class MeshBuilder {
 public:
  // `stop` (may be null) is read every 65536 vertices.
  MeshBuilder(TriangleMeshFile& out, const std::atomic<bool>* stop) : out_(out), stop_(stop, "reading a mesh") {}

  // Makes room for `triangles` more triangles and `vertices` more vertices, or throws
  // InputError when the file's total would pass mesh_triangle_limit() (or three vertices a
  // triangle). Call before allocating anything for them.
  void expect(std::int64_t triangles, std::int64_t vertices, const std::string& what);
  // The index of p after the weld (equal coordinates, -0 equal to 0); InputError naming
  // `what` when a coordinate is not finite.
  int vertex(Vec3 p, const std::string& what);
  // Adds a triangle, or counts it as degenerate when it repeats a vertex.
  void triangle(int a, int b, int c);

 private:
  struct Key {
    std::uint64_t x, y, z;
    bool operator==(const Key&) const = default;
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const noexcept;
  };
  TriangleMeshFile& out_;
  StopPoll stop_;
  std::int64_t triangles_expected_ = 0, vertices_expected_ = 0;
  std::unordered_map<Key, int, KeyHash> index_;
};

// The 3MF reader (lib3mf), in a file of its own because lib3mf's headers define Windows types.
void read_3mf(std::vector<std::uint8_t> bytes, MeshBuilder& builder, const std::string& source);

}  // namespace trivox::io_detail
