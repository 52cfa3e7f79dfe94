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

// Control points of one patch of a model file (all directions together). Readers check every
// count from a file against these before they allocate anything for it, so a corrupt or
// hostile header is an error naming the file and line, not an allocation of gigabytes.
inline constexpr long long kMaxModelControlPoints = 100'000'000;
// Coordinates per control point in a model file (G+Smo's geoDim, GoTools' dimension).
inline constexpr int kMaxModelPointDim = 1000;
// Auxiliary integers in the header of one GoTools object (a colour takes 4).
inline constexpr int kMaxModelHeaderValues = 1000;

}  // namespace trivox
