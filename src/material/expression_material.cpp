#include "trivox/material/expression_material.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <numbers>
#include <optional>

#include <fmt/format.h>
#include <muParser.h>

#include "material/expression_tree.h"

namespace trivox {

// The expressions as trees for enclose(): one per material, absent for an empty expression
// (0) and for one the tree does not read as muParser does (then nothing is bounded).
struct ExpressionMaterial::Trees {
  std::vector<std::optional<detail::ExpressionTree>> trees;
  std::vector<bool> trusted;  // per material: empty, or a tree that agrees with muParser
};

// One thread's private parsers. The variables live here, at a fixed address, because
// muParser binds each variable name to a pointer once (DefineVar) and reads through it on
// every evaluation.
struct ExpressionMaterial::Evaluator {
  double u = 0, v = 0, w = 0, x = 0, y = 0, z = 0;
  std::vector<std::unique_ptr<mu::Parser>> parsers;  // null for an empty expression (0)
};

struct ExpressionMaterial::State {
  ExpressionParams params;
  AffineParamMap map;
  std::unique_ptr<Trees> trees{};
  // Evaluators not in use: a row takes one under the mutex and gives it back (the header).
  std::mutex pool_mutex{};
  std::vector<std::unique_ptr<Evaluator>> pool{};
};

namespace {

constexpr std::string_view kVariables[] = {"u", "v", "w", "x", "y", "z"};

bool is_identifier(std::string_view name) {
  if (name.empty()) return false;
  auto letter = [](char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; };
  if (!letter(name.front())) return false;
  for (char c : name)
    if (!letter(c) && !(c >= '0' && c <= '9')) return false;
  return true;
}

void check_constant_names(const ExpressionParams& params) {
  for (const auto& [name, value] : params.constants) {
    if (!is_identifier(name))
      throw ExpressionError(-1, fmt::format("constant name '{}' is not an identifier (letters, "
                                            "digits and '_', not starting with a digit)",
                                            name));
    for (std::string_view reserved : kVariables)
      if (name == reserved)
        throw ExpressionError(-1, fmt::format("constant name '{}' is one of the variables "
                                              "u v w x y z",
                                              name));
    if (name == "pi") throw ExpressionError(-1, "constant name 'pi' is predefined");
    if (!std::isfinite(value))
      throw ExpressionError(-1, fmt::format("constant '{}' = {} is not a finite number", name, value));
  }
}

int expression_count(const ExpressionParams& params) { return static_cast<int>(params.expressions.size()); }

}  // namespace

ExpressionMaterial::ExpressionMaterial(ExpressionParams params, const ParamBox& cell_domain)
    : MaterialFunction(expression_count(params)),
      // State holds a mutex, which cannot move: built in place.
      state_(new State{std::move(params), AffineParamMap::between(cell_domain, kUnitParamBox)}) {
  check_constant_names(state_->params);
  // Building the first evaluator parses every expression, so errors surface here and not in
  // the middle of a slice; it then serves the first thread that evaluates.
  state_->pool.push_back(make_evaluator());
  build_trees();
}

namespace {

// Points at which a tree and muParser must agree before the tree is trusted: the corners and
// the centre of the unit cube, and points spread over it with positions of either sign.
std::vector<std::array<double, detail::kExpressionVariables>> check_points() {
  std::vector<std::array<double, detail::kExpressionVariables>> points;
  for (int c = 0; c < 8; ++c)
    points.push_back({c & 1 ? 1.0 : 0.0, c & 2 ? 1.0 : 0.0, c & 4 ? 1.0 : 0.0, c & 1 ? -7.5 : 12.25,
                      c & 2 ? 0.0 : 3.125, c & 4 ? 40.0 : -0.5});
  std::uint32_t state = 12345u;
  const auto next = [&state] {
    state = state * 1664525u + 1013904223u;
    return static_cast<double>(state >> 8) / 16777216.0;
  };
  for (int i = 0; i < 24; ++i)
    points.push_back({next(), next(), next(), 200.0 * next() - 100.0, 200.0 * next() - 100.0, 200.0 * next() - 100.0});
  points.push_back({0.5, 0.5, 0.5, 0.0, 0.0, 0.0});
  return points;
}

bool same_value(double a, double b) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
  if (a == b) return true;  // infinities of one sign too
  return std::abs(a - b) <= 1e-9 * std::max({1.0, std::abs(a), std::abs(b)});
}

}  // namespace

