// Operations on a finished job's output folder: merging the shards of a split job into one
// manifest, and verifying every file the manifest lists (docs/CLI.md, "merge", "verify").
#pragma once

#include <atomic>
#include <filesystem>
#include <string>
#include <vector>

#include "trivox/job/manifest.h"

namespace trivox {

// Finds the shard manifests of `dir` (manifest.shard-I-of-N.json), checks that all N are
// there, complete, of the same job (manifest_differences) and that together they list every
// job layer exactly once with files of the recorded size and SHA-256; then writes
// manifest.json - the same bytes a single run writes - and removes the shard manifests.
// Since it writes, it holds the folder's lock as a whole job does (job_lock.h), from after
// the shard manifests are found until it returns: a shard still running, or any job writing
// into the folder, makes it throw Error naming that job. Throws Error naming the folder and
// what is missing or inconsistent, IoError when a file cannot be read or written. Returns
// the merged manifest.
// A job with stack outputs (a GrabCAD package, an SL1S archive, ...) keeps its layers in
// stack parts in its shards (output/detail/stack_parts.h): its merged manifest lists them and
// says the job is interrupted, with the command that writes the stack outputs from them (the
// whole job's --resume, which then removes the parts).
// `stop` (optional, may be set from a signal handler) is read before each file: once it is
// true, merge_shards throws CancelledError having written nothing.
JobManifest merge_shards(const std::filesystem::path& dir, const std::atomic<bool>* stop = nullptr);

// Whether `dir` holds a job: its manifest.json or a shard's manifest.
bool holds_job(const std::filesystem::path& dir);

struct VerifyReport {
  JobManifest manifest;
  int files_checked = 0;
  // One line per problem, naming the file: missing, wrong size, wrong SHA-256, not
  // decodable, a layer without files, or a job that is not complete.
  std::vector<std::string> problems;
  bool ok() const noexcept { return problems.empty(); }
};

// Reads only, so takes no lock (a job running in the folder shows as not complete).
// Re-hashes every file manifest.json lists and decodes it by kind: PNG images, the legacy
// 1-bit BMPs, every page of a TIFF stack, every grid of an OpenVDB file, every entry of a
// GrabCAD package (CRC-32 checked, PNGs decoded). Legacy bitmaps, TIFF pages and package
// images must have the job's bitmap size; a TIFF or a package holds one page or image per
// job layer, an OpenVDB file one grid per material with no voxel outside the job's layers. Throws IoError when the
// folder has no readable manifest.json (and says so when only shard manifests are there),
// InputError when the manifest is malformed.
// `stop` (optional) is read before each file: once it is true, throws CancelledError.
VerifyReport verify_output(const std::filesystem::path& dir, const std::atomic<bool>* stop = nullptr);

}  // namespace trivox
