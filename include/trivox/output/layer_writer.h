// Printer outputs behind one interface, chosen by name from a registry.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "trivox/output/png_io.h"
#include "trivox/printer/printer_profile.h"
#include "trivox/raster/greyscale.h"
#include "trivox/raster/material_grid.h"

namespace trivox {

// How the "gcvf" package is written where the public writers differ (docs/FORMATS.md,
// "GrabCAD Voxel Print package").
struct GcvfOptions {
  // ConfigFile.xml names a material by its Stratasys code where one is known (e.g.
  // "VeroCY-V"), else as the scene does; false: always as the scene does.
  bool material_codes = true;
  // Materials with no voxel in the stack are left out of the material list; false: listed.
  bool omit_unused = true;
  // Extra members: "model.stl", the boundary of every cell's volume; "bounding_box.txt", the
  // stack's box in mm. Their bytes, by member name, in this order (the job makes them).
  std::vector<std::pair<std::string, std::string>> extras;

  bool operator==(const GcvfOptions&) const = default;
};

struct OutputContext {
  std::filesystem::path dir;                // existing output folder
  std::vector<std::string> material_names;  // scene materials, index j = label j + 1
  std::vector<std::array<std::uint8_t, 4>> material_rgba;
  // The library material each scene material matches, in the library's spelling; empty for
  // a custom one (printer/material_library.h).
  std::vector<std::string> material_library;
  // The background of the printer images (its alpha is 255: printer images are opaque).
  std::array<std::uint8_t, 4> background_rgba{0, 0, 0, 255};
  // The background of the previews, chosen by contrast with the materials (job_preview_background).
  std::array<std::uint8_t, 4> preview_background_rgba{0, 0, 0, 255};
  std::string prefix = "slice_";    // common file-name prefix
  int total_layers = 1;             // sets the zero padding of the numbers
  int width_px = 0, height_px = 0;  // the layer images' size (the bitmap of the model's box)
  int model_layers = 1;             // layers 0..model_layers-1 hold the model; the rest are padding
  // Pixel and layer pitch (mm), for outputs that show the stack at its true proportions.
  double pitch_x_mm = 1, pitch_y_mm = 1, layer_mm = 1;
  // Where the stack sits in model space (mm), for outputs that place it there: the left edge
  // of column 0, the top edge of row 0, and the bottom of job layer 0.
  double x0_mm = 0, y_top_mm = 0, z0_mm = 0;
  PngWriteParams png;
  // The printer: its name, and the display the greyscale archives lay the images on.
  PrinterProfile printer;
  GcvfOptions gcvf;
};

// For the job estimate (job_estimate.h): which of the layers a stack output was fed stand
// for which layers of the job.
struct StackSampling {
  std::vector<int> model_samples;  // job layers fed that stand for the model layers
  int padding_sample = -1;         // a job layer fed that stands for the padding layers; -1: none
  int model_layers = 0;            // layers of the job that hold the model
  int padded_layers = 0;           // empty layers after them
};

// What a stack output adds to a job beyond the files write_layer returns.
struct StackCost {
  int files = 0;                    // files finish() writes
  std::uint64_t file_bytes = 0;     // their size
  std::uint64_t scratch_bytes = 0;  // spool files on disk beside them until the job ends
  std::uint64_t memory_bytes = 0;   // what the writer holds at its largest (layers collected, grids built)
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
  // Greyscale outputs (resin printers) expose each pixel with a grey level: they take the
  // layer's grey image too (empty when the scene has no greyscale block, or for a padding
  // layer; the writer then exposes every pixel with a material fully). The job calls this
  // instead of write_layer when the writer asks for it.
  virtual bool takes_grey() const noexcept { return false; }
  virtual std::vector<std::string> write_grey_layer(int index, const LabelImage& labels, const GreyImage& grey) const {
    (void)grey;
    return write_layer(index, labels);
  }

