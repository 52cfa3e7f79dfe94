// ExpressionMaterial: one user expression per material over u, v, w (the cell's parameters
// mapped onto [0,1]^3) and x, y, z (model-space position, mm), parsed once by muParser
// (Debian libmuparser-dev). Syntax: muParser's (https://beltoforion.de/en/muparser):
// + - * / ^, comparisons, `c ? a : b`, sin cos tan asin acos atan sinh cosh tanh asinh
// acosh atanh log2 log10 log ln exp sqrt sign rint abs min max sum avg, constants _pi,
// _e, and `pi` defined here, plus any named constants given in the parameters.
//
// Evaluation: each row runs every expression's compiled bytecode over the row's samples,
// expression by expression. muParser's own bulk mode, Eval(double*, int), is deliberately
// not used: in the packaged muParser 2.3.3 it rebuilds the bytecode from the expression
// string on every call (about 8 us, allocating) and opens an OpenMP team on every call,
// which under the slicer's own worker threads oversubscribes the machine (measured 37x
// slower with two threads). The compiled single-sample path evaluates the same bytecode
// with no allocation.
//
// Threads: a muParser object is not safe to evaluate from two threads at once, so the
// material keeps a pool of evaluators (parsers bound to their own variables); a row checks
// one out under a mutex and returns it afterwards. The pool grows to the number of threads
// that evaluate at the same time, and the object stays const and thread-safe to its users.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "trivox/error.h"
#include "trivox/material/material_function.h"

namespace trivox {

struct ExpressionParams {
  // One per material (m entries); an empty string means the constant 0.
  std::vector<std::string> expressions;
  // Named constants usable in every expression: names are letters, digits and '_', start
  // with a letter or '_', and are none of u v w x y z pi.
  std::vector<std::pair<std::string, double>> constants;
};

// A syntax or name error in one expression (index: its material index) or, with index -1,
// in a constant's name. message(): muParser's message with the position in the expression.
class ExpressionError : public Error {
 public:
  ExpressionError(int index, const std::string& message) : Error(message), index_(index) {}
  int index() const noexcept { return index_; }

 private:
  int index_;
};

class ExpressionMaterial final : public MaterialFunction {
 public:
  // Parses every expression; throws ExpressionError on the first that does not compile.
  ExpressionMaterial(ExpressionParams params, const ParamBox& cell_domain);
  ~ExpressionMaterial() override;

  std::string_view kind() const noexcept override { return "expression"; }
  // Non-finite results (0/0, sqrt(-1)) are passed on; the fraction policy rejects them.
  void evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz, std::span<float> fractions) const override;
  // Interval arithmetic over each expression's tree, intersected with the mean-value form
  // (the value at the box's centre plus an enclosure of the gradient times the box's
  // half-widths), for each fraction and for their sum, whose gradients add up (1 - u and u
  // sum to exactly 1). An expression bounds nothing (everything, not finite) when its tree
  // did not read it as muParser does: before the trees are trusted, both evaluate every
  // expression at a fixed set of points and must agree.
  FractionEnclosure enclose(const ParamBox& box, const Box3& xyz) const override;

  const ExpressionParams& params() const noexcept;
  // Whether every non-empty expression has a tree to bound it with.
  bool boundable() const noexcept;

 private:
  struct Evaluator;
  struct Trees;
  std::unique_ptr<Evaluator> make_evaluator() const;
  void build_trees();
  struct State;  // the expressions, the parameter map, the trees and the pool of evaluators
  std::unique_ptr<State> state_;
};

}  // namespace trivox
