#include "trivox/raster/dither.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "raster/blue_noise.h"
#include "raster/dither_kernels.h"
#include "raster/skin.h"
#include "trivox/error.h"

namespace trivox {
namespace {

// ---- reference implementation ------------------------------------------------------------
//
// The algorithm of dither.h written the slow, obvious way: one error vector per pixel of the
// whole image (64-bit, so overflow is out of the question), receivers gathered into a
// vector per pixel. It shares with the fast version only the tap table, the fraction
// rounding and the tie-break's hash (src/raster/dither_kernels.h). With `tie_break` (layer
// variation) each choice takes the bonus that hash gives the pixel, larger within
// detail::kStartRows rows of where the part starts in its column in scan order.
struct ReferenceResult {
  LabelImage labels;
  std::int64_t max_abs_error = 0;  // largest |error| component emitted, fixed-point units
};

ReferenceResult reference_dither(const MaterialGrid& grid, const InsideMask& inside, bool serpentine,
                                 DiffusionKernel kernel = DiffusionKernel::kFloydSteinberg,
                                 detail::ScanOrientation orientation = {}, bool tie_break = false, int layer = 0) {
  const int w = grid.width_px();
  const int h = grid.height_px();
  const int m = grid.num_materials();
  const int c_count = m + 1;
  std::vector<std::int64_t> error(static_cast<std::size_t>(w * h * c_count), 0);
  auto err = [&](int x, int y, int c) -> std::int64_t& {
    return error[static_cast<std::size_t>((y * w + x) * c_count + c)];
  };
  const std::span<const detail::DiffusionTap> taps = detail::diffusion_taps(kernel);

  // The scan walks logical rows ly = 0 .. h - 1 top-down; a bottom-up orientation is the
  // same walk over the image flipped upside down: image row y = h - 1 - ly.
  const int flip = orientation.bottom_up ? 1 : 0;
  auto image_y = [&](int ly) { return flip ? h - 1 - ly : ly; };
  ReferenceResult result{LabelImage(w, h), 0};
  // Rows since the part started in each column, in scan order: counted over the logical rows.
  std::vector<int> depth(static_cast<std::size_t>(w * h), 0);
  for (int ly = 0; ly < h; ++ly)
    for (int x = 0; x < w; ++x)
      if (ly > 0 && inside.inside(x, image_y(ly)) && inside.inside(x, image_y(ly - 1)))
        depth[static_cast<std::size_t>(ly * w + x)] = depth[static_cast<std::size_t>((ly - 1) * w + x)] + 1;
  for (int ly = 0; ly < h; ++ly) {
    const int y = image_y(ly);
    const bool reverse = (serpentine && ly % 2 == 1) != orientation.first_row_reversed;
    for (int i = 0; i < w; ++i) {
      const int x = reverse ? w - 1 - i : i;
      if (!inside.inside(x, y)) continue;

      std::vector<std::int64_t> desired(static_cast<std::size_t>(c_count));
      std::int64_t material_total = 0;
      for (int k = 0; k < m; ++k) {
        const std::int64_t q = detail::fraction_to_fixed(grid.at(x, y, k));
        desired[static_cast<std::size_t>(k + 1)] = err(x, y, k + 1) + q;
        material_total += q;
      }
      desired[0] = err(x, y, 0) + kDitherFixedOne - material_total;

      std::vector<std::int64_t> choice = desired;
      if (tie_break) {
        const detail::TieBreak tb =
            detail::tie_break(detail::tie_break_row_seed(layer, y), x, static_cast<std::uint32_t>(c_count),
                              std::min(depth[static_cast<std::size_t>(ly * w + x)], 255));
        choice[tb.component] += tb.bonus;
      }
      int best = 0;
      for (int c = 1; c < c_count; ++c) {
        if (choice[static_cast<std::size_t>(c)] > choice[static_cast<std::size_t>(best)]) {
          best = c;
        }
      }
      result.labels.at(x, y) = static_cast<std::uint8_t>(best);
      desired[static_cast<std::size_t>(best)] -= kDitherFixedOne;
      for (std::int64_t e : desired) result.max_abs_error = std::max(result.max_abs_error, std::abs(e));

      struct Receiver {
        int x, y;
        std::int64_t weight;
      };
      std::vector<Receiver> receivers;
      for (const detail::DiffusionTap& tap : taps) {
        const int nx = x + (reverse ? -tap.dx : tap.dx);
        const int nly = ly + tap.dy;
        if (nx >= 0 && nx < w && nly < h && inside.inside(nx, image_y(nly))) {
          const int ny = image_y(nly);
          receivers.push_back({nx, ny, tap.weight});
        }
      }
      if (receivers.empty()) continue;
      std::int64_t weight_sum = 0;
      for (const Receiver& r : receivers) weight_sum += r.weight;
      for (int c = 0; c < c_count; ++c) {
        const std::int64_t e = desired[static_cast<std::size_t>(c)];
        std::int64_t given = 0;
        for (std::size_t j = 0; j + 1 < receivers.size(); ++j) {
          const std::int64_t share = e * receivers[j].weight / weight_sum;
          err(receivers[j].x, receivers[j].y, c) += share;
          given += share;
        }
        err(receivers.back().x, receivers.back().y, c) += e - given;
      }
    }
  }
  return result;
}

// Blue-noise thresholding the slow way: the threshold as the exact rational (rank + 1/2) /
// 4096, compared with running sums of the fractions (rounded to the same fixed-point grid
// as the input of every method) scaled to the same denominator.
LabelImage reference_blue_noise(const MaterialGrid& grid, const InsideMask& inside, int layer, bool vary) {
  const auto& tile = blue_noise_tile();
  const int m = grid.num_materials();
  const detail::TileOffset off = detail::tile_offset(layer, vary);
  LabelImage labels(grid.width_px(), grid.height_px());
  for (int y = 0; y < grid.height_px(); ++y) {
    for (int x = 0; x < grid.width_px(); ++x) {
      if (!inside.inside(x, y)) continue;
      const int tx = (x + off.dx) % kBlueNoiseTileSize, ty = (y + off.dy) % kBlueNoiseTileSize;
      const std::int64_t rank = tile[static_cast<std::size_t>(ty * kBlueNoiseTileSize + tx)];
      // threshold = (2 rank + 1) / 8192; component sums in units of 1 / 65536.
      const std::int64_t threshold_num = (2 * rank + 1) * 8;  // in units of 1 / 65536
      std::vector<std::int64_t> parts(static_cast<std::size_t>(m + 1));
      std::int64_t total = 0;
      for (int k = 0; k < m; ++k) {
        parts[static_cast<std::size_t>(k + 1)] = detail::fraction_to_fixed(grid.at(x, y, k));
        total += parts[static_cast<std::size_t>(k + 1)];
      }
      parts[0] = std::max<std::int64_t>(0, kDitherFixedOne - total);
      std::int64_t running = 0;
      int label = m;
      for (int c = 0; c <= m; ++c) {
        running += parts[static_cast<std::size_t>(c)];
        if (threshold_num < running) {
          label = c;
          break;
        }
      }
      labels.at(x, y) = static_cast<std::uint8_t>(label);
    }
  }
  return labels;
}

// Every method by name, each with and without layer variation.
std::vector<DitherParams> every_method() {
  std::vector<DitherParams> all;
  for (std::string_view name : dither_method_names()) {
    for (bool vary : {true, false}) {
      DitherParams p;
      EXPECT_TRUE(set_dither_method(name, p)) << name;
      p.vary_by_layer = vary;
      all.push_back(p);
    }
  }
  return all;
}

std::string describe(const DitherParams& p, int layer) {
  return std::string(dither_method_name(p)) + (p.vary_by_layer ? " varied" : " fixed") + " layer " +
         std::to_string(layer);
}

// ---- fixtures ----------------------------------------------------------------------------

// Portable uniform [0, 1): std::mt19937's sequence is specified by the standard, the real
// distributions are not.
float uniform(std::mt19937& rng) { return static_cast<float>(rng() >> 8) * 0x1p-24f; }
int uniform_int(std::mt19937& rng, int lo, int hi) {
  return lo + static_cast<int>(rng() % static_cast<std::uint32_t>(hi - lo + 1));
}

// Random fractions: smooth fields, noise, pure pixels and exact ties, all summing to <= 1.
MaterialGrid random_grid(std::mt19937& rng, int w, int h, int m) {
  MaterialGrid grid(w, h, m);
  const int style = uniform_int(rng, 0, 2);
  std::vector<float> phase(static_cast<std::size_t>(m));
  for (float& p : phase) p = 6.28f * uniform(rng);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      std::vector<float> raw(static_cast<std::size_t>(m));
      float total = 1.0f;
      if (style == 0) {  // smooth
        for (int k = 0; k < m; ++k) {
          raw[static_cast<std::size_t>(k)] = 1.0f + std::sin(0.11f * static_cast<float>(x) +
                                                             0.07f * static_cast<float>(y) * static_cast<float>(k + 1) +
                                                             phase[static_cast<std::size_t>(k)]);
        }
        total = 0.5f + 0.5f * std::cos(0.05f * static_cast<float>(x + y));
      } else if (style == 1) {  // noise
        for (float& r : raw) r = uniform(rng);
        total = uniform(rng);
      } else {  // pure pixels, void and ties
        const int kind = uniform_int(rng, 0, 3);
        if (kind == 0) raw[static_cast<std::size_t>(uniform_int(rng, 0, m - 1))] = 1.0f;
        if (kind == 1) total = 0.0f;
        if (kind >= 2) {
          for (float& r : raw) r = 1.0f;
          total = kind == 2 ? 1.0f : 0.5f;
        }
        if (kind == 1) raw[0] = 1.0f;
      }
      float sum = 0.0f;
      for (float r : raw) sum += r;
      for (int k = 0; k < m; ++k) {
        grid.at(x, y, k) = sum > 0.0f ? raw[static_cast<std::size_t>(k)] / sum * total : 0.0f;
      }
    }
  }
  return grid;
}

