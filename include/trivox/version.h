// The library's version (the CMake project version), recorded in every job manifest.
#pragma once

#include <string_view>

namespace trivox {

std::string_view version() noexcept;

}  // namespace trivox
