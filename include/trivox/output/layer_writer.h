// Printer outputs behind one interface, chosen by name from a registry.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "trivox/output/png_io.h"
#include "trivox/raster/material_grid.h"

namespace trivox {

struct OutputContext {
  std::filesystem::path dir;                // existing output folder
  std::vector<std::string> material_names;  // scene materials, index j = label j + 1
  std::vector<std::array<std::uint8_t, 4>> material_rgba;
  std::array<std::uint8_t, 4> background_rgba{255, 255, 255, 255};
  std::string prefix = "slice_";            // common file-name prefix
  int total_layers = 1;                     // sets the zero padding of the numbers
  PngWriteParams png;
};

// Writes one file set per layer. write_layer is called from several threads at once, each
// with a different index; implementations keep no mutable shared state.
class LayerWriter {
 public:
  virtual ~LayerWriter() = default;
  virtual std::string_view name() const noexcept = 0;
  // `index` counts from 0; files carry index + 1, zero-padded. Returns the files written
  // (relative to the output folder).
  virtual std::vector<std::string> write_layer(int index, const LabelImage& labels) const = 0;
};

// "voxelprint": one 32-bit RGBA PNG per layer (colour type 6), every material in its exact
//               colour, everything else the background colour; for GrabCAD Voxel Print.
// "bitmaps":    the paper's form, one 1-bit PNG per material per layer (1 = material).
std::unique_ptr<LayerWriter> make_layer_writer(std::string_view format, const OutputContext& context);
std::vector<std::string> layer_writer_names();

// Zero-padded layer number for file names: at least 5 digits.
std::string layer_number(int index, int total_layers);

}  // namespace trivox
