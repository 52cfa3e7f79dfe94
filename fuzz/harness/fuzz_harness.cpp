#include "harness/fuzz_harness.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <fstream>
#include <iterator>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "harness/pipeline_job.h"
#include "trivox/error.h"
#include "trivox/io/model.h"
#include "trivox/job/job.h"
#include "trivox/job/job_estimate.h"
#include "trivox/job/job_folder.h"
#include "trivox/material/expression_material.h"
#include "trivox/scene/construction_cache.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/slicer.h"

// The heap's size and its peak, counted by the sanitizer allocator's hooks where there is
// one (AddressSanitizer builds: the fuzzers and the sanitizer test suite).
#if defined(__SANITIZE_ADDRESS__)
#define TRIVOX_FUZZ_HEAP 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define TRIVOX_FUZZ_HEAP 1
#endif
#endif

#ifdef TRIVOX_FUZZ_HEAP
// The sanitizer runtime's allocator hooks (declared here: GCC ships the runtime that exports
// them but not clang's sanitizer/allocator_interface.h).
extern "C" {
std::size_t __sanitizer_get_allocated_size(const volatile void* p);
int __sanitizer_install_malloc_and_free_hooks(void (*malloc_hook)(const volatile void*, std::size_t),
                                              void (*free_hook)(const volatile void*));
}

namespace {
std::atomic<long long> g_heap_bytes{0}, g_heap_peak{0};

void on_malloc(const volatile void*, std::size_t size) {
  const long long now = g_heap_bytes.fetch_add(static_cast<long long>(size)) + static_cast<long long>(size);
  long long peak = g_heap_peak.load();
  while (now > peak && !g_heap_peak.compare_exchange_weak(peak, now)) {
  }
}
void on_free(const volatile void* p) {
  g_heap_bytes.fetch_sub(static_cast<long long>(__sanitizer_get_allocated_size(p)));
}
const bool g_hooks_installed = __sanitizer_install_malloc_and_free_hooks(on_malloc, on_free) != 0;
}  // namespace
#endif

