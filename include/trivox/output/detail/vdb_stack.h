// Internal to trivox, not part of its stable interface (docs/ARCHITECTURE.md, "Public surface").

// Reading the OpenVDB file the "vdb" output writes (layer_writer.h): one FloatGrid per
// material, named after it, value 1 on the voxels that hold the material and inactive
// elsewhere, with a linear transform from index space (column, rows counted from the bottom,
// job layer) to model space in mm (docs/FORMATS.md, "OpenVDB"). Read with OpenVDB's own
// reader; no OpenVDB type appears here.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace trivox {

struct VdbGridSummary {
  std::string name;
  std::string value_type;                   // OpenVDB's name of the value type, e.g. "float"
  std::string grid_class;                   // e.g. "fog volume"
  std::array<double, 3> voxel_size_mm{};    // the transform's scale along x, y, z
  std::array<double, 3> index_origin_mm{};  // model-space position of index (0, 0, 0)
  std::vector<std::array<int, 3>> active;   // every active voxel (i, j, k), tiles expanded, sorted
  std::int64_t values_not_one = 0;          // active voxels whose value is not exactly 1
};

struct VdbGridInfo {
  std::string name;
  std::string value_type;           // OpenVDB's name of the value type, e.g. "float"
  std::uint64_t active_voxels = 0;  // tiles counted voxel by voxel
  std::array<int, 3> min{}, max{};  // index box of the active voxels (when there are any)
  std::uint64_t memory_bytes = 0;   // what the grid takes in memory (OpenVDB's memUsage)
};

// Every grid of the file, in file order, read and decoded in full but summed up rather than
// listed voxel by voxel (for `trivox verify`: memory stays that of the grids). Throws IoError
// naming the file when OpenVDB cannot read it or a grid is not a float grid.
std::vector<VdbGridInfo> read_vdb_grid_info(const std::filesystem::path& path);

// Every grid of the file, in file order. Throws IoError naming the file when OpenVDB cannot
// read it or a grid is not a float grid with a linear transform.
std::vector<VdbGridSummary> read_vdb_stack(const std::filesystem::path& path);

}  // namespace trivox
