// G+Smo XML reader on small hand-written files with known values: uniform-mode knot
// vectors, fractions, wrong index attributes, a comment before the declaration, base64
// numbers of several types, NURBS weights before the inner basis, several Geometry elements
// without a MultiPatch, MultiPatch id lists, trimmed surfaces; and the base64 decoder.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "io/base64.h"
#include "trivox/error.h"
#include "trivox/io/model.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

fs::path model_path(const char* name) { return fs::path(TRIVOX_TEST_DATA_DIR) / "models" / name; }

TEST(GismoReader, UniformModeFractionsAndChildBasesInDocumentOrder) {
  const Model m = read_model(model_path("uniform_fractions.xml"));
  ASSERT_EQ(m.patches.size(), 1u);
  const Patch& p = m.patches[0];
  EXPECT_EQ(p.name, "Geometry id=7");
  EXPECT_EQ(p.id, 7);
  EXPECT_EQ(p.source_line, 4);
  const TensorSpline& s = p.spline;
  ASSERT_EQ(s.param_dim(), 3);
  // The first child basis says index="2" but is the u direction: document order counts.
  // mode="uniform" csize="4" degree="2": clamped uniform knots on [0, 1] for 4 functions.
  EXPECT_EQ(s.knots(0), KnotVector(3, {0, 0, 0, 0.5, 1, 1, 1}));
  EXPECT_EQ(s.knots(1), KnotVector(2, {0, 0, 1.0 / 3.0, 1, 1}));
  EXPECT_EQ(s.knots(2), KnotVector::bezier(2));
  EXPECT_EQ(s.total_ctrl(), 24);
  // x was written as the fractions 0, 1/3, 2/3, 1; y = 0.5 j; z = k.
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 4; ++i) {
        const auto q = s.point(i, j, k);
        EXPECT_EQ(q[0], static_cast<double>(i) / 3.0);
        EXPECT_EQ(q[1], 0.5 * j);
        EXPECT_EQ(q[2], static_cast<double>(k));
      }
}

TEST(GismoReader, Base64NumbersNurbsWeightsAndGeometriesWithoutMultiPatch) {
  const Model m = read_model(model_path("nurbs_base64.xml"));
  ASSERT_EQ(m.patches.size(), 3u);
  EXPECT_EQ(m.patches[0].name, "Geometry id=5");
  EXPECT_EQ(m.patches[1].name, "Geometry #1");  // no id: named and numbered by position
  EXPECT_EQ(m.patches[2].name, "Geometry #2");
  EXPECT_EQ(m.patches[0].id, 5);
  EXPECT_EQ(m.patches[1].id, 1);
  EXPECT_EQ(m.volume_indices(), std::vector<int>{0});

  // TensorNurbs3: weights (B64Float32) stand before the inner basis; coefs are B64Float64
  // wrapped over two lines.
  const TensorSpline& v = m.patches[0].spline;
  ASSERT_TRUE(v.is_rational());
  EXPECT_EQ(v.knots(2).lo(), -1.0);
  const std::array<double, 8> w = {1, 2, 0.5, 4, 1, 1, 2, 0.25};
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        EXPECT_EQ(v.weight(i, j, k), w[static_cast<std::size_t>(i + 2 * j + 4 * k)]);
        const auto q = v.point(i, j, k);
        EXPECT_EQ(q[0], 2.0 * i);
        EXPECT_EQ(q[1], 3.0 * j);
        EXPECT_EQ(q[2], 0.1 * k);  // binary: the exact double 0.1, no decimal round trip
      }

  const TensorSpline& surface = m.patches[1].spline;  // TensorBSpline2 in space
  EXPECT_EQ(surface.param_dim(), 2);
  EXPECT_EQ(surface.point_dim(), 3);
  EXPECT_FALSE(surface.is_rational());

  // Nurbs curve, weights 1 2 1 as B64Int32: at t = 1/2 the Bernstein values 1/4, 1/2, 1/4
  // times the weights give 1/4, 1, 1/4 (sum 3/2), so both coordinates are 5/6.
  const TensorSpline& curve = m.patches[2].spline;
  ASSERT_EQ(curve.param_dim(), 1);
  EXPECT_EQ(curve.point_dim(), 2);
  EXPECT_EQ(curve.weight(1), 2.0);
  std::array<double, 2> mid{};
  const std::array<double, 1> t{0.5};
  curve.evaluate(t, mid);
  EXPECT_NEAR(mid[0], 5.0 / 6.0, 1e-15);
  EXPECT_NEAR(mid[1], 5.0 / 6.0, 1e-15);
}

TEST(GismoReader, MultiPatchListsAndOrdersThePatches) {
  const Model m = read_model(model_path("multipatch_ids.xml"));
  // <patches type="id_index">12 10</patches>: Geometry 11 is not part of the model.
  ASSERT_EQ(m.patches.size(), 2u);
  EXPECT_EQ(m.patches[0].id, 12);
  EXPECT_EQ(m.patches[0].name, "Geometry id=12");
  EXPECT_EQ(m.patches[0].source_line, 11);
  EXPECT_EQ(m.patches[0].spline.point(1)[0], 12.0);
  EXPECT_EQ(m.patches[1].id, 10);
  EXPECT_EQ(m.patches[1].spline.point(1)[0], 10.0);
}

