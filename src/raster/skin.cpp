#include "raster/skin.h"

#include <algorithm>

namespace trivox::detail {

PixelPlane<std::uint16_t> chessboard_depth(const InsideMask& inside, std::uint16_t cap) {
  const int w = inside.width_px();
  const int h = inside.height_px();
  PixelPlane<std::uint16_t> depth(w, h, 0);
  // Outside the image counts as outside the part: depth 0.
  auto at = [&](int x, int y) -> int { return x < 0 || y < 0 || x >= w || y >= h ? 0 : depth.at(x, y); };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (!inside.inside(x, y)) continue;
      const int d = std::min({at(x - 1, y), at(x - 1, y - 1), at(x, y - 1), at(x + 1, y - 1)}) + 1;
      depth.at(x, y) = static_cast<std::uint16_t>(std::min<int>(d, cap));
    }
  }
  for (int y = h - 1; y >= 0; --y) {
    for (int x = w - 1; x >= 0; --x) {
      if (!inside.inside(x, y)) continue;
      const int d = std::min({at(x + 1, y), at(x + 1, y + 1), at(x, y + 1), at(x - 1, y + 1)}) + 1;
      depth.at(x, y) = static_cast<std::uint16_t>(std::min<int>({d, depth.at(x, y), cap}));
    }
  }
  return depth;
}

}  // namespace trivox::detail
