#include "trivox/version.h"

namespace trivox {

std::string_view version() noexcept { return TRIVOX_VERSION_STRING; }

}  // namespace trivox
