// Writes the outline mesh of every cell of a scene as one binary STL, for comparing trivox with
// a mesh slicer (bench/mesh_slicer_compare.py, docs/PERFORMANCE.md "Against a mesh slicer").
//
// The mesh is the one the slicer cuts into each layer's outline (src/slice/boundary_mesh.h):
// the six faces of the cell's volume (placement applied, printer mm) sampled on one grid
// shared by adjacent faces, refined until every grid cell lies within the outline tolerance
// of the true face, within the slicer's vertex budget. Trims are not applied. The triangles
// are turned to face outwards (consistently across shared edges, positive enclosed volume),
// since the slicer's mesh has no orientation of its own and a mesh slicer reads it from
// the triangles.
//
//   outline_stl SCENE OUT.stl [--tolerance-mm T] [--frame MARGIN_PX] [--count]
//
// --tolerance-mm T: the largest distance between a face and its triangles (default: the
//   slicer's, an eighth of the printer's finest pitch).
// --frame MARGIN_PX: moves the mesh so that trivox's bitmap of this scene, widened by
//   MARGIN_PX pixels on every side, starts at the origin: its left edge at x = 0, its bottom
//   edge at y = 0, the bottom of its stack of layers at z = 0 (whole pixels, so a pixel edge
//   of the bitmap falls on a pixel edge of a display that starts at the origin with the same
//   pitch). Two tetrahedra of 1 um are added below the first and above the last layer (at
//   z = 0 and at z = (layers + 0.25) * layer): no layer's plane cuts them, but they make the
//   mesh's box run from trivox's z0 to past its last layer, so that a slicer that stands the
//   mesh on its bed and slices at mid-layer heights from its bottom cuts it at trivox's
//   planes, and as many of them. Without --frame the mesh stays in model coordinates.
// --count: counts the pixel centres of trivox's grid inside the mesh (even-odd, every
//   layer), the count a centre-sampling mesh slicer would give; with several cells the
//   meshes are counted together, right for cells that do not overlap.
//
// Prints one JSON object on standard output: the layout of the bitmap, the mesh (triangles,
// vertices, samples per direction, the deviation measured), the translation applied and,
// with --count, the inside pixels (total and per layer).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "bench_support.h"
#include "slice/boundary_mesh.h"
#include "slice/scanline.h"
#include "trivox/error.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/slicer.h"

using namespace trivox;
using namespace trivox::bench;

