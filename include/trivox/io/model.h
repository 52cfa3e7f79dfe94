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
  std::string name;   // the object's name (IRIT) or "Geometry id=N" (G+Smo)
  int id = 0;         // G+Smo id attribute, or the patch's index when the file has none
  int source_line = 0;  // line in the file where the patch starts (1-based; 0 when unknown)
  TensorSpline spline;
};

struct Model {
  std::string source;          // the file it was read from (as given)
  std::vector<Patch> patches;  // in document order

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