InsideMask random_mask(std::mt19937& rng, int w, int h) {
  InsideMask mask(w, h, 1);
  const int style = uniform_int(rng, 0, 2);
  if (style == 0) return mask;  // all inside
  const float cx = uniform(rng) * static_cast<float>(w);
  const float cy = uniform(rng) * static_cast<float>(h);
  const float r = (0.2f + 0.6f * uniform(rng)) * static_cast<float>(std::max(w, h));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const float dx = static_cast<float>(x) - cx;
      const float dy = static_cast<float>(y) - cy;
      bool in = dx * dx + dy * dy < r * r;
      if (style == 2 && uniform(rng) < 0.15f) in = !in;  // speckle: isolated pixels, holes
      mask.at(x, y) = in ? 1 : 0;
    }
  }
  return mask;
}

std::uint64_t fnv1a(std::span<const std::uint8_t> bytes) {
  std::uint64_t hash = 14695981039346656037ull;
  for (std::uint8_t b : bytes) {
    hash ^= b;
    hash *= 1099511628211ull;
  }
  return hash;
}

// Share of pixels with `label` in a window.
double share(const LabelImage& labels, int x0, int y0, int w, int h, std::uint8_t label) {
  int count = 0;
  for (int y = y0; y < y0 + h; ++y) {
    for (int x = x0; x < x0 + w; ++x) count += labels.at(x, y) == label ? 1 : 0;
  }
  return static_cast<double>(count) / static_cast<double>(w * h);
}

