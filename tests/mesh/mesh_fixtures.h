// Fixtures for the triangle-mesh tests: small meshes (a box, a sphere), writers of the mesh
// formats written here from their specifications (not through the libraries trivox reads them
// with), an independent binary STL reader, and an exact point-in-solid test: ray parity with
// orientation predicates evaluated exactly (a floating-point filter, then integers).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include <boost/multiprecision/cpp_int.hpp>
#include <fmt/format.h>

#include "output/zip_writer.h"
#include "trivox/math.h"

namespace trivox::test {

struct TestMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
};

// An axis-aligned box, triangles counter-clockwise seen from outside.
inline TestMesh box_mesh(Vec3 lo, Vec3 hi) {
  TestMesh m;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) m.vertices.push_back({i ? hi.x : lo.x, j ? hi.y : lo.y, k ? hi.z : lo.z});
  // Corner i + 2j + 4k.
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

// A UV sphere: `rings` bands of latitude, `sectors` of longitude, outward.
inline TestMesh sphere_mesh(Vec3 c, double r, int rings, int sectors) {
  TestMesh m;
  m.vertices.push_back({c.x, c.y, c.z - r});
  for (int i = 1; i < rings; ++i) {
    const double th = std::numbers::pi * i / rings;
    for (int j = 0; j < sectors; ++j) {
      const double ph = 2 * std::numbers::pi * j / sectors;
      m.vertices.push_back(
          {c.x + r * std::sin(th) * std::cos(ph), c.y + r * std::sin(th) * std::sin(ph), c.z - r * std::cos(th)});
    }
  }
  m.vertices.push_back({c.x, c.y, c.z + r});
  const int top = static_cast<int>(m.vertices.size()) - 1;
  auto at = [&](int i, int j) { return 1 + (i - 1) * sectors + (j % sectors); };
  for (int j = 0; j < sectors; ++j) m.triangles.push_back({0, at(1, j + 1), at(1, j)});
  for (int i = 1; i + 1 < rings; ++i)
    for (int j = 0; j < sectors; ++j) {
      m.triangles.push_back({at(i, j), at(i, j + 1), at(i + 1, j + 1)});
      m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i + 1, j)});
    }
  for (int j = 0; j < sectors; ++j) m.triangles.push_back({at(rings - 1, j), at(rings - 1, j + 1), top});
  return m;
}

inline void put_float(std::string& out, float f) {
  char b[4];
  std::memcpy(b, &f, 4);
  out.append(b, 4);
}

inline std::string binary_stl(const TestMesh& m, std::string header = "trivox test") {
  std::string out = header;
  out.resize(80, '\0');
  const auto n = static_cast<std::uint32_t>(m.triangles.size());
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((n >> (8 * i)) & 0xFF));
  for (const auto& t : m.triangles) {
    for (int k = 0; k < 3; ++k) put_float(out, 0.0f);  // the normal, which readers recompute
    for (int v : t) {
      const Vec3 p = m.vertices[static_cast<std::size_t>(v)];
      put_float(out, static_cast<float>(p.x));
      put_float(out, static_cast<float>(p.y));
      put_float(out, static_cast<float>(p.z));
    }
    out.append(2, '\0');
  }
  return out;
}

inline std::string ascii_stl(const TestMesh& m) {
  std::string out = "solid test\n";
  for (const auto& t : m.triangles) {
    out += "  facet normal 0 0 0\n    outer loop\n";
    for (int v : t) {
      const Vec3 p = m.vertices[static_cast<std::size_t>(v)];
      out += fmt::format("      vertex {:.9g} {:.9g} {:.9g}\n", p.x, p.y, p.z);
    }
    out += "    endloop\n  endfacet\n";
  }
  return out + "endsolid test\n";
}