namespace {

const char* arg_text(int argc, char** argv, const char* name) {
  for (int i = 1; i + 1 < argc; ++i)
    if (std::strcmp(argv[i], name) == 0) return argv[i + 1];
  return nullptr;
}

// The slicer's vertex budget (slicer.cpp, pixel_budget): about two vertices per pixel of the
// six faces of the cell's image box, from 2^14 to 2^24; here of the bitmap's frame, which is
// the image box widened by a quarter pitch and rounded up to whole pixels.
std::int64_t frame_budget(const SliceLayout& l) {
  const double w = l.width_px + 1.0, h = l.height_px + 1.0, n = l.num_layers + 1.0;
  return static_cast<std::int64_t>(std::clamp(2 * (w * h + h * n + n * w), double{1 << 14}, double{1 << 24}));
}

// Orients the triangles of a closed mesh consistently (two triangles sharing an edge run it
// in opposite directions), each connected part so that it encloses a positive volume. Returns
// the edges that are not shared by exactly two triangles (0 for a closed manifold mesh), and
// in `misoriented` the shared edges that two triangles still run the same way (0 unless this
// function is wrong).
std::size_t orient_outwards(const std::vector<Vec3>& vertices, std::vector<SlicedMesh::Triangle>& triangles,
                            std::size_t& misoriented) {
  misoriented = 0;
  struct EdgeUse {
    std::uint64_t key;
    int triangle;
  };
  std::vector<EdgeUse> uses;
  uses.reserve(3 * triangles.size());
  auto key_of = [](int a, int b) {
    return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint32_t>(std::max(a, b));
  };
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (int e = 0; e < 3; ++e)
      uses.push_back({key_of(triangles[t][e], triangles[t][(e + 1) % 3]), static_cast<int>(t)});
  std::sort(uses.begin(), uses.end(), [](const EdgeUse& a, const EdgeUse& b) {
    return a.key != b.key ? a.key < b.key : a.triangle < b.triangle;
  });
  // Each triangle's neighbour across each of its edges (-1: none or more than one).
  std::vector<std::array<int, 3>> across(triangles.size(), {-1, -1, -1});
  std::size_t bad_edges = 0;
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key) ++j;
    if (j - i == 2) {
      for (int s = 0; s < 2; ++s) {
        const int t = uses[i + s].triangle, other = uses[i + 1 - s].triangle;
        const auto& tri = triangles[static_cast<std::size_t>(t)];
        for (int e = 0; e < 3; ++e)
          if (key_of(tri[e], tri[(e + 1) % 3]) == uses[i].key) across[static_cast<std::size_t>(t)][e] = other;
      }
    } else {
      ++bad_edges;
    }
    i = j;
  }
  // Does triangle t run the edge (a, b) from a to b?
  auto runs = [&](int t, int a, int b) {
    const auto& tri = triangles[static_cast<std::size_t>(t)];
    for (int e = 0; e < 3; ++e)
      if (tri[e] == a && tri[(e + 1) % 3] == b) return true;
    return false;
  };
  std::vector<int> part(triangles.size(), -1);
  std::vector<int> stack;
  int parts = 0;
  for (std::size_t seed = 0; seed < triangles.size(); ++seed) {
    if (part[seed] >= 0) continue;
    std::vector<int> members;
    part[seed] = parts;
    stack.push_back(static_cast<int>(seed));
    while (!stack.empty()) {
      const int t = stack.back();
      stack.pop_back();
      members.push_back(t);
      // t is settled; `across` was found before any triangle was turned, so each shared
      // edge is found again by its vertices in t's present order.
      const auto tri = triangles[static_cast<std::size_t>(t)];
      for (const int n : across[static_cast<std::size_t>(t)]) {
        if (n < 0 || part[static_cast<std::size_t>(n)] >= 0) continue;
        const auto& other = triangles[static_cast<std::size_t>(n)];
        auto holds = [&](int v) { return other[0] == v || other[1] == v || other[2] == v; };
        for (int e = 0; e < 3; ++e) {
          if (!holds(tri[e]) || !holds(tri[(e + 1) % 3])) continue;
          // t runs the shared edge from tri[e] to tri[e + 1]: n must run it the other way.
          if (runs(n, tri[e], tri[(e + 1) % 3]))
            std::swap(triangles[static_cast<std::size_t>(n)][1], triangles[static_cast<std::size_t>(n)][2]);
          break;
        }
        part[static_cast<std::size_t>(n)] = parts;
        stack.push_back(n);
      }
    }
    // Six times the enclosed volume, by the divergence theorem (positive when the triangles
    // run counter-clockwise seen from outside).
    double volume6 = 0;
    for (int t : members) {
      const auto& tri = triangles[static_cast<std::size_t>(t)];
      volume6 += dot(vertices[static_cast<std::size_t>(tri[0])],
                     cross(vertices[static_cast<std::size_t>(tri[1])], vertices[static_cast<std::size_t>(tri[2])]));
    }
    if (volume6 < 0)
      for (int t : members)
        std::swap(triangles[static_cast<std::size_t>(t)][1], triangles[static_cast<std::size_t>(t)][2]);
    ++parts;
  }
  // The check of the above: every shared edge is now run once each way.
  for (std::size_t i = 0; i + 1 < uses.size(); ++i) {
    if (uses[i].key != uses[i + 1].key || (i + 2 < uses.size() && uses[i + 2].key == uses[i].key) ||
        (i > 0 && uses[i - 1].key == uses[i].key))
      continue;
    const int a = static_cast<int>(uses[i].key >> 32), b = static_cast<int>(uses[i].key & 0xFFFFFFFFu);
    if (runs(uses[i].triangle, a, b) == runs(uses[i + 1].triangle, a, b)) ++misoriented;
  }
  return bad_edges;
}

void put_f32(std::string& out, double v) {
  const auto f = static_cast<float>(v);
  char b[4];
  std::memcpy(b, &f, 4);  // little-endian hosts, as the library's writers
  out.append(b, 4);
}

void put_triangle(std::string& out, const Vec3& a, const Vec3& b, const Vec3& c) {
  Vec3 normal = cross(b - a, c - a);
  const double len = norm(normal);
  if (len > 0) normal = (1.0 / len) * normal;
  for (const Vec3& p : {normal, a, b, c}) {
    put_f32(out, p.x);
    put_f32(out, p.y);
    put_f32(out, p.z);
  }
  out.append(2, '\0');
}

