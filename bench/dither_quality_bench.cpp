// Dithering quality figures for docs/DITHERING.md: a plain program (not a timing benchmark;
// nothing here depends on the machine), printing per method, on gradient and constant test
// blocks,
//  * the windowed fraction error: for windows of 8, 16 and 64 px at half-window steps, the
//    share of each label in the window minus the mean fraction asked for there, as the
//    largest absolute value and the root mean square over windows and labels;
//  * graininess: the root mean square of the error image (label indicator minus fraction,
//    per label, summed over labels) after a Gaussian low-pass of sigma 2 px and 4 px, the
//    part of the error the eye and the print do not average away;
//  * layer repetition: over 8 stacked layers of the same constant block, the share of pixels
//    that repeat the label of the layer below (a pattern that repeats draws vertical streaks
//    on walls), next to the share two independent patterns would give;
//  * streaks: the same per row and per column of blocks with a middle row and column (a part
//    symmetric about it), over 16 layers: a row that repeats draws a streak plane.
// Run: build/<preset>/bench/dither_quality_bench
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "trivox/raster/dither.h"

namespace {

using trivox::DitherParams;
using trivox::InsideMask;
using trivox::LabelImage;
using trivox::MaterialGrid;

constexpr int kSize = 512;

struct Block {
  std::string name;
  MaterialGrid grid;
};

std::vector<Block> blocks() {
  std::vector<Block> out;
  {
    MaterialGrid g(kSize, kSize, 2);
    for (int y = 0; y < kSize; ++y) {
      for (int x = 0; x < kSize; ++x) {
        const float t = (static_cast<float>(x) + 0.5f) / kSize;
        g.at(x, y, 0) = t;
        g.at(x, y, 1) = 1.0f - t;
      }
    }
    out.push_back({"gradient A->B", std::move(g)});
  }
  {
    MaterialGrid g(kSize, kSize, 1);
    for (int y = 0; y < kSize; ++y) {
      for (int x = 0; x < kSize; ++x) g.at(x, y, 0) = (static_cast<float>(x) + 0.5f) / kSize;
    }
    out.push_back({"gradient void->A", std::move(g)});
  }
  for (float f : {0.02f, 0.1f, 0.3f, 0.5f}) {
    MaterialGrid g(kSize, kSize, 1);
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) g.at(x, y, 0) = f;
    out.push_back({fmt::format("constant A {:.2f}", f), std::move(g)});
  }
  {
    MaterialGrid g(kSize, kSize, 3);
    for (int y = 0; y < kSize; ++y) {
      for (int x = 0; x < kSize; ++x) {
        g.at(x, y, 0) = 0.3f;
        g.at(x, y, 1) = 0.2f;
        g.at(x, y, 2) = 0.1f;
      }
    }
    out.push_back({"constant 0.3/0.2/0.1", std::move(g)});
  }
  return out;
}

// Error image of one label: indicator minus the fraction asked for (void = 1 - sum).
std::vector<double> error_image(const MaterialGrid& g, const LabelImage& labels, int label) {
  std::vector<double> e(static_cast<std::size_t>(kSize * kSize));
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      double f = 1.0;
      for (int k = 0; k < g.num_materials(); ++k) f -= g.at(x, y, k);
      if (label > 0) f = g.at(x, y, label - 1);
      e[static_cast<std::size_t>(y * kSize + x)] = (labels.at(x, y) == label ? 1.0 : 0.0) - f;
    }
  }
  return e;
}

struct WindowError {
  double max = 0, rms = 0;
};

WindowError window_error(const std::vector<std::vector<double>>& errors, int window) {
  WindowError out;
  double sum_sq = 0;
  long count = 0;
  for (const auto& e : errors) {
    for (int y0 = 0; y0 + window <= kSize; y0 += window / 2) {
      for (int x0 = 0; x0 + window <= kSize; x0 += window / 2) {
        double s = 0;
        for (int y = y0; y < y0 + window; ++y)
          for (int x = x0; x < x0 + window; ++x) s += e[static_cast<std::size_t>(y * kSize + x)];
        s /= window * window;
        out.max = std::max(out.max, std::abs(s));
        sum_sq += s * s;
        ++count;
      }
    }
  }
  out.rms = std::sqrt(sum_sq / static_cast<double>(count));
  return out;
}

