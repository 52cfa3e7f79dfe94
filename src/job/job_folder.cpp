#include "trivox/job/job_folder.h"

#include <algorithm>
#include <cstdint>
#include <map>
#include <optional>
#include <string_view>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "trivox/cancel.h"
#include "trivox/error.h"
#include "trivox/io/detail/sha256.h"
#include "trivox/job/job_lock.h"
#include "trivox/output/detail/bmp_image.h"
#include "trivox/output/detail/gcvf_package.h"
#include "trivox/output/detail/stack_parts.h"
#include "trivox/output/detail/tiff_stack.h"
#include "trivox/output/detail/vdb_stack.h"
#include "trivox/output/layer_writer.h"
#include "trivox/output/png_io.h"

namespace trivox {

namespace {

// A decimal number of 1 to 9 digits, or nullopt.
std::optional<int> small_number(std::string_view text) {
  if (text.empty() || text.size() > 9) return std::nullopt;
  int n = 0;
  for (char c : text) {
    if (c < '0' || c > '9') return std::nullopt;
    n = n * 10 + (c - '0');
  }
  return n;
}

// (I, N) from "manifest.shard-I-of-N.json", or nullopt for any other name. (Plain string
// work: GCC 12 warns inside <regex> under -Werror.)
std::optional<std::pair<int, int>> shard_of_name(std::string_view name) {
  constexpr std::string_view prefix = "manifest.shard-", suffix = ".json", middle = "-of-";
  if (name.size() <= prefix.size() + suffix.size() || name.substr(0, prefix.size()) != prefix ||
      name.substr(name.size() - suffix.size()) != suffix)
    return std::nullopt;
  const std::string_view core = name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
  const std::size_t at = core.find(middle);
  if (at == std::string_view::npos) return std::nullopt;
  const auto i = small_number(core.substr(0, at)), n = small_number(core.substr(at + middle.size()));
  if (!i || !n) return std::nullopt;
  return std::pair{*i, *n};
}

// The shard manifests in `dir`, by shard index, with their shard count.
std::map<int, std::filesystem::path> shard_manifests(const std::filesystem::path& dir, int* count) {
  std::map<int, std::filesystem::path> found;
  *count = 0;
  std::error_code ec;
  for (auto it = std::filesystem::directory_iterator(dir, ec); !ec && it != std::filesystem::end(it);
       it.increment(ec)) {
    const auto shard = shard_of_name(it->path().filename().string());
    if (!shard) continue;
    const int n = shard->second;
    if (*count != 0 && n != *count)
      throw Error(
          fmt::format("{}: shard manifests of {} and of {} shards are mixed in one folder", dir.string(), *count, n));
    *count = n;
    found[shard->first] = it->path();
  }
  if (ec) throw IoError(fmt::format("{}: cannot list the folder: {}", dir.string(), ec.message()));
  return found;
}

// Problems with one listed file: missing, size, hash.
std::string file_problem(const std::filesystem::path& dir, const ManifestFile& f) {
  const std::filesystem::path path = dir / f.name;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return fmt::format("{}: missing", path.string());
  const FileDigest d = sha256_file(path);
  if (d.bytes != f.bytes) return fmt::format("{}: {} bytes, the manifest says {}", path.string(), d.bytes, f.bytes);
  if (d.sha256 != f.sha256)
    return fmt::format("{}: SHA-256 {} differs from the manifest's {}", path.string(), d.sha256, f.sha256);
  return {};
}

// The bitmap size the manifest records ("WxH"), or {0, 0}.
std::pair<int, int> bitmap_size(const JobManifest& m) {
  for (const auto& [key, value] : m.settings)
    if (key == "bitmap_px") {
      const std::size_t x = value.find('x');
      if (x == std::string::npos) break;
      const auto w = small_number(std::string_view(value).substr(0, x)),
                 h = small_number(std::string_view(value).substr(x + 1));
      if (w && h) return {*w, *h};
    }
  return {0, 0};
}

// The output formats of the manifest's "formats" setting (comma-separated).
std::vector<std::string> manifest_formats(const JobManifest& m) {
  std::vector<std::string> formats;
  for (const auto& [key, value] : m.settings) {
    if (key != "formats") continue;
    std::size_t at = 0;
    while (at <= value.size()) {
      std::size_t end = value.find(',', at);
      if (end == std::string::npos) end = value.size();
      if (end > at) formats.push_back(value.substr(at, end - at));
      at = end + 1;
    }
  }
  return formats;
}

// The number of materials in the manifest's "materials" setting ("NAME=R,G,B,A ..."): the
// words that end in four numbers after a '='.
int material_count(const JobManifest& m) {
  int count = 0;
  for (const auto& [key, value] : m.settings) {
    if (key != "materials") continue;
    std::size_t at = 0;
    while (at < value.size()) {
      std::size_t end = value.find(' ', at);
      if (end == std::string::npos) end = value.size();
      const std::string_view word = std::string_view(value).substr(at, end - at);
      const std::size_t eq = word.rfind('=');
      if (eq != std::string_view::npos &&
          std::count(word.begin() + static_cast<std::ptrdiff_t>(eq), word.end(), ',') == 3)
        ++count;
      at = end + 1;
    }
  }
  return count;
}

// Decodes a file whose size and hash match the manifest, by kind: every PNG, the 1-bit BMPs
// of the legacy output, every page of a TIFF stack, every grid of an OpenVDB file and every
// entry of a GrabCAD package or a Prusa SL1/SL1S archive (their PNGs decoded). Returns the
// problem, or "".
std::string decode_problem(const std::filesystem::path& path, const JobManifest& m) {
  const std::string ext = path.extension().string();
  const std::pair<int, int> size = bitmap_size(m);
  const int width = size.first, height = size.second;  // (clang 14 cannot capture structured bindings)
  const auto size_problem = [&](const std::string& what, int w, int h) {
    if (width == 0 || (w == width && h == height)) return std::string();
    return fmt::format("{}: {} is {} x {} px, the job's layers are {} x {}", path.string(), what, w, h, width, height);
  };
  try {
    if (ext == ".png") {
      (void)read_png_rgba(path);
    } else if (ext == ".bmp") {
      const Bmp1Image im = read_bmp1(path);
      return size_problem("the bitmap", im.width_px, im.height_px);
    } else if (ext == ".tif") {
      std::string problem;
      const int pages = read_tiff_stack(path, [&](int page, const LabelImage& labels) {
        if (problem.empty())
          problem = size_problem(fmt::format("page {}", page + 1), labels.width_px(), labels.height_px());
      });
      if (!problem.empty()) return problem;
      if (pages != m.total_layers)
        return fmt::format("{}: {} pages, the job has {} layers", path.string(), pages, m.total_layers);
    } else if (ext == ".vdb") {
      const std::vector<VdbGridInfo> grids = read_vdb_grid_info(path);
      const int materials = material_count(m);
      if (static_cast<int>(grids.size()) != materials)
        return fmt::format("{}: {} grids, the job has {} materials", path.string(), grids.size(), materials);
      for (const VdbGridInfo& g : grids)
        if (g.active_voxels > 0 && (g.min[2] < 0 || g.max[2] >= m.total_layers || g.min[0] < 0 || g.min[1] < 0 ||
                                    (width > 0 && (g.max[0] >= width || g.max[1] >= height))))
          return fmt::format("{}: grid '{}' has voxels outside the job's {} layers of {} x {} px", path.string(),
                             g.name, m.total_layers, width, height);
    } else if (ext == ".gcvf") {
      std::string problem;
      const GcvfPackageSummary package = read_gcvf_package(path, [&](const std::string& name, const RgbaImage& im) {
        if (problem.empty()) problem = size_problem(fmt::format("entry '{}'", name), im.width_px, im.height_px);
      });
      if (!problem.empty()) return problem;
      if (package.images != m.total_layers)
        return fmt::format("{}: {} layer images, the job has {} layers", path.string(), package.images, m.total_layers);
      if (package.config_xml.empty()) return fmt::format("{}: no ConfigFile.xml", path.string());
    } else if (ext == ".sl1" || ext == ".sl1s") {
      // A Prusa print archive: every member against its CRC-32, every PNG decoded; one layer
      // image per job layer besides the two thumbnails.
      const GcvfPackageSummary archive = read_gcvf_package(path, [](const std::string&, const RgbaImage&) {});
      if (archive.images - 2 != m.total_layers)
        return fmt::format("{}: {} layer images, the job has {} layers", path.string(), archive.images - 2,
                           m.total_layers);
    }
  } catch (const Error& e) {
    return e.what();
  }
  return {};
}

// Which shards have no manifest, and how to slice just them: with the scene the other shards
// name, and with the array script of `trivox cluster slurm` when the folder has one.
std::string missing_shards_message(const std::filesystem::path& dir, const std::map<int, std::filesystem::path>& shards,
                                   const std::vector<std::string>& missing, int count) {
  std::string scene = "SCENE";
  for (const ManifestInput& in : read_manifest(shards.begin()->second).inputs)
    if (in.role == "scene") scene = in.name;
  std::string message = fmt::format(
      "{}: cannot merge: shard(s) {} of {} have no manifest yet; slice each with `trivox slice {} -o {} "
      "--shard I/{} --resume` and the options of the others",
      dir.string(), fmt::join(missing, ", "), count, scene, dir.string(), count);
  std::error_code ec;
  if (const auto script = dir / "slurm" / "shards.sbatch"; count <= 1000 && std::filesystem::exists(script, ec))
    message += fmt::format(", or on Slurm `sbatch --array={} {} 0`", fmt::join(missing, ","), script.string());
  return message;
}

// What a merged job with stack parts still needs, and the command that does it.
std::string stack_outputs_to_write_message(const std::filesystem::path& dir, const JobManifest& m) {
  std::vector<std::string> stacks;
  for (const std::string& format : manifest_formats(m))
    if (is_stack_format(format)) stacks.push_back(format);
  std::string scene = "SCENE";
  for (const ManifestInput& in : m.inputs)
    if (in.role == "scene") scene = in.name;
  if (stacks.empty()) stacks.emplace_back("the stack outputs");
  const std::string last = stacks.back();
  stacks.pop_back();
  return fmt::format(
      "the shards' layers are merged; {}{} {} still to be written from the layers they kept: "
      "run `trivox slice {} -o {} --resume` with the shards' options",
      stacks.empty() ? "" : fmt::format("{} and ", fmt::join(stacks, ", ")), last, stacks.empty() ? "is" : "are", scene,
      dir.string());
}

}  // namespace

bool holds_job(const std::filesystem::path& dir) {
  std::error_code ec;
  if (std::filesystem::exists(dir / manifest_file_name(1, 1), ec)) return true;
  for (auto it = std::filesystem::directory_iterator(dir, ec); !ec && it != std::filesystem::end(it); it.increment(ec))
    if (shard_of_name(it->path().filename().string())) return true;
  return false;
}

JobManifest merge_shards(const std::filesystem::path& dir, const std::atomic<bool>* stop) {
  int count = 0;
  const auto shards = shard_manifests(dir, &count);
  if (shards.empty())
    throw Error(fmt::format("{}: no shard manifests (manifest.shard-I-of-N.json) to merge", dir.string()));
  // Merging writes manifest.json and removes the shards' manifests: the folder is locked as
  // for a whole job, so a shard still running (or a job started meanwhile) refuses the merge.
  const JobFolderLock lock(dir);
  std::vector<std::string> missing;
  for (int i = 1; i <= count; ++i)
    if (!shards.count(i)) missing.push_back(std::to_string(i));
  if (!missing.empty()) throw Error(missing_shards_message(dir, shards, missing, count));

  JobManifest merged;
  std::vector<int> owner;
  for (const auto& [index, path] : shards) {
    JobManifest m = read_manifest(path);
    if (m.shard_index != index || m.shard_count != count)
      throw Error(fmt::format("{}: says it is shard {} of {}", path.string(), m.shard_index, m.shard_count));
    if (m.status != JobStatus::kComplete)
      throw Error(
          fmt::format("{}: shard {} of {} is {}, not complete; finish it with `trivox slice --shard {}/{} --resume`",
                      path.string(), index, count, to_string(m.status), index, count));
    if (index == 1) {
      merged = m;
      merged.files.clear();
      merged.printed.clear();
      owner.assign(static_cast<std::size_t>(m.total_layers), 0);
    } else if (const auto diffs = manifest_differences(merged, m); !diffs.empty()) {
      throw Error(fmt::format("{}: not the same job as shard 1: {}", path.string(), fmt::join(diffs, "; ")));
    }
    for (const ManifestFile& f : m.files) {
      if (f.layer < 1) {
        // Files of the whole job (layer 0) depend only on the settings: every shard writes
        // the same one, listed once.
        const auto same = std::find_if(merged.files.begin(), merged.files.end(),
                                       [&](const ManifestFile& g) { return g.layer == 0 && g.name == f.name; });
        if (same == merged.files.end()) {
          merged.files.push_back(f);
        } else if (same->sha256 != f.sha256) {
          throw Error(fmt::format("{}: {} differs from the other shards' copy", path.string(), f.name));
        }
        continue;
      }
      auto& o = owner[static_cast<std::size_t>(f.layer - 1)];
      if (o != 0 && o != index)
        throw Error(fmt::format("{}: layer {} is in shard {} and shard {}", dir.string(), f.layer, o, index));
      o = index;
      throw_if_stopped(stop, "merging the shards");
      if (const std::string problem = file_problem(dir, f); !problem.empty())
        throw Error(fmt::format("cannot merge: {}", problem));
      merged.files.push_back(f);
    }
    // Each layer's extent comes from the shard that owns it (every shard lists only its own).
    for (const ManifestPrinted& p : m.printed)
      if (owner[static_cast<std::size_t>(p.layer - 1)] == index) merged.printed.push_back(p);
  }
  for (std::size_t layer = 0; layer < owner.size(); ++layer)
    if (owner[layer] == 0) throw Error(fmt::format("{}: no shard has layer {}", dir.string(), layer + 1));
  merged.shard_index = 1;
  merged.shard_count = 1;
  merged.status = JobStatus::kComplete;
  merged.message.clear();
  if (std::any_of(merged.files.begin(), merged.files.end(),
                  [](const ManifestFile& f) { return detail::is_stack_part(f.name); })) {
    // The stack outputs are made from every layer in one process: the whole job's resume
    // writes them from the parts the shards kept.
    merged.status = JobStatus::kInterrupted;
    merged.message = stack_outputs_to_write_message(dir, merged);
  }
  merged.sort_files();
  write_manifest(dir / manifest_file_name(1, 1), merged);
  for (const auto& [index, path] : shards) {
    std::error_code ec;
    std::filesystem::remove(path, ec);
    if (ec) throw IoError(fmt::format("{}: cannot remove after merging: {}", path.string(), ec.message()));
  }
  // Every shard is complete and the folder is held: what a killed shard left on any machine goes.
  remove_stale_temporaries(dir, StaleTemporaries::kOfEveryMachine);
  return merged;
}

VerifyReport verify_output(const std::filesystem::path& dir, const std::atomic<bool>* stop) {
  const std::filesystem::path path = dir / manifest_file_name(1, 1);
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    int count = 0;
    const auto shards = shard_manifests(dir, &count);
    if (!shards.empty())
      throw IoError(fmt::format("{}: no manifest.json, only shard manifests: run `trivox merge {}` first", dir.string(),
                                dir.string()));
    throw IoError(fmt::format("{}: no manifest.json: not a trivox output folder", dir.string()));
  }
  VerifyReport report;
  report.manifest = read_manifest(path);
  const JobManifest& m = report.manifest;
  if (m.status != JobStatus::kComplete)
    report.problems.push_back(fmt::format("{}: the job is {}{}", path.string(), to_string(m.status),
                                          m.message.empty() ? "" : ": " + m.message));
  std::vector<char> has_files(static_cast<std::size_t>(m.total_layers), 0);
  for (const ManifestFile& f : m.files) {
    if (f.layer > 0) has_files[static_cast<std::size_t>(f.layer - 1)] = 1;
    ++report.files_checked;
    throw_if_stopped(stop, "verifying the files");
    std::string problem = file_problem(dir, f);
    if (problem.empty()) problem = decode_problem(dir / f.name, m);
    if (!problem.empty()) report.problems.push_back(std::move(problem));
  }
  if (m.status == JobStatus::kComplete) {
    // Formats that write files per layer need files in every layer; a stack output holds
    // every layer in its own file (its page or image count is checked when it is decoded),
    // which must be listed.
    bool per_layer = false;
    for (const std::string& format : manifest_formats(m)) {
      bool stack = false;
      try {
        stack = is_stack_format(format);
      } catch (const Error&) {
        report.problems.push_back(fmt::format("{}: unknown output format '{}'", path.string(), format));
        continue;
      }
      per_layer = per_layer || !stack;
      const std::string folder = format + "/";
      if (stack && std::none_of(m.files.begin(), m.files.end(), [&](const ManifestFile& f) {
            return f.layer == 0 && f.name.compare(0, folder.size(), folder) == 0;
          }))
        report.problems.push_back(fmt::format("{}: no file of the '{}' output is listed", path.string(), format));
    }
    if (per_layer)
      for (std::size_t layer = 0; layer < has_files.size(); ++layer)
        if (!has_files[layer])
          report.problems.push_back(fmt::format("{}: layer {} has no files", path.string(), layer + 1));
  }
  return report;
}

}  // namespace trivox
