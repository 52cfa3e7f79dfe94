// The layout's size limits: a model or printer resolution that would need more samples than
// a job can hold is refused with a message naming the axis and the printer field.
#include "trivox/slice/layout.h"

#include <string>

#include <gtest/gtest.h>

#include "trivox/error.h"
#include "trivox/limits.h"
#include "trivox/printer/printer_profile.h"

namespace trivox {
namespace {

PrinterProfile paper_printer() {
  PrinterProfile p;
  p.name = "test";
  p.layer_thickness_mm = 0.03;
  return p;  // 600 x 300 dpi
}

std::string layout_error(const Box3& box, const PrinterProfile& printer) {
  try {
    make_layout(box, printer);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(SliceLayout, TrayPrintIsLaidOutInWholePixels) {
  const SliceLayout l = make_layout(Box3{{0, 0, 0}, {490, 390, 1}}, paper_printer());
  EXPECT_EQ(l.width_px, 11575);  // ceil(490 mm / (25.4 / 600) mm)
  EXPECT_EQ(l.height_px, 4607);  // ceil(390 mm / (25.4 / 300) mm)
  EXPECT_EQ(l.num_layers, 34);   // ceil(1 / 0.03)
}

TEST(SliceLayout, TooManySamplesAlongOneAxisNameTheAxisAndField) {
  PrinterProfile fine = paper_printer();
  fine.x_dpi = 1e9;
  const std::string what = layout_error(Box3{{0, 0, 0}, {2, 2, 2}}, fine);
  EXPECT_NE(what.find("along x"), std::string::npos) << what;
  EXPECT_NE(what.find("x_dpi = 1e+09"), std::string::npos) << what;
  EXPECT_NE(layout_error(Box3{{0, 0, 0}, {1, 1, 1e6}}, paper_printer()).find("layer_thickness_mm"), std::string::npos);
}

TEST(SliceLayout, LayerAboveThePixelLimitIsRefused) {
  // 400 m square: fewer than 1e7 pixels along each side, but 4.4e13 in one layer.
  const std::string what = layout_error(Box3{{0, 0, 0}, {4e5, 4e5, 1}}, paper_printer());
  EXPECT_NE(what.find("one layer would be"), std::string::npos) << what;
  // Just under the limit is accepted: a layer of exactly kMaxLayerPixels.
  PrinterProfile p = paper_printer();
  p.x_dpi = p.y_dpi = 25.4;  // 1 mm pixels
  const SliceLayout l = make_layout(Box3{{0, 0, 0}, {32768, 32768, 1}}, p);
  EXPECT_EQ(static_cast<long long>(l.width_px) * l.height_px, kMaxLayerPixels);
}

}  // namespace
}  // namespace trivox
