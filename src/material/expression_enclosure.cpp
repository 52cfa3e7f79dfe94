// The interval enclosure of an expression tree over a box of its variables (value and
// gradient, ExpressionTree::enclose), apart from parsing and point evaluation
// (expression_tree.cpp): it exists for the fraction check (fraction_check.h), which proves
// over boxes of a cell that an expression material's fractions lie in [0, 1] and sum to 1, by
// the mean-value form where plain interval arithmetic cannot see that 1 - u and u sum to 1.
// Every rule here encloses what evaluate() (muParser's arithmetic) gives at the points of the
// box, rounding outwards (interval_math.h).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "material/expression_tree.h"

namespace trivox::detail {

using Op = ExpressionTree::Op;
using Func = ExpressionTree::Func;
using Node = ExpressionTree::Node;

namespace {

using Enclosure = ExpressionTree::Enclosure;
using Grad = std::array<IV, kExpressionVariables>;

Grad zero_gradient() {
  Grad g;
  g.fill(IV{0.0, 0.0, false});
  return g;
}
Enclosure constant(IV v) { return {v, true, zero_gradient()}; }
Enclosure not_differentiable(IV v) {
  Enclosure e{v, false, {}};
  return e;
}
Grad scaled(const Grad& g, const IV& s) {
  Grad out;
  for (std::size_t i = 0; i < g.size(); ++i) out[i] = g[i] * s;
  return out;
}
Grad plus(const Grad& a, const Grad& b) {
  Grad out;
  for (std::size_t i = 0; i < a.size(); ++i) out[i] = a[i] + b[i];
  return out;
}
Grad minus(const Grad& a, const Grad& b) {
  Grad out;
  for (std::size_t i = 0; i < a.size(); ++i) out[i] = a[i] - b[i];
  return out;
}
Grad hull(const Grad& a, const Grad& b) {
  Grad out;
  for (std::size_t i = 0; i < a.size(); ++i) out[i] = detail::hull(a[i], b[i]);
  return out;
}

// A monotone function of one variable applied to an interval: its values at the ends,
// widened for the C library's rounding.
template <class F>
IV increasing(const IV& a, F f) {
  return make(f(a.lo), f(a.hi));
}
template <class F>
IV decreasing(const IV& a, F f) {
  return make(f(a.hi), f(a.lo));
}

// Whether [lo, hi] holds (or nearly holds) a point c0 + k period for some integer k.
bool holds_periodic_point(double lo, double hi, double c0, double period) {
  const double slack = 1e-9 * std::max({1.0, std::abs(lo), std::abs(hi)});
  const double k = std::ceil((lo - slack - c0) / period);
  return c0 + k * period <= hi + slack;
}

// sin or cos (shift: the phase of the maxima, pi/2 for sin, 0 for cos).
IV trig(const IV& a, double max_at, double (*f)(double)) {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  if (!a.finite() || a.hi - a.lo >= kTwoPi) return {-1.0, 1.0, a.nan};
  const double fa = f(a.lo), fb = f(a.hi);
  IV r = make(std::min(fa, fb), std::max(fa, fb));
  if (holds_periodic_point(a.lo, a.hi, max_at, kTwoPi)) r.hi = 1.0;
  if (holds_periodic_point(a.lo, a.hi, max_at + std::numbers::pi, kTwoPi)) r.lo = -1.0;
  r.lo = std::max(r.lo, -1.0);
  r.hi = std::min(r.hi, 1.0);
  return r;
}

// An integer power of an interval.
IV integer_power(const IV& a, int n) {
  if (a.nan) return IV::undefined();
  if (n == 0) return IV::point(1.0);
  if (n < 0) {
    if (a.contains_zero()) return IV::undefined();
    return IV::point(1.0) / integer_power(a, -n);
  }
  const double pl = std::pow(a.lo, n), ph = std::pow(a.hi, n);
  if (n % 2 == 1) return make(pl, ph);
  if (a.lo >= 0.0) return make(pl, ph);
  if (a.hi <= 0.0) return make(ph, pl);
  return {0.0, up(std::max(pl, ph)), false};
}

bool truthy(const IV& a) { return !a.nan && (a.lo > 0.0 || a.hi < 0.0); }
bool falsy(const IV& a) { return !a.nan && a.lo == 0.0 && a.hi == 0.0; }
Enclosure boolean(bool is_true, bool is_false) {
  if (is_true) return constant(IV::point(1.0));
  if (is_false) return constant(IV::point(0.0));
  return not_differentiable({0.0, 1.0, false});
}

// A comparison or logical operator over its arguments' enclosures (arg(i)): 0, 1, or
// undecided.
template <class Arg>
ExpressionTree::Enclosure condition(const ExpressionTree::Node& n, const Arg& arg) {
  using Op = ExpressionTree::Op;
  if (n.op == Op::kAnd || n.op == Op::kOr) {
    const IV a = arg(0).value, b = arg(1).value;
    if (n.op == Op::kAnd) return boolean(truthy(a) && truthy(b), falsy(a) || falsy(b));
    return boolean(truthy(a) || truthy(b), falsy(a) && falsy(b));
  }
  const IV a = arg(0).value, b = arg(1).value;
  if (a.nan || b.nan) return not_differentiable({0.0, 1.0, false});
  switch (n.op) {
    case Op::kLt: return boolean(a.hi < b.lo, a.lo >= b.hi);
    case Op::kLe: return boolean(a.hi <= b.lo, a.lo > b.hi);
    case Op::kGt: return boolean(a.lo > b.hi, a.hi <= b.lo);
    case Op::kGe: return boolean(a.lo >= b.hi, a.hi < b.lo);
    case Op::kEq: return boolean(a.is_point() && b.is_point() && a.lo == b.lo, a.hi < b.lo || b.hi < a.lo);
    default: return boolean(a.hi < b.lo || b.hi < a.lo, a.is_point() && b.is_point() && a.lo == b.lo);
  }
}

// abs(t - rint(t)) with rint(t) = floor(t + 0.5), for the enclosure `t` of t: 0 at integers, 1/2
// at half-integers, slope 1 between (its generalised gradient: between -1 and 1 times t's).
Enclosure nearest_integer_distance(const Enclosure& t) {
  if (!t.value.finite()) return not_differentiable(IV::undefined());
  const auto distance = [](double x) { return std::abs(x - std::floor(x + 0.5)); };
  const double lo = t.value.lo, hi = t.value.hi;
  double dlo, dhi;
  if (hi - lo >= 1.0) {
    dlo = 0.0;
    dhi = 0.5;
  } else {
    dlo = std::ceil(lo) <= hi ? 0.0 : std::min(distance(lo), distance(hi));
    dhi = std::ceil(lo - 0.5) + 0.5 <= hi ? 0.5 : std::max(distance(lo), distance(hi));
  }
  Grad g;
  for (std::size_t i = 0; i < g.size(); ++i) g[i] = detail::hull(t.gradient[i], -t.gradient[i]);
  return {make(dlo, dhi), t.differentiable, g};
}

// An operator's enclosure from its arguments' (arg(i)); the comparisons and logical operators
// are named and enclosed by condition() before this is asked.
template <class Arg>
Enclosure enclose_operator(const Node& n, const std::array<IV, kExpressionVariables>& vars, const Arg& arg) {
  switch (n.op) {
    case Op::kConst: return constant(IV::point(n.value));
    case Op::kVar: {
      Enclosure e = constant(vars[static_cast<std::size_t>(n.var)]);
      e.gradient[static_cast<std::size_t>(n.var)] = IV::point(1.0);
      return e;
    }
    case Op::kNeg: {
      Enclosure a = arg(0);
      a.value = -a.value;
      for (IV& g : a.gradient) g = -g;
      return a;
    }
    case Op::kAdd:
    case Op::kSub: {
      const Enclosure a = arg(0), b = arg(1);
      const bool add = n.op == Op::kAdd;
      return {add ? a.value + b.value : a.value - b.value, a.differentiable && b.differentiable,
              add ? plus(a.gradient, b.gradient) : minus(a.gradient, b.gradient)};
    }
    case Op::kMul: {
      const Enclosure a = arg(0), b = arg(1);
      return {a.value * b.value, a.differentiable && b.differentiable,
              plus(scaled(a.gradient, b.value), scaled(b.gradient, a.value))};
    }
    case Op::kDiv: {
      const Enclosure a = arg(0), b = arg(1);
      const IV value = a.value / b.value;
      if (value.nan) return not_differentiable(value);
      const IV b2 = square(b.value);
      Grad g;
      for (std::size_t i = 0; i < g.size(); ++i) g[i] = (a.gradient[i] * b.value - b.gradient[i] * a.value) / b2;
      return {value, a.differentiable && b.differentiable, g};
    }
    case Op::kPow: {
      const Enclosure a = arg(0), b = arg(1);
      if (b.value.is_point() && std::abs(b.value.lo) <= 1024.0 && b.value.lo == std::rint(b.value.lo)) {
        const int k = static_cast<int>(b.value.lo);
        const IV value = integer_power(a.value, k);
        if (value.nan || k == 0) return k == 0 ? constant(IV::point(1.0)) : not_differentiable(value);
        const IV d = IV::point(static_cast<double>(k)) * integer_power(a.value, k - 1);
        return {value, a.differentiable && !d.nan, scaled(a.gradient, d)};
      }
      if (a.value.nan || b.value.nan || a.value.lo < 0.0 || (a.value.lo == 0.0 && b.value.lo <= 0.0))
        return not_differentiable(IV::undefined());
      const double c[4] = {std::pow(a.value.lo, b.value.lo), std::pow(a.value.lo, b.value.hi),
                           std::pow(a.value.hi, b.value.lo), std::pow(a.value.hi, b.value.hi)};
      const IV value = make(std::min(std::min(c[0], c[1]), std::min(c[2], c[3])),
                            std::max(std::max(c[0], c[1]), std::max(c[2], c[3])));
      if (a.value.lo <= 0.0) return not_differentiable(value);
      // d(x^y) = x^y (y / x dx + ln x dy)
      const IV lnx = make(std::log(a.value.lo), std::log(a.value.hi));
      const IV y_over_x = b.value / a.value;
      Grad g;
      for (std::size_t i = 0; i < g.size(); ++i) g[i] = value * (y_over_x * a.gradient[i] + lnx * b.gradient[i]);
      return {value, a.differentiable && b.differentiable, g};
    }
    case Op::kLt:
    case Op::kLe:
    case Op::kGt:
    case Op::kGe:
    case Op::kEq:
    case Op::kNe:
    case Op::kAnd:
    case Op::kOr: return condition(n, arg);  // (comparisons are named, and returned above)
    case Op::kCond: {
      const IV c = arg(0).value;
      if (truthy(c)) return arg(1);
      if (falsy(c)) return arg(2);
      return not_differentiable(detail::hull(arg(1).value, arg(2).value));
    }
    case Op::kFunc: break;
  }
  return not_differentiable(IV::undefined());
}

// A function of one argument (the argument's enclosure `a`): the function's enclosure over
// a's interval, and the chain rule with its derivative's.
Enclosure enclose_elementary(Func func, const Enclosure& a) {
  const IV& x = a.value;
  // f(x) with derivative d over the interval: the chain rule.
  const auto chain = [&](IV value, IV d) {
    if (value.nan || d.nan) return Enclosure{value, false, {}};
    return Enclosure{value, a.differentiable, scaled(a.gradient, d)};
  };
  switch (func) {
    case Func::kSin: return chain(trig(x, std::numbers::pi / 2, std::sin), trig(x, 0.0, std::cos));
    case Func::kCos: return chain(trig(x, 0.0, std::cos), -trig(x, std::numbers::pi / 2, std::sin));
    case Func::kTan: {
      if (!x.finite() || x.hi - x.lo >= std::numbers::pi ||
          holds_periodic_point(x.lo, x.hi, std::numbers::pi / 2, std::numbers::pi))
        return not_differentiable(IV::undefined());
      const IV t = increasing(x, [](double v) { return std::tan(v); });
      return chain(t, IV::point(1.0) + square(t));
    }
    case Func::kAsin:
    case Func::kAcos: {
      if (x.lo < -1.0 || x.hi > 1.0) return not_differentiable(IV::undefined());
      const IV value = func == Func::kAsin ? increasing(x, [](double v) { return std::asin(v); })
                                           : decreasing(x, [](double v) { return std::acos(v); });
      if (x.lo <= -1.0 || x.hi >= 1.0) return not_differentiable(value);
      IV d = IV::point(1.0) / increasing(IV::point(1.0) - square(x), [](double v) { return std::sqrt(v); });
      return chain(value, func == Func::kAsin ? d : -d);
    }
    case Func::kAtan:
      return chain(increasing(x, [](double v) { return std::atan(v); }), IV::point(1.0) / (IV::point(1.0) + square(x)));
    case Func::kSinh: {
      const IV cosh = x.lo >= 0.0   ? increasing(x, [](double v) { return std::cosh(v); })
                      : x.hi <= 0.0 ? decreasing(x, [](double v) { return std::cosh(v); })
                                    : IV{1.0, up(std::max(std::cosh(x.lo), std::cosh(x.hi))), false};
      return chain(increasing(x, [](double v) { return std::sinh(v); }), cosh);
    }
    case Func::kCosh: {
      const IV value = x.lo >= 0.0   ? increasing(x, [](double v) { return std::cosh(v); })
                       : x.hi <= 0.0 ? decreasing(x, [](double v) { return std::cosh(v); })
                                     : IV{1.0, up(std::max(std::cosh(x.lo), std::cosh(x.hi))), false};
      return chain(value, increasing(x, [](double v) { return std::sinh(v); }));
    }
    case Func::kTanh: {
      const IV t = increasing(x, [](double v) { return std::tanh(v); });
      return chain(t, IV::point(1.0) - square(t));
    }
    case Func::kAsinh:
      return chain(increasing(x, [](double v) { return std::asinh(v); }),
                   IV::point(1.0) / increasing(square(x) + IV::point(1.0), [](double v) { return std::sqrt(v); }));
    case Func::kAcosh: {
      if (x.lo < 1.0) return not_differentiable(IV::undefined());
      const IV value = increasing(x, [](double v) { return std::acosh(v); });
      if (x.lo <= 1.0) return not_differentiable(value);
      return chain(value, IV::point(1.0) / increasing(square(x) - IV::point(1.0),
                                                      [](double v) { return std::sqrt(std::max(v, 0.0)); }));
    }
    case Func::kAtanh: {
      if (x.lo <= -1.0 || x.hi >= 1.0) return not_differentiable(IV::undefined());
      return chain(increasing(x, [](double v) { return std::atanh(v); }),
                   IV::point(1.0) / (IV::point(1.0) - square(x)));
    }
    case Func::kLog2:
    case Func::kLog10:
    case Func::kLn: {
      if (x.lo <= 0.0) return not_differentiable(IV::undefined());
      const double base = func == Func::kLog2 ? std::numbers::ln2 : func == Func::kLog10 ? std::numbers::ln10 : 1.0;
      const IV value = func == Func::kLog2    ? increasing(x, [](double v) { return std::log2(v); })
                       : func == Func::kLog10 ? increasing(x, [](double v) { return std::log10(v); })
                                              : increasing(x, [](double v) { return std::log(v); });
      return chain(value, IV::point(1.0) / (x * IV{down(base), up(base), false}));
    }
    case Func::kExp: {
      const IV e = increasing(x, [](double v) { return std::exp(v); });
      return chain(e, e);
    }
    case Func::kSqrt: {
      if (x.lo < 0.0) return not_differentiable(IV::undefined());
      const IV s = increasing(x, [](double v) { return std::sqrt(v); });
      if (x.lo <= 0.0) return not_differentiable(s);
      return chain(s, IV::point(0.5) / s);
    }
    case Func::kSign: {
      if (x.lo > 0.0) return constant(IV::point(1.0));
      if (x.hi < 0.0) return constant(IV::point(-1.0));
      if (x.lo == 0.0 && x.hi == 0.0) return constant(IV::point(0.0));
      return not_differentiable({-1.0, 1.0, false});
    }
    case Func::kRint: {
      const double lo = std::floor(x.lo + 0.5), hi = std::floor(x.hi + 0.5);
      if (lo == hi) return constant(IV::point(lo));
      return not_differentiable({lo, hi, false});
    }
    case Func::kAbs: {
      if (x.lo >= 0.0) return a;
      if (x.hi <= 0.0) {
        Enclosure e = a;
        e.value = -x;
        for (IV& g : e.gradient) g = -g;
        return e;
      }
      // Lipschitz: the generalised gradient at 0 lies between -g and g.
      Grad g;
      for (std::size_t i = 0; i < g.size(); ++i) g[i] = detail::hull(a.gradient[i], -a.gradient[i]);
      return {{0.0, std::max(-x.lo, x.hi), false}, a.differentiable, g};
    }
    default: break;
  }
  return not_differentiable(IV::undefined());
}

// atan2(y, x) from the enclosures of y (`a`) and x (`b`).
Enclosure enclose_atan2(const Enclosure& a, const Enclosure& b) {
  const IV& y = a.value;
  const IV& xx = b.value;
  if (y.nan || xx.nan) return not_differentiable(IV::undefined());
  // Off the branch cut (the negative x axis, the origin) atan2 is monotone in each
  // variable, so its extremes over the box are at the corners.
  const bool off_cut = xx.lo > 0.0 || y.lo > 0.0 || y.hi < 0.0;
  if (!off_cut) return not_differentiable(IV{-std::numbers::pi, std::numbers::pi, false} + IV::point(0.0));
  const double c[4] = {std::atan2(y.lo, xx.lo), std::atan2(y.lo, xx.hi), std::atan2(y.hi, xx.lo),
                       std::atan2(y.hi, xx.hi)};
  const IV value =
      make(std::min(std::min(c[0], c[1]), std::min(c[2], c[3])), std::max(std::max(c[0], c[1]), std::max(c[2], c[3])));
  // d atan2(y, x) = (x dy - y dx) / (x^2 + y^2)
  const IV r2 = square(xx) + square(y);
  Grad g;
  for (std::size_t i = 0; i < g.size(); ++i) g[i] = (xx * a.gradient[i] - y * b.gradient[i]) / r2;
  return {value, a.differentiable && b.differentiable, g};
}

// min, max, sum and avg of the arguments' enclosures (the first `a`, the others arg(i)).
template <class Arg>
Enclosure enclose_list(const Node& n, const Enclosure& a, const Arg& arg) {
  std::vector<Enclosure> args{a};
  for (std::size_t i = 1; i < n.args.size(); ++i) args.push_back(arg(i));
  for (const Enclosure& e : args)
    if (e.value.nan) return not_differentiable(IV::undefined());
  if (n.func == Func::kSum || n.func == Func::kAvg) {
    Enclosure s = args.front();
    for (std::size_t i = 1; i < args.size(); ++i) {
      s.value = s.value + args[i].value;
      s.differentiable = s.differentiable && args[i].differentiable;
      s.gradient = plus(s.gradient, args[i].gradient);
    }
    if (n.func == Func::kAvg) {
      const IV count = IV::point(static_cast<double>(args.size()));
      s.value = s.value / count;
      s.gradient = scaled(s.gradient, IV::point(1.0) / count);
    }
    return s;
  }
  const bool is_min = n.func == Func::kMin;
  // The value: [min of the lows, min of the highs] (max: of the lows, of the highs); the
  // gradient: the hull of those of the arguments that can be the extreme one.
  double lo = args.front().value.lo, hi = args.front().value.hi;
  for (const Enclosure& e : args) {
    lo = is_min ? std::min(lo, e.value.lo) : std::max(lo, e.value.lo);
    hi = is_min ? std::min(hi, e.value.hi) : std::max(hi, e.value.hi);
  }
  Enclosure out{{lo, hi, false}, true, {}};
  bool first = true;
  for (const Enclosure& e : args) {
    const bool can_be = is_min ? e.value.lo <= hi : e.value.hi >= lo;
    if (!can_be) continue;
    out.differentiable = out.differentiable && e.differentiable;
    out.gradient = first ? e.gradient : hull(out.gradient, e.gradient);
    first = false;
  }
  return out;
}

}  // namespace

ExpressionTree::Enclosure ExpressionTree::enclose(const std::array<IV, kExpressionVariables>& vars) const {
  return encl(root_, vars, {}, nullptr);
}

ExpressionTree::Enclosure ExpressionTree::enclose(const std::array<IV, kExpressionVariables>& vars,
                                                  const Forced& forced, std::vector<std::string>* undecided) const {
  return encl(root_, vars, forced, undecided);
}

ExpressionTree::Enclosure ExpressionTree::encl(int index, const std::array<IV, kExpressionVariables>& vars,
                                               const Forced& forced, std::vector<std::string>* undecided) const {
  const Node& n = nodes_[static_cast<std::size_t>(index)];
  const std::string& name = keys_[static_cast<std::size_t>(index)];
  if (!name.empty()) {
    for (const auto& [k, value] : forced)
      if (k == name) return constant(IV::point(value));
  }
  const auto arg = [&](std::size_t i) { return encl(n.args[i], vars, forced, undecided); };
  if (nearest_integer_distance_[static_cast<std::size_t>(index)]) {
    const Node& d = nodes_[static_cast<std::size_t>(n.args[0])];
    return nearest_integer_distance(encl(d.args[0], vars, forced, undecided));
  }
  if (!name.empty() && undecided != nullptr) {
    // A condition: note it when it stays undecided over the box.
    const Enclosure e = condition(n, arg);
    if (!e.value.is_point() && std::find(undecided->begin(), undecided->end(), name) == undecided->end())
      undecided->push_back(name);
    return e;
  }
  if (!name.empty()) return condition(n, arg);
  if (n.op != Op::kFunc) return enclose_operator(n, vars, arg);
  const Enclosure a = arg(0);
  const IV& x = a.value;
  if (x.nan && n.func != Func::kMin && n.func != Func::kMax && n.func != Func::kSum && n.func != Func::kAvg &&
      n.func != Func::kAtan2)
    return not_differentiable(IV::undefined());
  if (n.func == Func::kAtan2) return enclose_atan2(a, arg(1));
  if (n.func == Func::kMin || n.func == Func::kMax || n.func == Func::kSum || n.func == Func::kAvg)
    return enclose_list(n, a, arg);
  return enclose_elementary(n.func, a);
}

}  // namespace trivox::detail
