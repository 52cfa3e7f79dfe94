// Damped Newton on V(u,v,w) = x inside a parameter box: the shared core of invert() and of
// the global solver's leaf step. The traced steps built on it, which the slicer's tracer
// uses too, are declared in trivox/inverse/detail/trace.h.
#pragma once

#include "trivox/inverse/detail/trace.h"
#include "trivox/inverse/invert.h"

namespace trivox::detail {

InverseResult newton_in_box(const Volume& volume, Vec3 x, Vec3 start, const ParamBox& box,
                            const InverseParams& params) noexcept;

}  // namespace trivox::detail