// ---- tests -------------------------------------------------------------------------------

TEST(DitherTest, MatchesReferenceBitForBit) {
  std::mt19937 rng(20240611u);
  std::int64_t worst_error = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const int w = uniform_int(rng, 1, 90);
    const int h = uniform_int(rng, 1, 50);
    const int m = trial % 50 == 7 ? kMaxMaterials : uniform_int(rng, 1, 10);  // 1 to 8 unrolled, beyond generic
    const MaterialGrid grid = random_grid(rng, w, h, m);
    const InsideMask mask = random_mask(rng, w, h);
    DitherParams params;
    params.serpentine = trial % 2 == 0;
    params.kernel = static_cast<DiffusionKernel>(trial % 3);
    params.vary_by_layer = trial % 7 != 3;
    const int layer = (trial / 2) % 5;
    const LabelImage fast = dither(grid, mask, params, layer);
    const ReferenceResult ref =
        reference_dither(grid, mask, params.serpentine, params.kernel,
                         detail::scan_orientation(layer, params.vary_by_layer), params.vary_by_layer, layer);
    ASSERT_EQ(fast, ref.labels) << "trial " << trial << ": " << w << " x " << h << ", m = " << m << ", "
                                << describe(params, layer);
    worst_error = std::max(worst_error, ref.max_abs_error);
  }
  // The fast version keeps errors in int32 (32768 units of kDitherFixedOne): far away.
  EXPECT_LT(worst_error, 8 * std::int64_t{kDitherFixedOne});
}

// Blocks of pure material with graded seams between them (the porous tiles of the paper's
// duck): inside a block a pixel's choice meets its desire exactly and it has no error to pass
// on, which the fast path skips; across a seam the error flows again. Both bit for bit the
// reference.
TEST(DitherTest, PureBlocksMatchReferenceBitForBit) {
  std::mt19937 rng(8u);
  int exact_pixels = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const int w = uniform_int(rng, 20, 120), h = uniform_int(rng, 10, 60), m = uniform_int(rng, 1, 4);
    const int block = uniform_int(rng, 3, 12), seam = uniform_int(rng, 0, 3);
    MaterialGrid grid(w, h, m);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const int bx = x / block, by = y / block;
        const int material = (bx + 2 * by) % (m + 1);  // m: a void block
        const bool in_seam = x % block < seam;
        if (in_seam) {
          for (int k = 0; k < m; ++k) grid.at(x, y, k) = 0.7f / static_cast<float>(m);
        } else if (material < m) {
          grid.at(x, y, material) = 1.0f;
          ++exact_pixels;
        }
      }
    const InsideMask mask = random_mask(rng, w, h);
    DitherParams params;
    params.serpentine = trial % 2 == 0;
    params.kernel = static_cast<DiffusionKernel>(trial % 3);
    const int layer = trial % 4;
    const LabelImage fast = dither(grid, mask, params, layer);
    const ReferenceResult ref =
        reference_dither(grid, mask, params.serpentine, params.kernel,
                         detail::scan_orientation(layer, params.vary_by_layer), params.vary_by_layer, layer);
    ASSERT_EQ(fast, ref.labels) << "trial " << trial << ": " << w << " x " << h << ", m = " << m << ", block " << block
                                << ", seam " << seam;
  }
  EXPECT_GT(exact_pixels, 10000);
}

TEST(DitherTest, LabelsAreMaterialsOrVoid) {
  std::mt19937 rng(7u);
  for (int m : {1, 2, 3, 6, 17}) {
    const MaterialGrid grid = random_grid(rng, 64, 48, m);
    const InsideMask mask = random_mask(rng, 64, 48);
    for (DitherParams params : every_method()) {
      for (int skin : {0, 2}) {
        params.skin_voxels = skin;
        for (int layer : {0, 1, 6}) {
          const LabelImage labels = dither(grid, mask, params, layer);
          for (int y = 0; y < 48; ++y) {
            for (int x = 0; x < 64; ++x) {
              const std::uint8_t label = labels.at(x, y);
              ASSERT_LE(label, m) << describe(params, layer);
              if (!mask.inside(x, y)) {
                ASSERT_EQ(label, LabelImage::kVoid) << describe(params, layer);
              }
            }
          }
        }
      }
    }
  }
}

TEST(DitherTest, BlueNoiseMatchesReference) {
  std::mt19937 rng(4242u);
  for (int trial = 0; trial < 60; ++trial) {
    const int w = uniform_int(rng, 1, 150);
    const int h = uniform_int(rng, 1, 90);
    const int m = uniform_int(rng, 1, 6);
    const MaterialGrid grid = random_grid(rng, w, h, m);
    const InsideMask mask = random_mask(rng, w, h);
    DitherParams params;
    params.method = DitherMethod::kBlueNoise;
    params.vary_by_layer = trial % 2 == 0;
    const int layer = uniform_int(rng, 0, 200);
    ASSERT_EQ(dither(grid, mask, params, layer), reference_blue_noise(grid, mask, layer, params.vary_by_layer))
        << "trial " << trial << ": " << describe(params, layer);
  }
}

