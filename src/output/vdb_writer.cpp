// The "vdb" output: one OpenVDB grid per material in vdb/stack.vdb, for volume tools
// (Blender, Houdini, ParaView). The only file that includes OpenVDB's headers: they are heavy,
// and their types stay out of the public headers.
//
// Grids are FloatGrids of class "fog volume" with value 1 where the voxel holds the material,
// inactive (background 0) elsewhere: a float grid is what volume renderers treat as density
// (Blender's volume shader reads one by name), whereas bool and mask grids carry no value to
// render and usually need converting first; an inactive background costs nothing, so memory
// and file size follow the active voxels only.
//
// Layers finish in any order on several threads. Each worker deflates its label image into a
// spool (layer_spool.h); when the job completes, finish() builds the grids from the spool in
// increasing layer order, one layer in memory at a time, pruning uniform 8-layer blocks into
// tiles as it goes, and writes the file once under a temporary name that is renamed when
// whole. The write goes through a stream this file checks (OpenVDB's File::write does not),
// so a full disk is an error and never a truncated file.
//
// OpenVDB stamps every file with a random UUID (bytes 21..56 of the header). trivox replaces
// it with one derived from the SHA-256 of the file with the UUID zeroed, so the file depends
// only on the grids; everything else OpenVDB writes (grid and file metadata, Blosc-compressed
// buffers) is a function of the grids.
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <mutex>
#include <sstream>
#include <system_error>
#include <utility>

#include <fmt/format.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Prune.h>
#include <tbb/task_arena.h>

#include "output/layer_spool.h"
#include "output/stack_writers.h"
#include "trivox/error.h"
#include "trivox/io/detail/sha256.h"
#include "trivox/output/atomic_file.h"
#include "trivox/output/detail/vdb_stack.h"

