// B-spline basis functions and their derivatives (The NURBS Book, Algorithms A2.2, A2.3).
// Allocation-free: callers pass output arrays of at least the sizes stated.
#pragma once

#include "trivox/spline/knot_vector.h"

namespace trivox {

// The k = order non-zero basis functions N_{s-k+1..s} at t in span s (from find_span):
// out[0..k-1].
void basis_functions(const KnotVector& kv, int span, double t, double* out) noexcept;

// Values and derivatives up to order n (n <= degree is meaningful; higher ones are 0):
// ders[d * k + j] is the d-th derivative of N_{s-k+1+j} at t, for d = 0..n, j = 0..k-1.
// `ders` must hold (n + 1) * k values.
void basis_derivatives(const KnotVector& kv, int span, double t, int n, double* ders) noexcept;

}  // namespace trivox
