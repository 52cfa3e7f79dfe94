// Where each layer and pixel of a job lies in model space.
//
// Frames: model coordinates are millimetres. The bitmap covers the bounding rectangle of the
// model in x and y at the printer's pitch; pixel (col, row) samples the point at its centre,
//   x = x0_mm + (col + 0.5) * pitch_x_mm,   y = y_top_mm - (row + 0.5) * pitch_y_mm,
// so row 0 is the top (largest y) and the image reads like a view from above with x to the
// right, x along the printer's X (600 dpi) axis. Layer l samples the plane at its centre,
//   z = z0_mm + (l + 0.5) * layer_mm.
#pragma once

#include "trivox/math.h"
#include "trivox/printer/printer_profile.h"

namespace trivox {

struct SliceLayout {
  double x0_mm = 0, y_top_mm = 0, z0_mm = 0;
  double pitch_x_mm = 0, pitch_y_mm = 0, layer_mm = 0;
  int width_px = 0, height_px = 0, num_layers = 0;

  double x_of_col(int col) const noexcept { return x0_mm + (col + 0.5) * pitch_x_mm; }
  double y_of_row(int row) const noexcept { return y_top_mm - (row + 0.5) * pitch_y_mm; }
  double z_of_layer(int layer) const noexcept { return z0_mm + (layer + 0.5) * layer_mm; }
  // Fractional column / row of a model-space coordinate (pixel centres at .0 + 0.5).
  double col_of_x(double x) const noexcept { return (x - x0_mm) / pitch_x_mm - 0.5; }
  double row_of_y(double y) const noexcept { return (y_top_mm - y) / pitch_y_mm - 0.5; }
};

// The layout that covers `bounds` (model mm) at the printer's resolution: whole pixels and
// layers, at least one of each. For a printer with a display (a masked-resin printer) the
// width and height take the display's parity, one pixel more where needed, so that the bitmap
// centred on the display lies on its pixel grid.
SliceLayout make_layout(const Box3& bounds, const PrinterProfile& printer);

}  // namespace trivox
