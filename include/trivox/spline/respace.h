// Changes of spline space that keep the geometry: degree elevation, re-expression in a
// finer space, affine reparametrization, direction permutation; and interpolation of points
// at given parameters, which the exact re-expressions are built on.
//
// Method: a spline whose space S is contained in a target space T (higher degree, and every
// knot at least as often as in S plus the degree raise) equals its interpolant in T at any
// Schoenberg-Whitney point set, here T's Greville abscissae. Interpolating in homogeneous
// coordinates keeps rational splines exact. This is a simple exact alternative to The NURBS
// Book's A5.9 (degree elevation by Bezier extraction and knot removal): one dense solve per
// direction, exact up to rounding.
#pragma once

#include <array>
#include <span>
#include <vector>

#include "trivox/spline/tensor_spline.h"

namespace trivox {

// Greville abscissae of a basis: xi_i = (t_{i+1} + ... + t_{i+p}) / p (the knot averages;
// for order 1 the span midpoints). Sum_i xi_i N_i(t) = t (linear precision).
std::vector<double> greville_abscissae(const KnotVector& kv);

// Control values c (num_basis x dim, row-major) of the spline sum_i c_i N_i(t) through
// values[k] at params[k], k = 0..num_basis-1. Throws ModelError when the collocation matrix
// is singular (the parameters break the Schoenberg-Whitney condition) or counts disagree.
std::vector<double> interpolate_values(const KnotVector& kv, std::span<const double> params,
                                       std::span<const double> values, int dim);

// The same geometry expressed along `dir` in the (clamped, non-periodic) space of `target`,
// which must contain the spline's space over the same domain. Throws ModelError when the
// domains differ or the target space does not contain the spline's (checked: the order is
// not lower, and every interior knot's multiplicity is at least its multiplicity in the
// spline plus the order raise).
TensorSpline respace(const TensorSpline& s, int dir, const KnotVector& target);

// Raises the degree along `dir` by `times` (>= 0), every interior knot's multiplicity raised
// by as much, so that the continuity is kept. The spline is first clamped (refine.h).
TensorSpline elevate_degree(const TensorSpline& s, int dir, int times);

// The knot vector of s along `dir` after elevating by `times` (what elevate_degree uses).
KnotVector elevated_knots(const KnotVector& clamped_kv, int times);

// The same geometry with its domain along `dir` mapped affinely onto [lo, hi] (lo < hi).
TensorSpline reparametrized(const TensorSpline& s, int dir, double lo, double hi);

// Reorders the parametric directions: direction d of the result is direction order[d] of
// s (a permutation of 0..param_dim-1). The image is unchanged; the Jacobian's sign flips
// for odd permutations.
TensorSpline permuted(const TensorSpline& s, std::span<const int> order);

// The same geometry with direction `dir` reversed: parameter t becomes lo + hi - t.
TensorSpline reversed(const TensorSpline& s, int dir);

}  // namespace trivox
