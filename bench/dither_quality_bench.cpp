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
//    on walls), next to the share two independent patterns would give.
// Run: build/<preset>/bench/dither_quality_bench
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
  return 0;
}
