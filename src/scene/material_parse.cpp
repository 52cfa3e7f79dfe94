// Material functions of a scene (docs/SCENE.md, "Material functions"): the JSON of each kind
// turned into its MaterialFunction, with materials referred to by name.
#include <optional>

#include <fmt/format.h>

#include "scene/scene_parse.h"
#include "trivox/error.h"
#include "trivox/material/detail/constant_material.h"
#include "trivox/material/detail/scalar_gradient_material.h"
#include "trivox/material/detail/spline_field_material.h"
#include "trivox/material/detail/twisting_curves_material.h"
#include "trivox/material/expression_material.h"
#include "trivox/material/porous_tiles_material.h"

namespace trivox::detail {

namespace {

std::optional<int> lookup(const std::vector<std::string>& names, std::string_view name) {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  return std::nullopt;
}

[[noreturn]] void unknown_material(const JsonView& where, std::string_view name,
                                   const std::vector<std::string>& names) {
  std::string list;
  for (const std::string& n : names) list += fmt::format("{}{}", list.empty() ? "" : ", ", shown_name(n, '"'));
  where.fail(
      fmt::format("unknown material {}; the scene's materials are {} (and \"void\" for "
                  "no material)",
                  shown_name(name, '"'), list));
}

}  // namespace

int SceneContext::material_ref(const JsonView& name) const {
  const std::string& s = name.string();
  if (s == "void") return kVoidMaterial;
  if (const auto j = lookup(material_names_, s)) return *j;
  unknown_material(name, s, material_names_);
}

std::vector<float> SceneContext::fraction_map(const JsonView& object) const {
  std::vector<float> fractions(material_names_.size(), 0.0f);
  for (const auto& [key, value] : object.members()) {
    if (key == "void") value.fail("\"void\" is implicit (1 minus the sum of the others); leave it out");
    const auto j = lookup(material_names_, key);
    if (!j) unknown_material(value, key, material_names_);
    fractions[static_cast<std::size_t>(*j)] = static_cast<float>(value.number());
  }
  return fractions;
}

namespace {

constexpr std::string_view kKinds =
    "\"constant\", \"spline_field\", \"scalar_gradient\", \"expression\", \"porous_tiles\", "
    "\"twisting_curves\", \"texture\", \"transfer\", \"blend\", \"threshold\", \"select\", \"void_mask\"";

int axis_ref(const JsonView& v) {
  const std::string& s = v.string();
  if (s == "u") return 0;
  if (s == "v") return 1;
  if (s == "w") return 2;
  v.fail(fmt::format("expected \"u\", \"v\" or \"w\", got \"{}\"", s));
}

std::shared_ptr<const MaterialFunction> spline_field(const JsonView& node, SceneContext& ctx, const ParamBox& domain) {
  node.expect_object({"kind", "components", "field"});
  std::vector<int> components;
  for (const JsonView& c : node.at("components").elements(1, kMaxMaterials)) {
    const int j = ctx.material_ref(c);
    for (std::size_t k = 0; k < components.size(); ++k)
      if (j != kVoidMaterial && components[k] == j)
        c.fail(fmt::format("material \"{}\" is component {} already", c.string(), k));
    components.push_back(j);
  }
  TensorSpline field = parse_field(node.at("field"), ctx, static_cast<int>(components.size()));
  return std::make_shared<SplineFieldMaterial>(std::move(field), std::move(components), ctx.num_materials(), domain);
}

}  // namespace

std::vector<GradientStop> parse_stops(const JsonView& node, const SceneContext& ctx) {
  std::vector<GradientStop> stops;
  for (const JsonView& s : node.elements(1)) {
    s.expect_object({"value", "fractions"});
    const JsonView value = s.at("value");
    GradientStop stop{value.number(), ctx.fraction_map(s.at("fractions"))};
    if (!stops.empty() && stop.value < stops.back().value)
      value.fail(fmt::format("stop values must not decrease: {} follows {}", stop.value, stops.back().value));
    stops.push_back(std::move(stop));
  }
  return stops;
}

namespace {

std::shared_ptr<const MaterialFunction> scalar_gradient(const JsonView& node, SceneContext& ctx,
                                                        const ParamBox& domain) {
  node.expect_object({"kind", "field", "stops"});
  TensorSpline field = parse_field(node.at("field"), ctx, 1);
  return std::make_shared<ScalarGradientMaterial>(std::move(field), parse_stops(node.at("stops"), ctx), domain);
}

std::shared_ptr<const MaterialFunction> expression(const JsonView& node, SceneContext& ctx, const ParamBox& domain) {
  node.expect_object({"kind", "fractions", "constants"});
  ExpressionParams params;
  params.expressions.assign(static_cast<std::size_t>(ctx.num_materials()), "");
  std::vector<std::optional<JsonView>> where(params.expressions.size());
  for (const auto& [key, value] : node.at("fractions").members()) {
    if (key == "void") value.fail("\"void\" is implicit (1 minus the sum of the others); leave it out");
    const auto j = lookup(ctx.material_names(), key);
    if (!j) unknown_material(value, key, ctx.material_names());
    const auto jj = static_cast<std::size_t>(*j);
    if (value.is_number()) {
      params.expressions[jj] = value.json().dump();
    } else if (value.is_string()) {
      if (value.string().empty()) value.fail("the expression is empty (leave the material out for 0)");
      params.expressions[jj] = value.string();
    } else {
      value.fail(
          fmt::format("expected an expression (a string) or a number, got {}", JsonView::describe(value.json())));
    }
    where[jj] = value;
  }
  std::optional<JsonView> constants = node.find("constants");
  if (constants)
    for (const auto& [key, value] : constants->members()) params.constants.emplace_back(key, value.number());
  try {
    return std::make_shared<ExpressionMaterial>(std::move(params), domain);
  } catch (const ExpressionError& e) {
    const auto j = static_cast<std::size_t>(e.index());
    if (e.index() >= 0 && where[j]) where[j]->fail(e.what());
    (constants ? *constants : node).fail(e.what());
  }
}

std::shared_ptr<const MaterialFunction> porous_tiles(const JsonView& node, SceneContext& ctx, const ParamBox& domain) {
  node.expect_object({"kind", "tiles", "radius", "materials", "cylinder_axes"});
  PorousTilesParams p;
  const JsonView tiles = node.at("tiles");
  if (tiles.is_number()) {
    p.tiles.fill(tiles.integer_in(1, 1 << 20));
  } else {
    const std::vector<JsonView> t = tiles.elements(3, 3);
    for (std::size_t d = 0; d < 3; ++d) p.tiles[d] = t[d].integer_in(1, 1 << 20);
  }
  if (const auto r = node.find("radius")) p.radius = r->number_in(0.0, 0.5);
  const std::vector<JsonView> materials = node.at("materials").elements(2, 2);
  for (std::size_t t = 0; t < 2; ++t) p.materials[t] = ctx.material_ref(materials[t]);
  if (const auto axes = node.find("cylinder_axes")) {
    const std::vector<JsonView> a = axes->elements(2, 2);
    for (std::size_t t = 0; t < 2; ++t) p.cylinder_axes[t] = axis_ref(a[t]);
    if (p.cylinder_axes[0] == p.cylinder_axes[1]) axes->fail("the two cylinders need different axes");
  }
  return std::make_shared<PorousTilesMaterial>(p, ctx.num_materials(), domain);
}

std::shared_ptr<const MaterialFunction> twisting_curves(const JsonView& node, SceneContext& ctx,
                                                        const ParamBox& domain) {
  node.expect_object({"kind", "points", "radius", "centre", "turns_per_w", "shift_per_w", "wrap", "background"});
  TwistingCurvesParams p;
  for (const JsonView& e : node.at("points").elements(1)) {
    e.expect_object({"uv", "material"});
    const std::vector<double> uv = e.at("uv").numbers(2, 2);
    p.points.push_back({uv[0], uv[1], ctx.material_ref(e.at("material"))});
  }
  const JsonView radius = node.at("radius");
  p.radius = radius.number();
  if (!(p.radius > 0.0)) radius.fail(fmt::format("the radius {} is not > 0", p.radius));
  if (const auto c = node.find("centre")) {
    const std::vector<double> v = c->numbers(2, 2);
    p.centre_u = v[0];
    p.centre_v = v[1];
  }
  if (const auto t = node.find("turns_per_w")) p.turns_per_w = t->number();
  if (const auto s = node.find("shift_per_w")) {
    const std::vector<double> v = s->numbers(2, 2);
    p.shift_u_per_w = v[0];
    p.shift_v_per_w = v[1];
  }
  if (const auto w = node.find("wrap")) {
    for (const JsonView& e : w->elements(0, 2)) {
      const int axis = axis_ref(e);
      if (axis == 2) e.fail("only \"u\" and \"v\" can wrap");
      (axis == 0 ? p.wrap_u : p.wrap_v) = true;
    }
  }
  if (const auto b = node.find("background")) p.background = ctx.material_ref(*b);
  return std::make_shared<TwistingCurvesMaterial>(std::move(p), ctx.num_materials(), domain);
}

}  // namespace

std::shared_ptr<const MaterialFunction> parse_material(const JsonView& node, SceneContext& ctx,
                                                       const ParamBox& cell_domain) {
  if (node.is_string()) {  // "material": "VeroCyan": that material throughout
    const int j = ctx.material_ref(node);
    std::vector<float> fractions(static_cast<std::size_t>(ctx.num_materials()), 0.0f);
    if (j != kVoidMaterial) fractions[static_cast<std::size_t>(j)] = 1.0f;
    return std::make_shared<ConstantMaterial>(std::move(fractions));
  }
  const JsonView kind_node = node.at("kind");
  const std::string& kind = kind_node.string();
  try {
    if (kind == "constant") {
      node.expect_object({"kind", "fractions"});
      return std::make_shared<ConstantMaterial>(ctx.fraction_map(node.at("fractions")));
    }
    if (kind == "spline_field") return spline_field(node, ctx, cell_domain);
    if (kind == "scalar_gradient") return scalar_gradient(node, ctx, cell_domain);
    if (kind == "expression") return expression(node, ctx, cell_domain);
    if (kind == "porous_tiles") return porous_tiles(node, ctx, cell_domain);
    if (kind == "twisting_curves") return twisting_curves(node, ctx, cell_domain);
    if (kind == "texture") return parse_texture(node, ctx, cell_domain);
    if (auto composite = parse_composite(kind, node, ctx, cell_domain)) return composite;
  } catch (const InputError&) {
    throw;
  } catch (const Error& e) {
    // A rule the material's own validation caught that the checks above did not.
    node.fail(e.what());
  }
  kind_node.fail(fmt::format("unknown material kind \"{}\"; the kinds are {}", kind, kKinds));
}

}  // namespace trivox::detail
