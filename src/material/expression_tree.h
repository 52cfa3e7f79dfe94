// The expressions of ExpressionMaterial as a tree, for bounding them (fraction_check.h):
// parsed with muParser's grammar and precedence for the operators and functions trivox
// documents (docs/SCENE.md, "expression"), evaluated at a point as muParser does, and over a
// box of the variables by interval arithmetic with an enclosure of the gradient, for the
// mean-value form (f(box) in f(c) + grad f(box) . (box - c)), which sees that 1 - u and u sum
// to exactly 1 where the intervals alone would not. Parsing and evaluation at a point are in
// expression_tree.cpp, the enclosure over a box in expression_enclosure.cpp.
//
// muParser itself stays the evaluator of record: ExpressionMaterial compares the two at a
// set of points before it trusts a tree, and bounds nothing for an expression this parser
// does not read the same way.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "material/interval_math.h"

namespace trivox::detail {

// Variables by index: u, v, w (normalised parameters), x, y, z (mm).
inline constexpr int kExpressionVariables = 6;

class ExpressionTree {
 public:
  // nullopt when the text is not an expression of the documented syntax (an unknown name, a
  // muParser feature trivox does not document such as `=` or `,` at the top level).
  static std::optional<ExpressionTree> parse(std::string_view text,
                                             const std::vector<std::pair<std::string, double>>& constants);

  // The value at a point, as muParser computes it.
  double evaluate(const std::array<double, kExpressionVariables>& vars) const;

  struct Enclosure {
    IV value;
    // False where the expression is not Lipschitz over the box (a comparison or `c ? a : b`
    // undecided there, a sign or rint that changes, a square root reaching 0); then `gradient`
    // means nothing.
    bool differentiable = true;
    std::array<IV, kExpressionVariables> gradient{};
  };
  // Encloses the value and the gradient over the box `vars` of the variables.
  Enclosure enclose(const std::array<IV, kExpressionVariables>& vars) const;

  // Case analysis on conditions: the comparisons (values 0 or 1) are named by a text of
  // their subtree, so the same comparison in several expressions has one name (&& and ||
  // then follow from their operands). enclose() with `forced` takes the conditions named there as those values; with
  // `undecided` it adds the names of the conditions it could not decide over the box. At any
  // point a condition is either true or false, and one name has one value, so the hull over
  // every assignment of the undecided conditions encloses the expressions there, and the
  // sum of several expressions in each case sees what they share (a pattern and its
  // complement sum to 1 on both sides of their boundary).
  using Forced = std::vector<std::pair<std::string, double>>;
  Enclosure enclose(const std::array<IV, kExpressionVariables>& vars, const Forced& forced,
                    std::vector<std::string>* undecided) const;

  // Whether the expression reads variable `var`.
  bool uses(int var) const noexcept;

  enum class Op {
    kConst,
    kVar,
    kNeg,
    kAdd,
    kSub,
    kMul,
    kDiv,
    kPow,
    kLt,
    kLe,
    kGt,
    kGe,
    kEq,
    kNe,
    kAnd,
    kOr,
    kCond,
    kFunc
  };
  enum class Func {
    kSin,
    kCos,
    kTan,
    kAsin,
    kAcos,
    kAtan,
    kSinh,
    kCosh,
    kTanh,
    kAsinh,
    kAcosh,
    kAtanh,
    kLog2,
    kLog10,
    kLn,
    kExp,
    kSqrt,
    kSign,
    kRint,
    kAbs,
    kMin,
    kMax,
    kSum,
    kAvg,
    kAtan2
  };
  struct Node {
    Op op = Op::kConst;
    Func func = Func::kSin;
    double value = 0.0;  // kConst
    int var = 0;         // kVar
    std::vector<int> args;
  };

 private:
  double eval(int node, const std::array<double, kExpressionVariables>& vars) const;
  Enclosure encl(int node, const std::array<IV, kExpressionVariables>& vars, const Forced& forced,
                 std::vector<std::string>* undecided) const;
  std::string key(int node) const;

  std::vector<Node> nodes_;
  std::vector<std::string> keys_;  // per node, for the comparisons (empty for other nodes)
  // Per node: abs(t - rint(t)), the distance of t to the nearest integer (stripes and helices
  // are written so), bounded as a whole: interval arithmetic on its parts would not see that
  // t and rint(t) move together.
  std::vector<char> nearest_integer_distance_;
  int root_ = 0;
  friend class ExpressionParser;
};

}  // namespace trivox::detail
