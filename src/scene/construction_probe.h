// A volume taken from the construction cache, checked at a few points against the inputs
// that build it before it is trusted (docs/SLICING.md, "The construction cache"). An entry's
// SHA-256 only says that its bytes are the bytes that were written; an entry replaced by
// another tool or person, its digest recomputed, passes that. Every constructor states an
// exact relation between its inputs and the faces of its volume (construct/*.h): the probe
// evaluates both sides at a few parameter points and names the first that disagrees. It costs
// some tens of evaluations, far less than building the volume.
#pragma once

#include <array>
#include <optional>
#include <span>
#include <string>

#include "trivox/construct/report.h"
#include "trivox/construct/revolve.h"
#include "trivox/construct/shell.h"
#include "trivox/spline/tensor_spline.h"

namespace trivox::detail {

// The volume's face where direction `fixed` is at the low (or, `at_hi`, the high) end of its
// domain, parametrized by its directions `dirs` in that order, equals `surface` moved by
// `offset_mm`, each domain mapped linearly onto the other (the faces of extrude, ruled and
// coons volumes, the profile of a revolved one).
struct FaceProbe {
  const TensorSpline* surface = nullptr;
  int fixed = 2;
  bool at_hi = false;
  std::array<int, 2> dirs{0, 1};
  Vec3 offset_mm{};
};

// nullopt when the volume agrees with every face; else where it does not.
std::optional<std::string> probe_faces(const Volume& volume, std::span<const FaceProbe> faces);
// A Coons volume interpolates its six faces (coons.h; u0, u1, v0, v1, w0, w1 in that order);
// untangling moves interior control points only.
std::optional<std::string> probe_coons(const Volume& volume, const std::array<TensorSpline, 6>& faces);
// A revolved volume: its first face is the profile; at the far end of the angle each probed
// point keeps its height along the axis and its distance from it, turned by the angle.
std::optional<std::string> probe_revolve(const Volume& volume, const TensorSpline& profile, const RevolveParams& p);
// A swept volume: at both ends of the path each point of the section lies as far from the
// path's end as from the section's origin (the frame is orthonormal, the twist a rotation).
std::optional<std::string> probe_sweep(const Constructed& built, const TensorSpline& section, const TensorSpline& path);
// A thick shell: at the corners of the surface (Greville abscissae, where the offset is
// interpolated) its two faces lie `thickness_mm` apart along a line through the surface.
std::optional<std::string> probe_shell(const Constructed& built, const TensorSpline& surface, const ShellParams& p);

}  // namespace trivox::detail
