// Knot insertion and subdivision (The NURBS Book, A5.1 and Section 5.3). Both leave the
// geometry unchanged; they work on homogeneous coordinates, so rational splines are exact.
#pragma once

#include <utility>
#include <vector>

#include "trivox/math.h"
#include "trivox/spline/tensor_spline.h"

namespace trivox {

// Inserts t `times` times along direction `dir`. A periodic direction is first converted to
// the equivalent unclamped one. Throws ModelError when t is outside the domain or the
// resulting multiplicity would exceed the order.
TensorSpline insert_knot(const TensorSpline& s, int dir, double t, int times = 1);

// Splits along `dir` at an interior parameter t into the parts over [lo, t] and [t, hi],
// each clamped at the cut (and at its other end).
std::pair<TensorSpline, TensorSpline> split(const TensorSpline& s, int dir, double t);

// The part of a spline over a parameter sub-box, clamped on every side: its control points
// are the tight control hull of that piece (used for conservative bounds).
TensorSpline restrict_to(const TensorSpline& s, std::span<const double> lo, std::span<const double> hi);

// Unwraps periodic directions and clamps both ends of every direction, without changing the
// geometry over the domain. A clamped spline is returned unchanged.
TensorSpline clamped(const TensorSpline& s);

// Splits a spline into its polynomial pieces, each a Bezier patch on its own knot span
// (knots inserted to full multiplicity), ordered u fastest, then v, then w.
std::vector<TensorSpline> bezier_patches(const TensorSpline& s);

}  // namespace trivox
