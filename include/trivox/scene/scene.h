// The scene: everything the slicer needs to print one FGM object, read from a documented
// JSON file (format: docs/SCENE.md; schema: docs/scene.schema.json; examples under
// examples/scenes/). A scene names the printer, the materials with their colours, and the
// cells of the object, each a trivariate volume in millimetres with its material function
// (paper, Section 3: FGM_cell = {V, M, S}), trimmed by other trivariates of the scene, by
// closed shells in model space or by closed surfaces in its parametric domain (trim.h).
#pragma once

#include <atomic>

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "trivox/material/material_function.h"
#include "trivox/math.h"
#include "trivox/printer/printer_profile.h"
#include "trivox/raster/dither.h"
#include "trivox/raster/greyscale.h"
#include "trivox/spline/volume.h"
#include "trivox/trim/trim.h"

namespace trivox {

struct MaterialDef {
  std::string name;
  // sRGB colour and alpha (255 = opaque) used for this material in printer images and
  // previews.
  std::array<std::uint8_t, 4> rgba{0, 0, 0, 255};
  // The library material (printer/material_library.h) the name matches, in the library's
  // spelling; empty for a custom material.
  std::string library;
};

struct Cell {
  std::string name;     // unique in the scene
  std::string pointer;  // JSON pointer of the cell's entry in the scene file, e.g. "/cells/2"
  // The cell's geometry in model space (mm), its placement already applied to the control
  // points (affine maps keep B-spline and NURBS volumes exact).
  Volume volume;
  // M(u,v,w) over volume.domain(), with the scene's fraction policy applied (a
  // CheckedMaterial): num_materials() == the scene's material count; its fractions obey the
  // rules of material_function.h or evaluation throws InputError naming this cell.
  std::shared_ptr<const MaterialFunction> material;
  // Index into Scene::volumes when the cell is parametrized by one of the scene's named
  // volumes (its `volume` is then a copy of that one), -1 otherwise. Cells that share a
  // named volume, or are trimmed by it, see one inversion of it per pixel.
  int scene_volume = -1;
  // The clauses every pixel of the cell satisfies besides lying inside `volume`; empty for a
  // whole volume.
  Trim trim{};
  // SHA-256 (hex) of what defines the cell in the scene file: its entry, the named volumes it
  // is parametrized or trimmed by, its trim clauses. Two scenes whose cell fingerprints agree
  // give the cell the same voxels; a resumed job compares them (manifest.h). Empty for cells
  // built in code.
  std::string fingerprint{};
  // The scene's greyscale source for this cell when it is a scalar source (one output,
  // evaluated like a material function), null otherwise (Scene::greyscale).
  std::shared_ptr<const MaterialFunction> grey_source{};
  // The volume folds over itself (det J takes both signs on the sampled grid) and the scene
  // accepts it ("allow_fold"): it is sliced by the fold rules (docs/SCENE.md, "Folded
  // cells"): a pixel is inside when any of its preimages is, and takes the material at the
  // preimage of largest |det J|.
  bool folds = false;
};

// The scene's "greyscale" block: instead of dithering, a masked-resin printer exposes each
// voxel with a grey level (docs/SCENE.md, "Greyscale").
struct GreyscaleDef {
  // The material whose fraction is the scalar; -1 when each cell's grey_source gives it.
  int material = -1;
  // Scalar -> grey level, of the printer and resin.
  GreyCalibration curve;
  // k: a pixel on an outline takes the mean grey of k x k sub-samples (its covered fraction
  // times its material's grey); 1 = no anti-aliasing. 1 to 8.
  int antialiasing = 4;
  // The resin's exposure (seconds) of a layer and of the first layers, for the print archives;
  // absent: the printer profile's.
  std::optional<double> exposure_s, initial_exposure_s;
  // The resin's name, for the print archives (config.ini's materialName); absent: the printer
  // profile's default resin when the exposures are its own, else none.
  std::optional<std::string> resin;
};

// A named trivariate of the scene ("volumes" in the scene file): a cell's parametrization
// or a trimming volume of other cells.
struct SceneVolume {
  std::string name;
  std::string pointer;  // JSON pointer of its entry
  Volume volume;        // model space (mm), placement applied
  bool folds = false;   // as Cell::folds
};

// A file a scene reads, with the SHA-256 of its bytes (for the job manifest).
struct SceneInputFile {
  std::string name;    // as the scene names it (relative to the scene file's folder)
  std::string sha256;  // lowercase hex
};

struct Scene {
  std::string source;  // the scene file as given
  // SHA-256 of the scene text that was parsed; empty for scenes built in code.
  std::string source_sha256;
  // SHA-256 (hex) of the scene without its cells, volumes, unions, description and fraction
  // policy: the printer, the materials, the dithering. Empty for scenes built in code.
  std::string settings_fingerprint;
  // Every model and field file the scene read, once each, in the order first used.
  std::vector<SceneInputFile> input_files;
  PrinterProfile printer;
  std::vector<MaterialDef> materials;  // material j of every material function is materials[j]
  FractionPolicy fraction_policy;
  // The scene's "dithering" settings; absent: the slicer's defaults (SliceParams::dither
  // overrides either).
  std::optional<DitherParams> dithering;
  // The scene's "greyscale" block; absent: the material layers are dithered, and greyscale
  // outputs expose every voxel that holds a material fully.
  std::optional<GreyscaleDef> greyscale;
  // Named trivariates that cells use as parametrization or trim (Cell::scene_volume,
  // TrimClause::volume).
  std::vector<SceneVolume> volumes;
  // In scene order. Where cells overlap, a pixel belongs to exactly one of them: the last in
  // this order that gives it a non-empty material, else the last that contains it.
  std::vector<Cell> cells;

  int num_materials() const noexcept { return static_cast<int>(materials.size()); }
  // Index of the material called `name`, or kVoidMaterial for "void" and for unknown names.
  int material_index(std::string_view name) const noexcept;
  // Conservative box of the whole object in model space (mm): the union of the cells'
  // control-point boxes.
  Box3 bounds() const noexcept;
};

class ConstructionCache;  // construction_cache.h

struct SceneReadOptions {
  // Checked by the long constructions (untangling): once it is true, reading throws
  // CancelledError. May be set from a signal handler.
  const std::atomic<bool>* stop = nullptr;
  // Constructed geometry is taken from this cache when it holds it, and stored in it when it
  // is built (construction_cache.h); null: every volume is built.
  ConstructionCache* construction_cache = nullptr;
};

// Reads a scene file. Model and field files it names are read relative to its folder.
// Throws IoError when the scene file cannot be read, and InputError for everything wrong
// inside it or in the files it names: what() is "scene.json: /json/pointer: rule" (or
// "scene.json:LINE: rule" for JSON syntax errors). `stop` (optional, may be set from a
// signal handler) is checked by the long constructions (untangling): once it is true,
// reading throws CancelledError.
Scene read_scene(const std::filesystem::path& path, const std::atomic<bool>* stop = nullptr);
Scene read_scene(const std::filesystem::path& path, const SceneReadOptions& options);

// The same from text: `source` names the scene in errors, and relative file names resolve
// against source's parent folder.
Scene parse_scene(std::string_view json_text, const std::filesystem::path& source,
                  const std::atomic<bool>* stop = nullptr);
Scene parse_scene(std::string_view json_text, const std::filesystem::path& source, const SceneReadOptions& options);

}  // namespace trivox
