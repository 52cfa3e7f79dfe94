#include "material/expression_tree.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>

namespace trivox::detail {

using Op = ExpressionTree::Op;
using Func = ExpressionTree::Func;
using Node = ExpressionTree::Node;

// Recursive descent over muParser's precedence (muParserDef.h): `c ? a : b` lowest and right
// associative, then ||, &&, the comparisons, + and -, * and /, the unary signs (with * and /,
// below ^), and ^ (right associative).
class ExpressionParser {
 public:
  ExpressionParser(std::string_view text, const std::vector<std::pair<std::string, double>>& constants)
      : text_(text), constants_(constants) {}

  std::optional<ExpressionTree> run() {
    ExpressionTree tree;
    tree_ = &tree;
    const int root = conditional();
    skip_space();
    if (failed_ || at_ != text_.size()) return std::nullopt;
    tree.root_ = root;
    fold_constant_logic(tree);
    tree.keys_.resize(tree.nodes_.size());
    for (std::size_t i = 0; i < tree.nodes_.size(); ++i) {
      const Op op = tree.nodes_[i].op;
      // The comparisons are the cases; && and || follow from them.
      if (op == Op::kLt || op == Op::kLe || op == Op::kGt || op == Op::kGe || op == Op::kEq || op == Op::kNe)
        tree.keys_[i] = tree.key(static_cast<int>(i));
    }
    tree.nearest_integer_distance_.assign(tree.nodes_.size(), 0);
    for (std::size_t i = 0; i < tree.nodes_.size(); ++i) {
      const Node& n = tree.nodes_[i];
      if (n.op != Op::kFunc || n.func != Func::kAbs) continue;
      const Node& d = tree.nodes_[static_cast<std::size_t>(n.args[0])];
      if (d.op != Op::kSub) continue;
      const Node& r = tree.nodes_[static_cast<std::size_t>(d.args[1])];
      if (r.op != Op::kFunc || r.func != Func::kRint) continue;
      tree.nearest_integer_distance_[i] = tree.key(d.args[0]) == tree.key(r.args[0]) ? 1 : 0;
    }
    return tree;
  }

