// The construction cache (include/trivox/scene/construction_cache.h): entries of a small
// binary format, every number little-endian, every double its IEEE 754 bits.
#include "trivox/scene/construction_cache.h"

#include <dlfcn.h>
#include <link.h>

#include <bit>
#include <cstdint>
#include <limits>
#include <new>
#include <system_error>

#include <fmt/format.h>

#include "trivox/error.h"
#include "trivox/io/detail/regular_file.h"
#include "trivox/io/detail/sha256.h"
#include "trivox/limits.h"
#include "trivox/output/atomic_file.h"
#include "trivox/version.h"

namespace trivox {

namespace {

// The header: magic, format, the key (64 hex digits), the payload's size and SHA-256.
constexpr std::string_view kMagic = "TRIVOXCV";
constexpr std::uint32_t kFormat = 1;
constexpr std::size_t kKeyBytes = 64;
constexpr std::size_t kDigestHexBytes = 64;
constexpr std::size_t kHeaderBytes = kMagic.size() + 4 + kKeyBytes + 8 + kDigestHexBytes;

// Little-endian on every machine: integers byte by byte, doubles as the integers of their bits.
class Writer {
 public:
  void u8(std::uint8_t v) { out_.push_back(static_cast<char>(v)); }
  void u32(std::uint32_t v) { le(v, 4); }
  void i32(std::int32_t v) { le(static_cast<std::uint32_t>(v), 4); }
  void u64(std::uint64_t v) { le(v, 8); }
  void f64(double v) { le(std::bit_cast<std::uint64_t>(v), 8); }
  void doubles(std::span<const double> v) {
    u64(v.size());
    for (double d : v) f64(d);
  }
  void text(std::string_view s) {
    u32(static_cast<std::uint32_t>(s.size()));
    out_.append(s);
  }
  void vec3(Vec3 v) {
    f64(v.x);
    f64(v.y);
    f64(v.z);
  }
  std::string& bytes() { return out_; }

 private:
  void le(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) out_.push_back(static_cast<char>((v >> (8 * i)) & 0xffu));
  }
  std::string out_;
};

// Reads what Writer wrote; every read is checked against the bytes left (a count is checked
// before anything is allocated for it), and a failure throws Damaged.
struct Damaged {
  std::string what;
};

class Reader {
 public:
  explicit Reader(std::string_view bytes) : in_(bytes) {}
  std::uint8_t u8() { return static_cast<std::uint8_t>(le(1)); }
  std::uint32_t u32() { return static_cast<std::uint32_t>(le(4)); }
  std::int32_t i32() { return static_cast<std::int32_t>(u32()); }
  std::uint64_t u64() { return le(8); }
  double f64() { return std::bit_cast<double>(le(8)); }
  std::vector<double> doubles(std::uint64_t at_most) {
    const std::uint64_t n = u64();
    if (n > at_most || n > (in_.size() - at_) / 8) throw Damaged{fmt::format("a count of {} numbers is too large", n)};
    std::vector<double> v(static_cast<std::size_t>(n));
    for (double& d : v) d = f64();
    return v;
  }
  std::string text() {
    const std::uint32_t n = u32();
    need(n);
    std::string s(in_.substr(at_, n));
    at_ += n;
    return s;
  }
  Vec3 vec3() {
    const double x = f64(), y = f64(), z = f64();
    return {x, y, z};
  }
  bool done() const noexcept { return at_ == in_.size(); }

