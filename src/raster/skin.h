// The skin of an inside mask: the pixels within k 8-neighbour steps of the outside (masked
// pixels and everything beyond the image border). Used by the dithering (dither.h).
#pragma once

#include <cstdint>

#include "trivox/raster/material_grid.h"

namespace trivox::detail {

// Per pixel: 0 outside the mask; for an inside pixel, its chessboard distance to the nearest
// outside pixel or to the outside of the image (1 on the border row of a part), capped at
// cap. Two passes of the classic chamfer propagation, exact for the chessboard metric.
PixelPlane<std::uint16_t> chessboard_depth(const InsideMask& inside, std::uint16_t cap);

}  // namespace trivox::detail