// RMS of the error after a separable Gaussian low-pass, summed in quadrature over labels,
// over the interior (3 sigma away from the border).
double low_pass_rms(const std::vector<std::vector<double>>& errors, double sigma) {
  const int r = static_cast<int>(std::ceil(3 * sigma));
  std::vector<double> k(static_cast<std::size_t>(2 * r + 1));
  double ks = 0;
  for (int i = -r; i <= r; ++i) ks += k[static_cast<std::size_t>(i + r)] = std::exp(-i * i / (2 * sigma * sigma));
  for (double& v : k) v /= ks;
  double sum_sq = 0;
  long count = 0;
  for (const auto& e : errors) {
    std::vector<double> h(e.size(), 0.0);
    for (int y = 0; y < kSize; ++y)
      for (int x = r; x < kSize - r; ++x) {
        double s = 0;
        for (int i = -r; i <= r; ++i)
          s += k[static_cast<std::size_t>(i + r)] * e[static_cast<std::size_t>(y * kSize + x + i)];
        h[static_cast<std::size_t>(y * kSize + x)] = s;
      }
    for (int y = r; y < kSize - r; ++y)
      for (int x = r; x < kSize - r; ++x) {
        double s = 0;
        for (int i = -r; i <= r; ++i)
          s += k[static_cast<std::size_t>(i + r)] * h[static_cast<std::size_t>((y + i) * kSize + x)];
        sum_sq += s * s;
        ++count;
      }
  }
  return std::sqrt(sum_sq / static_cast<double>(count) * static_cast<double>(errors.size()));
}

}  // namespace

