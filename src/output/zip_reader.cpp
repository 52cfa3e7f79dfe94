#include "output/zip_reader.h"

#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <system_error>

#include <fmt/format.h>

#include "trivox/error.h"

namespace trivox::detail {

namespace {

constexpr std::uint32_t kLocalHeader = 0x04034b50;
constexpr std::uint32_t kCentralHeader = 0x02014b50;
constexpr std::uint32_t kEndRecord = 0x06054b50;
constexpr std::uint32_t kZip64EndRecord = 0x06064b50;
constexpr std::uint32_t kZip64Locator = 0x07064b50;
constexpr std::uint64_t kMax16 = 0xFFFFu;
constexpr std::uint64_t kMax32 = 0xFFFFFFFFu;

// Little-endian fields of `s` from `at`; the caller has checked the length.
std::uint64_t field(const std::string& s, std::size_t at, int bytes) {
  std::uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(s[at + static_cast<std::size_t>(i)]);
  return v;
}

std::string errno_text(int error_number) {
  return error_number != 0 ? std::error_code(error_number, std::generic_category()).message()
                           : std::string("end of file");
}

}  // namespace

ZipReader::ZipReader(const std::filesystem::path& path) : path_(path) {
  file_ = std::fopen(path.c_str(), "rb");
  if (file_ == nullptr) throw IoError(fmt::format("{}: cannot open: {}", path.string(), errno_text(errno)));
  if (::fseeko(file_, 0, SEEK_END) != 0)
    throw IoError(fmt::format("{}: cannot read: {}", path.string(), errno_text(errno)));
  file_size_ = static_cast<std::uint64_t>(::ftello(file_));
  const std::string where = path.string();

  // The end record is the last 22 bytes, unless a comment (up to 64 KiB) follows it.
  const std::uint64_t tail_size = std::min<std::uint64_t>(file_size_, 22 + kMax16);
  if (file_size_ < 22) throw IoError(fmt::format("{}: not a zip archive: {} bytes, no end record", where, file_size_));
  const std::string tail = bytes_at(file_size_ - tail_size, tail_size, "the end record");
  std::size_t end_at = std::string::npos;
  for (std::size_t at = tail.size() - 22 + 1; at-- > 0;)
    if (field(tail, at, 4) == kEndRecord && at + 22 + field(tail, at + 20, 2) == tail.size()) {
      end_at = at;
      break;
    }
  if (end_at == std::string::npos)
    throw IoError(fmt::format("{}: not a zip archive: no end of central directory record", where));
  const std::uint64_t end_offset = file_size_ - tail_size + end_at;
  if (field(tail, end_at + 4, 2) != 0 || field(tail, end_at + 6, 2) != 0)
    throw IoError(fmt::format("{}: a zip archive split over several disks is not supported", where));
  std::uint64_t count = field(tail, end_at + 10, 2);
  std::uint64_t cd_size = field(tail, end_at + 12, 4);
  std::uint64_t cd_offset = field(tail, end_at + 16, 4);
  std::uint64_t cd_end_limit = end_offset;  // the central directory ends before the end records
  if (count == kMax16 || cd_size == kMax32 || cd_offset == kMax32) {
    // ZIP64: a locator just before the end record points to the ZIP64 end record.
    if (end_offset < 20)
      throw IoError(fmt::format("{}: the end record asks for ZIP64 records, which are missing", where));
    const std::string locator = bytes_at(end_offset - 20, 20, "the ZIP64 locator");
    if (field(locator, 0, 4) != kZip64Locator)
      throw IoError(fmt::format("{}: the end record asks for ZIP64 records, which are missing", where));
    const std::uint64_t record_offset = field(locator, 8, 8);
    if (record_offset + 56 > end_offset - 20)
      throw IoError(fmt::format("{}: the ZIP64 locator points outside the archive", where));
    const std::string record = bytes_at(record_offset, 56, "the ZIP64 end record");
    if (field(record, 0, 4) != kZip64EndRecord)
      throw IoError(fmt::format("{}: no ZIP64 end record where the locator points", where));
    count = field(record, 32, 8);
    cd_size = field(record, 40, 8);
    cd_offset = field(record, 48, 8);
    cd_end_limit = record_offset;
  }
  if (cd_offset > cd_end_limit || cd_size > cd_end_limit - cd_offset)
    throw IoError(
        fmt::format("{}: the central directory ({} bytes at {}) lies outside the archive", where, cd_size, cd_offset));
  if (count > cd_size / 46)
    throw IoError(fmt::format("{}: {} entries cannot fit a central directory of {} bytes", where, count, cd_size));

  const std::string cd = bytes_at(cd_offset, cd_size, "the central directory");
  std::size_t at = 0;
  for (std::uint64_t i = 0; i < count; ++i) {
    if (at + 46 > cd.size() || field(cd, at, 4) != kCentralHeader)
      throw IoError(fmt::format("{}: central directory entry {} is broken", where, i + 1));
    Entry e;
    const std::uint64_t flags = field(cd, at + 8, 2);
    e.method = static_cast<std::uint16_t>(field(cd, at + 10, 2));
    e.crc = static_cast<std::uint32_t>(field(cd, at + 16, 4));
    e.compressed_size = field(cd, at + 20, 4);
    e.size = field(cd, at + 24, 4);
    const std::size_t name_len = field(cd, at + 28, 2), extra_len = field(cd, at + 30, 2),
                      comment_len = field(cd, at + 32, 2);
    e.header_offset = field(cd, at + 42, 4);
    if (at + 46 + name_len + extra_len + comment_len > cd.size())
      throw IoError(fmt::format("{}: central directory entry {} runs past the directory", where, i + 1));
    e.name = cd.substr(at + 46, name_len);
    if (flags & 1u) throw IoError(fmt::format("{}: entry '{}' is encrypted", where, e.name));
    // ZIP64 extra field: the 64-bit values of the fields that hold their maximum, in order.
    const std::string extra = cd.substr(at + 46 + name_len, extra_len);
    for (std::size_t x = 0; x + 4 <= extra.size();) {
      const std::uint64_t id = field(extra, x, 2), len = field(extra, x + 2, 2);
      if (x + 4 + len > extra.size())
        throw IoError(fmt::format("{}: entry '{}' has a broken extra field", where, e.name));
      if (id == 0x0001) {
        std::size_t v = x + 4;
        const auto take = [&](std::uint64_t& value) {
          if (value != kMax32) return;
          if (v + 8 > x + 4 + len) throw IoError(fmt::format("{}: entry '{}' has a short ZIP64 field", where, e.name));
          value = field(extra, v, 8);
          v += 8;
        };
        take(e.size);
        take(e.compressed_size);
        take(e.header_offset);
      }
      x += 4 + len;
    }
    if (e.header_offset >= cd_offset || e.compressed_size > cd_offset - e.header_offset)
      throw IoError(fmt::format("{}: entry '{}' lies outside the archive's data", where, e.name));
    entries_.push_back(std::move(e));
    at += 46 + name_len + extra_len + comment_len;
  }
}

ZipReader::~ZipReader() {
  if (file_ != nullptr) std::fclose(file_);
}

std::string ZipReader::bytes_at(std::uint64_t offset, std::uint64_t count, const char* what) const {
  if (offset > file_size_ || count > file_size_ - offset)
    throw IoError(fmt::format("{}: {} lies outside the file", path_.string(), what));
  std::string bytes(count, '\0');
  errno = 0;
  if (::fseeko(file_, static_cast<off_t>(offset), SEEK_SET) != 0 || std::fread(bytes.data(), 1, count, file_) != count)
    throw IoError(fmt::format("{}: cannot read {}: {}", path_.string(), what, errno_text(errno)));
  return bytes;
}

std::string ZipReader::read(const Entry& e) const {
  const std::string where = fmt::format("{}: entry '{}'", path_.string(), e.name);
  const std::string local = bytes_at(e.header_offset, 30, "a local header");
  if (field(local, 0, 4) != kLocalHeader)
    throw IoError(fmt::format("{}: no local header at byte {}", where, e.header_offset));
  const std::uint64_t name_len = field(local, 26, 2), extra_len = field(local, 28, 2);
  if (bytes_at(e.header_offset + 30, name_len, "a local header") != e.name)
    throw IoError(fmt::format("{}: the local header names another entry", where));
  const std::uint64_t data_at = e.header_offset + 30 + name_len + extra_len;
  const std::string data = bytes_at(data_at, e.compressed_size, "an entry's data");
  std::string bytes;
  if (e.method == 0) {
    if (e.compressed_size != e.size)
      throw IoError(fmt::format("{}: stored with {} bytes but said to hold {}", where, e.compressed_size, e.size));
    bytes = data;
  } else if (e.method == 8) {
    // Deflate expands at most about 1032 to 1: a larger claim is a broken header.
    if (e.size > 1032 * e.compressed_size + 1024)
      throw IoError(fmt::format("{}: {} bytes cannot inflate to the {} claimed", where, e.compressed_size, e.size));
    bytes.assign(e.size, '\0');
    z_stream z{};
    if (inflateInit2(&z, -MAX_WBITS) != Z_OK) throw IoError(fmt::format("{}: cannot start zlib", where));
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
    z.next_out = reinterpret_cast<Bytef*>(bytes.data());
    int status = Z_OK;
    std::uint64_t in_left = data.size(), out_left = bytes.size();
    while (status == Z_OK) {
      // zlib counts in 32 bits: feed at most 1 GiB at a time.
      const auto in_chunk = static_cast<uInt>(std::min<std::uint64_t>(in_left, 1u << 30));
      const auto out_chunk = static_cast<uInt>(std::min<std::uint64_t>(out_left, 1u << 30));
      z.avail_in = in_chunk;
      z.avail_out = out_chunk;
      status = inflate(&z, Z_NO_FLUSH);
      in_left -= in_chunk - z.avail_in;
      out_left -= out_chunk - z.avail_out;
      if (status == Z_OK && in_chunk == z.avail_in && out_chunk == z.avail_out) status = Z_BUF_ERROR;  // no progress
    }
    inflateEnd(&z);
    if (status != Z_STREAM_END || out_left != 0 || in_left != 0)
      throw IoError(fmt::format("{}: the deflated data is broken or not {} bytes long", where, e.size));
  } else {
    throw IoError(
        fmt::format("{}: compression method {} is not supported (only stored and deflated)", where, e.method));
  }
  uLong crc = crc32(0L, Z_NULL, 0);
  for (std::size_t done = 0; done < bytes.size();) {
    const std::size_t n = std::min<std::size_t>(bytes.size() - done, 1u << 30);
    crc = crc32(crc, reinterpret_cast<const Bytef*>(bytes.data() + done), static_cast<uInt>(n));
    done += n;
  }
  if (static_cast<std::uint32_t>(crc) != e.crc)
    throw IoError(fmt::format("{}: CRC-32 {:08x} differs from the archive's {:08x}", where,
                              static_cast<std::uint32_t>(crc), e.crc));
  return bytes;
}

}  // namespace trivox::detail