namespace trivox {

namespace {

void initialize_openvdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

// OpenVDB runs some tree algorithms with TBB on every core (freeing a tree's nodes, the
// statistics it writes into a file, memory and voxel counts). trivox parallelises across
// layers only (docs/ARCHITECTURE.md, "One parallel seam"), so every use of OpenVDB here runs
// in an arena of one thread: on the calling thread, with nothing handed between threads.
template <class F>
auto on_calling_thread(F&& f) -> decltype(f()) {
  tbb::task_arena arena(1);
  return arena.execute(std::forward<F>(f));
}

constexpr long kUuidOffset = 21;  // magic (8), file version (4), library version (8), offsets flag (1)
constexpr std::size_t kUuidChars = 36;

// Why a stdio or stream call failed, from errno (which a short write need not set).
std::string errno_reason(int error_number) {
  return error_number != 0 ? std::error_code(error_number, std::generic_category()).message()
                           : std::string("short write");
}

bool looks_like_uuid(const char* s) {
  for (std::size_t i = 0; i < kUuidChars; ++i) {
    const bool dash = i == 8 || i == 13 || i == 18 || i == 23;
    if (dash ? s[i] != '-' : std::isxdigit(static_cast<unsigned char>(s[i])) == 0) return false;
  }
  return true;
}

// Replaces the random file UUID by one derived from the file's content (see the top).
void make_uuid_deterministic(const std::filesystem::path& file, const std::filesystem::path& target) {
  std::FILE* f = std::fopen(file.c_str(), "rb+");
  if (f == nullptr) throw IoError(fmt::format("{}: cannot reopen {}", target.string(), file.string()));
  struct Close {
    std::FILE* f;
    ~Close() {
      if (f != nullptr) std::fclose(f);
    }
  } close{f};
  char uuid[kUuidChars + 1] = {};
  if (std::fseek(f, kUuidOffset, SEEK_SET) != 0 || std::fread(uuid, 1, kUuidChars, f) != kUuidChars ||
      !looks_like_uuid(uuid))
    throw IoError(
        fmt::format("{}: the OpenVDB header has no file UUID where expected (byte {})", target.string(), kUuidOffset));
  const std::string zero = "00000000-0000-0000-0000-000000000000";
  if (std::fseek(f, kUuidOffset, SEEK_SET) != 0 || std::fwrite(zero.data(), 1, kUuidChars, f) != kUuidChars ||
      std::fflush(f) != 0)
    throw IoError(fmt::format("{}: cannot write {}", target.string(), file.string()));
  const std::string h = sha256_file(file).sha256;
  const std::string id =
      fmt::format("{}-{}-{}-{}-{}", h.substr(0, 8), h.substr(8, 4), h.substr(12, 4), h.substr(16, 4), h.substr(20, 12));
  if (std::fseek(f, kUuidOffset, SEEK_SET) != 0 || std::fwrite(id.data(), 1, kUuidChars, f) != kUuidChars ||
      std::fflush(f) != 0 || ::fsync(::fileno(f)) != 0)
    throw IoError(fmt::format("{}: cannot write {}", target.string(), file.string()));
}

// OpenVDB's File::write opens its own std::ofstream and never checks it after writing, so a
// full disk would leave a truncated file that looks written. This writes the same bytes (the
// seekable form File writes, with grid offsets) to a stream the caller checks.
class CheckedArchive final : public openvdb::io::Archive {
 public:
  void write_to(std::ostream& os, const openvdb::GridCPtrVec& grids, const openvdb::MetaMap& meta) const {
    write(os, grids, /*seekable=*/true, meta);
  }
};

openvdb::MetaMap file_metadata() {
  openvdb::MetaMap meta;
  meta.insertMeta("creator", openvdb::StringMetadata("trivox"));
  return meta;
}

}  // namespace

std::vector<VdbGridSummary> read_vdb_stack(const std::filesystem::path& path) {
  initialize_openvdb();
  return on_calling_thread([&] {
    std::vector<VdbGridSummary> out;
    try {
      openvdb::io::File file(path.string());
      file.open(false);  // read everything now: no delayed loading from a file that may change
      const openvdb::GridPtrVecPtr grids = file.getGrids();
      file.close();
      for (const openvdb::GridBase::Ptr& base : *grids) {
        const openvdb::FloatGrid::Ptr grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
        if (!grid) throw IoError(fmt::format("{}: grid '{}' is not a float grid", path.string(), base->getName()));
        const openvdb::math::Transform& xf = grid->transform();
        if (!xf.isLinear())
          throw IoError(fmt::format("{}: grid '{}' has no linear transform", path.string(), grid->getName()));
        VdbGridSummary s;
        s.name = grid->getName();
        s.value_type = grid->valueType();
        s.grid_class = openvdb::GridBase::gridClassToString(grid->getGridClass());
        const openvdb::Vec3d size = xf.voxelSize();
        const openvdb::Vec3d origin = xf.indexToWorld(openvdb::Vec3d(0, 0, 0));
        s.voxel_size_mm = {size.x(), size.y(), size.z()};
        s.index_origin_mm = {origin.x(), origin.y(), origin.z()};
        for (auto it = grid->tree().cbeginValueOn(); it; ++it) {
          const openvdb::CoordBBox box = it.getBoundingBox();  // one voxel, or a whole tile
          for (auto c = box.begin(); c; ++c) {
            s.active.push_back({(*c).x(), (*c).y(), (*c).z()});
            if (*it != 1.0f) ++s.values_not_one;
          }
        }
        std::sort(s.active.begin(), s.active.end());
        out.push_back(std::move(s));
      }
    } catch (const Error&) {
      throw;
    } catch (const std::exception& e) {  // OpenVDB's exceptions and its streams' failures
      throw IoError(fmt::format("{}: cannot read as OpenVDB: {}", path.string(), e.what()));
    }
    return out;
  });
}

std::vector<VdbGridInfo> read_vdb_grid_info(const std::filesystem::path& path) {
  initialize_openvdb();
  return on_calling_thread([&] {
    std::vector<VdbGridInfo> out;
    try {
      openvdb::io::File file(path.string());
      file.open(false);  // read every buffer now, so that a broken one is found
      const openvdb::GridPtrVecPtr grids = file.getGrids();
      file.close();
      for (const openvdb::GridBase::Ptr& base : *grids) {
        const openvdb::FloatGrid::Ptr grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
        if (!grid) throw IoError(fmt::format("{}: grid '{}' is not a float grid", path.string(), base->getName()));
        VdbGridInfo info;
        info.name = grid->getName();
        info.value_type = grid->valueType();
        info.active_voxels = static_cast<std::uint64_t>(grid->activeVoxelCount());
        info.memory_bytes = static_cast<std::uint64_t>(grid->memUsage());
        if (info.active_voxels > 0) {
          const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
          info.min = {box.min().x(), box.min().y(), box.min().z()};
          info.max = {box.max().x(), box.max().y(), box.max().z()};
        }
        out.push_back(std::move(info));
      }
    } catch (const Error&) {
      throw;
    } catch (const std::exception& e) {  // OpenVDB's exceptions and its streams' failures
      throw IoError(fmt::format("{}: cannot read as OpenVDB: {}", path.string(), e.what()));
    }
    return out;
  });
}

namespace detail {

namespace {

class VdbWriter final : public LayerWriter {
 public:
  explicit VdbWriter(OutputContext c) : c_(std::move(c)) {
    initialize_openvdb();
    std::error_code ec;
    std::filesystem::create_directories(c_.dir / "vdb", ec);
    if (ec) throw IoError(fmt::format("{}: cannot create folder: {}", (c_.dir / "vdb").string(), ec.message()));
    spool_ = std::make_unique<LayerSpool>(c_.dir / "vdb" / "stack.vdb.spool", c_.total_layers);
  }
  std::string_view name() const noexcept override { return "vdb"; }
  bool needs_whole_stack() const noexcept override { return true; }