  // Stack outputs (previews) need every layer of the job: write_layer only collects what
  // they need (bounded memory), and finish() writes their files once the last layer is in.
  // The job feeds them every layer, also those a resumed job keeps, and refuses to shard
  // them.
  virtual bool needs_whole_stack() const noexcept { return false; }
  // Called once when every layer of the job (or of its shard) is written; returns files of
  // the whole job (a text manifest, previews), which must depend only on the settings and,
  // for stack outputs, on the layers.
  virtual std::vector<std::string> finish() const { return {}; }
  // The cost of finish() and of what the writer keeps for it, scaled from the layers fed so
  // far to the whole job as `sampling` describes; nothing for a per-layer output.
  virtual StackCost stack_cost(const StackSampling& sampling) const {
    (void)sampling;
    return {};
  }
};

// The sum over the job of a per-layer figure known for the sampled layers: the mean of the
// model samples times the model layers, plus the padding sample times the padding layers.
std::uint64_t scaled_to_job(const StackSampling& sampling, const std::function<std::uint64_t(int)>& per_layer);

// "voxelprint": one 32-bit RGBA PNG per layer (colour type 6), every material in its exact
//               colour, everything else the background colour; for GrabCAD Voxel Print.
// "bitmaps":    the paper's form, one 1-bit PNG per material per layer (1 = material).
// "preview":    a stack output for a person: preview/contact_sheet.png (a grid of up to 64
//               downscaled model layers) and preview/cut_xy.png, cut_xz.png, cut_yz.png
//               (three orthogonal cuts through the middle of the stack), at true
//               proportions.
// "tiff":       tiff/stack.tif, one 8-bit palette page per job layer (value = label), for
//               stack viewers; a stack output (written when the job completes).
// "vdb":        vdb/stack.vdb, one OpenVDB FloatGrid per material named after it (1 = the voxel
//               holds that material, inactive elsewhere), placed in model space (mm); a
//               stack output.
// "gcvf":       gcvf/stack.gcvf, a GrabCAD Voxel Print package: the "voxelprint" PNGs and
//               ConfigFile.xml in one zip archive; a stack output.
// "legacy":     the bitmap method of the paper's printer: legacy/<prefix><n>_<material>.bmp,
//               one 1-bit BMP per material per layer (1 = material), and legacy/slices.txt
//               with the layer thickness, slice count and bitmap names.
// "greyscale":  greyscale/<prefix><n>.png, one 8-bit greyscale PNG per layer with its pixel
//               size in pHYs, for masked-resin printers: the scene's greyscale exposure
//               (0 = none), the bitmap of the model's box.
// "sl1", "sl1s": <prefix>.sl1 / <prefix>.sl1s, a Prusa SL1 / SL1S print archive (zip of
//               config.ini, prusaslicer.ini, the greyscale layers laid on the printer's
//               display, thumbnails); a stack output; the printer profile must have a display.
std::unique_ptr<LayerWriter> make_layer_writer(std::string_view format, const OutputContext& context);
std::vector<std::string> layer_writer_names();
// Whether the format is a stack output (its writers need the whole stack and write their
// files, under a folder named after the format, when the job completes) rather than one
// that writes files for every layer. Throws Error for an unknown name.
bool is_stack_format(std::string_view format);
// Whether `format` puts the materials' names into its file names ("bitmaps", "legacy").
bool layer_writer_names_files_by_material(std::string_view format);
// Whether GrabCAD Voxel Print reads `format` (voxelprint, gcvf): such stacks are padded to its
// minimum height (JobParams::min_layers); false for the others and for an unknown name.
bool layer_writer_feeds_voxel_print(std::string_view format);
// Whether `format` writes grey levels (greyscale, sl1, sl1s: its writers take_grey()) rather
// than the dithered materials; false for the others and for an unknown name.
bool layer_writer_writes_greys(std::string_view format);

// The longest text (bytes) the job puts into a file name from its settings or the scene: the
// prefix, a material's name.
inline constexpr std::size_t kMaxFileNamePartBytes = 100;
// Why `text` cannot become part of an output file's name, or nullopt when it can: a name is
// never a path, so it holds no '/', no '\\', no "..", no control character, and at most
// kMaxFileNamePartBytes bytes; a file named with it then always lies in the output folder.
std::optional<std::string> file_name_part_problem(std::string_view text);

// Feeds one layer to a writer: write_grey_layer for one that takes the grey image, else
// write_layer.
std::vector<std::string> write_layer_to(const LayerWriter& writer, int index, const LabelImage& labels,
                                        const GreyImage& grey);

// The grey levels a greyscale output writes for a layer: `grey` when it has the labels' size,
// else 255 wherever a label holds a material and 0 elsewhere.
GreyImage exposure_of(const LabelImage& labels, const GreyImage& grey);

// Display-colour PNGs of chosen layers at their true proportions, preview/layer_NNNNN.png
// (`trivox slice --preview`; layer_preview_writer.cpp). `layers` pairs a job layer index
// with the model layer number (1-based) its file is named after.
std::unique_ptr<LayerWriter> make_layer_preview_writer(const OutputContext& context,
                                                       std::vector<std::pair<int, int>> layers);

// Zero-padded layer number for file names: at least 5 digits.
std::string layer_number(int index, int total_layers);

}  // namespace trivox
