#include "trivox/material/expression_material.h"

#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <muParser.h>

namespace trivox {

// One thread's private parsers. The variables live here, at a fixed address, because
// muParser binds each variable name to a pointer once (DefineVar) and reads through it on
// every evaluation.
struct ExpressionMaterial::Evaluator {
  double u = 0, v = 0, w = 0, x = 0, y = 0, z = 0;
  std::vector<std::unique_ptr<mu::Parser>> parsers;  // null for an empty expression (0)
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
      params_(std::move(params)),
      map_(AffineParamMap::between(cell_domain, kUnitParamBox)) {
  check_constant_names(params_);
  // Building the first evaluator parses every expression, so errors surface here and not in
  // the middle of a slice; it then serves the first thread that evaluates.
  pool_.push_back(make_evaluator());
}

ExpressionMaterial::~ExpressionMaterial() = default;

std::unique_ptr<ExpressionMaterial::Evaluator> ExpressionMaterial::make_evaluator() const {
  auto ev = std::make_unique<Evaluator>();
  double* vars[] = {&ev->u, &ev->v, &ev->w, &ev->x, &ev->y, &ev->z};
  for (std::size_t j = 0; j < params_.expressions.size(); ++j) {
    const std::string& text = params_.expressions[j];
    if (text.empty()) {
      ev->parsers.emplace_back();
      continue;
    }
    auto parser = std::make_unique<mu::Parser>();
    try {
      parser->DefineConst("pi", std::numbers::pi);
      for (const auto& [name, value] : params_.constants) parser->DefineConst(name, value);
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
    const std::lock_guard lock(pool_mutex_);
    if (!pool_.empty()) {
      ev = std::move(pool_.back());
      pool_.pop_back();
    } else {
      pool_.reserve(pool_.capacity() + 1);
    }
  }
  if (!ev) ev = make_evaluator();
  struct Return {
    const ExpressionMaterial& self;
    std::unique_ptr<Evaluator>& slot;
    ~Return() {
      const std::lock_guard lock(self.pool_mutex_);
      self.pool_.push_back(std::move(slot));
    }
  } give_back{*this, ev};

  const auto m = static_cast<std::size_t>(num_materials());
  for (std::size_t s = 0; s < uvw.size(); ++s) {
    const Vec3 p = kUnitParamBox.clamp(map_(uvw[s]));
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
