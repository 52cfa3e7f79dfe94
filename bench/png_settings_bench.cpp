// PNG settings for the Voxel Print layer images, measured on real dithered layers: every
// combination of zlib level, row filter and zlib strategy below encodes the same layers (in
// memory, so the disk is not measured), and the program prints one Markdown row per setting
// with the median encoding time per layer, ns per pixel and the file size, for
// docs/PERFORMANCE.md. The layers are those of the duck-class job (bench_support.h): many
// inside voxels, two materials dithered by error diffusion.
//
//   png_settings_bench [--scale S] [--layers N] [--repeats R]
// --scale S: the duck-class model's scale (default 0.5: a 1941 x 970 bitmap)
// --layers N: layers sampled evenly over the height (default 3)
// --repeats R: encodings of each layer per setting; the median is reported (default 5)
#include <algorithm>
#include <chrono>
#include <vector>

#include <fmt/format.h>

#include "bench_support.h"
#include "trivox/output/png_io.h"
#include "trivox/slice/slicer.h"

using namespace trivox;
using namespace trivox::bench;

int main(int argc, char** argv) {
  const double scale = arg_double(argc, argv, "--scale", 0.5);
  const int layers = arg_int(argc, argv, "--layers", 3);
  const int repeats = arg_int(argc, argv, "--repeats", 5);

  const Scene scene = duck_class_scene(scale);
  const Slicer slicer(scene, SliceParams{});
  const SliceLayout& L = slicer.layout();
  // The layers as the Voxel Print writer colours them: background white, a colour per material.
  std::vector<std::vector<std::uint8_t>> images;
  for (int i = 0; i < layers; ++i) {
    const LayerResult r = slicer.slice_layer(static_cast<int>((i + 0.5) * L.num_layers / layers));
    std::vector<std::uint8_t> rgba;
    rgba.reserve(r.labels.values().size() * 4);
    for (std::uint8_t label : r.labels.values()) {
      const std::array<std::uint8_t, 4> c = label == LabelImage::kVoid
                                                ? std::array<std::uint8_t, 4>{255, 255, 255, 255}
                                                : scene.materials[static_cast<std::size_t>(label - 1)].rgba;
      rgba.insert(rgba.end(), c.begin(), c.end());
    }
    images.push_back(std::move(rgba));
  }
  const double pixels = static_cast<double>(L.width_px) * L.height_px;

  fmt::print("PNG settings on {} dithered layers of {} x {} px (median of {} encodings per layer, in memory)\n\n",
             layers, L.width_px, L.height_px, repeats);
  fmt::print(
      "| zlib level | filter | strategy | ms per layer | ns per pixel | size per layer [kB] |\n"
      "|---|---|---|---|---|---|\n");
  struct Setting {
    int level;
    PngFilter filter;
    PngStrategy strategy;
  };
  const std::vector<Setting> settings = {
      {1, PngFilter::kNone, PngStrategy::kDefault}, {1, PngFilter::kSub, PngStrategy::kDefault},
      {1, PngFilter::kUp, PngStrategy::kDefault},   {1, PngFilter::kPaeth, PngStrategy::kDefault},
      {1, PngFilter::kNone, PngStrategy::kRle},     {1, PngFilter::kSub, PngStrategy::kRle},
      {1, PngFilter::kUp, PngStrategy::kRle},       {1, PngFilter::kSub, PngStrategy::kHuffmanOnly},
      {3, PngFilter::kSub, PngStrategy::kRle},      {6, PngFilter::kNone, PngStrategy::kDefault},
      {6, PngFilter::kSub, PngStrategy::kRle},
  };
  for (const Setting& s : settings) {
    PngWriteParams params;
    params.zlib_level = s.level;
    params.filter = s.filter;
    params.strategy = s.strategy;
    double seconds = 0;
    double bytes = 0;
    for (const auto& rgba : images) {
      std::vector<double> times;
      std::size_t size = 0;
      for (int k = 0; k < repeats; ++k) {
        const auto start = std::chrono::steady_clock::now();
        size = encode_png_rgba(L.width_px, L.height_px, rgba, params).size();
        times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      }
      std::nth_element(times.begin(), times.begin() + repeats / 2, times.end());
      seconds += times[static_cast<std::size_t>(repeats / 2)];
      bytes += static_cast<double>(size);
    }
    fmt::print("| {} | {} | {} | {:.1f} | {:.2f} | {:.0f} |\n", s.level, to_string(s.filter), to_string(s.strategy),
               1e3 * seconds / layers, 1e9 * seconds / layers / pixels, bytes / layers / 1e3);
  }
  return 0;
}
