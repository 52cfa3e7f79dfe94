// Helpers for the tests of whole slice jobs: a file's bytes, an output folder's bytes, and a
// job stopped part way (as Ctrl-C stops it) and then resumed.
#pragma once

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "trivox/io/model.h"
#include "trivox/job/job.h"

namespace trivox::test {

// A tube revolved from a profile in a model file ("profile.itd" beside the scene): a
// constructed cell that slices in moments, for the construction cache's tests.
inline constexpr const char* kRevolvedTubeScene = R"({"version": 1, "units": "mm", "printer": "j750-hm",
 "materials": [{"name": "VeroCyan", "rgba": [20, 100, 200, 255]}],
 "cells": [{"name": "tube",
   "geometry": {"revolve": {"profile": {"file": "profile.itd"}, "angle_deg": 270}},
   "material": {"kind": "constant", "fractions": {"VeroCyan": 1}}}]})";

// The tube's profile: a plate from inner radius `inner` to 10 mm, 1.5 mm tall, in the xz plane.
inline void write_tube_profile(const std::filesystem::path& path, double inner) {
  const TensorSpline plate({KnotVector::bezier(2), KnotVector::bezier(2)}, 3,
                           {inner, 0, 0, 10, 0, 0, inner, 0, 1.5, 10, 0, 1.5});
  Model m;
  m.patches.push_back({"PROFILE", 0, 0, plate});
  std::ofstream out(path);
  write_itd(out, m);
}

// The bytes of a file; empty when it cannot be read.
inline std::string read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// Every regular file under `dir` (relative, '/'-separated) with its bytes; the stats files
// are left out (they hold timings).
inline std::map<std::string, std::string> folder_bytes(const std::filesystem::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    const std::string name = e.path().lexically_relative(dir).generic_string();
    if (name.rfind("stats", 0) == 0) continue;
    out[name] = read_bytes(e.path());
  }
  return out;
}

// A job of `formats` on 2 threads into a fresh folder of the temporary folder,
// "<name>-<pid>-<variant>", recording the manifest after every layer.
inline JobParams job_in_temp_folder(const std::string& name, const std::string& variant,
                                    std::vector<std::string> formats) {
  JobParams p;
  p.output_dir = std::filesystem::temp_directory_path() / (name + "-" + std::to_string(::getpid()) + "-" + variant);
  std::filesystem::remove_all(p.output_dir);
  p.formats = std::move(formats);
  p.threads = 2;
  p.manifest_interval_seconds = 0;
  return p;
}

// Raises a job's stop flag once `after` layers are complete.
class StopAfterLayers final : public ProgressSink {
 public:
  StopAfterLayers(std::atomic<bool>* flag, int after) : flag_(flag), after_(after) {}
  void on_layer_done(int done, int) override {
    if (done >= after_) flag_->store(true);
  }

 private:
  std::atomic<bool>* flag_;
  int after_;
};

// Runs `params` as a job that is stopped once `stop_after_layers` layers are complete (0:
// before the first); returns what the job reports.
inline JobStats slice_until_stopped(const Slicer& slicer, JobParams params, int stop_after_layers) {
  std::atomic<bool> stop{stop_after_layers == 0};
  StopAfterLayers sink(&stop, stop_after_layers);
  params.stop = &stop;
  return run_slice_job(slicer, params, &sink);
}

// Runs `params` again with resume, to the end.
inline JobStats slice_resumed(const Slicer& slicer, JobParams params) {
  params.resume = true;
  return run_slice_job(slicer, params);
}

}  // namespace trivox::test
