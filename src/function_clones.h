// TRIVOX_CLONED: scalar code on the per-voxel path that is not a SIMD kernel (the tracer's
// bookkeeping, Newton's step checks, painting a row, a material's row) but gains from the
// instructions of newer processors all the same (three-operand AVX forms without false
// dependencies, rounding instructions, BMI). GCC compiles such a function twice, for every
// x86-64 processor and for x86-64-v3 (AVX2, FMA, BMI2), and the dynamic loader picks one for
// the processor (function multi-versioning). The two give the same numbers: the project
// compiles with -ffp-contract=off, so neither fuses a multiply-add the source does not name.
// Only in GCC builds for x86-64 that are neither tuned for the building machine (which has
// AVX2 everywhere then) nor sanitized; elsewhere the macro is empty and the function is
// built once.
#pragma once

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && !defined(__AVX2__) && \
    !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
#define TRIVOX_CLONED __attribute__((target_clones("default", "arch=x86-64-v3")))
#else
#define TRIVOX_CLONED
#endif
