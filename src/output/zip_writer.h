// A minimal, deterministic zip archive writer for packaged outputs (".gcvf"): entries are
// STOREd (their content, PNGs, is already deflated), in the order added, all dated
// 1980-01-01 00:00 (the earliest DOS date) with Unix mode 0644, no extra data unless ZIP64
// needs it. The archive is the same bytes for the same entries, whatever the clock or the
// machine. ZIP64 records (APPNOTE 4.5.3, 4.3.14-4.3.15) are written where a size, an offset
// or the entry count outgrows the classic fields, so archives over 4 GiB stay readable.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

namespace trivox::detail {

class ZipWriter {
 public:
  // Writes to `file` (positioned at its start, owned by the caller); `what` names the
  // archive in errors. Sizes, offsets and counts at or above `zip64_from` use ZIP64 fields:
  // the default is the classic limit; tests lower it to exercise the ZIP64 path.
  ZipWriter(std::FILE* file, std::string what, std::uint64_t zip64_from = 0xFFFFFFFFu);

  // Appends one entry. Names use '/' separators and must be unique (not checked).
  void add(std::string_view name, std::string_view bytes);
  // Writes the central directory and the end records. Call once, after the last add().
  void finish();

 private:
  struct Entry {
    std::string name;
    std::uint32_t crc = 0;
    std::uint64_t size = 0, offset = 0;
  };
  void put(std::string_view bytes);
  std::FILE* file_;
  std::string what_;
  std::uint64_t zip64_from_;
  std::uint64_t at_ = 0;
  std::vector<Entry> entries_;
};

}  // namespace trivox::detail