const char* const kTrimmedSurface = R"(<?xml version="1.0"?>
<xml>
  <TrimSurface id="3">
    <Geometry type="TensorBSpline2">
      <Basis type="TensorBSplineBasis2">
        <Basis type="BSplineBasis"><KnotVector degree="1">0 0 1 1</KnotVector></Basis>
        <Basis type="BSplineBasis"><KnotVector degree="1">0 0 1 1</KnotVector></Basis>
      </Basis>
      <coefs geoDim="3">0 0 0 1 0 0 0 1 0 1 1 0</coefs>
    </Geometry>
    <PlanarDomain>
      <CurveLoop index="0">
        <Geometry type="BSpline" index="0">
          <Basis type="BSplineBasis"><KnotVector degree="1">0 0 1 1</KnotVector></Basis>
          <coefs geoDim="2">0 0 1 0</coefs>
        </Geometry>
      </CurveLoop>
    </PlanarDomain>
  </TrimSurface>
  <Solid><Volume>0</Volume></Solid>
</xml>
)";

TEST(GismoReader, TrimSurfaceGivesItsSurfaceAndSkipsTrimmingCurves) {
  const Model m = read_gismo_xml(kTrimmedSurface, "trimmed.xml");
  ASSERT_EQ(m.patches.size(), 1u);
  EXPECT_EQ(m.patches[0].name, "TrimSurface id=3");
  EXPECT_EQ(m.patches[0].id, 3);
  EXPECT_EQ(m.patches[0].source_line, 4);
  EXPECT_EQ(m.patches[0].spline.param_dim(), 2);
}

TEST(GismoReader, MultiPatchIdRangeWithDuplicateIdsIsRejected) {
  const std::string geometry = R"(
 <Geometry type="BSpline" id="1">
  <Basis type="BSplineBasis"><KnotVector degree="1">0 0 1 1</KnotVector></Basis>
  <coefs geoDim="1">0 1</coefs>
 </Geometry>)";
  const std::string text =
      "<xml>" + geometry + geometry + "\n <MultiPatch><patches type=\"id_range\">1 1</patches></MultiPatch>\n</xml>\n";
  try {
    read_gismo_xml(text, "dup.xml");
    FAIL() << "two Geometry elements with the listed id were accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 6);  // the second Geometry
    EXPECT_NE(std::string(e.what()).find("several <Geometry> elements have id 1"), std::string::npos) << e.what();
  }
  // Without a MultiPatch the same two elements are simply two patches, in document order.
  const Model m = read_gismo_xml("<xml>" + geometry + geometry + "</xml>", "dup.xml");
  EXPECT_EQ(m.patches.size(), 2u);
}

TEST(GismoReader, NurbsBasisLabelDimensionIsNotTrusted) {
  // lshape_thick_C0.xml (G+Smo) wraps a TensorBSplineBasis3 in a "TensorNurbsBasis2".
  const std::string text = R"(<xml>
 <Geometry type="TensorNurbs2">
  <Basis type="TensorNurbsBasis3">
   <Basis type="TensorBSplineBasis2">
    <Basis type="BSplineBasis"><KnotVector degree="1">0 0 1 1</KnotVector></Basis>
    <Basis type="BSplineBasis"><KnotVector degree="1">0 0 1 1</KnotVector></Basis>
   </Basis>
   <weights>1 1 1 1</weights>
  </Basis>
  <coefs geoDim="2">0 0 1 0 0 1 1 1</coefs>
 </Geometry>
</xml>)";
  EXPECT_EQ(read_gismo_xml(text, "label.xml").patches[0].spline.param_dim(), 2);
}

std::vector<std::uint8_t> bytes(const char* s) {
  return std::vector<std::uint8_t>(s, s + std::char_traits<char>::length(s));
}

TEST(GismoBase64, DecodesPaddedTextIgnoringBlanks) {
  std::vector<std::uint8_t> out;
  std::string error;
  ASSERT_TRUE(io_detail::decode_base64("TWFu", out, error)) << error;
  EXPECT_EQ(out, bytes("Man"));
  ASSERT_TRUE(io_detail::decode_base64(" TW\nE= ", out, error)) << error;
  EXPECT_EQ(out, bytes("Ma"));
  ASSERT_TRUE(io_detail::decode_base64("TQ==", out, error)) << error;
  EXPECT_EQ(out, bytes("M"));
  ASSERT_TRUE(io_detail::decode_base64("", out, error)) << error;
  EXPECT_TRUE(out.empty());
}

TEST(GismoBase64, RejectsMalformedText) {
  std::vector<std::uint8_t> out;
  std::string error;
  EXPECT_FALSE(io_detail::decode_base64("TQ=", out, error));       // length not a multiple of 4
  EXPECT_FALSE(io_detail::decode_base64("T===", out, error));      // too much padding
  EXPECT_FALSE(io_detail::decode_base64("TQ==TWFu", out, error));  // data after padding
  EXPECT_FALSE(io_detail::decode_base64("TW-u", out, error));      // '-' is base64url, not base64
  EXPECT_NE(error.find("'-'"), std::string::npos) << error;
}

}  // namespace
}  // namespace trivox