void ExpressionMaterial::build_trees() {
  state_->trees = std::make_unique<Trees>();
  Evaluator& ev = *state_->pool.front();
  const auto points = check_points();
  for (std::size_t j = 0; j < state_->params.expressions.size(); ++j) {
    const std::string& text = state_->params.expressions[j];
    if (text.empty()) {
      state_->trees->trees.emplace_back();
      state_->trees->trusted.push_back(true);
      continue;
    }
    std::optional<detail::ExpressionTree> tree = detail::ExpressionTree::parse(text, state_->params.constants);
    bool agrees = tree.has_value();
    for (const auto& p : points) {
      if (!agrees) break;
      ev.u = p[0];
      ev.v = p[1];
      ev.w = p[2];
      ev.x = p[3];
      ev.y = p[4];
      ev.z = p[5];
      agrees = same_value(tree->evaluate(p), ev.parsers[j]->Eval());
    }
    state_->trees->trees.push_back(agrees ? std::move(tree) : std::nullopt);
    state_->trees->trusted.push_back(agrees);
  }
}

bool ExpressionMaterial::boundable() const noexcept {
  return std::all_of(state_->trees->trusted.begin(), state_->trees->trusted.end(), [](bool t) { return t; });
}

namespace {

using Vars = std::array<detail::IV, detail::kExpressionVariables>;

// The fractions' and the sum's enclosures of the trees over `vars` with some comparisons
// forced: each fraction by interval arithmetic intersected with its mean-value form, the sum
// likewise from the sums of the values at the centre and of the gradients.
struct CaseEnclosure {
  std::vector<detail::IV> fractions;
  detail::IV sum;
};
CaseEnclosure enclose_case(const std::vector<std::optional<detail::ExpressionTree>>& trees, const Vars& vars,
                           const Vars& centre, const detail::ExpressionTree::Forced& forced,
                           std::vector<std::string>* undecided) {
  CaseEnclosure out;
  detail::IV natural_sum = detail::IV::point(0.0), centre_sum = detail::IV::point(0.0), rest = detail::IV::point(0.0);
  Vars gradient_sum;
  gradient_sum.fill(detail::IV::point(0.0));
  for (const auto& tree : trees) {
    if (!tree) {  // an empty expression: 0
      out.fractions.push_back(detail::IV::point(0.0));
      continue;
    }
    const detail::ExpressionTree::Enclosure over = tree->enclose(vars, forced, undecided);
    detail::IV value = over.value;
    natural_sum = natural_sum + value;
    if (over.differentiable && value.finite()) {
      const detail::IV at_centre = tree->enclose(centre, forced, nullptr).value;
      detail::IV mean_value = at_centre;
      for (std::size_t i = 0; i < vars.size(); ++i) {
        mean_value = mean_value + over.gradient[i] * (vars[i] - centre[i]);
        gradient_sum[i] = gradient_sum[i] + over.gradient[i];
      }
      centre_sum = centre_sum + at_centre;
      if (mean_value.finite()) value = detail::intersect(value, mean_value);
    } else {
      rest = rest + value;
    }
    out.fractions.push_back(value);
  }
  detail::IV sum = centre_sum;
  for (std::size_t i = 0; i < vars.size(); ++i) sum = sum + gradient_sum[i] * (vars[i] - centre[i]);
  sum = sum + rest;
  out.sum = sum.finite() ? detail::intersect(sum, natural_sum) : natural_sum;
  return out;
}

// Comparisons left undecided over a box that the sum is split on, at most.
constexpr std::size_t kMaxCaseConditions = 5;

}  // namespace