namespace trivox::fuzz {

namespace {

std::string_view as_text(std::span<const std::uint8_t> data) {
  return {reinterpret_cast<const char*>(data.data()), data.size()};
}

// A model the reader accepted must write as .itd and read back with the same patches: the
// writer promises a lossless round trip, so a failure here is the library's bug, not the
// input's.
void check_round_trip(const Model& model) {
  // IRIT stores points of 1 to 9 coordinates (E1..E9, P1..P9); G+Smo's geoDim has no such
  // limit, so for wider points the writer's documented refusal is the expected outcome.
  constexpr int kMaxItdPointDim = 9;
  bool fits_itd = true;
  for (const Patch& p : model.patches) fits_itd = fits_itd && p.spline.point_dim() <= kMaxItdPointDim;
  std::ostringstream out;
  try {
    write_itd(out, model);
  } catch (const ModelError& e) {
    if (!fits_itd) return;
    throw HarnessViolation(std::string("write_itd refused a model IRIT can hold: ") + e.what());
  }
  if (!fits_itd) throw HarnessViolation("write_itd wrote points wider than IRIT's nine coordinates");
  Model back;
  try {
    back = read_itd(out.str(), "round-trip.itd");
  } catch (const Error& e) {
    throw HarnessViolation(std::string("an accepted model does not read back from write_itd: ") + e.what());
  }
  if (back.patches.size() != model.patches.size())
    throw HarnessViolation("an accepted model reads back from write_itd with another patch count");
}

void run_model_reader(Model (*reader)(std::string_view, const std::string&, const std::atomic<bool>*),
                      std::span<const std::uint8_t> data, const std::string& source) {
  Model model;
  try {
    model = reader(as_text(data), source, nullptr);
  } catch (const Error&) {
    return;  // rejected with a documented error: the expected outcome for most inputs
  }
  check_round_trip(model);
}

// Corners and centre of the cell's domain, with positions from the cell's own volume.
void evaluate_materials(const Scene& scene) {
  std::vector<float> fractions(static_cast<std::size_t>(scene.num_materials()));
  for (const Cell& cell : scene.cells) {
    const ParamBox d = cell.volume.domain();
    std::vector<Vec3> samples{d.center()};
    for (int corner = 0; corner < 8; ++corner)
      samples.push_back({corner & 1 ? d.hi.x : d.lo.x, corner & 2 ? d.hi.y : d.lo.y, corner & 4 ? d.hi.z : d.lo.z});
    for (const Vec3& uvw : samples) cell.material->evaluate(uvw, cell.volume.evaluate(uvw), fractions);
  }
}

void write_file(const std::filesystem::path& path, std::string_view text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

// write_g2 promises that a model read from .g2 reads back identical.
void check_g2_round_trip(const Model& model) {
  std::ostringstream out;
  write_g2(out, model);
  Model back;
  try {
    back = read_g2(out.str(), "round-trip.g2");
  } catch (const Error& e) {
    throw HarnessViolation(std::string("an accepted .g2 model does not read back from write_g2: ") + e.what());
  }
  if (back.patches.size() != model.patches.size())
    throw HarnessViolation("an accepted .g2 model reads back from write_g2 with another patch count");
  for (std::size_t i = 0; i < model.patches.size(); ++i) {
    const TensorSpline& s = model.patches[i].spline;
    const TensorSpline& t = back.patches[i].spline;
    const bool same = s.all_knots() == t.all_knots() && s.point_dim() == t.point_dim() &&
                      std::equal(s.points().begin(), s.points().end(), t.points().begin(), t.points().end()) &&
                      std::equal(s.weights().begin(), s.weights().end(), t.weights().begin(), t.weights().end()) &&
                      model.patches[i].header_aux == back.patches[i].header_aux;
    if (!same) throw HarnessViolation("an accepted .g2 model reads back from write_g2 with other values");
  }
}

}  // namespace

void run_itd(std::span<const std::uint8_t> data) { run_model_reader(&read_itd, data, "fuzz.itd"); }

void run_g2(std::span<const std::uint8_t> data) {
  Model model;
  try {
    model = read_g2(as_text(data), "fuzz.g2");
  } catch (const Error&) {
    return;
  }
  check_g2_round_trip(model);
  check_round_trip(model);
}

void run_cache_entry(std::span<const std::uint8_t> data, const std::filesystem::path& work_dir) {
  const std::string_view bytes = as_text(data);
  // The key the header names (after the magic and the format), so that the fuzzer gets past
  // the header to the payload; any other bytes are tried under a fixed key.
  std::string key(64, '0');
  if (bytes.size() >= 76 && std::all_of(bytes.begin() + 12, bytes.begin() + 76,
                                        [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); }))
    key = std::string(bytes.substr(12, 64));
  std::string problem;
  const std::optional<Constructed> decoded = decode_construction_entry(bytes, key, &problem);
  if (decoded && encode_construction_entry(key, *decoded) != bytes)
    throw HarnessViolation("an accepted cache entry does not encode back to its bytes");
  const std::filesystem::path dir = work_dir / "cache";
  std::filesystem::create_directories(dir);
  ConstructionCache cache(dir, "fuzz");
  {
    std::ofstream out(cache.entry_path(key), std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  const std::optional<Constructed> loaded = cache.load(key);
  if (loaded.has_value() != decoded.has_value())
    throw HarnessViolation("the cache and the entry decoder disagree on an entry: " + problem);
  if (loaded && encode_construction_entry(key, *loaded) != bytes)
    throw HarnessViolation("a loaded cache entry is not the volume its bytes hold");
}

void run_gismo_xml(std::span<const std::uint8_t> data) { run_model_reader(&read_gismo_xml, data, "fuzz.xml"); }

void run_scene(std::span<const std::uint8_t> data, const std::filesystem::path& scene_dir) {
  try {
    const Scene scene = parse_scene(as_text(data), scene_dir / "scenes" / "scene.json");
    evaluate_materials(scene);
  } catch (const Error&) {
  }
}

void run_expression(std::span<const std::uint8_t> data) {
  ExpressionParams params;
  std::string_view text = as_text(data);
  while (params.expressions.size() < 8) {
    const auto end = text.find('\n');
    params.expressions.emplace_back(text.substr(0, end));
    if (end == std::string_view::npos) break;
    text.remove_prefix(end + 1);
  }
  params.constants = {{"k", 2.5}, {"period_mm", 10.0}};
  const ParamBox domain{{0.0, -1.0, 2.0}, {3.0, 1.0, 2.5}};
  try {
    const ExpressionMaterial material(std::move(params), domain);
    constexpr std::size_t kSamples = 5;
    std::array<Vec3, kSamples> uvw{}, xyz{};
    for (std::size_t s = 0; s < kSamples; ++s) {
      const double t = static_cast<double>(s) / (kSamples - 1);
      uvw[s] = domain.lo + t * domain.size();
      xyz[s] = {10.0 * t, -5.0 + t, 100.0 * t * t};
    }
    std::vector<float> fractions(kSamples * static_cast<std::size_t>(material.num_materials()));
    material.evaluate_row(uvw, xyz, fractions);
  } catch (const Error&) {
  }
}

namespace {

// The memory the fuzzed jobs may use beyond what the process holds when the input starts
// (the fuzzer's own corpus, a sanitizer's shadow), as `trivox slice --memory-limit` gives it.
constexpr std::uint64_t kPipelineMemoryLimit = 256'000'000;
// Jobs of more pixels are not sliced: the fuzzer's 10 s hold for jobs up to 1e6 pixels of a
// cubic volume (a pixel of a higher order volume costs more evaluations: the limit shrinks
// with the orders' product). The set-up's outline meshes cost about two evaluations per
// pixel of the whole model's faces, however few layers are sliced, so a model whose control
// points' box has more face pixels than that is not even prepared.
constexpr double kPipelinePixels = 1e6;

// Seconds after which a pipeline input's job is stopped, as Ctrl-C would stop it. The pixel
// budget above bounds the typical cost of a job, not the worst: a global solve's boxes
// depend on the volume's shape and weights (a rational cell of order 12 with weights from
// 1e-6 to 1e6, traced without seeds, costs several milliseconds a pixel under the
// sanitizers). The stop keeps every input within the fuzzer's 10 s and tests the stop
// itself: the slicer checks it before each global solve, and a stopped job must leave a
// folder that verifies as interrupted.
constexpr double kPipelineStopSeconds = 4.0;
// A stopped job must end within this long of its stop flag (the flag is read before each
// global solve, every 64 of its boxes and every row of an outline mesh's samples).
constexpr double kPipelineStopGraceSeconds = 4.0;

// Raises its flag once the given seconds have passed, unless destroyed first.
class Watchdog {
 public:
  explicit Watchdog(double seconds)
      : thread_([this, seconds] {
          std::unique_lock lock(mutex_);
          if (!wake_.wait_for(lock, std::chrono::duration<double>(seconds), [this] { return done_; }))
            flag_.store(true);
        }) {}
  ~Watchdog() {
    {
      std::lock_guard lock(mutex_);
      done_ = true;
    }
    wake_.notify_one();
    thread_.join();
  }
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;
  const std::atomic<bool>* flag() const { return &flag_; }
  bool raised() const { return flag_.load(); }

 private:
  std::mutex mutex_;
  std::condition_variable wake_;
  bool done_ = false;
  std::atomic<bool> flag_{false};
  std::thread thread_;  // last: it starts once the members it reads exist
};

// Pixels of the six faces of `box` at the printer's resolution (the outline meshes' budget,
// slicer.cpp).
double face_pixels(const Box3& box, const PrinterProfile& printer) {
  const Vec3 size = box.size();
  const double w = size.x / printer.pitch_x_mm() + 1, h = size.y / printer.pitch_y_mm() + 1,
               l = size.z / printer.layer_thickness_mm + 1;
  return 2 * (w * h + h * l + l * w);
}

std::uint64_t resident_bytes_now() {
  std::ifstream statm("/proc/self/statm");
  std::uint64_t size = 0, resident = 0;
  if (!(statm >> size >> resident)) return 0;
  return resident * static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE));
}

// A job its stop flag ended: the manifest says so, and every file it lists is whole (the
// layers done before the stop, none half-written).
void check_stopped_job(const std::filesystem::path& dir) {
  VerifyReport report;
  try {
    report = verify_output(dir);
  } catch (const Error& e) {
    throw HarnessViolation(std::string("a stopped job's folder cannot be verified: ") + e.what());
  }
  if (report.manifest.status != JobStatus::kInterrupted)
    throw HarnessViolation("a stopped job's manifest says " + std::string(to_string(report.manifest.status)));
  // verify_output's first problem is the status; any other is a damaged or missing file.
  if (report.problems.size() != 1) throw HarnessViolation("a stopped job does not verify: " + report.problems.back());
}

// The scene read through a construction cache whose entries are damaged between two reads: the
// second read must take none of them and give the cells a read without the cache gives, bit
// for bit (an entry must never change the geometry).
Scene read_through_damaged_cache(const PipelineJob& job, const std::filesystem::path& dir,
                                 const std::atomic<bool>* stop) {
  namespace fs = std::filesystem;
  const fs::path source = dir / "scene.json", cache_dir = dir / "cache";
  fs::remove_all(cache_dir);
  const Scene plain = parse_scene(job.scene_json, source, stop);
  ConstructionCache first(cache_dir, "fuzz");
  parse_scene(job.scene_json, source, SceneReadOptions{stop, &first});
  if (fs::is_directory(cache_dir))
    for (const auto& e : fs::directory_iterator(cache_dir)) damage_cache_entry(e.path(), job.cache_damage);
  ConstructionCache second(cache_dir, "fuzz");
  Scene again = parse_scene(job.scene_json, source, SceneReadOptions{stop, &second});
  if (second.hits() != 0) throw HarnessViolation("a damaged construction cache entry was used");
  for (std::size_t i = 0; i < plain.cells.size(); ++i) {
    const auto a = plain.cells[i].volume.spline().points(), b = again.cells[i].volume.spline().points();
    if (!std::equal(a.begin(), a.end(), b.begin(), b.end()))
      throw HarnessViolation("a damaged construction cache entry changed a cell's geometry");
  }
  return again;
}

}  // namespace

void damage_cache_entry(const std::filesystem::path& entry, int damage) {
  namespace fs = std::filesystem;
  if (damage == kTruncated) {
    fs::resize_file(entry, fs::file_size(entry) / 2);
    return;
  }
  if (damage == kReplacedGeometry) {
    const std::string key = entry.stem().string();
    std::ifstream in(entry, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::optional<Constructed> built = decode_construction_entry(bytes, key, nullptr);
    if (!built) throw HarnessViolation("the cache stored an entry it cannot read back");
    const TensorSpline& s = built->volume.spline();
    std::vector<double> points(s.points().begin(), s.points().end());
    for (std::size_t i = 2; i < points.size(); i += 3) points[i] = 3 * points[i] + 1;
    const Constructed tall{Volume(TensorSpline(s.all_knots(), 3, std::move(points),
                                               std::vector<double>(s.weights().begin(), s.weights().end()))),
                           built->report};
    write_file(entry, encode_construction_entry(key, tall));
    return;
  }
  fs::remove(entry);
  if (damage == kDirectory) fs::create_directory(entry);
  if (damage == kFifo && ::mkfifo(entry.c_str(), 0600) != 0) throw std::runtime_error("cannot make a FIFO");
  if (damage == kDeviceLink) fs::create_symlink("/dev/zero", entry);
}

PipelineOutcome run_pipeline(std::span<const std::uint8_t> data, const std::filesystem::path& work_dir) {
  const auto start = std::chrono::steady_clock::now();
  PipelineOutcome outcome;
  const auto finish = [&](PipelineOutcome::Kind kind) {
    outcome.kind = kind;
    outcome.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (kind == PipelineOutcome::Kind::kStopped && outcome.seconds > kPipelineStopSeconds + kPipelineStopGraceSeconds)
      throw HarnessViolation("a job ended " + std::to_string(outcome.seconds - kPipelineStopSeconds) +
                             " s after its stop flag was raised");
    return outcome;
  };
  const PipelineJob job = generate_pipeline_job(data);
  const Watchdog watchdog(kPipelineStopSeconds);
  try {
    if (!job.files.empty()) std::filesystem::create_directories(work_dir);
    for (const auto& [name, bytes] : job.files) write_file(work_dir / name, bytes);
    const Scene scene = job.cache_damage == kNoCache ? parse_scene(job.scene_json, work_dir / "scene.json")
                                                     : read_through_damaged_cache(job, work_dir, watchdog.flag());
    SliceParams sp;
    sp.tracing = parse_tracing_strategy(job.tracing).value_or(TracingStrategy::kFlood);
    sp.newton.residual_tolerance_model = job.residual_tolerance_mm;
    sp.outline_tolerance_mm = job.outline_tolerance_mm;
    const std::uint64_t memory_limit = resident_bytes_now() + kPipelineMemoryLimit;
    sp.memory_limit_bytes = memory_limit;
    sp.stop = watchdog.flag();
    double order_product = 1, model_face_pixels = 0;
    for (const Cell& c : scene.cells) {
      const auto o = c.volume.orders();
      order_product = std::max(order_product, static_cast<double>(o[0]) * o[1] * o[2]);
      model_face_pixels += face_pixels(c.volume.bounds(), scene.printer);
    }
    // (NaN, from a box beyond the doubles, counts as too large.)
    if (!(model_face_pixels * order_product / 64.0 <= kPipelinePixels)) return finish(PipelineOutcome::Kind::kTooLarge);
    const Slicer slicer(scene, sp);
    const SliceLayout& L = slicer.layout();
    JobParams jp;
    jp.output_dir = work_dir / "job";
    std::filesystem::remove_all(jp.output_dir);
    jp.formats = job.formats;
    jp.first_layer = std::min(L.num_layers - 1, static_cast<int>(job.first_layer_fraction * L.num_layers));
    jp.last_layer = std::min(L.num_layers - 1, jp.first_layer + job.layer_count - 1);
    jp.min_layers = 0;
    jp.threads = job.threads;
    jp.stop = watchdog.flag();
    jp.memory_limit_bytes = memory_limit;
    // Without tracing ("none", the reference strategy) every pixel near a cell is a global
    // solve, about a hundred times a traced pixel's cost: such jobs count 64 times.
    const double strategy_cost = sp.tracing == TracingStrategy::kNone ? 64.0 : 1.0;
    const double pixels = static_cast<double>(L.width_px) * L.height_px * (jp.last_layer - jp.first_layer + 1) *
                          order_product / 64.0 * strategy_cost;
    outcome.pixels = static_cast<double>(L.width_px) * L.height_px * (jp.last_layer - jp.first_layer + 1);
    if (pixels > kPipelinePixels) return finish(PipelineOutcome::Kind::kTooLarge);
    [[maybe_unused]] const std::uint64_t resident = resident_bytes_now();  // read under TRIVOX_FUZZ_HEAP
    const JobEstimate e = estimate_job(slicer, jp, EstimateParams{1});
    check_job_fits(e, jp, std::nullopt);
#ifdef TRIVOX_FUZZ_HEAP
    const long long heap_before = g_heap_bytes.load();
    g_heap_peak.store(heap_before);
#endif
    const JobStats stats = run_slice_job(slicer, jp);
#ifdef TRIVOX_FUZZ_HEAP
    const double grown = static_cast<double>(g_heap_peak.load() - heap_before);
    const double own_estimate = static_cast<double>(e.peak_memory_bytes) - static_cast<double>(resident);
    outcome.heap_grown_bytes = grown;
    outcome.estimate_bytes = own_estimate;
    if (grown > 1.5 * std::max(0.0, own_estimate) + 64e6)
      throw HarnessViolation("the job's heap grew by " + std::to_string(grown / 1e6) + " MB, more than 1.5 times its " +
                             "own estimate of " + std::to_string(own_estimate / 1e6) + " MB plus 64 MB");
#endif
    if (stats.interrupted) {
      if (!watchdog.raised()) throw HarnessViolation("a job whose stop flag is down reports itself interrupted");
      check_stopped_job(jp.output_dir);
      return finish(PipelineOutcome::Kind::kStopped);
    }
    const VerifyReport report = verify_output(jp.output_dir);
    if (!report.ok()) throw HarnessViolation("a completed job does not verify: " + report.problems.front());
    return finish(PipelineOutcome::Kind::kSliced);
  } catch (const HarnessViolation&) {
    throw;
  } catch (const CancelledError& e) {
    // Stopped while the slicer was set up or the estimate sliced its sample layer.
    if (!watchdog.raised()) throw HarnessViolation(std::string("cancelled with the stop flag down: ") + e.what());
    return finish(PipelineOutcome::Kind::kStopped);
  } catch (const Error& e) {
    // A documented refusal: bad or unworkable input, or a job too large for the limits.
    outcome.refusal = std::string(e.what()).substr(0, 160);
    return finish(PipelineOutcome::Kind::kRefused);
  }
}

void prepare_scene_dir(const std::filesystem::path& dir, const std::filesystem::path& examples_models) {
  namespace fs = std::filesystem;
  fs::create_directories(dir / "models");
  fs::create_directories(dir / "scenes");
  write_file(dir / "models" / "box.itd",
             "[OBJECT BOX\n"
             "    [TRIVAR BSPLINE 2 2 2 2 2 2 E3\n"
             "\t[KV 0 0 1 1]\n\t[KV 0 0 1 1]\n\t[KV 0 0 1 1]\n"
             "\t[0 0 0]\n\t[10 0 0]\n\t[0 10 0]\n\t[10 10 0]\n"
             "\t[0 0 5]\n\t[10 0 5]\n\t[0 10 5]\n\t[10 10 5]\n"
             "    ]\n]\n");
  write_file(dir / "models" / "box.xml",
             "<?xml version=\"1.0\"?>\n<xml>\n <Geometry type=\"TensorBSpline3\" id=\"0\">\n"
             "  <Basis type=\"TensorBSplineBasis3\">\n"
             "   <Basis type=\"BSplineBasis\" index=\"0\"><KnotVector degree=\"1\">0 0 1 1</KnotVector></Basis>\n"
             "   <Basis type=\"BSplineBasis\" index=\"1\"><KnotVector degree=\"1\">0 0 1 1</KnotVector></Basis>\n"
             "   <Basis type=\"BSplineBasis\" index=\"2\"><KnotVector degree=\"1\">0 0 1 1</KnotVector></Basis>\n"
             "  </Basis>\n"
             "  <coefs geoDim=\"3\">0 0 0 10 0 0 0 10 0 10 10 0 0 0 5 10 0 5 0 10 5 10 10 5</coefs>\n"
             " </Geometry>\n</xml>\n");
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(examples_models, ec))
    if (entry.is_regular_file())
      fs::copy_file(entry.path(), dir / "models" / entry.path().filename(), fs::copy_options::overwrite_existing);
}

bool run_target(std::string_view target, std::span<const std::uint8_t> data, const std::filesystem::path& scene_dir) {
  if (target == "itd")
    run_itd(data);
  else if (target == "gismo_xml")
    run_gismo_xml(data);
  else if (target == "scene")
    run_scene(data, scene_dir);
  else if (target == "expression")
    run_expression(data);
  else if (target == "pipeline")
    run_pipeline(data, scene_dir / "pipeline");
  else if (target == "g2")
    run_g2(data);
  else if (target == "cache_entry")
    run_cache_entry(data, scene_dir / "cache_entry");
  else
    return false;
  return true;
}

}  // namespace trivox::fuzz
