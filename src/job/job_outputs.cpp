#include "job_outputs.h"

#include "job_parts.h"

#include <unistd.h>

#include <algorithm>
#include <cstring>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "trivox/error.h"
#include "trivox/output/atomic_file.h"
#include "trivox/output/detail/stack_parts.h"
#include "trivox/output/display_colours.h"

namespace trivox {

namespace {

// A colour as the printer images show it: opaque.
std::array<std::uint8_t, 4> opaque(std::array<std::uint8_t, 4> rgba) {
  rgba[3] = 255;
  return rgba;
}

}  // namespace

std::array<std::uint8_t, 4> job_background(const Scene& scene, const JobParams& params) {
  if (params.background_rgba) return *params.background_rgba;
  auto taken = [&](const std::array<std::uint8_t, 4>& c) {
    for (const MaterialDef& m : scene.materials)
      if (opaque(m.rgba) == c) return true;
    return false;
  };
  // Black, as the public packages write it, else white, else the greys from black up.
  if (!taken({0, 0, 0, 255})) return {0, 0, 0, 255};
  if (!taken({255, 255, 255, 255})) return {255, 255, 255, 255};
  for (int n = 1; n < 255; ++n) {
    const auto g = static_cast<std::uint8_t>(n);
    if (!taken({g, g, g, 255})) return {g, g, g, 255};
  }
  throw Error("no grey is free for the background: give --background");  // 64 materials cannot take 256 greys
}

std::array<std::uint8_t, 4> job_preview_background(const Scene& scene, const JobParams& params) {
  if (params.background_rgba) return *params.background_rgba;
  std::vector<Rgba> rgba;
  for (const MaterialDef& m : scene.materials) rgba.push_back(m.rgba);
  return preview_background(rgba);
}

namespace detail {

// The context of the job's writers: the scene's materials and printer (with the greyscale
// block's exposure), the background in effect, the bitmap and its placement, the package's
// options and extra members.
OutputContext job_output_context(const Slicer& slicer, const JobParams& params, const std::filesystem::path& dir) {
  const Scene& scene = slicer.scene();
  const SliceLayout& L = slicer.layout();
  const LayerRange range = layer_range(L, params);
  const int total_layers = range.total(), model_layers = range.count, first_layer = range.first;
  OutputContext ctx;
  ctx.dir = dir;
  for (const MaterialDef& m : scene.materials) {
    ctx.material_names.push_back(m.name);
    ctx.material_rgba.push_back(m.rgba);
    ctx.material_library.push_back(m.library);
  }
  ctx.background_rgba = job_background(scene, params);
  ctx.preview_background_rgba = job_preview_background(scene, params);
  ctx.prefix = params.prefix;
  ctx.total_layers = total_layers;
  ctx.model_layers = model_layers;
  ctx.width_px = L.width_px;
  ctx.height_px = L.height_px;
  ctx.pitch_x_mm = L.pitch_x_mm;
  ctx.pitch_y_mm = L.pitch_y_mm;
  ctx.layer_mm = L.layer_mm;
  ctx.x0_mm = L.x0_mm;
  ctx.y_top_mm = L.y_top_mm;
  ctx.z0_mm = L.z0_mm + first_layer * L.layer_mm;
  ctx.png = params.png;
  ctx.printer = scene.printer;
  if (ctx.printer.display && scene.greyscale) {
    const GreyscaleDef& g = *scene.greyscale;
    MaskedDisplay& d = *ctx.printer.display;
    if (g.exposure_s) d.exposure_s = *g.exposure_s;
    if (g.initial_exposure_s) d.initial_exposure_s = *g.initial_exposure_s;
    // The profile's resin stands only for the profile's exposures.
    if (g.resin)
      d.resin = *g.resin;
    else if (g.exposure_s || g.initial_exposure_s)
      d.resin.clear();
  }
  ctx.gcvf.material_codes = params.gcvf.material_codes;
  ctx.gcvf.omit_unused = params.gcvf.omit_unused;
  const bool gcvf = std::find(params.formats.begin(), params.formats.end(), "gcvf") != params.formats.end();
  if (gcvf && params.gcvf.mesh_stl) ctx.gcvf.extras.emplace_back("model.stl", cells_boundary_stl(scene));
  if (gcvf && params.gcvf.bounding_box) {
    // The box the layer images cover, in model space.
    const double x1 = L.x0_mm + L.width_px * L.pitch_x_mm, y0 = L.y_top_mm - L.height_px * L.pitch_y_mm;
    const double z1 = ctx.z0_mm + total_layers * L.layer_mm;
    ctx.gcvf.extras.emplace_back(
        "bounding_box.txt",
        fmt::format("# trivox: the box the layer images cover, mm in model space: x_min y_min z_min x_max y_max "
                    "z_max\n{} {} {} {} {} {}\n",
                    L.x0_mm, y0, ctx.z0_mm, x1, L.y_top_mm, z1));
  }
  return ctx;
}

std::vector<std::unique_ptr<LayerWriter>> job_format_writers(const OutputContext& context, const JobParams& params) {
  std::vector<std::unique_ptr<LayerWriter>> writers;
  const bool shard = params.shard_count > 1;
  std::vector<std::string> stacks;
  for (const std::string& f : params.formats) {
    if (shard && is_stack_format(f))
      stacks.push_back(f);
    else
      writers.push_back(make_layer_writer(f, context));
  }
  if (stacks.empty()) return writers;
  {
    OutputContext scratch = context;
    scratch.dir =
        context.dir / kStackPartsFolder / fmt::format(".check-{}@{}", static_cast<long>(::getpid()), machine_name());
    struct Cleanup {
      std::filesystem::path dir;
      ~Cleanup() {
        std::error_code ec;
        std::filesystem::remove_all(dir, ec);
      }
    } cleanup{scratch.dir};
    std::error_code ec;
    std::filesystem::create_directories(scratch.dir, ec);
    if (ec) throw IoError(fmt::format("{}: cannot create: {}", scratch.dir.string(), ec.message()));
    for (const std::string& f : stacks) (void)make_layer_writer(f, scratch);
  }
  writers.push_back(make_stack_parts_writer(context));
  return writers;
}

std::vector<MaterialSheetRow> job_material_sheet(const Scene& scene) {
  std::vector<MaterialSheetRow> sheet;
  for (const MaterialDef& m : scene.materials) sheet.push_back({m.name, m.library, opaque(m.rgba)});
  return sheet;
}

namespace {

void put_f32(std::string& out, float v) {
  char b[4];
  std::memcpy(b, &v, 4);  // little-endian hosts only, as the rest of the writers
  out.append(b, 4);
}

}  // namespace

std::string cells_boundary_stl(const Scene& scene) {
  constexpr int n = 32;
  std::vector<std::array<Vec3, 3>> triangles;
  for (const Cell& cell : scene.cells) {
    const Volume& v = cell.volume;
    const ParamBox d = v.domain();
    const Vec3 mid = 0.5 * (d.lo + d.hi);
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side) {
        const int a = (axis + 1) % 3, b = (axis + 2) % 3;
        auto param = [&](int i, int j) {
          Vec3 p = mid;
          p[axis] = side == 0 ? d.lo[axis] : d.hi[axis];
          p[a] = d.lo[a] + (d.hi[a] - d.lo[a]) * i / n;
          p[b] = d.lo[b] + (d.hi[b] - d.lo[b]) * j / n;
          return p;
        };
        std::vector<Vec3> grid;
        for (int j = 0; j <= n; ++j)
          for (int i = 0; i <= n; ++i) grid.push_back(v.evaluate(param(i, j)));
        // Outwards: away from the point a little inside the face's centre.
        Vec3 inner_p = param(n / 2, n / 2);
        inner_p[axis] =
            side == 0 ? d.lo[axis] + 1e-3 * (d.hi[axis] - d.lo[axis]) : d.hi[axis] - 1e-3 * (d.hi[axis] - d.lo[axis]);
        const Vec3 inward = v.evaluate(inner_p) - v.evaluate(param(n / 2, n / 2));
        auto at = [&](int i, int j) { return grid[static_cast<std::size_t>(j * (n + 1) + i)]; };
        bool flip = false;
        {
          const Vec3 p0 = at(n / 2, n / 2), p1 = at(n / 2 + 1, n / 2), p2 = at(n / 2 + 1, n / 2 + 1);
          flip = dot(cross(p1 - p0, p2 - p0), inward) > 0;
        }
        for (int j = 0; j < n; ++j)
          for (int i = 0; i < n; ++i) {
            std::array<Vec3, 3> t1{at(i, j), at(i + 1, j), at(i + 1, j + 1)};
            std::array<Vec3, 3> t2{at(i, j), at(i + 1, j + 1), at(i, j + 1)};
            if (flip) {
              std::swap(t1[1], t1[2]);
              std::swap(t2[1], t2[2]);
            }
            triangles.push_back(t1);
            triangles.push_back(t2);
          }
      }
  }
  std::string out(80, '\0');
  const std::string header = "trivox: the boundary of every cell's volume, mm";
  std::copy(header.begin(), header.end(), out.begin());
  const auto count = static_cast<std::uint32_t>(triangles.size());
  out.append(reinterpret_cast<const char*>(&count), 4);
  for (const auto& t : triangles) {
    Vec3 normal = cross(t[1] - t[0], t[2] - t[0]);
    const double len = norm(normal);
    if (len > 0) normal = (1.0 / len) * normal;
    for (const Vec3& p : {normal, t[0], t[1], t[2]}) {
      put_f32(out, static_cast<float>(p.x));
      put_f32(out, static_cast<float>(p.y));
      put_f32(out, static_cast<float>(p.z));
    }
    out.append(2, '\0');
  }
  return out;
}

}  // namespace detail

std::string stack_resume_note(const JobParams& params) {
  if (params.shard_count > 1) return {};  // a shard keeps its layers for them (stack parts)
  std::vector<std::string> stacks, layered;
  for (const std::string& f : params.formats) (is_stack_format(f) ? stacks : layered).push_back(f);
  if (stacks.empty()) return {};
  if (layered.empty())
    return fmt::format(
        "{} {} written only when the job completes and {} no finished layer, so --resume slices "
        "every layer again",
        fmt::join(stacks, " and "), stacks.size() == 1 ? "is" : "are", stacks.size() == 1 ? "keeps" : "keep");
  return fmt::format(
      "--resume keeps the finished layers of {} and slices them once more for {}, written only when "
      "the job completes",
      fmt::join(layered, " and "), fmt::join(stacks, " and "));
}

}  // namespace trivox
