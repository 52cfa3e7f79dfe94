// Models read from files: an ordered list of spline patches (curves, surfaces, trivariates)
// with where each came from, so errors and reports can point back into the file.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

#include "trivox/spline/tensor_spline.h"

namespace trivox {

struct Patch {
  std::string name;     // the object's name (IRIT) or "Geometry id=N" (G+Smo)
  int id = 0;           // G+Smo id attribute, or the patch's index when the file has none
  int source_line = 0;  // line in the file where the patch starts (1-based; 0 when unknown)
  TensorSpline spline;
};

// An IRIT trimmed-surface model (MODEL): surfaces restricted to loops of trimming segments,
// each segment a curve in the parameter space of the one or two surfaces it borders.
struct TrimmedModel {
  struct Surface {
    int source_line = 0;
    int patch = -1;  // index of the untrimmed surface in Model::patches
    // Loops of segment references: k >= 1 is segment k - 1 as stored, -k the same reversed.
    std::vector<std::vector<int>> loops;
  };
  struct Segment {
    int source_line = 0;
    // The surfaces (indices into `surfaces`) it has a curve in: one, or two for a segment
    // shared by two surfaces; curves[i] lies in the parameter space of surfaces[i]. (A curve
    // in space, which IRIT may store as well, is not kept.)
    std::vector<int> surfaces;
    std::vector<TensorSpline> curves;
  };
  std::string name;  // the enclosing object's name
  int source_line = 0;
  std::vector<Surface> surfaces;
  std::vector<Segment> segments;
};

struct Model {
  std::string source;          // the file it was read from (as given)
  std::vector<Patch> patches;  // in document order
  // IRIT MODEL objects (their untrimmed surfaces are also in `patches`).
  std::vector<TrimmedModel> trimmed_models;

  // Indices of the patches with param_dim 3 (trivariates).
  std::vector<int> volume_indices() const;
};

// Reads a model by file type: `.itd` (IRIT text) or `.xml` (G+Smo). Throws InputError
// (file, line, rule) on malformed content, UnsupportedError on valid but unsupported types
// (e.g. THBSpline3), IoError when the file cannot be read. Never returns a partial model.
Model read_model(const std::filesystem::path& path);

// IRIT .itd text. `source` names the input in error messages.
Model read_itd(std::string_view text, const std::string& source);
// G+Smo XML.
Model read_gismo_xml(std::string_view text, const std::string& source);

// Writes every patch as an IRIT object (TRIVAR/SURFACE/CURVE BSPLINE, E<d> or P<d>, KV or
// KVP), with enough digits (17 significant) that reading it back gives identical doubles.
void write_itd(std::ostream& out, const Model& model);

}  // namespace trivox
