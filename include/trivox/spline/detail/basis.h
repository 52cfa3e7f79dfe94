// Internal to trivox, not part of its stable interface (docs/ARCHITECTURE.md, "Public surface").

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

// Values and first derivatives only, the hot path of evaluation with Jacobian: one pass of
// A2.2 to degree p - 1, then the last step produces the values and, from the same degree
// p - 1 functions, N'_{i,p} = p N_{i,p-1} / (t_{i+p} - t_i) - p N_{i+1,p-1} / (t_{i+p+1} - t_{i+1})
// (The NURBS Book, Eq. 2.7). `values` and `derivs` each receive `order` values.
void basis_first_derivatives(const KnotVector& kv, int span, double t, double* values, double* derivs) noexcept;

}  // namespace trivox