int main() {
  const InsideMask inside(kSize, kSize, 1);
  std::vector<DitherParams> methods;
  for (std::string_view name : trivox::dither_method_names()) {
    DitherParams p;
    trivox::set_dither_method(name, p);
    methods.push_back(p);
  }

  fmt::print("Windowed fraction error (max / rms over windows and labels, in percent) and graininess\n");
  fmt::print("(rms of the low-passed error, sigma 2 px and 4 px, in percent); {} x {} px blocks, layer 0.\n\n", kSize,
             kSize);
  fmt::print("| block | method | 8 px max / rms | 16 px max / rms | 64 px max / rms | grain s=2 | grain s=4 |\n");
  fmt::print("|---|---|---|---|---|---|---|\n");
  const std::vector<Block> all = blocks();
  for (const Block& b : all) {
    for (const DitherParams& p : methods) {
      const LabelImage labels = trivox::dither(b.grid, inside, p, 0);
      std::vector<std::vector<double>> errors;
      for (int label = 0; label <= b.grid.num_materials(); ++label)
        errors.push_back(error_image(b.grid, labels, label));
      std::string cells;
      for (int w : {8, 16, 64}) {
        const WindowError we = window_error(errors, w);
        cells += fmt::format(" {:.2f} / {:.2f} |", 100 * we.max, 100 * we.rms);
      }
      fmt::print("| {} | {} |{} {:.3f} | {:.3f} |\n", b.name, trivox::dither_method_name(p), cells,
                 100 * low_pass_rms(errors, 2.0), 100 * low_pass_rms(errors, 4.0));
    }
  }

  fmt::print("\nLayer repetition: share of pixels repeating the label of the layer below, 8 layers\n");
  fmt::print("(independent patterns would give the last column).\n\n");
  fmt::print("| block | method | fixed | varied by layer | independent |\n|---|---|---|---|---|\n");
  for (const Block& b : all) {
    if (b.name.rfind("constant", 0) != 0) continue;
    double independent = 0;
    {
      double sum = 0;
      for (int k = 0; k < b.grid.num_materials(); ++k) {
        const double f = b.grid.at(0, 0, k);
        independent += f * f;
        sum += f;
      }
      independent += (1 - sum) * (1 - sum);
    }
    for (DitherParams p : methods) {
      std::string cells;
      for (bool vary : {false, true}) {
        p.vary_by_layer = vary;
        long same = 0;
        LabelImage below = trivox::dither(b.grid, inside, p, 0);
        for (int layer = 1; layer < 8; ++layer) {
          LabelImage here = trivox::dither(b.grid, inside, p, layer);
          for (std::size_t i = 0; i < here.values().size(); ++i) same += here.values()[i] == below.values()[i] ? 1 : 0;
          below = std::move(here);
        }
        cells += fmt::format(" {:.3f} |", static_cast<double>(same) / (7.0 * kSize * kSize));
      }
      fmt::print("| {} | {} |{} {:.3f} |\n", b.name, trivox::dither_method_name(p), cells, independent);
    }
  }

  // Streaks: a part symmetric about its middle row (or column) must not repeat that row from
  // layer to layer, nor may any row or column come back in a later layer. Blocks of an odd
  // size, so that they have a middle row and column.
  constexpr int kOdd = kSize - 1;
  constexpr int kLayers = 16;
  fmt::print("\nStreaks: {} x {} px blocks (a middle row and column), {} layers varied by layer. Share of voxels\n",
             kOdd, kOdd, kLayers);
  fmt::print("repeating the label of the layer below: whole block, middle row, and the largest excess of a row and\n");
  fmt::print("of a column over what independent patterns give there; rows and columns repeated whole in two of\n");
  fmt::print("the layers (of {} pairs of layers x {} rows or columns); what independent patterns give.\n\n",
             kLayers * (kLayers - 1) / 2, kOdd);
  fmt::print(
      "| block | method | whole | middle row | largest row excess | largest column excess | rows repeated | "
      "columns repeated | independent |\n|---|---|---|---|---|---|---|---|---|\n");
  for (const Block& full : all) {
    if (full.name.rfind("constant A 0.02", 0) == 0 || full.name.rfind("constant A 0.10", 0) == 0) continue;
    MaterialGrid g(kOdd, kOdd, full.grid.num_materials());
    for (int y = 0; y < kOdd; ++y)
      for (int x = 0; x < kOdd; ++x)
        for (int k = 0; k < g.num_materials(); ++k)
          g.at(x, y, k) =
              full.name.rfind("gradient", 0) == 0 ? full.grid.at(x * kSize / kOdd, 0, k) : full.grid.at(0, 0, k);
    const InsideMask odd_inside(kOdd, kOdd, 1);
    // What independent patterns repeat at each voxel: the sum of squares of its fractions.
    std::vector<double> expected(static_cast<std::size_t>(kOdd) * kOdd);
    double expected_all = 0;
    for (int y = 0; y < kOdd; ++y)
      for (int x = 0; x < kOdd; ++x) {
        double sum = 0, sq = 0;
        for (int k = 0; k < g.num_materials(); ++k) {
          const double f = g.at(x, y, k);
          sq += f * f;
          sum += f;
        }
        sq += (1 - sum) * (1 - sum);
        expected[static_cast<std::size_t>(y) * kOdd + static_cast<std::size_t>(x)] = sq;
        expected_all += sq;
      }
    expected_all /= static_cast<double>(kOdd) * kOdd;
    for (DitherParams p : methods) {
      p.vary_by_layer = true;
      std::vector<LabelImage> layers;
      for (int layer = 0; layer < kLayers; ++layer) layers.push_back(trivox::dither(g, odd_inside, p, layer));
      std::vector<long> row_same(kOdd, 0), col_same(kOdd, 0);
      long same = 0;
      for (int layer = 1; layer < kLayers; ++layer) {
        const LabelImage& below = layers[static_cast<std::size_t>(layer - 1)];
        const LabelImage& here = layers[static_cast<std::size_t>(layer)];
        for (int y = 0; y < kOdd; ++y)
          for (int x = 0; x < kOdd; ++x) {
            const int s = here.at(x, y) == below.at(x, y) ? 1 : 0;
            row_same[static_cast<std::size_t>(y)] += s;
            col_same[static_cast<std::size_t>(x)] += s;
            same += s;
          }
      }
      long rows_repeated = 0, cols_repeated = 0;
      for (int a = 0; a < kLayers; ++a)
        for (int b = a + 1; b < kLayers; ++b) {
          const LabelImage& la = layers[static_cast<std::size_t>(a)];
          const LabelImage& lb = layers[static_cast<std::size_t>(b)];
          for (int i = 0; i < kOdd; ++i) {
            bool row = true, col = true;
            for (int j = 0; j < kOdd && (row || col); ++j) {
              row = row && la.at(j, i) == lb.at(j, i);
              col = col && la.at(i, j) == lb.at(i, j);
            }
            rows_repeated += row ? 1 : 0;
            cols_repeated += col ? 1 : 0;
          }
        }
      const double pairs = kLayers - 1;
      double row_excess = -1, col_excess = -1;
      for (int i = 0; i < kOdd; ++i) {
        double row_expected = 0, col_expected = 0;
        for (int j = 0; j < kOdd; ++j) {
          row_expected += expected[static_cast<std::size_t>(i) * kOdd + static_cast<std::size_t>(j)];
          col_expected += expected[static_cast<std::size_t>(j) * kOdd + static_cast<std::size_t>(i)];
        }
        row_excess = std::max(
            row_excess, (static_cast<double>(row_same[static_cast<std::size_t>(i)]) / pairs - row_expected) / kOdd);
        col_excess = std::max(
            col_excess, (static_cast<double>(col_same[static_cast<std::size_t>(i)]) / pairs - col_expected) / kOdd);
      }
      fmt::print("| {} | {} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {} | {} | {:.3f} |\n", full.name,
                 trivox::dither_method_name(p), static_cast<double>(same) / (pairs * kOdd * kOdd),
                 static_cast<double>(row_same[kOdd / 2]) / (pairs * kOdd), row_excess, col_excess, rows_repeated,
                 cols_repeated, expected_all);
    }
  }
  return 0;
}