 private:
  std::uint64_t le(int n) {
    need(static_cast<std::size_t>(n));
    std::uint64_t v = 0;
    for (int i = 0; i < n; ++i) v |= std::uint64_t{static_cast<unsigned char>(in_[at_++])} << (8 * i);
    return v;
  }
  void need(std::size_t n) const {
    if (n > in_.size() - at_) throw Damaged{"it ends early"};
  }
  std::string_view in_;
  std::size_t at_ = 0;
};

void write_region(Writer& w, const JacobianRegion& r) {
  w.i32(r.samples);
  w.vec3(r.box.lo);
  w.vec3(r.box.hi);
}

JacobianRegion read_region(Reader& r) {
  JacobianRegion region;
  region.samples = r.i32();
  region.box.lo = r.vec3();
  region.box.hi = r.vec3();
  return region;
}

std::string payload_of(const Constructed& built) {
  Writer w;
  const TensorSpline& s = built.volume.spline();
  w.u32(static_cast<std::uint32_t>(s.param_dim()));
  w.u32(static_cast<std::uint32_t>(s.point_dim()));
  for (const KnotVector& k : s.all_knots()) {
    w.u32(static_cast<std::uint32_t>(k.order()));
    w.u8(k.is_periodic() ? 1 : 0);
    w.u32(static_cast<std::uint32_t>(k.num_ctrl()));
    w.doubles(k.knots());
  }
  w.doubles(s.points());
  w.doubles(s.weights());
  const ConstructionReport& r = built.report;
  w.text(r.constructor);
  w.u32(static_cast<std::uint32_t>(r.jacobian.classification));
  w.i32(r.jacobian.positive);
  w.i32(r.jacobian.negative);
  w.i32(r.jacobian.zero);
  w.f64(r.jacobian.min_det);
  w.f64(r.jacobian.max_det);
  write_region(w, r.minority_sign);
  write_region(w, r.zero);
  w.u8(r.exact ? 1 : 0);
  w.f64(r.approximation_error_mm);
  return std::move(w.bytes());
}

Constructed constructed_of(std::string_view payload) {
  Reader r(payload);
  // Counts are bounded by what the payload can hold, and by the limits of a volume.
  const std::uint64_t most = payload.size() / 8;
  if (r.u32() != 3 || r.u32() != 3) throw Damaged{"it does not hold a trivariate with 3D points"};
  std::vector<KnotVector> knots;
  for (int d = 0; d < 3; ++d) {
    const std::uint32_t order = r.u32();
    const std::uint8_t periodic = r.u8();
    const std::uint32_t num_ctrl = r.u32();
    if (order < 1 || order > static_cast<std::uint32_t>(kMaxOrder) || periodic > 1)
      throw Damaged{"a knot vector's order or kind is out of range"};
    if (num_ctrl > std::numeric_limits<std::int32_t>::max()) throw Damaged{"a control point count is out of range"};
    std::vector<double> k = r.doubles(most);
    knots.push_back(periodic ? KnotVector::periodic(static_cast<int>(order), static_cast<int>(num_ctrl), std::move(k))
                             : KnotVector(static_cast<int>(order), std::move(k)));
  }
  std::vector<double> points = r.doubles(most), weights = r.doubles(most);
  Constructed built{Volume(TensorSpline(std::move(knots), 3, std::move(points), std::move(weights))), {}};
  ConstructionReport& rep = built.report;
  rep.constructor = r.text();
  const std::uint32_t classification = r.u32();
  if (classification > static_cast<std::uint32_t>(JacobianClass::kFolded))
    throw Damaged{"the Jacobian's classification is out of range"};
  rep.jacobian.classification = static_cast<JacobianClass>(classification);
  rep.jacobian.positive = r.i32();
  rep.jacobian.negative = r.i32();
  rep.jacobian.zero = r.i32();
  rep.jacobian.min_det = r.f64();
  rep.jacobian.max_det = r.f64();
  rep.minority_sign = read_region(r);
  rep.zero = read_region(r);
  const std::uint8_t exact = r.u8();
  if (exact > 1) throw Damaged{"a flag is out of range"};
  rep.exact = exact == 1;
  rep.approximation_error_mm = r.f64();
  if (!r.done()) throw Damaged{"bytes follow the report"};
  return built;
}

// The largest entry a volume within kMaxControlPoints can have: its points and weights, its
// knots (at most control points + order per direction), the report, the header. A larger file
// is refused before it is read (a sparse file of 100 GB would otherwise be allocated whole).
std::uint64_t max_entry_bytes() {
  constexpr std::uint64_t points = static_cast<std::uint64_t>(kMaxControlPoints);
  constexpr std::uint64_t numbers = 4 * points + 3 * (points + static_cast<std::uint64_t>(kMaxOrder) + 1);
  return kHeaderBytes + 8 * numbers + (1 << 16);
}

bool is_key(std::string_view key) {
  if (key.size() != kKeyBytes) return false;
  for (char c : key)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  return true;
}

// The file that holds this code: a shared library by its path, the executable by
// /proc/self/exe (its own name may be relative to a folder left since, or only a name found
// on PATH).
std::optional<std::filesystem::path> this_program_file() {
  static const char marker = 0;
  Dl_info info{};
  link_map* map = nullptr;
  if (dladdr1(&marker, &info, reinterpret_cast<void**>(&map), RTLD_DL_LINKMAP) == 0 || map == nullptr)
    return std::nullopt;
  if (map->l_name != nullptr && map->l_name[0] != '\0') return std::filesystem::path(map->l_name);
  return std::filesystem::path("/proc/self/exe");
}

}  // namespace

std::string encode_construction_entry(const std::string& key, const Constructed& built) {
  if (!is_key(key)) throw Error(fmt::format("a construction cache key is 64 lowercase hex digits, not \"{}\"", key));
  const std::string payload = payload_of(built);
  Writer w;
  for (char c : kMagic) w.u8(static_cast<std::uint8_t>(c));
  w.u32(kFormat);
  for (char c : key) w.u8(static_cast<std::uint8_t>(c));
  w.u64(payload.size());
  for (char c : sha256_hex(payload)) w.u8(static_cast<std::uint8_t>(c));
  w.bytes() += payload;
  return std::move(w.bytes());
}