 private:
  int add(Node n) {
    tree_->nodes_.push_back(std::move(n));
    return static_cast<int>(tree_->nodes_.size() - 1);
  }
  int node(Op op, std::vector<int> args) {
    Node n;
    n.op = op;
    n.args = std::move(args);
    return add(std::move(n));
  }
  int fail() {
    failed_ = true;
    return add(Node{});
  }
  void skip_space() {
    while (at_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[at_]))) ++at_;
  }
  bool eat(std::string_view token) {
    skip_space();
    if (text_.substr(at_, token.size()) != token) return false;
    at_ += token.size();
    return true;
  }
  // One of the single-character operators, not the start of a two-character one.
  bool eat_single(char c, char not_followed_by = '\0') {
    skip_space();
    if (at_ >= text_.size() || text_[at_] != c) return false;
    if (not_followed_by != '\0' && at_ + 1 < text_.size() && text_[at_ + 1] == not_followed_by) return false;
    ++at_;
    return true;
  }

  int conditional() {
    const int c = logical_or();
    if (failed_) return c;
    if (eat_single('?')) {
      const int a = conditional();
      if (!eat_single(':')) return fail();
      const int b = conditional();
      return node(Op::kCond, {c, a, b});
    }
    return c;
  }
  int logical_or() {
    int l = logical_and();
    while (!failed_ && eat("||")) l = node(Op::kOr, {l, logical_and()});
    return l;
  }
  int logical_and() {
    int l = comparison();
    while (!failed_ && eat("&&")) l = node(Op::kAnd, {l, comparison()});
    return l;
  }
  int comparison() {
    int l = additive();
    while (!failed_) {
      Op op;
      if (eat("<="))
        op = Op::kLe;
      else if (eat(">="))
        op = Op::kGe;
      else if (eat("=="))
        op = Op::kEq;
      else if (eat("!="))
        op = Op::kNe;
      else if (eat_single('<'))
        op = Op::kLt;
      else if (eat_single('>'))
        op = Op::kGt;
      else
        break;
      l = node(op, {l, additive()});
    }
    return l;
  }
  int additive() {
    int l = multiplicative();
    while (!failed_) {
      if (eat_single('+'))
        l = node(Op::kAdd, {l, multiplicative()});
      else if (eat_single('-'))
        l = node(Op::kSub, {l, multiplicative()});
      else
        break;
    }
    return l;
  }
  int multiplicative() {
    int l = unary();
    while (!failed_) {
      if (eat_single('*'))
        l = node(Op::kMul, {l, unary()});
      else if (eat_single('/'))
        l = node(Op::kDiv, {l, unary()});
      else
        break;
    }
    return l;
  }
  int unary() {
    if (eat_single('-')) return node(Op::kNeg, {unary()});
    if (eat_single('+')) return unary();
    return power();
  }
  int power() {
    const int base = primary();
    if (!failed_ && eat_single('^')) return node(Op::kPow, {base, unary()});
    return base;
  }
  int primary() {
    skip_space();
    if (at_ >= text_.size()) return fail();
    const char c = text_[at_];
    if (c == '(') {
      ++at_;
      const int inner = conditional();
      if (!eat_single(')')) return fail();
      return inner;
    }
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') return number();
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') return name();
    return fail();
  }
  int number() {
    // Digits with one point, then an optional exponent: what muParser's value reader takes.
    std::size_t end = at_;
    bool point = false;
    while (end < text_.size() &&
           (std::isdigit(static_cast<unsigned char>(text_[end])) || (text_[end] == '.' && !point))) {
      point = point || text_[end] == '.';
      ++end;
    }
    if (end < text_.size() && (text_[end] == 'e' || text_[end] == 'E')) {
      std::size_t e = end + 1;
      if (e < text_.size() && (text_[e] == '+' || text_[e] == '-')) ++e;
      if (e < text_.size() && std::isdigit(static_cast<unsigned char>(text_[e]))) {
        while (e < text_.size() && std::isdigit(static_cast<unsigned char>(text_[e]))) ++e;
        end = e;
      }
    }
    const std::string digits(text_.substr(at_, end - at_));
    char* stop = nullptr;
    const double value = std::strtod(digits.c_str(), &stop);
    if (digits.empty() || stop != digits.c_str() + digits.size()) return fail();
    at_ = end;
    Node n;
    n.op = Op::kConst;
    n.value = value;
    return add(std::move(n));
  }
  int name() {
    std::size_t end = at_;
    while (end < text_.size() && (std::isalnum(static_cast<unsigned char>(text_[end])) || text_[end] == '_')) ++end;
    const std::string id(text_.substr(at_, end - at_));
    at_ = end;
    static constexpr std::string_view kVariables[] = {"u", "v", "w", "x", "y", "z"};
    for (int k = 0; k < kExpressionVariables; ++k)
      if (id == kVariables[k]) {
        Node n;
        n.op = Op::kVar;
        n.var = k;
        return add(std::move(n));
      }
    const auto constant = [&](double value) {
      Node n;
      n.op = Op::kConst;
      n.value = value;
      return add(std::move(n));
    };
    for (const auto& [cname, value] : constants_)
      if (id == cname) return constant(value);
    if (id == "pi" || id == "_pi") return constant(std::numbers::pi);
    if (id == "_e") return constant(std::numbers::e);
    struct Known {
      std::string_view name;
      Func func;
      int min_args, max_args;
    };
    static constexpr Known kFunctions[] = {
        {"sin", Func::kSin, 1, 1},     {"cos", Func::kCos, 1, 1},     {"tan", Func::kTan, 1, 1},
        {"asin", Func::kAsin, 1, 1},   {"acos", Func::kAcos, 1, 1},   {"atan", Func::kAtan, 1, 1},
        {"sinh", Func::kSinh, 1, 1},   {"cosh", Func::kCosh, 1, 1},   {"tanh", Func::kTanh, 1, 1},
        {"asinh", Func::kAsinh, 1, 1}, {"acosh", Func::kAcosh, 1, 1}, {"atanh", Func::kAtanh, 1, 1},
        {"log2", Func::kLog2, 1, 1},   {"log10", Func::kLog10, 1, 1}, {"log", Func::kLn, 1, 1},
        {"ln", Func::kLn, 1, 1},       {"exp", Func::kExp, 1, 1},     {"sqrt", Func::kSqrt, 1, 1},
        {"sign", Func::kSign, 1, 1},   {"rint", Func::kRint, 1, 1},   {"abs", Func::kAbs, 1, 1},
        {"min", Func::kMin, 1, 256},   {"max", Func::kMax, 1, 256},   {"sum", Func::kSum, 1, 256},
        {"avg", Func::kAvg, 1, 256},   {"atan2", Func::kAtan2, 2, 2},
    };
    for (const Known& f : kFunctions) {
      if (id != f.name) continue;
      if (!eat_single('(')) return fail();
      std::vector<int> args{conditional()};
      while (!failed_ && eat_single(',')) args.push_back(conditional());
      if (failed_ || !eat_single(')')) return fail();
      if (static_cast<int>(args.size()) < f.min_args || static_cast<int>(args.size()) > f.max_args) return fail();
      Node n;
      n.op = Op::kFunc;
      n.func = f.func;
      n.args = std::move(args);
      return add(std::move(n));
    }
    return fail();
  }

  // muParser folds an operation whose operands are constants when it compiles, and folds &&
  // and || with its operands truncated to int (0.5 || 0 is 0 there, but 1 when 0.5 is a
  // variable's value). A subtree without variables and without `c ? a : b` (which is not
  // folded) is folded; && and || of two such become that constant here too.
  static void fold_constant_logic(ExpressionTree& tree) {
    std::vector<char> folded(tree.nodes_.size(), 0);
    // Children come before their parents in the node list.
    for (std::size_t i = 0; i < tree.nodes_.size(); ++i) {
      Node& n = tree.nodes_[i];
      bool f = n.op != Op::kVar && n.op != Op::kCond;
      for (int a : n.args) f = f && folded[static_cast<std::size_t>(a)];
      folded[i] = f ? 1 : 0;
      if (f && (n.op == Op::kAnd || n.op == Op::kOr)) {
        const std::array<double, kExpressionVariables> none{};
        const auto truncated = [](double x) {
          // x86's conversion gives INT_MIN (true) for values out of int's range and NaN.
          return !(std::abs(x) < 2147483648.0) || static_cast<int>(x) != 0;
        };
        const bool a = truncated(tree.eval(n.args[0], none)), b = truncated(tree.eval(n.args[1], none));
        const double value = (n.op == Op::kAnd ? a && b : a || b) ? 1.0 : 0.0;
        n.op = Op::kConst;
        n.value = value;
        n.args.clear();
      }
    }
  }

  std::string_view text_;
  const std::vector<std::pair<std::string, double>>& constants_;
  ExpressionTree* tree_ = nullptr;
  std::size_t at_ = 0;
  bool failed_ = false;
};

