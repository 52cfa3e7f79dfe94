// Coons (transfinite, trilinearly blended) volume from the six boundary surfaces of a
// cube-topology solid: V = P_u + P_v + P_w - P_uv - P_uw - P_vw + P_uvw, the Boolean sum of
// the linear interpolants between opposite faces (Gordon's transfinite interpolation, as in
// Farin, "Curves and Surfaces for CAGD", Chapter 22). The faces are made compatible (their
// domains mapped onto [0,1]^2, degrees raised and knots inserted, exact), after which the
// Coons volume is itself a tensor-product spline: its control points follow from the same
// formula applied to the faces' control points, the linear blends taken at the Greville
// abscissae (linear precision). So the volume interpolates its six faces exactly.
#pragma once

#include <array>
#include <vector>

#include "trivox/construct/report.h"
#include "trivox/spline/tensor_spline.h"

namespace trivox {

// The six faces, each a surface (2 parameters, 3D points) whose parameters are the volume's
// parameters along that face:
//   u0, u1: the faces u = 0 and u = 1, parametrized by (v, w);
//   v0, v1: v = 0 and v = 1, parametrized by (u, w);
//   w0, w1: w = 0 and w = 1, parametrized by (u, v).
// Faces meeting at an edge must agree along it (same curve, same parametrization).
enum CoonsFace { kFaceU0, kFaceU1, kFaceV0, kFaceV1, kFaceW0, kFaceW1 };

struct CoonsParams {
  // Two faces share an edge when their (homogeneous) control points along it agree within
  // this fraction of the faces' control-box diagonal.
  double edge_tolerance_relative = 1e-9;
  JacobianCheckParams check{9};
};

// Throws ModelError naming the two faces and the edge when faces do not share an edge, and
// when rational faces blend into a non-positive weight.
Constructed coons(const std::array<TensorSpline, 6>& faces, const CoonsParams& params = {});

// The name of a face ("u0", ...), for messages.
const char* coons_face_name(int face) noexcept;

// Six surfaces of a closed shell of cube topology given in any order and orientation (the
// patches of a B-rep, e.g. G+Smo's duck), arranged as Coons faces: the first surface
// becomes w0 with its own (u, v); the others are matched by their corners and turned
// (parameters swapped and/or reversed, exact) to run as coons() expects. Corners closer than
// `tolerance_relative` times the shell's control-box diagonal are the same vertex. Throws
// ModelError when the corners do not make the 8 vertices and 12 edges of a cube.
std::array<TensorSpline, 6> arrange_cube_faces(const std::vector<TensorSpline>& surfaces,
                                               double tolerance_relative = 1e-9);

}  // namespace trivox
