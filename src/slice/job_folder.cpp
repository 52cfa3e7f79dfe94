#include "trivox/slice/job_folder.h"

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <string_view>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "trivox/error.h"
#include "trivox/io/sha256.h"
#include "trivox/output/png_io.h"
#include "trivox/output/tiff_stack.h"

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
  for (auto it = std::filesystem::directory_iterator(dir, ec); !ec && it != std::filesystem::end(it); it.increment(ec)) {
    const auto shard = shard_of_name(it->path().filename().string());
    if (!shard) continue;
    const int n = shard->second;
    if (*count != 0 && n != *count)
      throw Error(fmt::format("{}: shard manifests of {} and of {} shards are mixed in one folder", dir.string(), *count, n));
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
  if (d.sha256 != f.sha256) return fmt::format("{}: SHA-256 {} differs from the manifest's {}", path.string(), d.sha256, f.sha256);
  return {};
}

// A BMP's headers against its size: the "BM" tag, the file size field, and a pixel array
// of stride x height bytes after the pixel offset.
std::string bmp_problem(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto u32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(bytes[at + static_cast<std::size_t>(i)]);
    return v;
  };
  const auto u16 = [&](std::size_t at) {
    return static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[at]) | (static_cast<unsigned char>(bytes[at + 1]) << 8));
  };
  if (bytes.size() < 54 || bytes[0] != 'B' || bytes[1] != 'M') return fmt::format("{}: not a BMP file", path.string());
  if (u32(2) != bytes.size()) return fmt::format("{}: BMP header says {} bytes, the file has {}", path.string(), u32(2), bytes.size());
  const std::uint64_t width = u32(18), height = u32(22), bpp = u16(28);
  const std::uint64_t stride = (width * bpp + 31) / 32 * 4;
  if (bpp == 0 || u32(10) + stride * height != bytes.size())
    return fmt::format("{}: BMP pixel data does not fill the file ({} x {} px, {} bits)", path.string(), width, height, bpp);
  return {};
}

}  // namespace

JobManifest merge_shards(const std::filesystem::path& dir) {
  int count = 0;
  const auto shards = shard_manifests(dir, &count);
  if (shards.empty()) throw Error(fmt::format("{}: no shard manifests (manifest.shard-I-of-N.json) to merge", dir.string()));
  std::vector<std::string> missing;
  for (int i = 1; i <= count; ++i)
    if (!shards.count(i)) missing.push_back(std::to_string(i));
  if (!missing.empty())
    throw Error(fmt::format("{}: cannot merge: shard(s) {} of {} have no manifest yet", dir.string(), fmt::join(missing, ", "), count));

  JobManifest merged;
  std::vector<int> owner;
  for (const auto& [index, path] : shards) {
    JobManifest m = read_manifest(path);
    if (m.shard_index != index || m.shard_count != count)
      throw Error(fmt::format("{}: says it is shard {} of {}", path.string(), m.shard_index, m.shard_count));
    if (m.status != JobStatus::kComplete)
      throw Error(fmt::format("{}: shard {} of {} is {}, not complete; finish it with `trivox slice --shard {}/{} --resume`",
                              path.string(), index, count, to_string(m.status), index, count));
    if (index == 1) {
      merged = m;
      merged.files.clear();
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
      if (const std::string problem = file_problem(dir, f); !problem.empty())
        throw Error(fmt::format("cannot merge: {}", problem));
      merged.files.push_back(f);
    }
  }
  for (std::size_t layer = 0; layer < owner.size(); ++layer)
    if (owner[layer] == 0) throw Error(fmt::format("{}: no shard has layer {}", dir.string(), layer + 1));
  merged.shard_index = 1;
  merged.shard_count = 1;
  merged.status = JobStatus::kComplete;
  merged.message.clear();
  merged.sort_files();
  write_manifest(dir / manifest_file_name(1, 1), merged);
  for (const auto& [index, path] : shards) {
    std::error_code ec;
    std::filesystem::remove(path, ec);
    if (ec) throw IoError(fmt::format("{}: cannot remove after merging: {}", path.string(), ec.message()));
  }
  return merged;
}

VerifyReport verify_output(const std::filesystem::path& dir) {
  const std::filesystem::path path = dir / manifest_file_name(1, 1);
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    int count = 0;
    const auto shards = shard_manifests(dir, &count);
    if (!shards.empty())
      throw IoError(fmt::format("{}: no manifest.json, only shard manifests: run `trivox merge {}` first", dir.string(), dir.string()));
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
    std::string problem = file_problem(dir, f);
    const std::string ext = std::filesystem::path(f.name).extension().string();
    if (problem.empty() && ext == ".png") {
      try {
        (void)read_png_rgba(dir / f.name);
      } catch (const Error& e) {
        problem = e.what();
      }
    }
    if (problem.empty() && ext == ".bmp") problem = bmp_problem(dir / f.name);
    if (problem.empty() && ext == ".tif") {
      try {
        const int pages = read_tiff_stack(dir / f.name, [](int, const LabelImage&) {});
        if (pages != m.total_layers)
          problem = fmt::format("{}: {} pages, the job has {} layers", (dir / f.name).string(), pages, m.total_layers);
      } catch (const Error& e) {
        problem = e.what();
      }
    }
    if (!problem.empty()) report.problems.push_back(std::move(problem));
  }
  if (m.status == JobStatus::kComplete)
    for (std::size_t layer = 0; layer < has_files.size(); ++layer)
      if (!has_files[layer]) report.problems.push_back(fmt::format("{}: layer {} has no files", path.string(), layer + 1));
  return report;
}

}  // namespace trivox
