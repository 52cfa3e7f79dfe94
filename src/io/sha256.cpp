#include "trivox/io/detail/sha256.h"

#include <openssl/evp.h>

#include <cerrno>
#include <cstdio>
#include <system_error>
#include <vector>

#include <fmt/format.h>

#include "trivox/cancel.h"
#include "trivox/error.h"

namespace trivox {

struct Sha256::State {
  EVP_MD_CTX* ctx = nullptr;
  bool finished = false;
};

Sha256::Sha256() : state_(std::make_unique<State>()) {
  state_->ctx = EVP_MD_CTX_new();
  if (state_->ctx == nullptr || EVP_DigestInit_ex(state_->ctx, EVP_sha256(), nullptr) != 1) {
    EVP_MD_CTX_free(state_->ctx);
    throw Error("SHA-256: cannot create an OpenSSL digest context");
  }
}

Sha256::~Sha256() { EVP_MD_CTX_free(state_->ctx); }

void Sha256::update(std::span<const std::uint8_t> bytes) {
  if (state_->finished) throw Error("SHA-256: update after hex()");
  if (!bytes.empty() && EVP_DigestUpdate(state_->ctx, bytes.data(), bytes.size()) != 1)
    throw Error("SHA-256: OpenSSL digest update failed");
}

void Sha256::update(std::string_view bytes) {
  update(std::span(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()));
}

std::string Sha256::hex() {
  if (state_->finished) throw Error("SHA-256: hex() called twice");
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int size = 0;
  if (EVP_DigestFinal_ex(state_->ctx, digest, &size) != 1) throw Error("SHA-256: OpenSSL digest failed");
  state_->finished = true;
  std::string out;
  out.reserve(2 * size);
  for (unsigned int i = 0; i < size; ++i) out += fmt::format("{:02x}", digest[i]);
  return out;
}

std::string sha256_hex(std::string_view bytes) {
  Sha256 h;
  h.update(bytes);
  return h.hex();
}

FileDigest sha256_file(const std::filesystem::path& path, const std::atomic<bool>* stop) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr)
    throw IoError(
        fmt::format("{}: cannot open: {}", path.string(), std::error_code(errno, std::generic_category()).message()));
  Sha256 h;
  FileDigest d;
  std::vector<std::uint8_t> block(1 << 16);
  for (;;) {
    if (stop != nullptr && stop->load(std::memory_order_relaxed)) {
      std::fclose(file);
      throw_if_stopped(stop, "hashing an input file");
    }
    const std::size_t n = std::fread(block.data(), 1, block.size(), file);
    if (n > 0) {
      h.update(std::span(block.data(), n));
      d.bytes += n;
    }
    if (n < block.size()) break;
  }
  const bool failed = std::ferror(file) != 0;
  std::fclose(file);
  if (failed) throw IoError(fmt::format("{}: cannot read", path.string()));
  d.sha256 = h.hex();
  return d;
}

}  // namespace trivox
