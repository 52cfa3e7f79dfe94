// Limits shared by several layers of the library.
#pragma once

namespace trivox {

// Materials in one scene (besides void). Labels of dithered layers are bytes with 0 for void,
// and error diffusion keeps one error term per material and pixel, so the bound stays small.
inline constexpr int kMaxMaterials = 64;

}  // namespace trivox
