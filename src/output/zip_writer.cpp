#include "output/zip_writer.h"

#include <zlib.h>

#include <fmt/format.h>

#include "trivox/error.h"

namespace trivox::detail {

namespace {

// Little-endian fields, as zip stores them.
void u16(std::string& s, std::uint64_t v) {
  for (int i = 0; i < 2; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}
void u32(std::string& s, std::uint64_t v) {
  for (int i = 0; i < 4; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}
void u64(std::string& s, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}

constexpr std::uint64_t kMax32 = 0xFFFFFFFFu;
constexpr std::uint64_t kMax16 = 0xFFFFu;
constexpr std::uint16_t kDosDate = (0 << 9) | (1 << 5) | 1;  // 1980-01-01
constexpr std::uint16_t kDosTime = 0;                        // 00:00:00
constexpr std::uint16_t kMadeByUnix = (3 << 8) | 45;         // Unix, APPNOTE 4.5
constexpr std::uint32_t kUnixMode0644 = 0100644u << 16;      // regular file, rw-r--r--

}  // namespace

ZipWriter::ZipWriter(std::FILE* file, std::string what, std::uint64_t zip64_from)
    : file_(file), what_(std::move(what)), zip64_from_(std::min(zip64_from, kMax32)) {}

void ZipWriter::put(std::string_view bytes) {
  if (!bytes.empty() && std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size())
    throw IoError(fmt::format("{}: cannot write the zip archive", what_));
  at_ += bytes.size();
}

void ZipWriter::add(std::string_view name, std::string_view bytes) {
  if (name.empty() || name.size() > kMax16)
    throw Error(fmt::format("{}: zip entry name '{}' is empty or too long", what_, name));
  Entry e;
  e.name = std::string(name);
  e.size = bytes.size();
  e.offset = at_;
  uLong crc = crc32(0L, Z_NULL, 0);
  for (std::size_t done = 0; done < bytes.size();) {  // crc32 takes at most 4 GiB - 1 at once
    const std::size_t n = std::min<std::size_t>(bytes.size() - done, 1u << 30);
    crc = crc32(crc, reinterpret_cast<const Bytef*>(bytes.data() + done), static_cast<uInt>(n));
    done += n;
  }
  e.crc = static_cast<std::uint32_t>(crc);
  const bool big = e.size >= zip64_from_;
  std::string h;
  u32(h, 0x04034b50);
  u16(h, big ? 45 : 20);  // version needed: 4.5 for ZIP64, else 2.0
  u16(h, 0x0800);         // names are UTF-8
  u16(h, 0);              // STORE
  u16(h, kDosTime);
  u16(h, kDosDate);
  u32(h, e.crc);
  u32(h, big ? kMax32 : e.size);
  u32(h, big ? kMax32 : e.size);
  u16(h, e.name.size());
  u16(h, big ? 20 : 0);
  h += e.name;
  if (big) {  // the local ZIP64 field holds both sizes (APPNOTE 4.5.3)
    u16(h, 0x0001);
    u16(h, 16);
    u64(h, e.size);
    u64(h, e.size);
  }
  put(h);
  put(bytes);
  entries_.push_back(std::move(e));
}

void ZipWriter::finish() {
  const std::uint64_t cd_offset = at_;
  for (const Entry& e : entries_) {
    const bool big_size = e.size >= zip64_from_;
    const bool big_offset = e.offset >= zip64_from_;
    std::string extra;
    if (big_size || big_offset) {
      u16(extra, 0x0001);
      u16(extra, (big_size ? 16 : 0) + (big_offset ? 8 : 0));
      if (big_size) {
        u64(extra, e.size);
        u64(extra, e.size);
      }
      if (big_offset) u64(extra, e.offset);
    }
    std::string h;
    u32(h, 0x02014b50);
    u16(h, kMadeByUnix);
    u16(h, extra.empty() ? 20 : 45);
    u16(h, 0x0800);
    u16(h, 0);
    u16(h, kDosTime);
    u16(h, kDosDate);
    u32(h, e.crc);
    u32(h, big_size ? kMax32 : e.size);
    u32(h, big_size ? kMax32 : e.size);
    u16(h, e.name.size());
    u16(h, extra.size());
    u16(h, 0);  // comment
    u16(h, 0);  // disk
    u16(h, 0);  // internal attributes
    u32(h, kUnixMode0644);
    u32(h, big_offset ? kMax32 : e.offset);
    h += e.name;
    h += extra;
    put(h);
  }
  const std::uint64_t cd_size = at_ - cd_offset;
  const std::uint64_t count = entries_.size();
  const bool big = count >= std::min(zip64_from_, kMax16) || cd_size >= zip64_from_ || cd_offset >= zip64_from_;
  std::string t;
  if (big) {
    const std::uint64_t record_offset = at_;
    u32(t, 0x06064b50);  // ZIP64 end of central directory record
    u64(t, 44);          // its size after this field
    u16(t, kMadeByUnix);
    u16(t, 45);
    u32(t, 0);
    u32(t, 0);
    u64(t, count);
    u64(t, count);
    u64(t, cd_size);
    u64(t, cd_offset);
    u32(t, 0x07064b50);  // its locator
    u32(t, 0);
    u64(t, record_offset);
    u32(t, 1);
  }
  u32(t, 0x06054b50);
  u16(t, 0);
  u16(t, 0);
  u16(t, big ? kMax16 : count);
  u16(t, big ? kMax16 : count);
  u32(t, big ? kMax32 : cd_size);
  u32(t, big ? kMax32 : cd_offset);
  u16(t, 0);
  put(t);
}

}  // namespace trivox::detail
