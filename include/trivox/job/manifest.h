// manifest.json: the record of a job's output folder (docs/FORMATS.md, "manifest.json").
// It names the tool version, the effective settings, the SHA-256 of the scene and of every
// model it reads, and every output file with its layer, size and SHA-256, plus the job's
// status. A running job rewrites it atomically as layers complete; the final content depends
// only on the inputs and settings (files sorted, no times, no thread count), so an
// interrupted-and-resumed job, a sharded-and-merged job and a single run end with the same
// bytes.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace trivox {

enum class JobStatus { kRunning, kComplete, kInterrupted, kFailed };
std::string_view to_string(JobStatus status) noexcept;
std::optional<JobStatus> parse_job_status(std::string_view text) noexcept;

struct ManifestInput {
  std::string role;    // "scene" or "model"
  std::string name;    // as given on the command line / in the scene
  std::string sha256;  // lowercase hex; empty for a scene built in code
};

struct ManifestFile {
  // 1-based job layer (padding layers included), as in the file names; 0 for a file of the
  // whole stack (a preview), written when the job completes.
  int layer = 0;
  std::string name;  // relative to the output folder, '/'-separated
  std::uint64_t bytes = 0;
  std::string sha256;
};

// The voxels of one job layer that hold a material (printed_extent.h), kept so that a resumed
// job reports the printed extent of the whole job and not only of the layers it sliced. Only
// layers with a material are listed.
struct ManifestPrinted {
  int layer = 0;                                       // 1-based job layer, as ManifestFile::layer
  int col_lo = 0, col_hi = 0, row_lo = 0, row_hi = 0;  // inclusive pixel bounds
};

// A cell of the scene, for resuming a job after a correction of the scene.
struct ManifestCell {
  std::string name;
  std::string sha256;  // Cell::fingerprint
  // The job layers (1-based) its volume may reach: the planes of those layers meet its
  // control points' box; 0, 0 when it reaches none of the job's.
  int first_layer = 0, last_layer = 0;
};

// What shapes the layers, part by part (Scene::settings_fingerprint, the fraction policy and
// the cells' fingerprints): the record that lets a job resume after the scene changed in a way
// that cannot change the layers it kept (resume_differences).
struct ManifestSceneParts {
  std::string settings_sha256;
  std::string fraction_sums;  // "error TOLERANCE" or "normalise"
  std::vector<ManifestCell> cells;
};

struct JobManifest {
  std::string tool_version;
  JobStatus status = JobStatus::kRunning;
  std::string message;  // why the job stopped (interrupted / failed); empty otherwise
  std::vector<ManifestInput> inputs;
  // Effective settings that shape the output bytes, in a fixed order: name -> canonical text.
  std::vector<std::pair<std::string, std::string>> settings;
  int total_layers = 0;  // job layers, padding included
  int shard_index = 1;   // 1-based; 1 of 1 for an unsharded job
  int shard_count = 1;
  // Absent for a scene built in code (and in manifests of earlier versions).
  std::optional<ManifestSceneParts> scene_parts;
  std::vector<ManifestFile> files;       // sorted by (layer, name)
  std::vector<ManifestPrinted> printed;  // sorted by layer; absent in manifests of earlier versions

  // Sorts files by (layer, name) and printed by layer.
  void sort_files();
};

// The manifest's file name: "manifest.json", or "manifest.shard-I-of-N.json" for shard I of N.
std::string manifest_file_name(int shard_index, int shard_count);
// The statistics' file name (FORMATS.md, "stats.json"): "stats.json", or
// "stats.shard-I-of-N.json" for shard I of N.
std::string stats_file_name(int shard_index, int shard_count);

// Whether job layer `index` (0-based) belongs to shard `shard_index` (1-based) of
// `shard_count`: layers are dealt round-robin, index % N == I - 1, so every shard gets a
// share of the tall and the short parts of the object.
bool shard_has_layer(int index, int shard_index, int shard_count) noexcept;

// The manifest as text (deterministic: same manifest, same bytes).
std::string manifest_text(const JobManifest& manifest);
// Parses manifest text; throws InputError naming `source` and the field.
JobManifest parse_manifest(std::string_view text, const std::string& source);
// Reads / atomically writes a manifest file (IoError when it cannot be read or written).
JobManifest read_manifest(const std::filesystem::path& path);
void write_manifest(const std::filesystem::path& path, const JobManifest& manifest);

// What stops a job from continuing another's work: a different tool version, input file,
// setting or layer count. One line per difference, empty when `previous` and `current`
// describe the same job (shard numbers and files are not compared).
std::vector<std::string> manifest_differences(const JobManifest& previous, const JobManifest& current);

// What stops a job (`current`) from keeping the job layers `kept` (1-based) that the job of
// `previous` completed: manifest_differences, except that a scene file that changed is
// accepted when the scene parts show that the change cannot change those layers: the same
// settings (printer, materials, dithering), a fraction policy that accepts every sample the
// previous one accepted ("error" to "normalise", or a larger tolerance: a completed layer met
// no sample beyond the old tolerance, and within it both clean the fractions alike), the same
// number of cells, and every cell whose definition changed reaching none of the kept layers.
// One line per reason, empty when the layers can be kept.
std::vector<std::string> resume_differences(const JobManifest& previous, const JobManifest& current,
                                            const std::vector<int>& kept);

}  // namespace trivox