std::optional<Constructed> decode_construction_entry(std::string_view bytes, const std::string& key,
                                                     std::string* problem) {
  auto fail = [&](std::string why) -> std::optional<Constructed> {
    if (problem) *problem = std::move(why);
    return std::nullopt;
  };
  if (bytes.size() < kHeaderBytes) return fail(fmt::format("it has {} bytes, less than a header", bytes.size()));
  if (bytes.substr(0, kMagic.size()) != kMagic) return fail("it is not a construction cache entry");
  std::size_t at = kMagic.size();
  const std::uint32_t format = Reader(bytes.substr(at, 4)).u32();
  at += 4;
  if (format != kFormat) return fail(fmt::format("it is of format {}, not {}", format, kFormat));
  if (bytes.substr(at, kKeyBytes) != key) return fail("it is the entry of another key");
  at += kKeyBytes;
  const std::uint64_t size = Reader(bytes.substr(at, 8)).u64();
  at += 8;
  const std::string_view digest = bytes.substr(at, kDigestHexBytes);
  at += kDigestHexBytes;
  const std::string_view payload = bytes.substr(at);
  if (payload.size() != size)
    return fail(fmt::format("it holds {} bytes after its header, the header says {}", payload.size(), size));
  if (sha256_hex(payload) != digest) return fail("its SHA-256 differs from the one its header records");
  try {
    Constructed built = constructed_of(payload);
    // What was read must write back as the same bytes: nothing was lost on the way.
    if (payload_of(built) != payload) return fail("it does not read back as it was written");
    return built;
  } catch (const Damaged& d) {
    return fail(d.what);
  } catch (const Error& e) {
    return fail(fmt::format("its volume is not valid: {}", e.what()));
  }
}

std::optional<std::string> this_program_sha256() {
  const auto file = this_program_file();
  if (!file) return std::nullopt;
  try {
    return sha256_file(*file).sha256;
  } catch (const Error&) {
    return std::nullopt;
  }
}

ConstructionCache::ConstructionCache(std::filesystem::path dir) : dir_(std::move(dir)) {}

ConstructionCache::ConstructionCache(std::filesystem::path dir, std::string program_identity)
    : dir_(std::move(dir)), identity_(std::move(program_identity)) {}

const std::string& ConstructionCache::program_identity() {
  if (!identity_) {
    const auto digest = this_program_sha256();
    identity_ = digest ? fmt::format("trivox {} program sha256 {}", version(), *digest) : std::string();
    if (!digest)
      warnings_.push_back(fmt::format(
          "construction cache: the running program cannot be read to identify it; {} is not used", dir_.string()));
  }
  return *identity_;
}

std::filesystem::path ConstructionCache::entry_path(const std::string& key) const { return dir_ / (key + ".volume"); }

std::optional<Constructed> ConstructionCache::load(const std::string& key, const std::atomic<bool>* stop) {
  if (program_identity().empty()) return std::nullopt;
  const std::filesystem::path path = entry_path(key);
  if (not_a_regular_file(path) == "no file") return std::nullopt;
  // Whatever is wrong with an entry (not a regular file, too large, damaged, a volume that
  // cannot be held) is a warning and a rebuild, never a failed scene: the folder is shared and
  // copied, so anything may stand there.
  std::string problem;
  try {
    const std::string bytes = read_regular_file(path, max_entry_bytes(), stop);
    if (auto built = decode_construction_entry(bytes, key, &problem)) {
      ++hits_;
      return built;
    }
  } catch (const CancelledError&) {
    throw;  // a stop is no fault of the entry
  } catch (const IoError& e) {
    warnings_.push_back(
        fmt::format("construction cache: cannot use {}: {}; the volume is built again", path.string(), e.what()));
    return std::nullopt;
  } catch (const std::bad_alloc&) {
    problem = "its volume does not fit in memory";
  } catch (const Error& e) {
    problem = e.what();
  }
  warnings_.push_back(
      fmt::format("construction cache: {} is damaged ({}); the volume is built again and the entry "
                  "replaced",
                  path.string(), problem));
  return std::nullopt;
}

void ConstructionCache::reject(const std::string& key, const std::string& why) {
  --hits_;
  warnings_.push_back(
      fmt::format("construction cache: {} does not agree with the inputs that build it ({}); the volume is built "
                  "again and the entry replaced",
                  entry_path(key).string(), why));
}

void ConstructionCache::store(const std::string& key, const Constructed& built) {
  if (program_identity().empty()) return;
  const std::filesystem::path path = entry_path(key);
  try {
    const std::string bytes = encode_construction_entry(key, built);
    std::filesystem::create_directories(dir_);
    write_file_atomic(path, bytes);
    ++stored_;
  } catch (const std::exception& e) {
    warnings_.push_back(fmt::format("construction cache: cannot store {} ({}); the next run builds the volume again",
                                    path.string(), e.what()));
  }
}

}  // namespace trivox
