#include "job/job_resume.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "trivox/io/detail/sha256.h"
#include "trivox/material/material_function.h"
#include "trivox/output/detail/stack_parts.h"

namespace trivox::detail {

std::optional<ManifestSceneParts> scene_parts(const Scene& scene, const SliceLayout& L, int first, int model_layers) {
  if (scene.settings_fingerprint.empty()) return std::nullopt;
  ManifestSceneParts parts;
  parts.settings_sha256 = scene.settings_fingerprint;
  parts.fraction_sums = scene.fraction_policy.policy == SumPolicy::kError
                            ? fmt::format("error {}", scene.fraction_policy.tolerance)
                            : std::string("normalise");
  for (const Cell& cell : scene.cells) {
    ManifestCell c;
    c.name = cell.name;
    c.sha256 = cell.fingerprint;
    // Layer l samples the plane z = z0 + (l + 1/2) layer: those between the bottom and the top
    // of the cell's control points' box (which holds the cell), with a margin for rounding.
    const Box3& box = cell.volume.bounds();
    const double margin = 1e-9 * std::max(1.0, std::abs(box.hi.z) + std::abs(box.lo.z));
    const int lo = static_cast<int>(std::ceil((box.lo.z - margin - L.z0_mm) / L.layer_mm - 0.5));
    const int hi = static_cast<int>(std::floor((box.hi.z + margin - L.z0_mm) / L.layer_mm - 0.5));
    const int a = std::max(lo, first), b = std::min(hi, first + model_layers - 1);
    if (a <= b) {
      c.first_layer = a - first + 1;
      c.last_layer = b - first + 1;
    }
    parts.cells.push_back(std::move(c));
  }
  return parts;
}

std::vector<ManifestFile> intact_files(const std::filesystem::path& dir, const JobManifest& previous) {
  std::map<int, std::vector<ManifestFile>> by_layer;
  for (const ManifestFile& f : previous.files)
    if (f.layer > 0) by_layer[f.layer].push_back(f);  // stack files (layer 0) are rewritten at the end
  std::vector<ManifestFile> kept;
  for (auto& [layer, files] : by_layer) {
    const bool intact = std::all_of(files.begin(), files.end(), [&](const ManifestFile& f) {
      std::error_code ec;
      const auto path = dir / f.name;
      if (!std::filesystem::is_regular_file(path, ec) || std::filesystem::file_size(path, ec) != f.bytes || ec)
        return false;
      return sha256_file(path).sha256 == f.sha256;
    });
    if (intact) kept.insert(kept.end(), files.begin(), files.end());
  }
  return kept;
}

std::vector<std::vector<std::string>> stack_parts_by_layer(const std::vector<ManifestFile>& files, int total_layers) {
  std::vector<std::vector<std::string>> parts(static_cast<std::size_t>(std::max(0, total_layers)));
  for (const ManifestFile& f : files)
    if (f.layer >= 1 && f.layer <= total_layers && is_stack_part(f.name))
      parts[static_cast<std::size_t>(f.layer - 1)].push_back(f.name);
  return parts;
}

void take_stack_parts(std::vector<ManifestFile>& files) {
  files.erase(std::remove_if(files.begin(), files.end(), [](const ManifestFile& f) { return is_stack_part(f.name); }),
              files.end());
}

void remove_stack_parts(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::remove_all(dir / kStackPartsFolder, ec);
}

std::vector<int> layers_of(const std::vector<ManifestFile>& files) {
  std::vector<int> layers;
  for (const ManifestFile& f : files)
    if (f.layer > 0) layers.push_back(f.layer);
  std::sort(layers.begin(), layers.end());
  layers.erase(std::unique(layers.begin(), layers.end()), layers.end());
  return layers;
}

std::vector<ManifestPrinted> printed_of_kept_layers(const JobManifest& previous,
                                                    const std::vector<ManifestFile>& kept) {
  const std::vector<int> layers = layers_of(kept);
  std::vector<ManifestPrinted> out;
  for (const ManifestPrinted& p : previous.printed)
    if (std::binary_search(layers.begin(), layers.end(), p.layer)) out.push_back(p);
  return out;
}

std::optional<LayerResult> slice_layer_unless_failed(const Slicer& slicer, int layer, std::atomic<bool>& failed) {
  if (failed.load()) return std::nullopt;
  try {
    return slicer.slice_layer(layer);
  } catch (const FractionError& e) {
    failed.store(true);
    throw e.in_layer(layer + 1, slicer.layout().z_of_layer(layer));
  } catch (...) {
    failed.store(true);
    throw;
  }
}

}  // namespace trivox::detail
