#include "output/layer_spool.h"

#include <cerrno>
#include <system_error>

#include <fmt/format.h>

#include "trivox/error.h"

namespace trivox::detail {

namespace {

// Why a stdio call failed, from errno (which a short write need not set).
std::string errno_text(int error_number) {
  return error_number != 0 ? std::error_code(error_number, std::generic_category()).message()
                           : std::string("short write");
}

}  // namespace

LayerSpool::LayerSpool(std::filesystem::path path, int layers) : path_(std::move(path)) {
  file_ = std::fopen(path_.c_str(), "w+b");
  if (file_ == nullptr) throw IoError(fmt::format("{}: cannot create the layer spool", path_.string()));
  slots_.resize(static_cast<std::size_t>(std::max(0, layers)));
}

LayerSpool::~LayerSpool() {
  if (file_ != nullptr) std::fclose(file_);
  std::error_code ec;
  std::filesystem::remove(path_, ec);
}

void LayerSpool::put(int index, std::string_view bytes) {
  std::lock_guard lock(mutex_);
  if (index < 0 || static_cast<std::size_t>(index) >= slots_.size())
    throw Error(fmt::format("{}: layer {} is outside the spool's {} layers", path_.string(), index + 1, slots_.size()));
  errno = 0;
  if (std::fseek(file_, 0, SEEK_END) != 0 || std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size())
    throw IoError(fmt::format("{}: cannot write the layer spool: {}", path_.string(), errno_text(errno)));
  slots_[static_cast<std::size_t>(index)] = {end_, bytes.size(), true};
  end_ += bytes.size();
}

bool LayerSpool::has(int index) const {
  std::lock_guard lock(mutex_);
  return index >= 0 && static_cast<std::size_t>(index) < slots_.size() &&
         slots_[static_cast<std::size_t>(index)].stored;
}

std::uint64_t LayerSpool::size(int index) const {
  std::lock_guard lock(mutex_);
  if (index < 0 || static_cast<std::size_t>(index) >= slots_.size()) return 0;
  return slots_[static_cast<std::size_t>(index)].size;
}

std::string LayerSpool::get(int index) const {
  std::lock_guard lock(mutex_);
  if (index < 0 || static_cast<std::size_t>(index) >= slots_.size() || !slots_[static_cast<std::size_t>(index)].stored)
    throw Error(fmt::format("{}: layer {} never reached the stack writer", path_.string(), index + 1));
  const Slot& s = slots_[static_cast<std::size_t>(index)];
  std::string bytes(s.size, '\0');
  if (std::fflush(file_) != 0 || std::fseek(file_, static_cast<long>(s.offset), SEEK_SET) != 0 ||
      std::fread(bytes.data(), 1, bytes.size(), file_) != bytes.size())
    throw IoError(fmt::format("{}: cannot read the layer spool", path_.string()));
  return bytes;
}

}  // namespace trivox::detail
