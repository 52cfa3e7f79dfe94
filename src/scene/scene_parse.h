// The scene reader's parts (see docs/SCENE.md): the reading context shared by all parts,
// geometry and spline sources (spline_parse.cpp), material functions (material_parse.cpp),
// and the top level (scene_reader.cpp). Every failure is an InputError naming the scene file
// and the JSON pointer of the offending field.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "scene/json_view.h"
#include "trivox/io/model.h"
#include "trivox/material/material_function.h"
#include "trivox/scene/scene.h"
#include "trivox/spline/tensor_spline.h"
#include "trivox/spline/volume.h"

namespace trivox::detail {

class SceneContext {
 public:
  SceneContext(std::string source, std::filesystem::path base_dir)
      : source_(std::move(source)), base_dir_(std::move(base_dir)) {}

  const std::string& source() const noexcept { return source_; }

  void set_material_names(std::vector<std::string> names) { material_names_ = std::move(names); }
  const std::vector<std::string>& material_names() const noexcept { return material_names_; }
  int num_materials() const noexcept { return static_cast<int>(material_names_.size()); }

  // The material a string names: its index, or kVoidMaterial for "void". Fails on unknown names.
  int material_ref(const JsonView& name) const;
  // An object {material name: fraction, ...} as m fractions (materials not named get 0).
  std::vector<float> fraction_map(const JsonView& object) const;

  // The model file a string field names, relative to the scene's folder; read once per scene.
  const Model& model(const JsonView& file_field);
  // The files model() read, with their SHA-256, in first-use order.
  const std::vector<SceneInputFile>& input_files() const noexcept { return input_files_; }

 private:
  std::string source_;
  std::filesystem::path base_dir_;
  std::vector<std::string> material_names_;
  std::map<std::string, Model> models_;  // by resolved path
  std::vector<SceneInputFile> input_files_;
};

// One trivariate of a cell's geometry and the label that tells several apart ("" for the
// only one; the patch index with "patch": "all").
struct GeometryPart {
  Volume volume;
  std::string label;
};

// A cell's "geometry": a model file and patch selection, or an inline spline.
std::vector<GeometryPart> parse_geometry(const JsonView& node, SceneContext& ctx);

// An optional "placement" applied to a volume's control points.
Volume parse_and_apply_placement(const JsonView& node, const Volume& volume);

// A trivariate spline field with `point_dim` components: {"file", "patch"} or inline
// {"orders", "knots", "points", "weights"}.
TensorSpline parse_field(const JsonView& node, SceneContext& ctx, int point_dim);

// A cell's "material", built for the cell's parametric domain (not yet policy-checked).
std::shared_ptr<const MaterialFunction> parse_material(const JsonView& node, SceneContext& ctx,
                                                       const ParamBox& cell_domain);

}  // namespace trivox::detail
