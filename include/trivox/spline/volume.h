// Volume: a trivariate with 3D points (polynomial or rational) and the fast evaluators the
// slicer and the inverse map run per voxel: value, and value plus Jacobian in one pass.
// Construction packs the control points as homogeneous (w*x, w*y, w*z, w) rows with periodic
// directions unwrapped, so evaluation is branch-free tensor contraction with no allocation.
#pragma once

#include <array>
#include <vector>

#include "trivox/math.h"
#include "trivox/spline/tensor_spline.h"

namespace trivox {
namespace detail {
struct VolumeData;
}

class Volume {
 public:
  // Throws ModelError unless the spline has param_dim 3 and point_dim 3.
  explicit Volume(TensorSpline spline);

  const TensorSpline& spline() const noexcept { return spline_; }
  const ParamBox& domain() const noexcept { return domain_; }
  std::array<int, 3> orders() const noexcept {
    return {spline_.knots(0).order(), spline_.knots(1).order(), spline_.knots(2).order()};
  }

  // V(u,v,w). Parameters are clamped to the domain.
  Vec3 evaluate(Vec3 uvw) const noexcept;

  // V and its Jacobian (column c = dV/d(param c)) in one pass.
  void evaluate_jacobian(Vec3 uvw, Vec3& value, Mat3& jacobian) const noexcept;

  // Box of all Euclidean control points: contains the whole image.
  const Box3& bounds() const noexcept { return bounds_; }

  // Conservative bounds of the image of a parameter sub-box: the box of the control points
  // whose basis support meets `box` (convex hull property; weights are positive).
  Box3 bounds(const ParamBox& box) const noexcept;

 private:
  TensorSpline spline_;
  ParamBox domain_;
  Box3 bounds_;
  std::array<int, 3> num_basis_{};
  // Homogeneous control points, basis-index layout (periodic directions unwrapped), u fastest.
  std::vector<std::array<double, 4>> hpoints_;
  // Kernels specialised for this volume's orders (chosen once, in the constructor).
  Vec3 (*evaluate_fn_)(const detail::VolumeData&, Vec3) noexcept = nullptr;
  void (*evaluate_jacobian_fn_)(const detail::VolumeData&, Vec3, Vec3&, Mat3&) noexcept = nullptr;
  detail::VolumeData data() const noexcept;
};

}  // namespace trivox
