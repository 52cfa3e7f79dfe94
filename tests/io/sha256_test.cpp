// SHA-256 against the FIPS 180-4 example digests, and the file digest against the string one.
#include "trivox/io/detail/sha256.h"

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "trivox/error.h"

namespace trivox {
namespace {

TEST(Sha256, KnownDigests) {
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(sha256_hex(std::string(1000000, 'a')), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Sha256, IncrementalEqualsOneShotAndFileEqualsBytes) {
  std::mt19937 rng(7);
  std::string bytes(200000, '\0');
  for (char& c : bytes) c = static_cast<char>(rng() & 0xff);
  Sha256 h;
  for (std::size_t at = 0; at < bytes.size(); at += 777) h.update(std::string_view(bytes).substr(at, 777));
  const std::string whole = sha256_hex(bytes);
  EXPECT_EQ(h.hex(), whole);
  const auto path = std::filesystem::temp_directory_path() / "trivox-sha256-test.bin";
  std::ofstream(path, std::ios::binary) << bytes;
  const FileDigest d = sha256_file(path);
  EXPECT_EQ(d.bytes, bytes.size());
  EXPECT_EQ(d.sha256, whole);
  std::filesystem::remove(path);
}

TEST(Sha256, MissingFileIsAnIoErrorNamingIt) {
  try {
    sha256_file("/nonexistent/trivox-no-such-file");
    FAIL();
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("trivox-no-such-file"), std::string::npos);
  }
}

}  // namespace
}  // namespace trivox
