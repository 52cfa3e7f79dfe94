#include "trivox/slice/layout.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "trivox/error.h"
#include "trivox/limits.h"

namespace trivox {

SliceLayout make_layout(const Box3& bounds, const PrinterProfile& printer) {
  printer.validate();
  if (bounds.empty()) throw Error("cannot lay out slices of an empty model");
  SliceLayout l;
  l.pitch_x_mm = printer.pitch_x_mm();
  l.pitch_y_mm = printer.pitch_y_mm();
  l.layer_mm = printer.layer_thickness_mm;
  const Vec3 size = bounds.size();
  auto count = [&](double extent, double pitch, const char* axis, const char* field, double value) {
    const double n = std::ceil(extent / pitch - 1e-9);
    if (!(n < 1e7))
      throw Error(
          fmt::format("the model is {:g} mm along {}, which at printer '{}' {} = {:g} needs {:g} samples "
                      "(at most 1e7): is the model in mm, and the printer's {} right?",
                      extent, axis, printer.name, field, value, n, field));
    return std::max(1, static_cast<int>(n));
  };
  l.width_px = count(size.x, l.pitch_x_mm, "x", "x_dpi", printer.x_dpi);
  l.height_px = count(size.y, l.pitch_y_mm, "y", "y_dpi", printer.y_dpi);
  if (printer.display) {
    // A masked-resin printer's images are the bitmap centred on its display, as slicers
    // centre the model on the bed: a bitmap of the display's parity lies on its pixel grid.
    l.width_px += (printer.display->pixels_x - l.width_px) % 2 != 0 ? 1 : 0;
    l.height_px += (printer.display->pixels_y - l.height_px) % 2 != 0 ? 1 : 0;
  }
  l.num_layers = count(size.z, l.layer_mm, "z", "layer_thickness_mm", printer.layer_thickness_mm);
  const double layer_pixels = static_cast<double>(l.width_px) * l.height_px;
  if (layer_pixels > static_cast<double>(kMaxLayerPixels))
    throw Error(
        fmt::format("one layer would be {} x {} = {:g} pixels, above the limit of {:g}; is the model in mm, "
                    "and is the printer's resolution right?",
                    l.width_px, l.height_px, layer_pixels, static_cast<double>(kMaxLayerPixels)));
  // Centre the pixel grid on the model so the margin is split evenly on both sides.
  l.x0_mm = bounds.lo.x - 0.5 * (l.width_px * l.pitch_x_mm - size.x);
  l.y_top_mm = bounds.hi.y + 0.5 * (l.height_px * l.pitch_y_mm - size.y);
  l.z0_mm = bounds.lo.z - 0.5 * (l.num_layers * l.layer_mm - size.z);
  return l;
}

}  // namespace trivox
