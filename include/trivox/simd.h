// The SIMD targets of the evaluation kernels. The kernels that evaluate volumes and bound
// Bezier nets are compiled once per target (the portable fallback, SSE4, AVX2, AVX-512) and
// the best one this processor supports is used (docs/ARCHITECTURE.md, "SIMD targets"). The
// targets with a fused multiply-add (AVX2, AVX-512) give the same slices bit for bit; the
// others round each multiply-add twice, which moves fractions by far less than 1e-12
// (docs/PERFORMANCE.md, "SIMD targets").
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace trivox {

// The targets compiled into this build that this processor supports, best first, by the
// names use_simd_target accepts: some of "avx512", "avx2", "sse4" and always "baseline".
std::vector<std::string> simd_targets();

// The target the kernels run on now (the first of simd_targets() unless restricted).
std::string simd_target();

// Restricts the kernels to `name` (one of simd_targets()) or, with "best", lifts the
// restriction. Affects the volumes built afterwards (a Volume keeps the kernels it was built
// with); call it before reading a scene. The environment variable TRIVOX_SIMD, read by the
// trivox program at start, calls this. Throws InputError naming the accepted names when
// `name` is unknown or the processor lacks it.
void use_simd_target(std::string_view name);

}  // namespace trivox
