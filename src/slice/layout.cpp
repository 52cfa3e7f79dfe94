#include "trivox/slice/layout.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "trivox/error.h"

namespace trivox {

SliceLayout make_layout(const Box3& bounds, const PrinterProfile& printer) {
  printer.validate();
  if (bounds.empty()) throw Error("cannot lay out slices of an empty model");
  SliceLayout l;
  l.pitch_x_mm = printer.pitch_x_mm();
  l.pitch_y_mm = printer.pitch_y_mm();
  l.layer_mm = printer.layer_thickness_mm;
  const Vec3 size = bounds.size();
  auto count = [](double extent, double pitch) {
    const double n = std::ceil(extent / pitch - 1e-9);
    if (!(n < 1e7)) throw Error(fmt::format("the model needs {} samples of {} mm along one axis; is it in mm?", n, pitch));
    return std::max(1, static_cast<int>(n));
  };
  l.width_px = count(size.x, l.pitch_x_mm);
  l.height_px = count(size.y, l.pitch_y_mm);
  l.num_layers = count(size.z, l.layer_mm);
  // Centre the pixel grid on the model so the margin is split evenly on both sides.
  l.x0_mm = bounds.lo.x - 0.5 * (l.width_px * l.pitch_x_mm - size.x);
  l.y_top_mm = bounds.hi.y + 0.5 * (l.height_px * l.pitch_y_mm - size.y);
  l.z0_mm = bounds.lo.z - 0.5 * (l.num_layers * l.layer_mm - size.z);
  return l;
}

}  // namespace trivox