FractionEnclosure ExpressionMaterial::enclose(const ParamBox& box, const Box3& xyz) const {
  const auto m = static_cast<std::size_t>(num_materials());
  if (!boundable()) return FractionEnclosure::unknown(num_materials());
  // The variables' box: normalised parameters (clamped, as evaluate_row clamps them) and the
  // positions; and its centre.
  const ParamBox unit = state_->map(box);
  Vars vars, centre;
  for (int d = 0; d < 3; ++d) {
    const double lo = std::clamp(std::min(unit.lo[d], unit.hi[d]), 0.0, 1.0);
    const double hi = std::clamp(std::max(unit.lo[d], unit.hi[d]), 0.0, 1.0);
    vars[static_cast<std::size_t>(d)] = {lo, hi, false};
    vars[static_cast<std::size_t>(3 + d)] = {xyz.lo[d], xyz.hi[d], false};
  }
  for (std::size_t i = 0; i < vars.size(); ++i) centre[i] = detail::IV::point(0.5 * (vars[i].lo + vars[i].hi));
  std::vector<std::string> undecided;
  CaseEnclosure all = enclose_case(state_->trees->trees, vars, centre, {}, &undecided);
  // Comparisons undecided over the box: every assignment of them is a case, and the point's
  // values lie in one case's enclosure.
  if (!undecided.empty() && undecided.size() <= kMaxCaseConditions) {
    std::optional<CaseEnclosure> hull;
    for (unsigned bits = 0; bits < (1u << undecided.size()); ++bits) {
      detail::ExpressionTree::Forced forced;
      for (std::size_t c = 0; c < undecided.size(); ++c)
        forced.emplace_back(undecided[c], (bits >> c) & 1u ? 1.0 : 0.0);
      const CaseEnclosure one = enclose_case(state_->trees->trees, vars, centre, forced, nullptr);
      if (!hull) {
        hull = one;
        continue;
      }
      for (std::size_t j = 0; j < m; ++j) hull->fractions[j] = detail::hull(hull->fractions[j], one.fractions[j]);
      hull->sum = detail::hull(hull->sum, one.sum);
    }
    for (std::size_t j = 0; j < m; ++j) all.fractions[j] = detail::intersect(all.fractions[j], hull->fractions[j]);
    all.sum = detail::intersect(all.sum, hull->sum);
  }
  FractionEnclosure e;
  e.finite = all.sum.finite();
  for (const detail::IV& f : all.fractions) {
    e.finite = e.finite && f.finite();
    e.fractions.push_back({f.lo, f.hi});
  }
  if (!e.finite) return FractionEnclosure::unknown(num_materials());
  e.sum = {all.sum.lo, all.sum.hi};
  return e;
}

ExpressionMaterial::~ExpressionMaterial() = default;

const ExpressionParams& ExpressionMaterial::params() const noexcept { return state_->params; }

std::unique_ptr<ExpressionMaterial::Evaluator> ExpressionMaterial::make_evaluator() const {
  auto ev = std::make_unique<Evaluator>();
  double* vars[] = {&ev->u, &ev->v, &ev->w, &ev->x, &ev->y, &ev->z};
  for (std::size_t j = 0; j < state_->params.expressions.size(); ++j) {
    const std::string& text = state_->params.expressions[j];
    if (text.empty()) {
      ev->parsers.emplace_back();
      continue;
    }
    auto parser = std::make_unique<mu::Parser>();
    try {
      parser->DefineConst("pi", std::numbers::pi);
      for (const auto& [name, value] : state_->params.constants) parser->DefineConst(name, value);
      for (std::size_t k = 0; k < std::size(kVariables); ++k) parser->DefineVar(std::string(kVariables[k]), vars[k]);
      parser->SetExpr(text);
      parser->Eval();  // compiles the bytecode; syntax and unknown names fail here
    } catch (const mu::Parser::exception_type& e) {
      throw ExpressionError(static_cast<int>(j), fmt::format("expression \"{}\": {}", text, e.GetMsg()));
    }
    ev->parsers.push_back(std::move(parser));
  }
  return ev;
}

void ExpressionMaterial::evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz,
                                      std::span<float> fractions) const {
  // Check an evaluator out of the pool (or make one: this thread is the pool's first user at
  // this moment); the capacity grows with each new one, so returning it cannot allocate.
  std::unique_ptr<Evaluator> ev;
  {
    const std::lock_guard lock(state_->pool_mutex);
    if (!state_->pool.empty()) {
      ev = std::move(state_->pool.back());
      state_->pool.pop_back();
    } else {
      state_->pool.reserve(state_->pool.capacity() + 1);
    }
  }
  if (!ev) ev = make_evaluator();
  struct Return {
    const ExpressionMaterial& self;
    std::unique_ptr<Evaluator>& slot;
    ~Return() {
      const std::lock_guard lock(self.state_->pool_mutex);
      self.state_->pool.push_back(std::move(slot));
    }
  } give_back{*this, ev};

  const auto m = static_cast<std::size_t>(num_materials());
  for (std::size_t s = 0; s < uvw.size(); ++s) {
    const Vec3 p = kUnitParamBox.clamp(state_->map(uvw[s]));
    ev->u = p.x;
    ev->v = p.y;
    ev->w = p.z;
    ev->x = xyz[s].x;
    ev->y = xyz[s].y;
    ev->z = xyz[s].z;
    float* f = fractions.data() + s * m;
    for (std::size_t j = 0; j < m; ++j) {
      const mu::Parser* parser = ev->parsers[j].get();
      f[j] = parser ? static_cast<float>(parser->Eval()) : 0.0f;
    }
  }
}

}  // namespace trivox
