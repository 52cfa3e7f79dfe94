// Limits shared by several layers of the library.
//
// Every count or size that comes from input (knots, control points, pixels, layers, texture
// dimensions, mesh sizes) is checked against these with product_within() before anything
// is allocated for it, so that no product overflows and no input makes the library ask for
// more memory than the limit allows.
#pragma once

#include <cstdint>
#include <optional>

namespace trivox {

// Control points of one spline, all directions together. 1e8 homogeneous points are 3.2 GB:
// the largest spline a reader or a constructor accepts.
inline constexpr std::int64_t kMaxControlPoints = 100'000'000;

// a * b when both are >= 0 and the product is at most `limit`; nullopt when it exceeds the
// limit (or would overflow 64 bits, which a limit below 2^63 implies).
constexpr std::optional<std::int64_t> product_within(std::int64_t a, std::int64_t b, std::int64_t limit) noexcept {
  if (a < 0 || b < 0 || limit < 0) return std::nullopt;
  if (a != 0 && b > limit / a) return std::nullopt;
  return a * b;
}

// Triangles of one triangle mesh read from a file (a mesh trim), after a 3MF file's
// components and build items are instanced. 5e7 triangles are a 2.5 GB binary STL; welded,
// checked and bucketed by height they take about 4 GB.
inline constexpr std::int64_t kMaxMeshTriangles = 50'000'000;

// Bytes a mesh trim takes per triangle at its peak, while it is read, placed and checked: the
// file's welded arrays and the weld's index, the placed copy, the sliced mesh and its height
// buckets, and the check's edge uses, boxes, cell ranges and at most 8 grid entries
// (mesh/detail/mesh_check.h), with two vertices a triangle as a closed mesh has.
inline constexpr std::int64_t kMeshTrimBytesPerTriangle = 400;

// The memory this process may use: the machine's physical memory, lowered to RLIMIT_AS when
// that is set; nullopt when neither is known. The budget up-front refusals measure against.
std::optional<std::uint64_t> process_memory_limit_bytes();

// A job's memory limit from a setting in MB (the program's --memory-limit, Python's
// memory_limit_mb): that many bytes when positive (beyond 1.8e13 MB, 2^64 bytes, a limit is no
// limit), else process_memory_limit_bytes().
std::optional<std::uint64_t> memory_limit_from_mb(double megabytes);

// Triangles one mesh file may have: kMaxMeshTriangles, lowered so that a mesh trim at its peak
// (kMeshTrimBytesPerTriangle) takes at most half of process_memory_limit_bytes(), the other
// half being the job's. A 3 MB 3MF that instances 20 million triangles is then refused before
// they are allocated on a machine (or under a limit) of less than 16 GB.
std::int64_t mesh_triangle_limit();

// Bytes one model or mesh file may have, checked before it is read: a tenth of
// process_memory_limit_bytes() (no limit when that is unknown). A model's text parses into
// doubles of up to four times its size (a number may be written in two characters), so the
// file and its parse take at most half of the memory, the other half being the job's.
std::uint64_t input_file_byte_limit();

// Materials in one scene (besides void). Labels of dithered layers are bytes with 0 for void,
// and error diffusion keeps one error term per material and pixel, so the bound stays small.
inline constexpr int kMaxMaterials = 64;

// Pixels in one layer. A whole J750/J850 tray (490 x 390 mm at 600 x 300 dpi) is 5.3e7
// pixels; each pixel of a layer in flight costs some tens of bytes, so beyond this a job is a
// unit or resolution mistake that would exhaust memory, and it is refused up front.
inline constexpr long long kMaxLayerPixels = 1LL << 30;

// The largest magnitude of a number read from a model file (a coordinate, a knot, a weight) or
// of a length a constructor takes (a shell's thickness). det J multiplies three derivatives
// and the inverse squares distances: past about 1e100 these overflow a double (1.8e308), and
// no printable object is measured in such numbers, so they are refused where they are read,
// as overflowing, rather than found later as an infinite or undefined det J.
inline constexpr double kMaxModelNumber = 1e100;

// The largest ratio of one spline's largest weight to its smallest. Weights from 1e-6 to 1e6
// (a ratio of 1e12) are legal and sliced; far beyond, the weights squeeze most of the image
// into a slab of the parameter domain thinner than a double resolves next to the knots (a
// cell weighted 1e-3 to 1e300 maps a whole box onto parameters that round to one value), so
// the inversion cannot find its points and spends minutes failing. Such a spline is refused
// where it is built, with a message about the weights' range.
inline constexpr double kMaxWeightRatio = 1e12;

// Coordinates per control point in a model file (G+Smo's geoDim, GoTools' dimension).
inline constexpr int kMaxModelPointDim = 1000;
// Auxiliary integers in the header of one GoTools object (a colour takes 4).
inline constexpr int kMaxModelHeaderValues = 1000;

}  // namespace trivox