// The tile is a permutation of 0 .. 4095 and its thresholded patterns are even: every
// aligned 8 x 8 block of the pattern for any level n holds close to n / 64 of its pixels
// (a white-noise permutation misses by several pixels), and the sparsest patterns keep their
// points apart.
TEST(DitherTest, BlueNoiseTileIsAnEvenPermutation) {
  const auto& tile = blue_noise_tile();
  std::vector<int> seen(kBlueNoiseTileCells, 0);
  for (std::uint16_t r : tile) {
    ASSERT_LT(r, kBlueNoiseTileCells);
    ++seen[r];
  }
  for (int count : seen) ASSERT_EQ(count, 1);

  // The worst miss of an aligned 8 x 8 block against its share n / 64, over 15 levels.
  auto worst_block_miss = [](const auto& ranks) {
    int worst = 0;
    for (int level = 256; level < kBlueNoiseTileCells; level += 256) {
      for (int by = 0; by < kBlueNoiseTileSize; by += 8) {
        for (int bx = 0; bx < kBlueNoiseTileSize; bx += 8) {
          int on = 0;
          for (int y = by; y < by + 8; ++y)
            for (int x = bx; x < bx + 8; ++x) on += ranks[static_cast<std::size_t>(y * 64 + x)] < level ? 1 : 0;
          worst = std::max(worst, std::abs(64 * on - level) / 64);
        }
      }
    }
    return worst;
  };
  std::vector<int> white(kBlueNoiseTileCells);
  for (int i = 0; i < kBlueNoiseTileCells; ++i) white[static_cast<std::size_t>(i)] = i;
  std::mt19937 rng(3u);
  for (int i = kBlueNoiseTileCells - 1; i > 0; --i)
    std::swap(white[static_cast<std::size_t>(i)], white[static_cast<std::size_t>(uniform_int(rng, 0, i))]);
  const int blue_miss = worst_block_miss(tile);
  const int white_miss = worst_block_miss(white);
  RecordProperty("worst_block_miss_blue_px", blue_miss);
  RecordProperty("worst_block_miss_white_px", white_miss);
  EXPECT_LE(2 * blue_miss, white_miss);
  EXPECT_LE(blue_miss, 6);

  // The first 5 % of ranks: no two points closer than 2 pixels (toroidal distance).
  std::vector<std::pair<int, int>> points;
  for (int c = 0; c < kBlueNoiseTileCells; ++c)
    if (tile[static_cast<std::size_t>(c)] < kBlueNoiseTileCells / 20) points.emplace_back(c % 64, c / 64);
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (std::size_t j = i + 1; j < points.size(); ++j) {
      int dx = std::abs(points[i].first - points[j].first), dy = std::abs(points[i].second - points[j].second);
      dx = std::min(dx, 64 - dx);
      dy = std::min(dy, 64 - dy);
      ASSERT_GE(dx * dx + dy * dy, 4) << i << ", " << j;
    }
  }
}

// Blue noise depends on the pixel position only: dithering a crop that starts on a tile
// boundary gives the crop of the whole, whatever the neighbours hold.
TEST(DitherTest, BlueNoiseIsPositionDeterministic) {
  std::mt19937 rng(11u);
  const MaterialGrid grid = random_grid(rng, 200, 150, 3);
  const InsideMask mask(200, 150, 1);
  DitherParams params;
  params.method = DitherMethod::kBlueNoise;
  for (int layer : {0, 3}) {
    const LabelImage whole = dither(grid, mask, params, layer);
    MaterialGrid crop(70, 80, 3);
    for (int y = 0; y < 80; ++y)
      for (int x = 0; x < 70; ++x)
        for (int k = 0; k < 3; ++k) crop.at(x, y, k) = grid.at(x + 128, y + 64, k);
    // The crop starts at (128, 64), a multiple of the tile: the same tile cells.
    const LabelImage part = dither(crop, InsideMask(70, 80, 1), params, layer);
    for (int y = 0; y < 80; ++y)
      for (int x = 0; x < 70; ++x) ASSERT_EQ(part.at(x, y), whole.at(x + 128, y + 64)) << x << ", " << y;
  }
}

// Without variation every layer gets the same pattern; with it every layer another (no
// pattern stacks up into vertical streaks), each still exact in the mean. Blue noise's
// layer 0 is the unshifted tile, as without variation.
TEST(DitherTest, LayerVariationChangesThePattern) {
  MaterialGrid grid(96, 64, 2);
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 96; ++x) {
      grid.at(x, y, 0) = 0.3f;
      grid.at(x, y, 1) = 0.45f;
    }
  }
  const InsideMask mask(96, 64, 1);
  for (std::string_view name : dither_method_names()) {
    DitherParams varied;
    set_dither_method(name, varied);
    DitherParams fixed = varied;
    fixed.vary_by_layer = false;
    if (varied.method == DitherMethod::kBlueNoise) {
      EXPECT_EQ(dither(grid, mask, varied, 0), dither(grid, mask, fixed, 0));
    } else {
      EXPECT_NE(dither(grid, mask, varied, 0), dither(grid, mask, fixed, 0)) << name;
    }
    std::vector<LabelImage> layers;
    for (int layer = 0; layer < 8; ++layer) {
      layers.push_back(dither(grid, mask, varied, layer));
      EXPECT_EQ(dither(grid, mask, fixed, layer), dither(grid, mask, fixed, 0)) << name << " layer " << layer;
      EXPECT_NEAR(share(layers.back(), 0, 0, 96, 64, 1), 0.3, 0.01) << name;
      EXPECT_NEAR(share(layers.back(), 0, 0, 96, 64, 2), 0.45, 0.01) << name;
    }
    for (int a = 0; a < 8; ++a)
      for (int b = a + 1; b < 8; ++b)
        EXPECT_NE(layers[static_cast<std::size_t>(a)], layers[static_cast<std::size_t>(b)])
            << name << " layers " << a << ", " << b;
  }
}

