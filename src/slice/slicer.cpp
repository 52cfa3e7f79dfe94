#include "trivox/slice/slicer.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "boundary_mesh.h"
#include "cell_preparation.h"
#include "check.h"
#include "coverage.h"
#include "slicer_parts.h"
#include "trivox/error.h"
#include "trivox/trim/detail/shell_mesh.h"

namespace trivox {

void Slicer::Impl::LayerBuffers::clear() {
  const auto m = static_cast<std::size_t>(grid.num_materials());
  for (std::size_t y = 0; y < written.size(); ++y) {
    auto& [first, last] = written[y];
    if (first > last) continue;
    TRIVOX_CHECK_GE(first, 0);
    TRIVOX_CHECK_LT(last, inside.width_px());
    const auto n = static_cast<std::size_t>(last - first + 1);
    std::fill_n(inside.row(static_cast<int>(y)).begin() + first, n, std::uint8_t{0});
    std::fill_n(grid.row(static_cast<int>(y)).begin() + static_cast<std::ptrdiff_t>(first * m), n * m, 0.0f);
    written[y] = {1, 0};
  }
}

std::unique_ptr<Slicer::Impl::LayerBuffers> Slicer::Impl::take_buffers() const {
  {
    const std::lock_guard lock(buffers_mutex);
    if (!free_buffers.empty()) {
      auto buffers = std::move(free_buffers.back());
      free_buffers.pop_back();
      return buffers;
    }
  }
  return std::make_unique<LayerBuffers>(layout.width_px, layout.height_px, scene.num_materials());
}

void Slicer::Impl::give_back(std::unique_ptr<LayerBuffers> buffers) const {
  buffers->clear();
  const std::lock_guard lock(buffers_mutex);
  free_buffers.push_back(std::move(buffers));
}

namespace {

// Vertices an outline mesh of a cell whose image spans `box` may take: about two per pixel
// of the box's six faces at printer resolution (a mesh finer than that decides no more
// pixels by itself), from 2^14 to 2^24.
std::int64_t pixel_budget(const Box3& box, const PrinterProfile& printer) {
  const Vec3 size = box.size();
  const double w = size.x / printer.pitch_x_mm() + 1, h = size.y / printer.pitch_y_mm() + 1,
               l = size.z / printer.layer_thickness_mm + 1;
  const double faces = 2 * (w * h + h * l + l * w);
  return static_cast<std::int64_t>(std::clamp(faces, double{1 << 14}, double{1 << 24}));
}

}  // namespace

Slicer::Slicer(const Scene& scene, SliceParams params) : impl_(std::make_unique<Impl>(scene, std::move(params))) {}

Slicer::~Slicer() = default;

const SliceLayout& Slicer::layout() const noexcept { return impl_->layout; }
const Box3& Slicer::object_bounds() const noexcept { return impl_->object_bounds; }
const SliceParams& Slicer::params() const noexcept { return impl_->params; }
const Scene& Slicer::scene() const noexcept { return impl_->scene; }
const DitherParams& Slicer::dither_params() const noexcept { return impl_->dither; }

LayerResult Slicer::slice_layer(int layer) const { return impl_->slice_layer(layer, LayerRequest{}); }

LayerResult Slicer::slice_layer(int layer, const LayerRequest& request) const {
  return impl_->slice_layer(layer, request);
}

Slicer::Impl::Impl(const Scene& scene_in, SliceParams params_in) : scene(scene_in), params(std::move(params_in)) {
  params.validate();
  scene.printer.validate();
  dither = params.dither.value_or(scene.dithering.value_or(DitherParams{}));
  dither.validate();
  // An eighth of the finest pitch: the band of candidates the outline cannot decide, and so
  // the global solves that prove its pixels outside, halve with the tolerance, while the
  // outline meshes grow little (measured in docs/PERFORMANCE.md).
  const double finest_pitch_mm = scene.printer.finest_pitch_mm();
  outline_tolerance_mm = params.outline_tolerance_mm.value_or(0.125 * finest_pitch_mm);
  check_model_fits(finest_pitch_mm);
  // Model-space shells decide pixels by their tessellation alone: half the outline
  // tolerance when one is given, else an eighth of the finest pitch.
  detail::LayerDecision::Setup setup;
  setup.outline_tolerance_mm = outline_tolerance_mm;
  setup.shell_tolerance_mm = params.outline_tolerance_mm ? 0.5 * *params.outline_tolerance_mm : 0.125 * finest_pitch_mm;
  decision = std::make_unique<detail::LayerDecision>(scene, params, setup);
  lay_out(finest_pitch_mm);
  build_meshes();
  decision->set_layout(layout);
  // Greyscale: anti-aliased edges (coverage.h).
  if (scene.greyscale && scene.greyscale->antialiasing > 1)
    coverage = std::make_unique<detail::EdgeCoverage>(scene, params, layout);
}

// The control points' box holds every cell, so its layout bounds the final one: checking it
// first refuses a job too large to lay out, or too far from the origin for a double to
// resolve its pixels, before anything is built.
void Slicer::Impl::check_model_fits(double finest_pitch_mm) const {
  const Box3 hull = scene.bounds();
  if (hull.empty()) return;
  try {
    make_layout(hull, scene.printer);
  } catch (const Error& e) {
    throw Error(fmt::format("{}: {}", scene.source, e.what()));
  }
  const double far = std::max({std::abs(hull.lo.x), std::abs(hull.lo.y), std::abs(hull.lo.z), std::abs(hull.hi.x),
                               std::abs(hull.hi.y), std::abs(hull.hi.z)});
  // Pixel centres, outlines and inverses are computed in model coordinates: a thousandth of
  // a pixel must still be a difference a double can hold there.
  const double resolution = far * std::numeric_limits<double>::epsilon();
  if (!(resolution <= 1e-3 * finest_pitch_mm))
    throw Error(
        fmt::format("{}: the model reaches {:.6g} mm from the origin, where a double resolves only {:.3g} mm, "
                    "more than a thousandth of the printer's {:.4g} mm pitch; place it nearer the origin "
                    "(a placement's \"translate\")",
                    scene.source, far, resolution, finest_pitch_mm));
}

namespace {

// A box that holds every point a model-space "inside" clause keeps, or nullopt when the
// clause does not bound its cell that way (an "outside" clause, a parametric trim, a mesh
// decided by its winding number): the box of a closed mesh's vertices, the control points' box
// of a shell's surfaces (their convex hulls hold them and what they enclose), the tight image
// of a trimming volume. An open mesh is left out: its winding number may reach 1/2 beyond its
// vertices' hull where sheets of it overlap as seen from a point.
std::optional<Box3> clause_box(const detail::LayerDecision& decision, const detail::LayerDecision::Clause& k) {
  if (k.side != TrimSide::kInside) return std::nullopt;
  if (k.kind == TrimKind::kVolume) return decision.trivariates()[static_cast<std::size_t>(k.trivariate)]->image;
  if (k.kind != TrimKind::kShell || k.source == nullptr || !k.source->shell) return std::nullopt;
  const TrimShell& shell = *k.source->shell;
  if (shell.mesh) return shell.rule == InsideRule::kEvenOdd ? std::optional<Box3>(shell.mesh->bounds()) : std::nullopt;
  Box3 box;
  for (const TensorSpline& s : shell.surfaces) box.expand(s.control_box());
  for (const TrimmedSurface& t : shell.trimmed) box.expand(t.surface.control_box());
  return box;
}

Box3 intersection(const Box3& a, const Box3& b) {
  Box3 out{{std::max(a.lo.x, b.lo.x), std::max(a.lo.y, b.lo.y), std::max(a.lo.z, b.lo.z)},
           {std::min(a.hi.x, b.hi.x), std::min(a.hi.y, b.hi.y), std::min(a.hi.z, b.hi.z)}};
  return out.lo.x <= out.hi.x && out.lo.y <= out.hi.y && out.lo.z <= out.hi.z ? out : Box3{};
}

}  // namespace

// The object's box: per cell, the tight box of its volume's image (GlobalSolver::image_bounds),
// never an approximation of it, cut down to the boxes of the model-space trims it must lie
// inside (a bunny mesh in a box keeps the bunny's box); the union over the cells. When the
// cut leaves nothing (no cell's volume meets its trims), or without SliceParams::
// frame_from_trims, the volumes' boxes alone.
Box3 Slicer::Impl::tight_object_bounds() const {
  Box3 untrimmed, trimmed;
  for (const auto& cd : decision->cells()) {
    const Box3& image = decision->trivariates()[static_cast<std::size_t>(cd->trivariate)]->image;
    untrimmed.expand(image);
    Box3 box = image;
    if (params.frame_from_trims)
      for (const auto& k : cd->clauses)
        if (const auto bound = clause_box(*decision, k); bound && !box.empty()) box = intersection(box, *bound);
    trimmed.expand(box);
  }
  return trimmed.empty() ? untrimmed : trimmed;
}

// The frame and the layers come from the object's box (tight_object_bounds), widened by a
// quarter of the finest pitch. A setting such as the outline tolerance cannot move them.
void Slicer::Impl::lay_out(double finest_pitch_mm) {
  decision->bound_images(1e-3 * finest_pitch_mm);
  object_bounds = tight_object_bounds();
  Box3 bounds = object_bounds;
  const double margin_mm = 0.25 * finest_pitch_mm;
  // A masked-resin printer builds from its platform: the first layer starts at the model's
  // bottom, as slicers for these printers lay it.
  const Vec3 grow{margin_mm, margin_mm, scene.printer.display ? 0.0 : margin_mm};
  if (!bounds.empty()) bounds = Box3{bounds.lo - grow, bounds.hi + grow};
  layout = make_layout(bounds, scene.printer);
}

// Outline meshes within their budgets (half the memory limit at most, shared out by the
// cells' sizes in pixels, before any is built), then the trim shells' meshes (layer_decision.h).
void Slicer::Impl::build_meshes() {
  std::vector<std::int64_t> budgets;
  double wanted = 0;
  for (const auto& tv : decision->trivariates()) {
    budgets.push_back(pixel_budget(tv->image.empty() ? Box3{} : tv->image, scene.printer));
    wanted += static_cast<double>(budgets.back());
  }
  if (params.memory_limit_bytes > 0) {
    const double allowed =
        0.5 * static_cast<double>(params.memory_limit_bytes) / static_cast<double>(detail::kBoundaryMeshBytesPerVertex);
    if (wanted > allowed)
      for (std::int64_t& b : budgets)
        b = std::max<std::int64_t>(64, static_cast<std::int64_t>(static_cast<double>(b) * allowed / wanted));
  }
  decision->build_meshes(budgets);
}

std::uint64_t Slicer::tracing_bytes_per_worker() const noexcept {
  const SliceLayout& L = impl_->layout;
  const auto pixels = static_cast<std::uint64_t>(L.width_px) * static_cast<std::uint64_t>(L.height_px);
  std::uint64_t bytes = detail::CellTracer::ring_bytes(L.width_px);
  // A constant-material cell's filled row (slice_cell).
  bytes += static_cast<std::uint64_t>(L.width_px) * detail::CellTracer::kTracedBytesPerPixel;
  for (const auto& tv : impl_->decision->trivariates())
    if (tv->traced_first) bytes += pixels * detail::CellTracer::kTracedBytesPerPixel;
  return bytes;
}

}  // namespace trivox
