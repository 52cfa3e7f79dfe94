// Helpers of run_slice_job (job.cpp) for stopping a job at its first bad layer and resuming
// it after a correction of the scene: the scene's parts for the manifest, and the layer loop's
// guard that names the layer in a fraction error and stops the other workers.
#pragma once

#include <atomic>
#include <filesystem>
#include <string>
#include <vector>

#include "trivox/job/manifest.h"
#include "trivox/slice/slicer.h"

namespace trivox::detail {

// The scene's parts (manifest.h) for a job of model layers first .. first + model_layers - 1;
// nullopt for a scene built in code.
std::optional<ManifestSceneParts> scene_parts(const Scene& scene, const SliceLayout& layout, int first,
                                              int model_layers);

// The files of `previous`'s layers whose files all exist with their recorded size and SHA-256:
// what a resumed job keeps. Whole-job files (layer 0) are not kept: they are written again.
std::vector<ManifestFile> intact_files(const std::filesystem::path& dir, const JobManifest& previous);

// The stack parts (output/detail/stack_parts.h) among `files`, by job layer (index 0 for
// layer 1) of a job of `total_layers`.
std::vector<std::vector<std::string>> stack_parts_by_layer(const std::vector<ManifestFile>& files, int total_layers);
// Takes the stack parts out of `files` (once the stack outputs are written from them).
void take_stack_parts(std::vector<ManifestFile>& files);
// Removes the parts' folder of `dir` with what it holds (also a damaged part a resume sliced
// again), once the manifest that no longer lists them is written; what cannot be removed stays
// (it is no longer listed, and harms nothing).
void remove_stack_parts(const std::filesystem::path& dir);

// The job layers (1-based) that `files` hold, sorted, once each.
std::vector<int> layers_of(const std::vector<ManifestFile>& files);

// The printed extents `previous` recorded for the layers `kept` holds files of: what a resumed
// job keeps of them, so that it reports the whole job's printed extent.
std::vector<ManifestPrinted> printed_of_kept_layers(const JobManifest& previous, const std::vector<ManifestFile>& kept);

// slicer.slice_layer(layer), unless `failed` is set (another worker met an error: nullopt).
// A FractionError is rethrown with the layer named (1-based model layer and its height), and
// any error sets `failed`, so that the job's other workers start no new layer.
std::optional<LayerResult> slice_layer_unless_failed(const Slicer& slicer, int layer, std::atomic<bool>& failed);

}  // namespace trivox::detail
