// The scene reader's parts (see docs/SCENE.md): the reading context shared by all parts,
// geometry and spline sources (spline_parse.cpp), material functions (material_parse.cpp),
// and the top level (scene_reader.cpp). Every failure is an InputError naming the scene file
// and the JSON pointer of the offending field.
#pragma once

#include <atomic>

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "scene/json_view.h"
#include "trivox/construct/report.h"
#include "trivox/io/detail/volume_image.h"
#include "trivox/io/model.h"
#include "trivox/io/triangle_mesh.h"
#include "trivox/material/detail/scalar_gradient_material.h"
#include "trivox/material/material_function.h"
#include "trivox/scene/construction_cache.h"
#include "trivox/scene/scene.h"
#include "trivox/spline/jacobian_check.h"
#include "trivox/spline/tensor_spline.h"
#include "trivox/spline/volume.h"

namespace trivox {
struct MeshCheck;
}

namespace trivox::detail {

// Parses JSON text, rejecting keys repeated in one object; syntax errors are InputErrors with
// the line.
Json parse_json_text(std::string_view text, const std::string& source);

// The bytes of a JSON file (`what`: "scene", "construction"); IoError when `path` is a folder
// (called `folder_word` in the message) or cannot be opened or read.
std::string read_json_file(const std::filesystem::path& path, std::string_view what, std::string_view folder_word);

class SceneContext {
 public:
  SceneContext(std::string source, std::filesystem::path base_dir)
      : source_(std::move(source)), base_dir_(std::move(base_dir)) {}

  const std::string& source() const noexcept { return source_; }

  // The caller's stop flag, for the long constructions (untangling); may be null.
  void set_stop(const std::atomic<bool>* stop) noexcept { stop_ = stop; }
  const std::atomic<bool>* stop() const noexcept { return stop_; }

  // Where constructed geometry is looked up before it is built, and stored after; may be null.
  void set_construction_cache(ConstructionCache* cache) noexcept { construction_cache_ = cache; }
  ConstructionCache* construction_cache() const noexcept { return construction_cache_; }

  // The finest pitch of the scene's printer (mm): the scale at which a mesh trim must not
  // intersect itself.
  void set_pixel_mm(double pixel_mm) noexcept { pixel_mm_ = pixel_mm; }
  double pixel_mm() const noexcept { return pixel_mm_; }

  void set_material_names(std::vector<std::string> names) { material_names_ = std::move(names); }
  const std::vector<std::string>& material_names() const noexcept { return material_names_; }
  int num_materials() const noexcept { return static_cast<int>(material_names_.size()); }

  // The material a string names: its index, or kVoidMaterial for "void". Fails on unknown names.
  int material_ref(const JsonView& name) const;
  // An object {material name: fraction, ...} as m fractions (materials not named get 0).
  std::vector<float> fraction_map(const JsonView& object) const;

  // The model file a string field names, relative to the scene's folder; read once per scene.
  const Model& model(const JsonView& file_field);
  // The SHA-256 of the model file a string field names (read by model() if it was not yet).
  const std::string& model_sha256(const JsonView& file_field);
  // The triangle mesh file a string field names (trivox/io/triangle_mesh.h), relative to the
  // scene's folder; read once per scene and hashed like a model file.
  const TriangleMeshFile& triangle_mesh(const JsonView& file_field);
  // The files model() and triangle_mesh() read, with their SHA-256, in first-use order.
  const std::vector<SceneInputFile>& input_files() const noexcept { return input_files_; }

  // A file a string field names, relative to the scene's folder (normalised); fails naming
  // the field when there is no such file.
  std::filesystem::path existing_file(const JsonView& file_field, std::string_view what) const;

  // The volume image an "image" object names (texture_parse.cpp); read once per scene.
  std::shared_ptr<const VolumeImage> volume_image(const JsonView& image);

