# One interface target carries the project's warning, sanitizer and tuning flags, so every
# trivox target gets the same set by linking it.
add_library(trivox_options INTERFACE)
target_compile_options(trivox_options INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion
  -Wnon-virtual-dtor -Wold-style-cast -Woverloaded-virtual -Wimplicit-fallthrough)
# sqrt and the like need not set errno (nothing reads it): the compiler can then use the
# instruction alone, and vectorize it, with the same correctly rounded results.
target_compile_options(trivox_options INTERFACE -fno-math-errno)
# The compiler fuses no multiply and add by itself (its choice depends on the target and on
# inlining, so the numbers would depend on the processor the kernels were compiled for); the
# kernels fuse where they say so (src/spline/kernel_arithmetic-inl.h). Slices are then the same
# bytes from every build and every SIMD target that has the fused instruction.
target_compile_options(trivox_options INTERFACE -ffp-contract=off)
# The SIMD targets the kernels are compiled for: the portable fallback (EMU128), SSE4, AVX2 and
# AVX-512 (Highway's AVX3); SSSE3 and AVX3_DL would add compile time and nothing these kernels use.
# The kernels pass four-double vectors (V4) by value only among functions compiled for one
# target (what crosses targets, spline/homogeneous.h's load, is always inlined), so GCC's note
# that such a vector's calling convention differs with and without AVX concerns no call here.
target_compile_options(trivox_options INTERFACE -Wno-psabi)
target_compile_definitions(trivox_options INTERFACE "HWY_DISABLED_TARGETS=(HWY_SSSE3|HWY_AVX3_DL)")
if(TRIVOX_WERROR)
  target_compile_options(trivox_options INTERFACE -Werror)
endif()
if(TRIVOX_BUILD_FUZZERS)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "TRIVOX_BUILD_FUZZERS needs clang (libFuzzer): configure with "
                        "-DCMAKE_CXX_COMPILER=clang++ or use the preset 'fuzz'")
  endif()
  if(TRIVOX_SANITIZE AND NOT TRIVOX_SANITIZE STREQUAL "address" AND NOT TRIVOX_SANITIZE STREQUAL "ON")
    message(FATAL_ERROR "TRIVOX_BUILD_FUZZERS builds with AddressSanitizer; TRIVOX_SANITIZE=${TRIVOX_SANITIZE} conflicts")
  endif()
  # Coverage instrumentation everywhere; the fuzz targets alone link libFuzzer's main.
  target_compile_options(trivox_options INTERFACE -fsanitize=fuzzer-no-link)
  set(TRIVOX_SANITIZE address)
endif()
if(TRIVOX_SANITIZE STREQUAL "thread")
  target_compile_options(trivox_options INTERFACE -fsanitize=thread -fno-omit-frame-pointer)
  target_link_options(trivox_options INTERFACE -fsanitize=thread)
elseif(TRIVOX_SANITIZE)
  target_compile_options(trivox_options INTERFACE
    -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)
  target_link_options(trivox_options INTERFACE -fsanitize=address,undefined)
  # Checks clang leaves out of other projects' headers, each entry explained in the file (GCC
  # reports none there and has no such option).
  if(CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    target_compile_options(trivox_options INTERFACE
      "-fsanitize-ignorelist=${PROJECT_SOURCE_DIR}/tests/asan/ubsan_ignorelist.txt")
  endif()
endif()
# The sanitizer builds keep line tables only (GCC's -g1, clang's -gline-tables-only): their
# reports name every frame's function, file and line, and the builds take about a fifth less
# time than with full debug information (CI builds three of them; docs/RELIABILITY.md).
if(TRIVOX_SANITIZE)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    target_compile_options(trivox_options INTERFACE -gline-tables-only)
  else()
    target_compile_options(trivox_options INTERFACE -g1)
  endif()
endif()
# The library's invariant checks (src/check.h) run in the sanitizer and Debug builds.
if(TRIVOX_SANITIZE OR CMAKE_BUILD_TYPE STREQUAL "Debug")
  target_compile_definitions(trivox_options INTERFACE TRIVOX_CHECKS=1)
endif()
if(TRIVOX_NATIVE)
  target_compile_options(trivox_options INTERFACE -march=native)
endif()