  std::vector<std::string> write_layer(int index, const LabelImage& labels) const override {
    uLongf size = compressBound(static_cast<uLong>(labels.values().size()));
    std::string packed(size, '\0');
    if (compress2(reinterpret_cast<Bytef*>(packed.data()), &size, labels.values().data(),
                  static_cast<uLong>(labels.values().size()), 1) != Z_OK)
      throw Error(fmt::format("vdb: cannot compress layer {}", index + 1));
    packed.resize(size);
    {
      std::lock_guard lock(mutex_);
      width_ = labels.width_px();
      height_ = labels.height_px();
    }
    spool_->put(index, packed);
    return {};
  }

  // The grids hold every active voxel of the job, so they are what the writer's memory
  // grows with. A leaf spans 8 layers: the model layers fill whole 8-layer slabs, where
  // uniform leaves become tiles, and the last slab may be partly empty (padding), where no
  // leaf with voxels is uniform. Both are measured on grids built from the sampled layers:
  // each sample repeated over a whole slab, and over the first model_layers % 8 layers of a
  // slab left empty above; scaled to the job's slabs. The file is measured the same way, as
  // OpenVDB writes those grids.
  StackCost stack_cost(const StackSampling& sampling) const override {
    StackCost cost;
    cost.files = 1;
    cost.scratch_bytes = scaled_to_job(sampling, [&](int index) { return spool_->size(index); });
    if (sampling.model_samples.empty() || sampling.model_layers <= 0) return cost;
    const auto samples = static_cast<int>(sampling.model_samples.size());
    const int full_slabs = sampling.model_layers / 8, rest = sampling.model_layers % 8;
    // Memory and file bytes of `samples` slabs, slab s holding sample s in its first `filled`
    // layers.
    const auto measure = [&](int filled) {
      return on_calling_thread([&] {
        const std::vector<openvdb::FloatGrid::Ptr> grids = build_grids(
            8 * samples,
            [&](int k) { return k % 8 < filled ? sampling.model_samples[static_cast<std::size_t>(k / 8)] : -1; },
            c_.dir / "vdb");
        std::uint64_t memory = 0;
        for (const auto& g : grids) memory += static_cast<std::uint64_t>(g->memUsage());
        std::ostringstream file;
        CheckedArchive().write_to(file, openvdb::GridCPtrVec(grids.begin(), grids.end()), file_metadata());
        return std::pair<std::uint64_t, std::uint64_t>{memory, static_cast<std::uint64_t>(file.tellp())};
      });
    };
    std::pair<std::uint64_t, std::uint64_t> total{0, 0};
    const auto add = [&](const std::pair<std::uint64_t, std::uint64_t>& measured, int slabs) {
      const auto n = static_cast<std::uint64_t>(samples);
      total.first += (measured.first * static_cast<std::uint64_t>(slabs) + n - 1) / n;
      total.second += (measured.second * static_cast<std::uint64_t>(slabs) + n - 1) / n;
    };
    if (full_slabs > 0) add(measure(8), full_slabs);
    if (rest > 0) add(measure(rest), 1);
    cost.file_bytes = total.second;
    std::uint64_t largest_blob = 0;
    for (int index : sampling.model_samples) largest_blob = std::max(largest_blob, spool_->size(index));
    // The grids, one layer of labels and its compressed form.
    cost.memory_bytes =
        total.first + static_cast<std::uint64_t>(width_) * static_cast<std::uint64_t>(height_) + largest_blob;
    return cost;
  }

  std::vector<std::string> finish() const override {
    return on_calling_thread([&] { return write_file(); });
  }

 private:
  std::vector<std::string> write_file() const {
    const std::string file = "vdb/stack.vdb";
    const std::filesystem::path target = c_.dir / file;
    const std::vector<openvdb::FloatGrid::Ptr> grids = build_grids(
        c_.total_layers, [](int k) { return k; }, target);
    // OpenVDB writes to a stream of its own: the atomic file gives it the temporary name,
    // removes it on failure and, once whole, syncs it and renames it over the target.
    AtomicFile atomic(target);
    const std::filesystem::path& temp = atomic.temporary();
    {
      std::ofstream out(temp, std::ios::binary | std::ios::trunc);
      if (!out)
        throw IoError(fmt::format("{}: cannot create {}: {}", target.string(), temp.string(), errno_reason(errno)));
      try {
        errno = 0;
        CheckedArchive().write_to(out, openvdb::GridCPtrVec(grids.begin(), grids.end()), file_metadata());
        out.flush();
      } catch (const openvdb::Exception& e) {
        throw IoError(fmt::format("{}: cannot write {}: {}", target.string(), temp.string(), e.what()));
      }
      const int error_number = errno;
      if (!out)
        throw IoError(
            fmt::format("{}: cannot write {}: {}", target.string(), temp.string(), errno_reason(error_number)));
      out.close();
      if (!out)
        throw IoError(fmt::format("{}: cannot write {}: {}", target.string(), temp.string(), errno_reason(errno)));
    }
    make_uuid_deterministic(temp, target);
    atomic.commit();
    return {file};
  }

