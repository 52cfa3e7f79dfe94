// Reading zip archives such as the ".gcvf" packages trivox writes (zip_writer.h), to verify
// them: the central directory (with its ZIP64 records), each entry's local header against
// it, and each entry's bytes against its CRC-32. Entries may be STOREd or deflated. Every
// inconsistency is an IoError naming the archive and, where there is one, the entry.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace trivox::detail {

class ZipReader {
 public:
  struct Entry {
    std::string name;
    std::uint16_t method = 0;  // 0 stored, 8 deflated
    std::uint32_t crc = 0;
    std::uint64_t compressed_size = 0, size = 0;
    std::uint64_t header_offset = 0;  // of the local header
  };

  // Opens `path` and reads its central directory. Throws IoError naming the file when it
  // cannot be read or is not a zip archive.
  explicit ZipReader(const std::filesystem::path& path);
  ~ZipReader();
  ZipReader(const ZipReader&) = delete;
  ZipReader& operator=(const ZipReader&) = delete;

  // The entries in central-directory order.
  const std::vector<Entry>& entries() const noexcept { return entries_; }
  // The bytes of `entry`, inflated when deflated, checked against its size and CRC-32.
  std::string read(const Entry& entry) const;

 private:
  std::string bytes_at(std::uint64_t offset, std::uint64_t count, const char* what) const;

  std::filesystem::path path_;
  std::FILE* file_ = nullptr;
  std::uint64_t file_size_ = 0;
  std::vector<Entry> entries_;
};

}  // namespace trivox::detail