// A tetrahedron of edge `size` with its base corner at `p`, facing outwards.
void put_marker(std::string& out, const Vec3& p, double size) {
  const Vec3 a = p, b = p + Vec3{size, 0, 0}, c = p + Vec3{0, size, 0}, d = p + Vec3{0, 0, size};
  put_triangle(out, a, c, b);
  put_triangle(out, a, b, d);
  put_triangle(out, a, d, c);
  put_triangle(out, b, c, d);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3 || argv[1][0] == '-' || argv[2][0] == '-') {
    std::fprintf(stderr, "usage: outline_stl SCENE OUT.stl [--tolerance-mm T] [--frame MARGIN_PX] [--count]\n");
    return 2;
  }
  try {
    const std::string scene_path = argv[1], out_path = argv[2];
    const Scene scene = read_scene(scene_path);
    // The slicer gives the layout (the frame and the layers come from the cells' tight image
    // boxes, never from the mesh) and the tolerance it uses by default.
    const Slicer slicer(scene, SliceParams{});
    const SliceLayout& L = slicer.layout();
    const double finest_pitch_mm = std::min({L.pitch_x_mm, L.pitch_y_mm, L.layer_mm});
    const double tolerance_mm = arg_double(argc, argv, "--tolerance-mm", 0.125 * finest_pitch_mm);
    const char* frame = arg_text(argc, argv, "--frame");
    const bool count = has_flag(argc, argv, "--count");
    const std::int64_t budget = frame_budget(L);

    std::vector<Vec3> vertices;
    std::vector<SlicedMesh::Triangle> triangles;
    double deviation_mm = 0;
    std::string samples;
    for (const Cell& c : scene.cells) {
      detail::BoundaryMesh built = detail::build_boundary_mesh(c.volume, tolerance_mm, budget);
      deviation_mm = std::max(deviation_mm, built.deviation_mm);
      samples += fmt::format("{}[{}, {}, {}]", samples.empty() ? "" : ", ", built.samples[0], built.samples[1],
                             built.samples[2]);
      const int offset = static_cast<int>(vertices.size());
      vertices.insert(vertices.end(), built.mesh.vertices().begin(), built.mesh.vertices().end());
      for (SlicedMesh::Triangle t : built.mesh.triangles())
        triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
    }
    std::size_t misoriented = 0;
    const std::size_t bad_edges = orient_outwards(vertices, triangles, misoriented);

    // The translation that puts the widened frame's lower left corner at the origin.
    Vec3 shift{0, 0, 0};
    int margin_px = 0;
    if (frame != nullptr) {
      margin_px = std::stoi(frame);
      shift = {-(L.x0_mm - margin_px * L.pitch_x_mm), -(L.y_top_mm - (L.height_px + margin_px) * L.pitch_y_mm),
               -L.z0_mm};
    }
    std::string out(80, '\0');
    const std::string header = "trivox outline_stl: the cells' outline meshes, mm";
    std::copy(header.begin(), header.end(), out.begin());
    const auto n = static_cast<std::uint32_t>(triangles.size() + (frame != nullptr ? 8 : 0));
    for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((n >> (8 * i)) & 0xFF));
    out.reserve(out.size() + 50 * static_cast<std::size_t>(n));
    for (const auto& t : triangles)
      put_triangle(out, vertices[static_cast<std::size_t>(t[0])] + shift,
                   vertices[static_cast<std::size_t>(t[1])] + shift, vertices[static_cast<std::size_t>(t[2])] + shift);
    if (frame != nullptr) {
      // Beside the model, at the frame's lower left pixel: 1 um, far below any slicer's detail.
      const Vec3 corner{0.25 * L.pitch_x_mm, 0.25 * L.pitch_y_mm, 0};
      put_marker(out, corner, 1e-3);
      put_marker(out, corner + Vec3{0, 0, (L.num_layers + 0.25) * L.layer_mm}, 1e-3);
    }
    std::ofstream file(out_path, std::ios::binary);
    file.write(out.data(), static_cast<std::streamsize>(out.size()));
    file.close();
    if (!file) throw IoError(fmt::format("{}: cannot write the STL", out_path));

    std::string counted;
    if (count) {
      const SlicedMesh mesh(vertices, triangles);
      std::vector<Segment2> segments;
      std::vector<std::vector<double>> rows;
      std::vector<std::pair<int, int>> runs;
      std::int64_t total = 0;
      std::string per_layer;
      for (int layer = 0; layer < L.num_layers; ++layer) {
        mesh.cut(L.z_of_layer(layer), segments);
        detail::shell_row_crossings(segments, L, rows);
        std::int64_t inside = 0;
        for (const auto& xs : rows) {
          detail::crossing_runs(xs, nullptr, true, L, runs);
          for (const auto& [c0, c1] : runs) inside += c1 - c0 + 1;
        }
        total += inside;
        per_layer += fmt::format("{}{}", layer ? ", " : "", inside);
      }
      counted =
          fmt::format(",\n \"mesh_pixels_inside\": {},\n \"mesh_pixels_inside_per_layer\": [{}]", total, per_layer);
    }
    fmt::print(
        "{{\"bitmap\": {{\"width_px\": {}, \"height_px\": {}, \"layers\": {}, \"x0_mm\": {:.17g}, \"y_top_mm\": "
        "{:.17g}, "
        "\"z0_mm\": {:.17g}, \"pitch_x_mm\": {:.17g}, \"pitch_y_mm\": {:.17g}, \"layer_mm\": {:.17g}}},\n"
        " \"frame_margin_px\": {}, \"shift_mm\": [{:.17g}, {:.17g}, {:.17g}], \"markers\": {},\n"
        " \"triangles\": {}, \"vertices\": {}, \"samples\": [{}], \"tolerance_mm\": {:.6g}, \"deviation_mm\": {:.6g}, "
        "\"vertex_budget\": {}, \"unpaired_edges\": {}, \"misoriented_edges\": {}{}}}\n",
        L.width_px, L.height_px, L.num_layers, L.x0_mm, L.y_top_mm, L.z0_mm, L.pitch_x_mm, L.pitch_y_mm, L.layer_mm,
        margin_px, shift.x, shift.y, shift.z, frame != nullptr ? 2 : 0, triangles.size(), vertices.size(), samples,
        tolerance_mm, deviation_mm, budget, bad_edges, misoriented, counted);
    return bad_edges == 0 && misoriented == 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "outline_stl: %s\n", e.what());
    return 1;
  }
}
