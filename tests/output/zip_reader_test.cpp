// The zip reader that `verify` opens GrabCAD packages with: it reads back what the zip writer
// writes (classic and ZIP64 records), and what an independent writer (Python's zipfile,
// deflated and stored entries) writes; it reports a changed byte by the entry's CRC-32 and a
// cut archive by its missing records, naming the file and the entry.
#include "output/zip_reader.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "job/job_fixtures.h"
#include "output/zip_writer.h"
#include "trivox/error.h"
#include "trivox/output/atomic_file.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

using Files = std::vector<std::pair<std::string, std::string>>;

Files sample_files() {
  std::string noise;
  for (int i = 0; i < 5000; ++i) noise += static_cast<char>((i * 7919) % 251);
  return {{"a.png", std::string("\x89PNG\r\n\x1a\n", 8) + std::string(1000, '\x07')},
          {"dir/empty.txt", ""},
          {"noise.bin", noise},
          {"b.xml", "<x/>\n"}};
}

fs::path scratch(const std::string& name) {
  return fs::temp_directory_path() / fmt::format("trivox-zip-reader-{}-{}", ::getpid(), name);
}

void write_with_zip_writer(const fs::path& path, const Files& files, std::uint64_t zip64_from) {
  AtomicFile out(path);
  detail::ZipWriter zip(out.file(), path.string(), zip64_from);
  for (const auto& [name, bytes] : files) zip.add(name, bytes);
  zip.finish();
  out.commit();
}

void expect_reads_back(const fs::path& path, const Files& files) {
  const detail::ZipReader zip(path);
  ASSERT_EQ(zip.entries().size(), files.size());
  for (std::size_t i = 0; i < files.size(); ++i) {
    EXPECT_EQ(zip.entries()[i].name, files[i].first);
    EXPECT_EQ(zip.read(zip.entries()[i]), files[i].second) << files[i].first;
  }
}

TEST(ZipReader, ReadsClassicAndZip64ArchivesOfTheZipWriter) {
  for (const std::uint64_t zip64_from : {std::uint64_t{0xFFFFFFFFu}, std::uint64_t{0}}) {
    SCOPED_TRACE(zip64_from);
    const fs::path path = scratch(fmt::format("own-{}.zip", zip64_from));
    write_with_zip_writer(path, sample_files(), zip64_from);
    expect_reads_back(path, sample_files());
    fs::remove(path);
  }
}

TEST(ZipReader, ReadsDeflatedAndStoredEntriesOfAnotherWriter) {
  const fs::path dir = scratch("python");
  fs::create_directories(dir);
  const Files files = sample_files();
  for (std::size_t i = 0; i < files.size(); ++i)
    std::ofstream(dir / fmt::format("a.zip.in{}", i), std::ios::binary) << files[i].second;
  // Every other entry deflated; a comment after the end record, as some tools write.
  std::ofstream(dir / "make.py") << "import sys, zipfile\n"
                                    "names = sys.argv[2:]\n"
                                    "with zipfile.ZipFile(sys.argv[1], 'w') as z:\n"
                                    "    for i, name in enumerate(names):\n"
                                    "        method = zipfile.ZIP_DEFLATED if i % 2 == 0 else zipfile.ZIP_STORED\n"
                                    "        z.write(sys.argv[1] + '.in%d' % i, name, compress_type=method)\n"
                                    "    z.comment = b'made for the test'\n";
  std::string command = fmt::format("cd '{}' && python3 make.py a.zip", dir.string());
  for (const auto& f : files) command += " '" + f.first + "'";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  const detail::ZipReader zip(dir / "a.zip");
  ASSERT_EQ(zip.entries().size(), files.size());
  EXPECT_EQ(zip.entries()[2].method, 8);  // the noise, deflated
  EXPECT_EQ(zip.entries()[1].method, 0);
  expect_reads_back(dir / "a.zip", files);
  fs::remove_all(dir);
}

TEST(ZipReader, ReportsAChangedByteAndACutArchive) {
  const fs::path path = scratch("damaged.zip");
  write_with_zip_writer(path, sample_files(), 0xFFFFFFFFu);
  std::string bytes = test::read_bytes(path);
  // A byte of noise.bin's data: after the entries before it and its own header and name.
  const std::size_t at = bytes.find("noise.bin") + std::string("noise.bin").size() + 10;
  bytes[at] = static_cast<char>(bytes[at] ^ 0x20);
  std::ofstream(path, std::ios::binary) << bytes;
  {
    const detail::ZipReader zip(path);
    EXPECT_EQ(zip.read(zip.entries()[0]), sample_files()[0].second);  // the others still read
    try {
      (void)zip.read(zip.entries()[2]);
      FAIL() << "a changed byte was not found";
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find("noise.bin"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("CRC-32"), std::string::npos) << e.what();
    }
  }
  for (const std::size_t keep : {bytes.size() - 1, bytes.size() / 2, std::size_t{10}, std::size_t{0}}) {
    std::ofstream(path, std::ios::binary) << bytes.substr(0, keep);
    try {
      const detail::ZipReader zip(path);
      for (const auto& e : zip.entries()) (void)zip.read(e);
      FAIL() << "an archive cut to " << keep << " bytes was read";
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
    }
  }
  fs::remove(path);
}

}  // namespace
}  // namespace trivox