// A part symmetric about its middle row and column (the bar, the tube): the scan orientations
// alone mirror layers into each other, so its middle row and column would repeat in pairs of
// layers (a streak plane), and layers four apart would be the same. With the tie-break no row
// and no column of any two of 16 layers is the same.
TEST(DitherTest, ASymmetricPartRepeatsNoRowOrColumn) {
  constexpr int kW = 61, kH = 41, kLayers = 16;
  MaterialGrid grid(kW, kH, 2);
  InsideMask mask(kW, kH, 0);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const double dx = std::abs(x - kW / 2) / (kW / 2.0), dy = std::abs(y - kH / 2) / (kH / 2.0);
      grid.at(x, y, 0) = static_cast<float>(0.2 + 0.4 * dx);
      grid.at(x, y, 1) = static_cast<float>(0.15 + 0.2 * dy);
      mask.at(x, y) = dx * dx + dy * dy <= 1.0 ? 1 : 0;
    }
  const auto same_row = [](const LabelImage& a, const LabelImage& b, int y) {
    for (int x = 0; x < a.width_px(); ++x)
      if (a.at(x, y) != b.at(x, y)) return false;
    return true;
  };
  const auto same_column = [](const LabelImage& a, const LabelImage& b, int x) {
    for (int y = 0; y < a.height_px(); ++y)
      if (a.at(x, y) != b.at(x, y)) return false;
    return true;
  };
  for (int kernel = 0; kernel < 3; ++kernel) {
    DitherParams params;
    params.kernel = static_cast<DiffusionKernel>(kernel);
    SCOPED_TRACE(describe(params, 0));
    // The orientations alone: layers 1 and 2 mirror each other about the middle row.
    const auto without = [&](int layer) {
      return reference_dither(grid, mask, true, params.kernel, detail::scan_orientation(layer, true)).labels;
    };
    EXPECT_TRUE(same_row(without(1), without(2), kH / 2));
    EXPECT_EQ(without(0), without(4));
    std::vector<LabelImage> layers;
    for (int layer = 0; layer < kLayers; ++layer) layers.push_back(dither(grid, mask, params, layer));
    for (int a = 0; a < kLayers; ++a)
      for (int b = a + 1; b < kLayers; ++b) {
        // Rows and columns that hold a few pixels only may repeat by chance: not those.
        for (int y = 4; y < kH - 4; ++y)
          EXPECT_FALSE(same_row(layers[a], layers[b], y)) << a << " " << b << " row " << y;
        for (int x = 4; x < kW - 4; ++x)
          EXPECT_FALSE(same_column(layers[a], layers[b], x)) << a << " " << b << " column " << x;
      }
  }
}

// The tie-break only decides near-ties: a pure material (or void) never flips, whatever the
// mask and the layer.
TEST(DitherTest, VariationNeverChangesAPureMaterial) {
  std::mt19937 rng(31u);
  for (int trial = 0; trial < 60; ++trial) {
    const int w = uniform_int(rng, 1, 70), h = uniform_int(rng, 1, 50), m = uniform_int(rng, 1, 4);
    const int material = uniform_int(rng, 0, m);  // m: void
    MaterialGrid grid(w, h, m);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (material < m) grid.at(x, y, material) = 1.0f;
    const InsideMask mask = random_mask(rng, w, h);
    DitherParams params;
    params.kernel = static_cast<DiffusionKernel>(trial % 3);
    params.serpentine = trial % 2 == 0;
    const std::uint8_t expected = material < m ? LabelImage::label_of_material(material) : LabelImage::kVoid;
    for (int layer = 0; layer < 12; ++layer) {
      const LabelImage labels = dither(grid, mask, params, layer);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
          ASSERT_EQ(labels.at(x, y), mask.inside(x, y) ? expected : LabelImage::kVoid) << "trial " << trial;
    }
  }
}

// The chessboard depth against its definition: the smallest max(|dx|, |dy|) to an outside
// pixel or to a pixel beyond the border.
TEST(DitherTest, SkinDepthMatchesBruteForce) {
  std::mt19937 rng(5u);
  for (int trial = 0; trial < 20; ++trial) {
    const int w = uniform_int(rng, 1, 40), h = uniform_int(rng, 1, 30);
    const InsideMask mask = random_mask(rng, w, h);
    const auto depth = detail::chessboard_depth(mask, 1000);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        int expected = 0;
        if (mask.inside(x, y)) {
          expected = std::min({x + 1, y + 1, w - x, h - y});
          for (int yy = 0; yy < h; ++yy)
            for (int xx = 0; xx < w; ++xx)
              if (!mask.inside(xx, yy)) expected = std::min(expected, std::max(std::abs(xx - x), std::abs(yy - y)));
        }
        ASSERT_EQ(depth.at(x, y), expected) << "trial " << trial << " at " << x << ", " << y;
      }
    }
  }
}