  // One grid per material over `layers` layers, layer k holding the spooled labels of job
  // layer source(k) (none when it is negative), built in increasing k; `what` names the
  // output in errors.
  std::vector<openvdb::FloatGrid::Ptr> build_grids(int layers, const std::function<int(int)>& source,
                                                   const std::filesystem::path& what) const {
    std::vector<openvdb::FloatGrid::Ptr> grids;
    // Index (i, j, k) = (column, rows from the bottom, job layer); voxel centres sit at whole
    // index coordinates, so the centre of pixel (col, row) of job layer k lands at
    // (x0 + (col + 1/2) px, y_top - (row + 1/2) py, z0 + (k + 1/2) layer), as in the slicer.
    const double y_bottom_mm = c_.y_top_mm - height_ * c_.pitch_y_mm;
    openvdb::math::Transform::Ptr xf = openvdb::math::Transform::createLinearTransform(1.0);
    xf->preScale(openvdb::Vec3d(c_.pitch_x_mm, c_.pitch_y_mm, c_.layer_mm));
    xf->postTranslate(openvdb::Vec3d(c_.x0_mm + 0.5 * c_.pitch_x_mm, y_bottom_mm + 0.5 * c_.pitch_y_mm,
                                     c_.z0_mm + 0.5 * c_.layer_mm));
    for (std::size_t j = 0; j < c_.material_names.size(); ++j) {
      openvdb::FloatGrid::Ptr g = openvdb::FloatGrid::create(0.0f);
      g->setName(c_.material_names[j]);
      g->setGridClass(openvdb::GRID_FOG_VOLUME);
      g->setTransform(xf->copy());
      g->setSaveFloatAsHalf(false);
      if (j < c_.material_rgba.size()) {
        const auto& c = c_.material_rgba[j];
        g->insertMeta("rgba", openvdb::Vec4IMetadata(openvdb::Vec4i(c[0], c[1], c[2], c[3])));
      }
      grids.push_back(std::move(g));
    }
    try {
      std::vector<openvdb::FloatGrid::Accessor> access;
      for (const auto& g : grids) access.push_back(g->getAccessor());
      std::vector<std::uint8_t> labels(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_));
      for (int k = 0; k < layers; ++k) {
        const int index = source(k);
        if (index >= 0) {
          const std::string packed = spool_->get(index);
          uLongf size = static_cast<uLongf>(labels.size());
          if (uncompress(labels.data(), &size, reinterpret_cast<const Bytef*>(packed.data()),
                         static_cast<uLong>(packed.size())) != Z_OK ||
              size != labels.size())
            throw Error(fmt::format("vdb: layer {} does not decompress to {} x {} labels", index + 1, width_, height_));
        } else {
          std::fill(labels.begin(), labels.end(), std::uint8_t{0});  // an empty layer
        }
        for (int row = 0; row < height_; ++row) {
          const std::uint8_t* line = labels.data() + static_cast<std::size_t>(row) * static_cast<std::size_t>(width_);
          const int j_index = height_ - 1 - row;
          for (int col = 0; col < width_; ++col) {
            const std::uint8_t l = line[col];
            if (l == 0 || l > access.size()) continue;
            access[l - 1u].setValueOn(openvdb::Coord(col, j_index, k), 1.0f);
          }
        }
        // A leaf spans 8 layers: once its last layer is in, uniform leaves become tiles.
        if (k % 8 == 7 || k == layers - 1)
          for (std::size_t j = 0; j < grids.size(); ++j) {
            access[j].clear();
            openvdb::tools::prune(grids[j]->tree(), 0.0f, /*threaded=*/false);
          }
      }
    } catch (const openvdb::Exception& e) {
      throw Error(fmt::format("{}: cannot build the grids: {}", what.string(), e.what()));
    }
    return grids;
  }

  OutputContext c_;
  std::unique_ptr<LayerSpool> spool_;
  mutable std::mutex mutex_;
  mutable int width_ = 0, height_ = 0;
};

}  // namespace

std::unique_ptr<LayerWriter> make_vdb_writer(const OutputContext& context) {
  return std::make_unique<VdbWriter>(context);
}

}  // namespace detail

}  // namespace trivox