 private:
  std::string source_;
  std::filesystem::path base_dir_;
  const std::atomic<bool>* stop_ = nullptr;
  ConstructionCache* construction_cache_ = nullptr;
  std::vector<std::string> material_names_;
  double pixel_mm_ = 0;
  std::map<std::string, Model> models_;                               // by resolved path
  std::map<std::string, std::string> model_sha256_;                   // by resolved path
  std::map<std::string, TriangleMeshFile> meshes_;                    // by resolved path
  std::map<std::string, std::shared_ptr<const VolumeImage>> images_;  // by the image object's text
  std::vector<SceneInputFile> input_files_;
};

// One trivariate of a cell's geometry and the label that tells several apart ("" for the
// only one; the patch index with "patch": "all").
struct GeometryPart {
  Volume volume;
  std::string label;
};

// An inline spline {"orders", "knots", "points", "weights"} with `param_dim` parameters (1:
// a curve, 2: a surface, 3: a trivariate) and `point_dim` coordinates per control point.
TensorSpline parse_inline_spline(const JsonView& node, int param_dim, int point_dim);

// A curve or surface (`param_dim` 1 or 2, 3D points) for a constructor: {"file", "patch"}
// (patch: index among the file's curves or surfaces) or inline.
TensorSpline parse_curve_or_surface(const JsonView& node, SceneContext& ctx, int param_dim);

// True when a geometry object names a constructor ("extrude", "ruled", "revolve", "sweep",
// "coons", "shell"; docs/SCENE.md, "Constructed geometry").
bool is_constructed_geometry(const JsonView& node);
// True when `geometry` says "allow_fold": true, as a constructor's field or beside a model
// file's "file" and "patch": the user accepts a volume that folds over itself, sliced by the
// fold rules (docs/SCENE.md, "Folded cells").
bool geometry_allows_fold(const JsonView& geometry);
// The sampled Jacobian check of `volume` (a cell or named volume called `what`), failing on
// `geometry` when its numbers overflow (det J infinite or NaN: check_jacobian's ModelError) or
// when det J vanishes at every sample: it has no interior and can own no voxel. Where the
// volume lies too far from the origin for a double to resolve a thousandth of `pixel_mm`, its
// control points may have merged by rounding alone; the slicer refuses that with its reason.
JacobianReport checked_jacobian(const Volume& volume, const std::string& what, const JsonView& geometry,
                                double pixel_mm);
// The volume a constructor builds, with its report; fails naming the field when an input is
// wrong (a fold is in the report, not an error).
Constructed parse_construction(const JsonView& node, SceneContext& ctx);
// The same for a cell: also fails when the volume folds over itself, unless "allow_fold" is
// true.
Volume parse_constructed_geometry(const JsonView& node, SceneContext& ctx);

// A cell's "geometry": a model file and patch selection, an inline spline, or a constructor.
std::vector<GeometryPart> parse_geometry(const JsonView& node, SceneContext& ctx);

// An optional "placement" applied to a volume's control points (or a surface's, with three
// coordinates per point).
Volume parse_and_apply_placement(const JsonView& node, const Volume& volume);
TensorSpline parse_and_apply_placement(const JsonView& node, const TensorSpline& spline);

// The scene's "volumes": named trivariates for cells and trims (trim_parse.cpp).
std::vector<SceneVolume> parse_volumes(const JsonView& node, SceneContext& ctx);
// The index of the scene volume a string field names; fails listing the names otherwise.
int volume_ref(const JsonView& name, const std::vector<SceneVolume>& volumes);
// An optional "placement" applied to points (a mesh trim's vertices).
std::vector<Vec3> parse_and_apply_placement(const JsonView& node, std::vector<Vec3> points);

// A shell given as {"mesh": F, "placement", "inside_rule"} (mesh_trim_parse.cpp): the mesh
// file read, placed and, for the even-odd rule, checked (trivox/mesh/detail/mesh_check.h). `what`
// is "model-space" or "parametric" (which a mesh cannot be).
std::shared_ptr<const TrimShell> parse_mesh_shell(const JsonView& node, SceneContext& ctx, std::string_view what);

// The failed checks of a mesh (check_mesh), each with an example triangle in the file's
// coordinates: the words a refused mesh trim and `trivox info` give (mesh_file_report.cpp).
std::string mesh_check_report(const TriangleMeshFile& file, const MeshCheck& check, double tolerance_mm);

// Geometry {"bounding_box": {"mesh": F, "placement", "margin_mm"}} (mesh_trim_parse.cpp): the
// trilinear box, u, v, w along x, y, z, around the placed mesh's vertices widened by the
// margin, the volume a mesh trim cuts its part out of.
bool is_bounding_box_geometry(const JsonView& node);
Volume parse_bounding_box_geometry(const JsonView& node, SceneContext& ctx);

// A cell's "trim" clauses. `own_volume` is the index of the cell's scene volume (-1: none),
// which a clause may not name.
Trim parse_trim(const JsonView& node, SceneContext& ctx, const std::vector<SceneVolume>& volumes, int own_volume);

// A trivariate spline field with `point_dim` components: {"file", "patch"} or inline
// {"orders", "knots", "points", "weights"}. kAnyPointDim accepts any number of components
// (an inline field's count is that of its first point).
inline constexpr int kAnyPointDim = -1;
TensorSpline parse_field(const JsonView& node, SceneContext& ctx, int point_dim);

// The "stops" of a gradient or transfer function: values non-decreasing, fractions maps.
std::vector<GradientStop> parse_stops(const JsonView& node, const SceneContext& ctx);

// A "texture" material function (texture_parse.cpp).
std::shared_ptr<const MaterialFunction> parse_texture(const JsonView& node, SceneContext& ctx,
                                                      const ParamBox& cell_domain);

// {"texture": image, "channel": k, "filter", "wrap", "repeats"}: one channel as a scalar source.
std::shared_ptr<const MaterialFunction> parse_texture_scalar(const JsonView& node, SceneContext& ctx,
                                                             const ParamBox& cell_domain);

// A scalar source (composite_parse.cpp): a number, an expression string, {"field": ...,
// "component": k} or {"field": ..., "magnitude": true}, {"texture": image, "channel": k,
// ...}; a function with one output.
std::shared_ptr<const MaterialFunction> parse_scalar(const JsonView& node, SceneContext& ctx,
                                                     const ParamBox& cell_domain);

// The composition kinds "transfer", "blend", "threshold", "select", "void_mask"
// (composite_parse.cpp); nullptr for another kind.
std::shared_ptr<const MaterialFunction> parse_composite(const std::string& kind, const JsonView& node,
                                                        SceneContext& ctx, const ParamBox& cell_domain);

// The scene's "cells" (cell_parse.cpp): each cell's geometry placed, checked for folds, and
// its material policy-checked, appended to scene.cells.
void parse_cells(const JsonView& node, SceneContext& ctx, Scene& scene);
// One "unions" entry: a cell per non-empty subset of the volumes it joins (cell_parse.cpp).
void parse_union(const JsonView& u, SceneContext& ctx, Scene& scene);

// A cell's "material", built for the cell's parametric domain (not yet policy-checked).
std::shared_ptr<const MaterialFunction> parse_material(const JsonView& node, SceneContext& ctx,
                                                       const ParamBox& cell_domain);

}  // namespace trivox::detail