// The skin takes the nearest pure label; the core is dithered exactly as a part whose mask
// is the core alone, so no error crosses between skin and core.
TEST(DitherTest, SkinIsPureAndSeparate) {
  std::mt19937 rng(17u);
  constexpr int kW = 70, kH = 50, kSkin = 3;
  const MaterialGrid grid = random_grid(rng, kW, kH, 3);
  InsideMask mask(kW, kH, 0);
  for (int y = 5; y < 45; ++y)
    for (int x = 4; x < 66; ++x) mask.at(x, y) = (x - 35) * (x - 35) / 4 + (y - 25) * (y - 25) < 500 ? 1 : 0;
  for (DitherParams params : every_method()) {
    params.skin_voxels = kSkin;
    const LabelImage labels = dither(grid, mask, params, 1);
    const auto depth = detail::chessboard_depth(mask, kSkin + 1);
    InsideMask core(kW, kH, 0);
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) core.at(x, y) = depth.at(x, y) > kSkin ? 1 : 0;
    DitherParams no_skin = params;
    no_skin.skin_voxels = 0;
    const LabelImage core_only = dither(grid, core, no_skin, 1);
    for (int y = 0; y < kH; ++y) {
      for (int x = 0; x < kW; ++x) {
        const int d = depth.at(x, y);
        if (d == 0 || d > kSkin) {
          ASSERT_EQ(labels.at(x, y), core_only.at(x, y)) << describe(params, 1);
          continue;
        }
        // Nearest pure label: the largest component, void first on ties.
        std::int32_t best_value = kDitherFixedOne;
        for (int k = 0; k < 3; ++k) best_value -= detail::fraction_to_fixed(grid.at(x, y, k));
        int best = 0;
        for (int k = 0; k < 3; ++k) {
          if (detail::fraction_to_fixed(grid.at(x, y, k)) > best_value) {
            best_value = detail::fraction_to_fixed(grid.at(x, y, k));
            best = k + 1;
          }
        }
        ASSERT_EQ(labels.at(x, y), best) << describe(params, 1) << " at " << x << ", " << y;
      }
    }
  }
}

TEST(DitherTest, ConstantFractionGivesItsShare) {
  MaterialGrid grid(256, 256, 1);
  for (int y = 0; y < 256; ++y) {
    for (int x = 0; x < 256; ++x) grid.at(x, y, 0) = 0.3f;
  }
  for (const DitherParams& params : every_method()) {
    const LabelImage labels = dither(grid, InsideMask(256, 256, 1), params, 5);
    EXPECT_NEAR(share(labels, 0, 0, 256, 256, 1), 0.3, 0.01) << describe(params, 5);
    EXPECT_NEAR(share(labels, 0, 0, 256, 256, LabelImage::kVoid), 0.7, 0.01) << describe(params, 5);
  }

  MaterialGrid three(256, 256, 3);
  for (int y = 0; y < 256; ++y) {
    for (int x = 0; x < 256; ++x) {
      three.at(x, y, 0) = 0.3f;
      three.at(x, y, 1) = 0.2f;
      three.at(x, y, 2) = 0.1f;
    }
  }
  for (const DitherParams& params : every_method()) {
    const LabelImage mixed = dither(three, InsideMask(256, 256, 1), params, 2);
    EXPECT_NEAR(share(mixed, 0, 0, 256, 256, 1), 0.3, 0.01) << describe(params, 2);
    EXPECT_NEAR(share(mixed, 0, 0, 256, 256, 2), 0.2, 0.01) << describe(params, 2);
    EXPECT_NEAR(share(mixed, 0, 0, 256, 256, 3), 0.1, 0.01) << describe(params, 2);
    EXPECT_NEAR(share(mixed, 0, 0, 256, 256, LabelImage::kVoid), 0.4, 0.01) << describe(params, 2);
  }
}

// The slicer's requirement: a two-material linear gradient across x keeps every 64 x 64
// window within 1% (absolute) of the window's mean analytic fraction.
TEST(DitherTest, GradientMatchesEveryWindow) {
  constexpr int kSize = 512;
  constexpr int kWindow = 64;
  MaterialGrid grid(kSize, kSize, 2);
  auto t_of = [](int x) { return (static_cast<double>(x) + 0.5) / kSize; };
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      const auto t = static_cast<float>(t_of(x));
      grid.at(x, y, 0) = t;
      grid.at(x, y, 1) = 1.0f - t;
    }
  }
  std::vector<std::pair<DitherParams, int>> cases;
  for (const DitherParams& p : every_method())
    for (int layer : {0, 1, 2, 3}) cases.emplace_back(p, layer);
  DitherParams raster;
  raster.serpentine = false;
  cases.emplace_back(raster, 0);
  for (const auto& [params, layer] : cases) {
    const LabelImage labels = dither(grid, InsideMask(kSize, kSize, 1), params, layer);
    double worst = 0.0;
    // Every window position on a 16-pixel lattice, which includes the 64 disjoint windows.
    for (int y0 = 0; y0 + kWindow <= kSize; y0 += 16) {
      for (int x0 = 0; x0 + kWindow <= kSize; x0 += 16) {
        double mean_t = 0.0;
        for (int x = x0; x < x0 + kWindow; ++x) mean_t += t_of(x) / kWindow;
        const double a = share(labels, x0, y0, kWindow, kWindow, 1);
        const double b = share(labels, x0, y0, kWindow, kWindow, 2);
        EXPECT_NEAR(a, mean_t, 0.01) << "window at " << x0 << ", " << y0 << ", " << describe(params, layer);
        EXPECT_NEAR(b, 1.0 - mean_t, 0.01) << "window at " << x0 << ", " << y0 << ", " << describe(params, layer);
        worst = std::max({worst, std::abs(a - mean_t), std::abs(b - (1.0 - mean_t))});
      }
    }
    RecordProperty("worst_window_error_" + describe(params, layer) + (params.serpentine ? "" : " raster"),
                   std::to_string(worst));
  }
}

