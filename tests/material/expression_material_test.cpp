// Expression materials: rows against the same formulas computed here, errors that name the
// expression, and concurrent evaluation from several threads.
#include <cmath>
#include <numbers>
#include <thread>

#include <gtest/gtest.h>

#include "material/material_test_util.h"
#include "trivox/material/expression_material.h"

namespace trivox {
namespace {

constexpr ParamBox kUnit{{0, 0, 0}, {1, 1, 1}};

ExpressionParams two_expressions() {
  ExpressionParams p;
  p.expressions = {"0.5 * (1 + sin(2 * pi * x / period)) * (1 - w)", "u * v + z / 100", ""};
  p.constants = {{"period", 10.0}};
  return p;
}

TEST(MaterialExpression, RowMatchesDirectFormula) {
  // A cell on [0,2] x [0,4] x [1,3]: expressions see u, v, w normalised to [0,1].
  const ParamBox cell{{0, 0, 1}, {2, 4, 3}};
  const ExpressionMaterial f(two_expressions(), cell);
  ASSERT_EQ(f.num_materials(), 3);
  const std::vector<Vec3> uvw = test::random_params(cell, 1000, 3);
  const std::vector<Vec3> xyz = test::random_params({{-20, -20, 0}, {20, 20, 50}}, 1000, 4);
  const std::vector<float> out = test::eval_row(f, uvw, xyz);
  for (std::size_t s = 0; s < uvw.size(); ++s) {
    const double u = uvw[s].x / 2, v = uvw[s].y / 4, w = (uvw[s].z - 1) / 2;
    const double a = 0.5 * (1 + std::sin(2 * std::numbers::pi * xyz[s].x / 10.0)) * (1 - w);
    const double b = u * v + xyz[s].z / 100;
    EXPECT_FLOAT_EQ(out[3 * s], static_cast<float>(a));
    EXPECT_FLOAT_EQ(out[3 * s + 1], static_cast<float>(b));
    EXPECT_EQ(out[3 * s + 2], 0.0f);  // an empty expression is 0
  }
}

TEST(MaterialExpression, ParametersOutsideTheCellAreClamped) {
  ExpressionParams p;
  p.expressions = {"u", "w"};
  const ExpressionMaterial f(p, {{0, 0, 10}, {2, 2, 20}});
  EXPECT_EQ(test::eval_one(f, {-1.0, 1.0, 25.0}), (std::vector<float>{0.0f, 1.0f}));
  EXPECT_EQ(test::eval_one(f, {3.0, 1.0, 5.0}), (std::vector<float>{1.0f, 0.0f}));
}

TEST(MaterialExpression, SyntaxErrorNamesTheExpression) {
  ExpressionParams p;
  p.expressions = {"u + ", "v"};
  try {
    ExpressionMaterial f(p, kUnit);
    FAIL() << "no error";
  } catch (const ExpressionError& e) {
    EXPECT_EQ(e.index(), 0);
    EXPECT_NE(std::string(e.what()).find("u + "), std::string::npos) << e.what();
  }
  p.expressions = {"u", "sin(q)"};  // unknown name
  try {
    ExpressionMaterial f(p, kUnit);
    FAIL() << "no error";
  } catch (const ExpressionError& e) {
    EXPECT_EQ(e.index(), 1);
  }
}

TEST(MaterialExpression, BadConstantNames) {
  for (const char* name : {"u", "pi", "2x", "a-b"}) {
    ExpressionParams p;
    p.expressions = {"1"};
    p.constants = {{name, 1.0}};
    try {
      ExpressionMaterial f(p, kUnit);
      FAIL() << "no error for " << name;
    } catch (const ExpressionError& e) {
      EXPECT_EQ(e.index(), -1) << name;
    }
  }
}

TEST(MaterialExpression, ConcurrentRowsGiveTheSameResults) {
  const ExpressionMaterial f(two_expressions(), kUnit);
  const std::vector<Vec3> uvw = test::random_params(kUnit, 512, 5);
  const std::vector<Vec3> xyz = test::random_params({{0, 0, 0}, {30, 30, 30}}, 512, 6);
  const std::vector<float> reference = test::eval_row(f, uvw, xyz);
  std::vector<int> mismatches(4, 0);
  std::vector<std::thread> threads;
  for (std::size_t t = 0; t < mismatches.size(); ++t)
    threads.emplace_back([&, t] {
      for (int rep = 0; rep < 200; ++rep)
        if (test::eval_row(f, uvw, xyz) != reference) ++mismatches[t];
    });
  for (std::thread& th : threads) th.join();
  for (int m : mismatches) EXPECT_EQ(m, 0);
}

}  // namespace
}  // namespace trivox
