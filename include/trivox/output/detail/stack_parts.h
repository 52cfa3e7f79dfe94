// The layers a shard keeps for the stack outputs of its job (docs/CLUSTER.md, "Stack
// formats"). A stack output (a GrabCAD package, an SL1S archive, a TIFF or OpenVDB stack, the
// previews) needs every layer of the job in one process, so a shard does not write it: it
// writes each of its layers' labels (and greys, for a greyscale scene) as stack parts, which
// the whole job's resume after `trivox merge` feeds to the stack writers instead of slicing
// the layers again, then removes.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "trivox/output/layer_writer.h"
#include "trivox/raster/greyscale.h"
#include "trivox/raster/material_grid.h"

namespace trivox::detail {

// The folder of the parts in the output folder, with its '/'.
inline constexpr std::string_view kStackPartsFolder = "stack_parts/";

// A per-layer writer: stack_parts/<prefix>NNNNN.labels.png, an 8-bit grey PNG whose values
// are the layer's labels, and, when the layer has a grey image, <prefix>NNNNN.grey.png with
// its greys. Lossless, so the stack outputs made from them are the bytes one process makes.
std::unique_ptr<LayerWriter> make_stack_parts_writer(const OutputContext& context);

// Whether a file of the manifest (a '/'-separated name) is a stack part.
bool is_stack_part(std::string_view name);

struct StackPart {
  LabelImage labels;
  GreyImage grey;  // empty when the layer had none
};

// The layer that the part files `names` (relative to `dir`, as the manifest lists them) hold.
// Throws IoError naming the file when one cannot be read or decoded, is not `width_px` x
// `height_px`, holds a label above `materials`, or when no labels file is among `names`.
StackPart read_stack_part(const std::filesystem::path& dir, const std::vector<std::string>& names, int width_px,
                          int height_px, int materials);

}  // namespace trivox::detail