inline std::string obj_text(const TestMesh& m) {
  std::string out = "# trivox test\nmtllib absent.mtl\no test\n";
  for (const Vec3& p : m.vertices) out += fmt::format("v {:.17g} {:.17g} {:.17g}\n", p.x, p.y, p.z);
  for (const auto& t : m.triangles) out += fmt::format("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
  return out;
}

inline std::string ply_ascii(const TestMesh& m) {
  std::string out = fmt::format(
      "ply\nformat ascii 1.0\ncomment trivox test\nelement vertex {}\nproperty float x\nproperty float y\nproperty "
      "float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
      m.vertices.size(), m.triangles.size());
  for (const Vec3& p : m.vertices) out += fmt::format("{:.9g} {:.9g} {:.9g}\n", p.x, p.y, p.z);
  for (const auto& t : m.triangles) out += fmt::format("3 {} {} {}\n", t[0], t[1], t[2]);
  return out;
}

inline std::string ply_binary(const TestMesh& m) {
  std::string out = fmt::format(
      "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float "
      "z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
      m.vertices.size(), m.triangles.size());
  for (const Vec3& p : m.vertices) {
    put_float(out, static_cast<float>(p.x));
    put_float(out, static_cast<float>(p.y));
    put_float(out, static_cast<float>(p.z));
  }
  for (const auto& t : m.triangles) {
    out.push_back(3);
    for (int v : t) {
      char b[4];
      const auto u = static_cast<std::int32_t>(v);
      std::memcpy(b, &u, 4);
      out.append(b, 4);
    }
  }
  return out;
}

// The <mesh> element of a 3MF object.
inline std::string threemf_mesh(const TestMesh& m) {
  std::string out = "<mesh><vertices>";
  for (const Vec3& p : m.vertices)
    out += fmt::format("<vertex x=\"{:.9g}\" y=\"{:.9g}\" z=\"{:.9g}\"/>", p.x, p.y, p.z);
  out += "</vertices><triangles>";
  for (const auto& t : m.triangles) out += fmt::format("<triangle v1=\"{}\" v2=\"{}\" v3=\"{}\"/>", t[0], t[1], t[2]);
  return out + "</triangles></mesh>";
}

// A 3MF package (OPC zip: content types, the root relationship, the model part) around a
// model part's XML.
inline void write_3mf(const std::filesystem::path& path, const std::string& model_xml) {
  std::FILE* f = std::fopen(path.string().c_str(), "wb");
  if (f == nullptr) throw std::runtime_error("cannot write " + path.string());
  detail::ZipWriter zip(f, path.string());
  zip.add("[Content_Types].xml",
          "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<Types "
          "xmlns=\"http://schemas.openxmlformats.org/package/2006/content-types\"><Default Extension=\"rels\" "
          "ContentType=\"application/vnd.openxmlformats-package.relationships+xml\"/><Default Extension=\"model\" "
          "ContentType=\"application/vnd.ms-package.3dmanufacturing-3dmodel+xml\"/></Types>");
  zip.add("_rels/.rels",
          "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<Relationships "
          "xmlns=\"http://schemas.openxmlformats.org/package/2006/relationships\"><Relationship "
          "Target=\"/3D/3dmodel.model\" "
          "Id=\"rel0\" Type=\"http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel\"/></Relationships>");
  zip.add("3D/3dmodel.model", model_xml);
  zip.finish();
  std::fclose(f);
}

inline void write_bytes(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// A binary STL read here, independently of trivox's reader: float32 corners, no weld.
inline std::vector<std::array<Vec3, 3>> read_stl_soup(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::uint32_t n = 0;
  std::memcpy(&n, b.data() + 80, 4);
  std::vector<std::array<Vec3, 3>> out(n);
  for (std::uint32_t t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k) {
      float c[3];
      std::memcpy(c, b.data() + 84 + 50 * t + 12 + 12 * k, 12);
      out[t][static_cast<std::size_t>(k)] = {c[0], c[1], c[2]};
    }
  return out;
}

// Exact signs of orientation determinants of double coordinates: evaluated in doubles and
// trusted when the value clears a bound on the rounding error, otherwise again in integers
// (every double is an integer times a power of two; all are scaled to one exponent).
class ExactSign {
 public:
  using Int = boost::multiprecision::cpp_int;

  // Sign of (b - a) x (c - a) in 2D.
  static int orient2d(double ax, double ay, double bx, double by, double cx, double cy) {
    const double l = (bx - ax) * (cy - ay), r = (by - ay) * (cx - ax);
    const double det = l - r, bound = 1e-14 * (std::abs(l) + std::abs(r));
    if (det > bound) return 1;
    if (det < -bound) return -1;
    const double in[6] = {ax, ay, bx, by, cx, cy};
    Int v[6];
    scaled(in, 6, v);
    const Int d = (v[2] - v[0]) * (v[5] - v[1]) - (v[3] - v[1]) * (v[4] - v[0]);
    return d > 0 ? 1 : (d < 0 ? -1 : 0);
  }

  // Sign of det[b - a, c - a, d - a].
  static int orient3d(Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
    const Vec3 u = b - a, v = c - a, w = d - a;
    const double t0 = u.x * (v.y * w.z - v.z * w.y), t1 = u.y * (v.z * w.x - v.x * w.z),
                 t2 = u.z * (v.x * w.y - v.y * w.x);
    const double det = t0 + t1 + t2;
    const double perm = std::abs(u.x) * (std::abs(v.y * w.z) + std::abs(v.z * w.y)) +
                        std::abs(u.y) * (std::abs(v.z * w.x) + std::abs(v.x * w.z)) +
                        std::abs(u.z) * (std::abs(v.x * w.y) + std::abs(v.y * w.x));
    const double bound = 1e-14 * perm;
    if (det > bound) return 1;
    if (det < -bound) return -1;
    const double in[12] = {a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.x, d.y, d.z};
    Int q[12];
    scaled(in, 12, q);
    const Int ux = q[3] - q[0], uy = q[4] - q[1], uz = q[5] - q[2];
    const Int vx = q[6] - q[0], vy = q[7] - q[1], vz = q[8] - q[2];
    const Int wx = q[9] - q[0], wy = q[10] - q[1], wz = q[11] - q[2];
    const Int e = ux * (vy * wz - vz * wy) + uy * (vz * wx - vx * wz) + uz * (vx * wy - vy * wx);
    return e > 0 ? 1 : (e < 0 ? -1 : 0);
  }

 private:
  static void scaled(const double* in, int n, Int* out) {
    int lowest = 100000;
    for (int i = 0; i < n; ++i)
      if (in[i] != 0) {
        int e;
        std::frexp(in[i], &e);
        lowest = std::min(lowest, e - 53);
      }
    for (int i = 0; i < n; ++i) {
      if (in[i] == 0) {
        out[i] = 0;
        continue;
      }
      int e;
      const double m = std::frexp(in[i], &e);                          // in = m 2^e, 0.5 <= |m| < 1
      const auto mant = static_cast<std::int64_t>(std::ldexp(m, 53));  // exact: 53 bits
      out[i] = Int(mant) << (e - 53 - lowest);
    }
  }
};

// Whether p lies inside a closed triangle soup: the parity of the triangles a ray from p
// along +x, +y or +z crosses (the first axis whose ray meets no edge, vertex or plane of a
// triangle exactly), every decision an exact sign. `degenerate` is set when all three rays
// are degenerate (p on the surface, or aligned with it along every axis). `nearest_hit`
// receives the distance along the +x ray to the nearest triangle it meets (HUGE_VAL when none,
// the hits computed in doubles): the only thing that can move a scanline's decision at p.
class ExactRays {
 public:
  explicit ExactRays(std::vector<std::array<Vec3, 3>> triangles) : tris_(std::move(triangles)) {
    for (const auto& t : tris_) {
      Box3 b;
      for (const Vec3& p : t) b.expand(p);
      boxes_.push_back(b);
      bounds_.expand(b);
    }
    // Per axis, the triangles by a kGrid x kGrid grid of the two other coordinates (a
    // triangle in every cell its box overlaps): a ray looks at one cell's list.
    for (int axis = 0; axis < 3; ++axis) {
      auto& g = grids_[static_cast<std::size_t>(axis)];
      g.assign(kGrid * kGrid, {});
      for (std::size_t k = 0; k < tris_.size(); ++k) {
        const auto [u0, u1] = cells(axis, 1, boxes_[k]);
        const auto [v0, v1] = cells(axis, 2, boxes_[k]);
        for (int i = u0; i <= u1; ++i)
          for (int j = v0; j <= v1; ++j) g[static_cast<std::size_t>(i * kGrid + j)].push_back(static_cast<int>(k));
      }
    }
  }

  bool inside(Vec3 p, bool& degenerate, double& nearest_hit) const {
    nearest_hit = HUGE_VAL;
    degenerate = false;
    for (int axis = 0; axis < 3; ++axis) {
      bool bad = false;
      const bool in = ray(p, axis, bad, axis == 0 ? &nearest_hit : nullptr);
      if (!bad) return in;
    }
    degenerate = true;
    return false;
  }

 private:
  // The ray from p along +axis: parity of the triangles it crosses; `bad` when it meets one
  // in a degenerate way.
  bool ray(Vec3 p, int axis, bool& bad, double* nearest) const {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    bool inside = false;
    Box3 at;
    at.expand(p);
    const int cu = cells(axis, 1, at).first, cv = cells(axis, 2, at).first;
    for (int kk : grids_[static_cast<std::size_t>(axis)][static_cast<std::size_t>(cu * kGrid + cv)]) {
      const auto k = static_cast<std::size_t>(kk);
      const Box3& b = boxes_[k];
      // Triangles a little behind p still give the distance to their hit.
      if (b.hi[axis] < p[axis] - 1e-3 || b.lo[u] > p[u] || b.hi[u] < p[u] || b.lo[v] > p[v] || b.hi[v] < p[v]) continue;
      const auto& t = tris_[k];
      const int s = ExactSign::orient2d(t[0][u], t[0][v], t[1][u], t[1][v], t[2][u], t[2][v]);
      const int s0 = ExactSign::orient2d(t[0][u], t[0][v], t[1][u], t[1][v], p[u], p[v]);
      const int s1 = ExactSign::orient2d(t[1][u], t[1][v], t[2][u], t[2][v], p[u], p[v]);
      const int s2 = ExactSign::orient2d(t[2][u], t[2][v], t[0][u], t[0][v], p[u], p[v]);
      if (s == 0) {
        // The triangle is parallel to the ray: only a ray in its plane, through it, meets it.
        if (ExactSign::orient3d(t[0], t[1], t[2], p) == 0) bad = true;
        continue;
      }
      if ((s0 != 0 && s0 != s) || (s1 != 0 && s1 != s) || (s2 != 0 && s2 != s)) continue;
      if (s0 == 0 || s1 == 0 || s2 == 0) {
        bad = true;  // through an edge or a vertex of the projection
        continue;
      }
      // Which side of the plane p lies on decides whether the hit is ahead (see the test).
      const int o = ExactSign::orient3d(t[0], t[1], t[2], p);
      if (o == 0) {
        bad = true;  // p on the triangle
        continue;
      }
      const bool ahead = o == -s;
      if (nearest != nullptr) {
        const Vec3 n = cross(t[1] - t[0], t[2] - t[0]);
        const double along = -dot(n, p - t[0]) / n[axis];
        *nearest = std::min(*nearest, std::abs(along));
      }
      if (ahead) inside = !inside;
    }
    return inside;
  }

  static constexpr int kGrid = 64;
  // The grid cells [first, last] that coordinate (axis + which) % 3 of box b spans (clamped:
  // a point outside the mesh's box falls in an edge cell, which holds what it could meet).
  std::pair<int, int> cells(int axis, int which, const Box3& b) const {
    const int c = (axis + which) % 3;
    const double lo = bounds_.lo[c], size = std::max(bounds_.hi[c] - bounds_.lo[c], 1e-300);
    auto cell = [&](double x) {
      return static_cast<int>(std::clamp(std::floor((x - lo) / size * kGrid), 0.0, double(kGrid - 1)));
    };
    return {cell(b.lo[c]), cell(b.hi[c])};
  }

  std::vector<std::array<Vec3, 3>> tris_;
  std::vector<Box3> boxes_;
  Box3 bounds_;
  std::array<std::vector<std::vector<int>>, 3> grids_;
};

}  // namespace trivox::test