TEST(DitherTest, MaskedPixelsStayBackground) {
  std::mt19937 rng(99u);
  MaterialGrid grid(80, 60, 2);
  for (int y = 0; y < 60; ++y) {
    for (int x = 0; x < 80; ++x) grid.at(x, y, 0) = 1.0f;  // material everywhere, even outside
  }
  const InsideMask mask = random_mask(rng, 80, 60);
  for (const DitherParams& params : every_method()) {
    const LabelImage labels = dither(grid, mask, params, 3);
    for (int y = 0; y < 60; ++y) {
      for (int x = 0; x < 80; ++x) {
        ASSERT_EQ(labels.at(x, y), mask.inside(x, y) ? 1 : LabelImage::kVoid)
            << x << ", " << y << ", " << describe(params, 3);
      }
    }
  }
}

// Error neither enters nor leaves through masked pixels: a part's labels do not depend on
// anything beyond a one-pixel gap (the Floyd-Steinberg reach).
TEST(DitherTest, ErrorDoesNotCrossTheMask) {
  constexpr int kW = 61, kH = 40;
  InsideMask mask(kW, kH, 1);
  for (int y = 0; y < kH; ++y) mask.at(30, y) = 0;  // left part x < 30, right part x > 30
  MaterialGrid grid(kW, kH, 2);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < 30; ++x) grid.at(x, y, 0) = 0.37f;
  }
  MaterialGrid other = grid;
  for (int y = 0; y < kH; ++y) {
    for (int x = 31; x < kW; ++x) {
      grid.at(x, y, 1) = 0.9f;
      other.at(x, y, 0) = 0.1f;
      other.at(x, y, 1) = 0.2f;
    }
    other.at(30, y, 0) = 1.0f;  // the masked gap's fractions are ignored too
  }
  const LabelImage a = dither(grid, mask);
  const LabelImage b = dither(other, mask);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < 30; ++x) ASSERT_EQ(a.at(x, y), b.at(x, y)) << x << ", " << y;
  }
}

// A one-pixel wall keeps its material share: its error is not lost to the air beside it.
TEST(DitherTest, ThinWallKeepsItsShare) {
  constexpr int kH = 1000;
  MaterialGrid grid(5, kH, 1);
  InsideMask mask(5, kH, 0);
  for (int y = 0; y < kH; ++y) {
    grid.at(2, y, 0) = 0.3f;
    mask.at(2, y) = 1;
  }
  const LabelImage labels = dither(grid, mask);
  EXPECT_NEAR(share(labels, 2, 0, 1, kH, 1), 0.3, 0.002);
}

// Without layer variation ties go to the lowest label; with it, the layer's tie-break
// decides, so both sides of a tie occur over the layers.
TEST(DitherTest, TiesGoToTheLowestLabel) {
  DitherParams fixed;
  fixed.vary_by_layer = false;
  MaterialGrid half_void(1, 1, 1);
  half_void.at(0, 0, 0) = 0.5f;
  EXPECT_EQ(dither(half_void, InsideMask(1, 1, 1), fixed).at(0, 0), LabelImage::kVoid);

  MaterialGrid two(1, 1, 3);
  two.at(0, 0, 1) = 0.5f;
  two.at(0, 0, 2) = 0.5f;
  EXPECT_EQ(dither(two, InsideMask(1, 1, 1), fixed).at(0, 0), LabelImage::label_of_material(1));

  std::set<std::uint8_t> varied;
  for (int layer = 0; layer < 64; ++layer)
    varied.insert(dither(two, InsideMask(1, 1, 1), DitherParams{}, layer).at(0, 0));
  EXPECT_EQ(varied, (std::set<std::uint8_t>{LabelImage::label_of_material(1), LabelImage::label_of_material(2)}));
}

// A fixed input must give these exact labels on every machine and compiler (fixed-point
// arithmetic); a change here is a change of output format.
TEST(DitherTest, GoldenHash) {
  // Fractions from single integer divisions only, so the input is exact everywhere too.
  constexpr int kW = 97, kH = 61;
  MaterialGrid grid(kW, kH, 3);
  InsideMask mask(kW, kH, 0);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      grid.at(x, y, 0) = static_cast<float>(6 * x) / static_cast<float>(10 * (kW - 1));
      grid.at(x, y, 1) = static_cast<float>(3 * y) / static_cast<float>(10 * (kH - 1));
      grid.at(x, y, 2) = static_cast<float>((7 * x + 13 * y) % 17) / 170.0f;
      const int dx = x - 48, dy = y - 30;
      mask.at(x, y) = dx * dx + dy * dy < 900 ? 1 : 0;
    }
  }
  // Without layer variation (the tie-break changed nothing there).
  DitherParams fixed;
  fixed.vary_by_layer = false;
  EXPECT_EQ(fnv1a(dither(grid, mask, fixed).values()), 7913593261764580648ull);
  fixed.serpentine = false;
  EXPECT_EQ(fnv1a(dither(grid, mask, fixed).values()), 1078253651600671865ull);
  // With it, in two layers.
  EXPECT_EQ(fnv1a(dither(grid, mask, DitherParams{}, 0).values()), 3357401875976725726ull);
  EXPECT_EQ(fnv1a(dither(grid, mask, DitherParams{}, 5).values()), 12681323035572302222ull);
  DitherParams raster;
  raster.serpentine = false;
  EXPECT_EQ(fnv1a(dither(grid, mask, raster, 0).values()), 3464753017930425491ull);
}

