// Limits shared by several layers of the library.
#pragma once

namespace trivox {

// Materials in one scene (besides void). Labels of dithered layers are bytes with 0 for void,
// and error diffusion keeps one error term per material and pixel, so the bound stays small.
inline constexpr int kMaxMaterials = 64;

// Pixels in one layer. A whole J750/J850 tray (490 x 390 mm at 600 x 300 dpi) is 5.3e7
// pixels; each pixel of a layer in flight costs some tens of bytes, so beyond this a job is a
// unit or resolution mistake that would exhaust memory, and it is refused up front.
inline constexpr long long kMaxLayerPixels = 1LL << 30;

}  // namespace trivox
