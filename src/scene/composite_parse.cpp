// Scalar sources and composed material functions of a scene (docs/SCENE.md, "Composition").
#include <fmt/format.h>

#include "scene/scene_parse.h"
#include "trivox/error.h"
#include "trivox/material/detail/composite_material.h"
#include "trivox/material/detail/constant_material.h"
#include "trivox/material/detail/field_scalar_material.h"
#include "trivox/material/expression_material.h"

namespace trivox::detail {

std::shared_ptr<const MaterialFunction> parse_scalar(const JsonView& node, SceneContext& ctx,
                                                     const ParamBox& cell_domain) {
  if (node.is_number())
    return std::make_shared<ConstantMaterial>(std::vector<float>{static_cast<float>(node.number())});
  if (node.is_string()) {
    if (node.string().empty()) node.fail("the expression is empty");
    ExpressionParams params;
    params.expressions = {node.string()};
    try {
      return std::make_shared<ExpressionMaterial>(std::move(params), cell_domain);
    } catch (const ExpressionError& e) {
      node.fail(e.what());
    }
  }
  if (node.is_object() && node.find("texture")) return parse_texture_scalar(node, ctx, cell_domain);
  if (node.is_object() && node.find("field")) {
    node.expect_object({"field", "component", "magnitude"});
    TensorSpline field = parse_field(node.at("field"), ctx, kAnyPointDim);
    FieldScalarChoice choice;
    if (const auto c = node.find("component")) choice.component = c->integer_in(0, field.point_dim() - 1);
    if (const auto m = node.find("magnitude")) {
      choice.magnitude = m->boolean();
      if (choice.magnitude && node.find("component")) m->fail("give either \"component\" or \"magnitude\", not both");
    }
    return std::make_shared<FieldScalarMaterial>(std::move(field), choice, cell_domain);
  }
  node.fail(
      fmt::format("expected a scalar: a number, an expression (a string), {{\"field\": ..., \"component\": k or "
                  "\"magnitude\": true}} "
                  "or {{\"texture\": ..., \"channel\": k}}, got {}",
                  JsonView::describe(node.json())));
}

namespace {

ParamBox parse_box(const JsonView& node) {
  node.expect_object({"lo", "hi"});
  const std::vector<double> lo = node.at("lo").numbers(3, 3);
  const std::vector<double> hi = node.at("hi").numbers(3, 3);
  for (std::size_t d = 0; d < 3; ++d)
    if (lo[d] > hi[d]) node.fail(fmt::format("lo[{}] = {} is above hi[{}] = {}", d, lo[d], d, hi[d]));
  return {{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}};
}

}  // namespace

std::shared_ptr<const MaterialFunction> parse_composite(const std::string& kind, const JsonView& node,
                                                        SceneContext& ctx, const ParamBox& cell_domain) {
  if (kind == "transfer") {
    node.expect_object({"kind", "source", "stops"});
    return std::make_shared<TransferMaterial>(parse_scalar(node.at("source"), ctx, cell_domain),
                                              parse_stops(node.at("stops"), ctx));
  }
  if (kind == "blend") {
    node.expect_object({"kind", "a", "b", "weight"});
    return std::make_shared<BlendMaterial>(parse_material(node.at("a"), ctx, cell_domain),
                                           parse_material(node.at("b"), ctx, cell_domain),
                                           parse_scalar(node.at("weight"), ctx, cell_domain));
  }
  if (kind == "threshold") {
    node.expect_object({"kind", "source", "level", "below", "above"});
    return std::make_shared<ThresholdMaterial>(
        parse_scalar(node.at("source"), ctx, cell_domain), node.at("level").number(),
        parse_material(node.at("below"), ctx, cell_domain), parse_material(node.at("above"), ctx, cell_domain));
  }
  if (kind == "select") {
    node.expect_object({"kind", "regions", "otherwise"});
    std::vector<SelectRegion> regions;
    for (const JsonView& r : node.at("regions").elements(1)) {
      r.expect_object({"box", "material"});
      regions.push_back({parse_box(r.at("box")), parse_material(r.at("material"), ctx, cell_domain)});
    }
    return std::make_shared<SelectMaterial>(std::move(regions), parse_material(node.at("otherwise"), ctx, cell_domain),
                                            cell_domain);
  }
  if (kind == "void_mask") {
    node.expect_object({"kind", "material", "void"});
    return std::make_shared<VoidMaskMaterial>(parse_material(node.at("material"), ctx, cell_domain),
                                              parse_scalar(node.at("void"), ctx, cell_domain));
  }
  return nullptr;
}

}  // namespace trivox::detail
