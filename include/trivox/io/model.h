// Models read from files: an ordered list of spline patches (curves, surfaces, trivariates)
// with where each came from, so errors and reports can point back into the file.
#pragma once

#include <atomic>
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "trivox/spline/tensor_spline.h"

namespace trivox {

struct Patch {
  std::string name;     // the object's name (IRIT), "Geometry id=N" (G+Smo) or "SplineVolume #k" (GoTools)
  int id = 0;           // G+Smo id attribute, or the patch's index when the file has none
  int source_line = 0;  // line in the file where the patch starts (1-based; 0 when unknown)
  TensorSpline spline;
  // GoTools .g2: the auxiliary integers of the object's header (such as an RGBA colour),
  // which write_g2 writes back; empty for the other formats.
  std::vector<int> header_aux{};
};

// Something a reader skipped or assumed without failing, such as a GoTools object of a class
// trivox does not read. The library never prints notes; `trivox info` does.
struct ModelNote {
  int line = 0;  // where in the file (1-based; 0 when unknown)
  std::string text;
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
  // In file order.
  std::vector<ModelNote> notes{};

  // Indices of the patches with param_dim 3 (trivariates).
  std::vector<int> volume_indices() const;
};

// Reads a model by file type: `.itd` (IRIT text), `.xml` (G+Smo) or `.g2` (GoTools). Throws
// InputError (file, line, rule) on malformed content, UnsupportedError on valid but
// unsupported types (e.g. THBSpline3), IoError when the file cannot be read. Never returns a
// partial model. `stop` (optional, may be set from a signal handler) is read while the file
// is read and every 65536 numbers while it is parsed: once it is raised, CancelledError
// (error.h). A file is at most input_file_byte_limit() (limits.h) bytes, checked before it is
// read.
Model read_model(const std::filesystem::path& path, const std::atomic<bool>* stop = nullptr);

// IRIT .itd text. `source` names the input in error messages; `stop` as for read_model.
Model read_itd(std::string_view text, const std::string& source, const std::atomic<bool>* stop = nullptr);
// G+Smo XML. The XML parse itself (pugixml, about a gigabyte a second) does not read `stop`.
Model read_gismo_xml(std::string_view text, const std::string& source, const std::atomic<bool>* stop = nullptr);
// GoTools .g2 text: SplineCurve, SplineSurface and SplineVolume objects (classes 100, 200,
// 700); objects of other classes are skipped, each with a note in Model::notes. At least one
// object must be read.
Model read_g2(std::string_view text, const std::string& source, const std::atomic<bool>* stop = nullptr);

// Writes every patch as an IRIT object (TRIVAR/SURFACE/CURVE BSPLINE, E<d> or P<d>, KV or
// KVP), with enough digits (17 significant) that reading it back gives identical doubles.
void write_itd(std::ostream& out, const Model& model);

// Writes every patch as a GoTools object (SplineCurve 100, SplineSurface 200, SplineVolume
// 700, header version 1 0 with the patch's header_aux), 17 significant digits. A periodic
// direction is written as the unclamped basis it evaluates as, its wrapped control points
// repeated (GoTools has no periodic knot vectors): the same spline, read back as an
// ordinary one. Rational points are homogeneous (w*x, ..., w), chosen so that reading
// divides back to the same double wherever one exists (docs/FORMATS.md).
void write_g2(std::ostream& out, const Model& model);

// Writes every patch as a G+Smo <Geometry> (BSpline, Nurbs, TensorBSpline2/3,
// TensorNurbs2/3, id = the patch's index; a periodic direction as the unclamped basis it
// evaluates as) and, when all patches have the same number of parameters, a <MultiPatch>
// with the interfaces and boundary sides find_topology (src/io/topology.h) finds. Numbers in the
// shortest form that reads back to the same double: read_gismo_xml gives the model back
// exactly (names aside: G+Smo stores none).
void write_gismo_xml(std::ostream& out, const Model& model);

// The model formats trivox writes, chosen by a file name's extension.
enum class ModelFormat { kItd, kGismoXml, kG2 };
// .itd, .xml or .g2 (any case); nullopt for another extension.
std::optional<ModelFormat> model_format_of(const std::filesystem::path& path);
void write_model(std::ostream& out, const Model& model, ModelFormat format);

}  // namespace trivox