TEST(DitherTest, ReusesAndResizesTheOutput) {
  MaterialGrid grid(10, 4, 1);
  LabelImage labels(3, 3, 7);
  dither(grid, InsideMask(10, 4, 1), DitherParams{}, labels);
  EXPECT_EQ(labels.width_px(), 10);
  EXPECT_EQ(labels.height_px(), 4);
  for (std::uint8_t label : labels.values()) EXPECT_EQ(label, LabelImage::kVoid);

  MaterialGrid empty(0, 0, 2);
  EXPECT_TRUE(dither(empty, InsideMask(0, 0)).values().empty());
}

TEST(DitherTest, RejectsBadInput) {
  MaterialGrid grid(4, 3, 2);
  const InsideMask mask(4, 3, 1);
  EXPECT_THROW(dither(grid, InsideMask(3, 4, 1)), Error);

  DitherParams bad_tolerance;
  bad_tolerance.fraction_tolerance = -1.0f;
  EXPECT_THROW(dither(grid, mask, bad_tolerance), Error);
  bad_tolerance.fraction_tolerance = NAN;
  EXPECT_THROW(bad_tolerance.validate(), Error);
  DitherParams bad_kernel;
  bad_kernel.kernel = static_cast<DiffusionKernel>(99);
  EXPECT_THROW(bad_kernel.validate(), Error);
  DitherParams bad_method;
  bad_method.method = static_cast<DitherMethod>(7);
  EXPECT_THROW(bad_method.validate(), Error);
  DitherParams bad_skin;
  bad_skin.skin_voxels = -1;
  EXPECT_THROW(bad_skin.validate(), Error);
  bad_skin.skin_voxels = DitherParams::kMaxSkinVoxels + 1;
  EXPECT_THROW(bad_skin.validate(), Error);
  EXPECT_THROW(dither(grid, mask, DitherParams{}, -1), Error);
  DitherParams named;
  EXPECT_FALSE(set_dither_method("floyd", named));
  for (std::string_view name : dither_method_names()) {
    EXPECT_TRUE(set_dither_method(name, named));
    EXPECT_EQ(dither_method_name(named), name);
  }

  auto message_for = [&](const MaterialGrid& g) -> std::string {
    try {
      dither(g, mask);
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  MaterialGrid nan_grid = grid;
  nan_grid.at(2, 1, 1) = NAN;
  EXPECT_NE(message_for(nan_grid).find("pixel (2, 1) material 1"), std::string::npos);
  MaterialGrid above_one = grid;
  above_one.at(3, 2, 0) = 1.01f;
  EXPECT_NE(message_for(above_one).find("pixel (3, 2)"), std::string::npos);
  MaterialGrid sum_above_one = grid;
  sum_above_one.at(0, 1, 0) = 0.6f;
  sum_above_one.at(0, 1, 1) = 0.6f;
  EXPECT_NE(message_for(sum_above_one).find("sum"), std::string::npos);
  MaterialGrid rounding = grid;  // within the default tolerance: accepted
  rounding.at(1, 1, 0) = 0.70000005f;
  rounding.at(1, 1, 1) = 0.30000001f;
  EXPECT_NO_THROW(dither(rounding, mask));

  EXPECT_THROW(MaterialGrid(4, 4, 0), Error);
  EXPECT_THROW(MaterialGrid(4, 4, kMaxMaterials + 1), Error);
  EXPECT_THROW(MaterialGrid(-1, 4, 1), Error);
  EXPECT_THROW(InsideMask(4, -4), Error);
}

TEST(MaterialGridCheck, FindsTheBadPixelForEveryMaterialCount) {
  // The row check is compiled for one to eight materials and for any count; each must find
  // the same first bad pixel as the message names it.
  for (int m = 1; m <= 10; ++m) {
    MaterialGrid grid(7, 5, m);
    for (int y = 0; y < 5; ++y)
      for (int x = 0; x < 7; ++x)
        for (int k = 0; k < m; ++k) grid.at(x, y, k) = 1.0f / static_cast<float>(m + 1);
    EXPECT_NO_THROW(grid.check_fractions(1e-5f)) << m;
    for (const float bad : {NAN, -0.5f, 1.5f, INFINITY}) {
      MaterialGrid broken = grid;
      broken.at(4, 3, m - 1) = bad;
      try {
        broken.check_fractions(1e-5f);
        ADD_FAILURE() << "m = " << m << ", value " << bad << " passed";
      } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("pixel (4, 3)"), std::string::npos) << e.what();
      }
    }
    MaterialGrid crowded = grid;
    for (int k = 0; k < m; ++k) crowded.at(6, 4, k) = 1.0f / static_cast<float>(m) + 0.01f;
    if (m > 1) {
      EXPECT_THROW(crowded.check_fractions(1e-5f), Error) << m;
    }
  }
}

}  // namespace
}  // namespace trivox