std::optional<ExpressionTree> ExpressionTree::parse(std::string_view text,
                                                    const std::vector<std::pair<std::string, double>>& constants) {
  return ExpressionParser(text, constants).run();
}

bool ExpressionTree::uses(int var) const noexcept {
  return std::any_of(nodes_.begin(), nodes_.end(), [var](const Node& n) { return n.op == Op::kVar && n.var == var; });
}

double ExpressionTree::evaluate(const std::array<double, kExpressionVariables>& vars) const {
  return eval(root_, vars);
}

// As muParser's operators and MathImpl functions compute them.
double ExpressionTree::eval(int index, const std::array<double, kExpressionVariables>& vars) const {
  const Node& n = nodes_[static_cast<std::size_t>(index)];
  const auto arg = [&](std::size_t i) { return eval(n.args[i], vars); };
  switch (n.op) {
    case Op::kConst: return n.value;
    case Op::kVar: return vars[static_cast<std::size_t>(n.var)];
    case Op::kNeg: return -arg(0);
    case Op::kAdd: return arg(0) + arg(1);
    case Op::kSub: return arg(0) - arg(1);
    case Op::kMul: return arg(0) * arg(1);
    case Op::kDiv: return arg(0) / arg(1);
    case Op::kPow: return std::pow(arg(0), arg(1));
    case Op::kLt: return arg(0) < arg(1) ? 1.0 : 0.0;
    case Op::kLe: return arg(0) <= arg(1) ? 1.0 : 0.0;
    case Op::kGt: return arg(0) > arg(1) ? 1.0 : 0.0;
    case Op::kGe: return arg(0) >= arg(1) ? 1.0 : 0.0;
    case Op::kEq: return arg(0) == arg(1) ? 1.0 : 0.0;
    case Op::kNe: return arg(0) != arg(1) ? 1.0 : 0.0;
    case Op::kAnd: {
      const double a = arg(0), b = arg(1);
      return a != 0.0 && b != 0.0 ? 1.0 : 0.0;
    }
    case Op::kOr: {
      const double a = arg(0), b = arg(1);
      return a != 0.0 || b != 0.0 ? 1.0 : 0.0;
    }
    case Op::kCond: return arg(0) == 0.0 ? arg(2) : arg(1);
    case Op::kFunc: break;
  }
  const double a = arg(0);
  switch (n.func) {
    case Func::kSin: return std::sin(a);
    case Func::kCos: return std::cos(a);
    case Func::kTan: return std::tan(a);
    case Func::kAsin: return std::asin(a);
    case Func::kAcos: return std::acos(a);
    case Func::kAtan: return std::atan(a);
    case Func::kSinh: return std::sinh(a);
    case Func::kCosh: return std::cosh(a);
    case Func::kTanh: return std::tanh(a);
    case Func::kAsinh: return std::asinh(a);
    case Func::kAcosh: return std::acosh(a);
    case Func::kAtanh: return std::atanh(a);
    case Func::kLog2: return std::log2(a);
    case Func::kLog10: return std::log10(a);
    case Func::kLn: return std::log(a);
    case Func::kExp: return std::exp(a);
    case Func::kSqrt: return std::sqrt(a);
    case Func::kSign: return a < 0.0 ? -1.0 : a > 0.0 ? 1.0 : 0.0;
    case Func::kRint: return std::floor(a + 0.5);
    case Func::kAbs: return std::fabs(a);
    case Func::kAtan2: return std::atan2(a, arg(1));
    case Func::kMin:
    case Func::kMax:
    case Func::kSum:
    case Func::kAvg: {
      double r = a;
      for (std::size_t i = 1; i < n.args.size(); ++i) {
        const double b = arg(i);
        r = n.func == Func::kMin ? std::min(r, b) : n.func == Func::kMax ? std::max(r, b) : r + b;
      }
      return n.func == Func::kAvg ? r / static_cast<double>(n.args.size()) : r;
    }
  }
  return std::numeric_limits<double>::quiet_NaN();
}

// A text that names a subtree: equal texts, equal values at every point.
std::string ExpressionTree::key(int index) const {
  const Node& n = nodes_[static_cast<std::size_t>(index)];
  // Appended piece by piece: `"(" + std::to_string(...)` makes GCC 12 warn of an overlapping
  // copy (-Wrestrict) that cannot happen.
  std::string k = "(";
  k += std::to_string(static_cast<int>(n.op));
  if (n.op == Op::kConst) {
    char bits[32];
    std::snprintf(bits, sizeof bits, "%a", n.value);
    k += ' ';
    k += bits;
  } else if (n.op == Op::kVar) {
    k += " v";
    k += std::to_string(n.var);
  } else if (n.op == Op::kFunc) {
    k += " f";
    k += std::to_string(static_cast<int>(n.func));
  }
  for (int a : n.args) {
    k += ' ';
    k += key(a);
  }
  k += ')';
  return k;
}

}  // namespace trivox::detail
