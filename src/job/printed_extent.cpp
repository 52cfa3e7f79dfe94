#include "trivox/job/printed_extent.h"

#include <algorithm>
#include <cstdint>
#include <cstring>

namespace trivox {

void PrintedExtent::add(const PrintedExtent& other) noexcept {
  if (other.empty()) return;
  col_lo = std::min(col_lo, other.col_lo);
  col_hi = std::max(col_hi, other.col_hi);
  row_lo = std::min(row_lo, other.row_lo);
  row_hi = std::max(row_hi, other.row_hi);
  layer_lo = std::min(layer_lo, other.layer_lo);
  layer_hi = std::max(layer_hi, other.layer_hi);
}

PrintedExtent printed_extent(const LabelImage& labels, int layer) {
  static_assert(LabelImage::kVoid == 0, "void rows are found as zero words");
  PrintedExtent e;
  const int width = labels.width_px();
  for (int y = 0; y < labels.height_px(); ++y) {
    const std::uint8_t* row = labels.row(y).data();
    // Most rows of a layer are empty or have long empty ends: skip them eight bytes at a time.
    int first = 0;
    auto empty8 = [row](int x) {
      std::uint64_t word;
      std::memcpy(&word, row + x, sizeof word);
      return word == 0;
    };
    while (first + 8 <= width && empty8(first)) first += 8;
    while (first < width && row[first] == 0) ++first;
    if (first == width) continue;
    int last = width - 1;
    while (last - 7 > first && empty8(last - 7)) last -= 8;
    while (row[last] == 0) --last;
    e.col_lo = std::min(e.col_lo, first);
    e.col_hi = std::max(e.col_hi, last);
    e.row_lo = std::min(e.row_lo, y);
    e.row_hi = y;
  }
  if (!e.empty()) e.layer_lo = e.layer_hi = layer;
  return e;
}

PrintedExtent printed_extent(const ManifestPrinted& recorded, int layer) {
  PrintedExtent e;
  e.col_lo = recorded.col_lo, e.col_hi = recorded.col_hi, e.row_lo = recorded.row_lo, e.row_hi = recorded.row_hi;
  e.layer_lo = e.layer_hi = layer;
  return e;
}

Box3 printed_box_mm(const PrintedExtent& e, const SliceLayout& L) {
  if (e.empty()) return {};
  Box3 box;
  box.lo = {L.x0_mm + e.col_lo * L.pitch_x_mm, L.y_top_mm - (e.row_hi + 1) * L.pitch_y_mm,
            L.z0_mm + e.layer_lo * L.layer_mm};
  box.hi = {L.x0_mm + (e.col_hi + 1) * L.pitch_x_mm, L.y_top_mm - e.row_lo * L.pitch_y_mm,
            L.z0_mm + (e.layer_hi + 1) * L.layer_mm};
  return box;
}

}  // namespace trivox
