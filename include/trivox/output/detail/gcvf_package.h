// Internal to trivox, not part of its stable interface (docs/ARCHITECTURE.md, "Public surface").

// Reading the GrabCAD Voxel Print package the "gcvf" output writes (layer_writer.h): a zip
// archive of the layer PNGs and ConfigFile.xml (docs/FORMATS.md, "GrabCAD Voxel Print
// package"), for `trivox verify` and for tests.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

#include "trivox/output/png_io.h"

namespace trivox {

struct GcvfPackageSummary {
  int entries = 0;         // every entry of the archive
  int images = 0;          // the PNG entries
  std::string config_xml;  // ConfigFile.xml; empty when the package has none
};

// Reads every entry of the package in archive order, checks it against its CRC-32, decodes
// each PNG entry and hands it to `visit(entry name, image)`. Throws IoError naming the file
// and the entry when the archive or an image cannot be read.
GcvfPackageSummary read_gcvf_package(const std::filesystem::path& path,
                                     const std::function<void(const std::string&, const RgbaImage&)>& visit);

}  // namespace trivox
