#include "trivox/job/manifest.h"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <limits>
#include <tuple>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "trivox/error.h"
#include "trivox/output/atomic_file.h"

namespace trivox {

namespace {

using Json = nlohmann::ordered_json;

constexpr std::string_view kFormatName = "trivox job manifest";
constexpr int kFormatVersion = 1;

}  // namespace

std::string_view to_string(JobStatus status) noexcept {
  switch (status) {
    case JobStatus::kRunning: return "running";
    case JobStatus::kComplete: return "complete";
    case JobStatus::kInterrupted: return "interrupted";
    case JobStatus::kFailed: return "failed";
  }
  return "unknown";
}

std::optional<JobStatus> parse_job_status(std::string_view text) noexcept {
  for (JobStatus s : {JobStatus::kRunning, JobStatus::kComplete, JobStatus::kInterrupted, JobStatus::kFailed})
    if (to_string(s) == text) return s;
  return std::nullopt;
}

void JobManifest::sort_files() {
  std::sort(files.begin(), files.end(), [](const ManifestFile& a, const ManifestFile& b) {
    return std::tie(a.layer, a.name) < std::tie(b.layer, b.name);
  });
  std::sort(printed.begin(), printed.end(),
            [](const ManifestPrinted& a, const ManifestPrinted& b) { return a.layer < b.layer; });
}

std::string manifest_file_name(int shard_index, int shard_count) {
  if (shard_count <= 1) return "manifest.json";
  return fmt::format("manifest.shard-{}-of-{}.json", shard_index, shard_count);
}

std::string stats_file_name(int shard_index, int shard_count) {
  if (shard_count <= 1) return "stats.json";
  return fmt::format("stats.shard-{}-of-{}.json", shard_index, shard_count);
}

bool shard_has_layer(int index, int shard_index, int shard_count) noexcept {
  return shard_count <= 1 || index % shard_count == shard_index - 1;
}

std::string manifest_text(const JobManifest& m) {
  Json head;
  head["format"] = kFormatName;
  head["format_version"] = kFormatVersion;
  head["tool"] = {{"name", "trivox"}, {"version", m.tool_version}};
  head["status"] = to_string(m.status);
  if (!m.message.empty()) head["message"] = m.message;
  head["hash"] = "sha256";
  Json inputs = Json::array();
  for (const ManifestInput& in : m.inputs)
    inputs.push_back({{"role", in.role}, {"name", in.name}, {"sha256", in.sha256}});
  head["inputs"] = inputs;
  Json settings = Json::object();
  for (const auto& [k, v] : m.settings) settings[k] = v;
  head["settings"] = settings;
  if (m.scene_parts) {
    Json cells = Json::array();
    for (const ManifestCell& c : m.scene_parts->cells)
      cells.push_back({{"name", c.name}, {"sha256", c.sha256}, {"layers", Json::array({c.first_layer, c.last_layer})}});
    head["scene_parts"] = {{"settings_sha256", m.scene_parts->settings_sha256},
                           {"fraction_sums", m.scene_parts->fraction_sums},
                           {"cells", cells}};
  }
  head["total_layers"] = m.total_layers;
  head["shard"] = {{"index", m.shard_index}, {"count", m.shard_count}};
  // The head with two-space indents, then one line per file: readable, and small diffs.
  std::string text = head.dump(2);
  text.resize(text.size() - 2);  // drop "\n}"
  text += ",\n  \"files\": [";
  for (std::size_t i = 0; i < m.files.size(); ++i) {
    const ManifestFile& f = m.files[i];
    const Json entry = {{"layer", f.layer}, {"name", f.name}, {"bytes", f.bytes}, {"sha256", f.sha256}};
    text += i == 0 ? "\n    " : ",\n    ";
    text += entry.dump();
  }
  text += m.files.empty() ? "]" : "\n  ]";
  // Then one line per layer with a material: its printed extent in pixels.
  if (!m.printed.empty()) {
    text += ",\n  \"printed\": [";
    for (std::size_t i = 0; i < m.printed.size(); ++i) {
      const ManifestPrinted& p = m.printed[i];
      const Json entry = {{"layer", p.layer},
                          {"columns", Json::array({p.col_lo, p.col_hi})},
                          {"rows", Json::array({p.row_lo, p.row_hi})}};
      text += i == 0 ? "\n    " : ",\n    ";
      text += entry.dump();
    }
    text += "\n  ]";
  }
  text += "\n}\n";
  return text;
}

namespace {

// Field access that names the manifest and the field in errors.
class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  const Json& at(const Json& obj, const std::string& key, const std::string& where) const {
    if (!obj.is_object() || !obj.contains(key)) fail(where + "/" + key, "is missing");
    return obj.at(key);
  }
  std::string str(const Json& obj, const std::string& key, const std::string& where) const {
    const Json& v = at(obj, key, where);
    if (!v.is_string()) fail(where + "/" + key, "must be a string");
    return v.get<std::string>();
  }
  // A name (of an input, a cell, a file): a string without NUL or other control characters,
  // which would cut or garble every message that shows it.
  std::string name(const Json& obj, const std::string& key, const std::string& where) const {
    std::string text = str(obj, key, where);
    if (const auto c = first_control_character(text))
      fail(where + "/" + key,
           fmt::format("{} holds the control character 0x{:02X}; names hold none", shown_name(text, '"'), *c));
    return text;
  }
  std::int64_t integer(const Json& obj, const std::string& key, const std::string& where, std::int64_t lo,
                       std::int64_t hi) const {
    const Json& v = at(obj, key, where);
    if (!v.is_number_integer()) fail(where + "/" + key, "must be an integer");
    const auto x = v.get<std::int64_t>();
    if (x < lo || x > hi) fail(where + "/" + key, fmt::format("must be in [{}, {}], is {}", lo, hi, x));
    return x;
  }
  [[noreturn]] void fail(const std::string& where, const std::string& rule) const {
    throw InputError(source_, 0, where.empty() ? "/" : where, rule);
  }

 private:
  std::string source_;
};

}  // namespace

JobManifest parse_manifest(std::string_view text, const std::string& source) {
  const Reader r(source);
  Json doc;
  try {
    doc = Json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    r.fail("", fmt::format("not valid JSON: {}", e.what()));
  }
  if (r.str(doc, "format", "") != kFormatName) r.fail("/format", fmt::format("must be \"{}\"", kFormatName));
  if (r.integer(doc, "format_version", "", 1, 1000) != kFormatVersion)
    r.fail("/format_version", fmt::format("this reader knows version {}", kFormatVersion));
  JobManifest m;
  m.tool_version = r.str(r.at(doc, "tool", ""), "version", "/tool");
  const std::string status = r.str(doc, "status", "");
  const auto parsed = parse_job_status(status);
  if (!parsed) r.fail("/status", fmt::format("\"{}\" is not running, complete, interrupted or failed", status));
  m.status = *parsed;
  if (doc.contains("message")) m.message = r.str(doc, "message", "");
  const Json& inputs = r.at(doc, "inputs", "");
  if (!inputs.is_array()) r.fail("/inputs", "must be an array");
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const std::string where = fmt::format("/inputs/{}", i);
    m.inputs.push_back(
        {r.str(inputs[i], "role", where), r.name(inputs[i], "name", where), r.str(inputs[i], "sha256", where)});
  }
  const Json& settings = r.at(doc, "settings", "");
  if (!settings.is_object()) r.fail("/settings", "must be an object");
  for (const auto& [k, v] : settings.items()) {
    if (!v.is_string()) r.fail("/settings/" + k, "must be a string");
    m.settings.emplace_back(k, v.get<std::string>());
  }
  m.total_layers = static_cast<int>(r.integer(doc, "total_layers", "", 1, 100000000));
  if (doc.contains("scene_parts")) {
    const Json& parts = r.at(doc, "scene_parts", "");
    ManifestSceneParts p;
    p.settings_sha256 = r.str(parts, "settings_sha256", "/scene_parts");
    p.fraction_sums = r.str(parts, "fraction_sums", "/scene_parts");
    const Json& cells = r.at(parts, "cells", "/scene_parts");
    if (!cells.is_array()) r.fail("/scene_parts/cells", "must be an array");
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const std::string where = fmt::format("/scene_parts/cells/{}", i);
      ManifestCell c;
      c.name = r.name(cells[i], "name", where);
      c.sha256 = r.str(cells[i], "sha256", where);
      const Json& layers = r.at(cells[i], "layers", where);
      if (!layers.is_array() || layers.size() != 2 || !layers[0].is_number_integer() || !layers[1].is_number_integer())
        r.fail(where + "/layers", "must be two integers");
      c.first_layer = layers[0].get<int>();
      c.last_layer = layers[1].get<int>();
      p.cells.push_back(std::move(c));
    }
    m.scene_parts = std::move(p);
  }
  const Json& shard = r.at(doc, "shard", "");
  m.shard_count = static_cast<int>(r.integer(shard, "count", "/shard", 1, 1000000));
  m.shard_index = static_cast<int>(r.integer(shard, "index", "/shard", 1, m.shard_count));
  const Json& files = r.at(doc, "files", "");
  if (!files.is_array()) r.fail("/files", "must be an array");
  for (std::size_t i = 0; i < files.size(); ++i) {
    const std::string where = fmt::format("/files/{}", i);
    ManifestFile f;
    f.layer = static_cast<int>(r.integer(files[i], "layer", where, 0, m.total_layers));
    f.name = r.name(files[i], "name", where);
    // Names stay inside the folder: no absolute paths, no "..".
    const std::filesystem::path p(f.name);
    if (f.name.empty() || p.is_absolute() || std::find(p.begin(), p.end(), "..") != p.end())
      r.fail(where + "/name",
             fmt::format("{} is not a relative path inside the output folder", shown_name(f.name, '"')));
    f.bytes =
        static_cast<std::uint64_t>(r.integer(files[i], "bytes", where, 0, std::numeric_limits<std::int64_t>::max()));
    f.sha256 = r.str(files[i], "sha256", where);
    m.files.push_back(std::move(f));
  }
  if (doc.contains("printed")) {
    const Json& printed = r.at(doc, "printed", "");
    if (!printed.is_array()) r.fail("/printed", "must be an array");
    if (printed.size() > static_cast<std::size_t>(m.total_layers))
      r.fail("/printed", fmt::format("lists {} layers, the job has {}", printed.size(), m.total_layers));
    std::vector<char> seen(static_cast<std::size_t>(m.total_layers), 0);
    for (std::size_t i = 0; i < printed.size(); ++i) {
      const std::string where = fmt::format("/printed/{}", i);
      ManifestPrinted p;
      p.layer = static_cast<int>(r.integer(printed[i], "layer", where, 1, m.total_layers));
      if (seen[static_cast<std::size_t>(p.layer - 1)]++)
        r.fail(where + "/layer", fmt::format("layer {} is listed twice", p.layer));
      const auto range = [&](const char* key, int& lo, int& hi) {
        const Json& v = r.at(printed[i], key, where);
        if (!v.is_array() || v.size() != 2 || !v[0].is_number_integer() || !v[1].is_number_integer() ||
            v[0].get<std::int64_t>() < 0 || v[0].get<std::int64_t>() > v[1].get<std::int64_t>() ||
            v[1].get<std::int64_t>() > std::numeric_limits<int>::max())
          r.fail(where + "/" + key, "must be two integers, 0 <= first <= last");
        lo = v[0].get<int>();
        hi = v[1].get<int>();
      };
      range("columns", p.col_lo, p.col_hi);
      range("rows", p.row_lo, p.row_hi);
      m.printed.push_back(p);
    }
  }
  m.sort_files();
  return m;
}

JobManifest read_manifest(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(fmt::format("{}: cannot open the manifest", path.string()));
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw IoError(fmt::format("{}: cannot read the manifest", path.string()));
  return parse_manifest(text, path.string());
}

void write_manifest(const std::filesystem::path& path, const JobManifest& manifest) {
  write_file_atomic(path, manifest_text(manifest));
}

namespace {

std::vector<std::string> differences(const JobManifest& previous, const JobManifest& current, bool skip_scene_hash) {
  std::vector<std::string> out;
  if (previous.tool_version != current.tool_version)
    out.push_back(fmt::format("trivox version was {}, is {}", previous.tool_version, current.tool_version));
  const auto describe = [](const ManifestInput& in) { return fmt::format("{} \"{}\"", in.role, in.name); };
  const std::size_t n = std::max(previous.inputs.size(), current.inputs.size());
  for (std::size_t i = 0; i < n; ++i) {
    if (i >= previous.inputs.size()) {
      out.push_back(fmt::format("the scene now reads {} as well", describe(current.inputs[i])));
    } else if (i >= current.inputs.size()) {
      out.push_back(fmt::format("the scene no longer reads {}", describe(previous.inputs[i])));
    } else if (skip_scene_hash && previous.inputs[i].role == "scene" && current.inputs[i].role == "scene") {
      continue;  // judged by its parts
    } else if (previous.inputs[i].sha256 != current.inputs[i].sha256 ||
               previous.inputs[i].role != current.inputs[i].role) {
      out.push_back(fmt::format("{} has changed (SHA-256 was {}, is {})", describe(current.inputs[i]),
                                previous.inputs[i].sha256, current.inputs[i].sha256));
    }
  }
  for (const auto& [key, value] : current.settings) {
    // (Lambdas capture a copy of the name: clang 14 cannot capture structured bindings.)
    const auto it = std::find_if(previous.settings.begin(), previous.settings.end(),
                                 [name = key](const auto& kv) { return kv.first == name; });
    if (it == previous.settings.end())
      out.push_back(fmt::format("setting {} is new ({})", key, value));
    else if (it->second != value)
      out.push_back(fmt::format("setting {} was \"{}\", is \"{}\"", key, it->second, value));
  }
  for (const auto& [key, value] : previous.settings) {
    const bool kept = std::any_of(current.settings.begin(), current.settings.end(),
                                  [name = key](const auto& kv) { return kv.first == name; });
    if (!kept) out.push_back(fmt::format("setting {} (\"{}\") is gone", key, value));
  }
  if (previous.total_layers != current.total_layers)
    out.push_back(fmt::format("the job had {} layers, now {}", previous.total_layers, current.total_layers));
  return out;
}

// Whether the policy `now` accepts every sample `before` accepted, and cleans them alike.
bool policy_accepts_as_much(const std::string& before, const std::string& now) {
  if (before == now || now == "normalise") return true;
  const std::string prefix = "error ";
  if (before.rfind(prefix, 0) != 0 || now.rfind(prefix, 0) != 0) return false;
  try {
    return std::stod(now.substr(prefix.size())) >= std::stod(before.substr(prefix.size()));
  } catch (const std::exception&) {
    return false;
  }
}

// "3-5, 9" for sorted layer numbers.
std::string ranges_text(const std::vector<int>& layers) {
  std::string text;
  for (std::size_t i = 0; i < layers.size();) {
    std::size_t j = i;
    while (j + 1 < layers.size() && layers[j + 1] == layers[j] + 1) ++j;
    text +=
        (text.empty() ? "" : ", ") + (j == i ? std::to_string(layers[i]) : fmt::format("{}-{}", layers[i], layers[j]));
    i = j + 1;
  }
  return text;
}

}  // namespace

std::vector<std::string> manifest_differences(const JobManifest& previous, const JobManifest& current) {
  return differences(previous, current, false);
}

std::vector<std::string> resume_differences(const JobManifest& previous, const JobManifest& current,
                                            const std::vector<int>& kept) {
  const auto scene_hash = [](const JobManifest& m) {
    for (const ManifestInput& in : m.inputs)
      if (in.role == "scene") return in.sha256;
    return std::string();
  };
  if (scene_hash(previous) == scene_hash(current) || !previous.scene_parts || !current.scene_parts)
    return differences(previous, current, false);
  std::vector<std::string> out = differences(previous, current, true);
  const ManifestSceneParts& was = *previous.scene_parts;
  const ManifestSceneParts& is = *current.scene_parts;
  const std::string name =
      current.inputs.empty() ? std::string("the scene") : "scene \"" + current.inputs[0].name + "\"";
  if (was.settings_sha256 != is.settings_sha256)
    out.push_back(fmt::format("{} has changed outside its cells (the printer, the materials or the dithering)", name));
  if (was.cells.size() != is.cells.size()) {
    out.push_back(fmt::format("{} had {} cells, now {}", name, was.cells.size(), is.cells.size()));
    return out;
  }
  const bool policy_ok = policy_accepts_as_much(was.fraction_sums, is.fraction_sums);
  if (!policy_ok)
    out.push_back(
        fmt::format("the fraction policy was \"{}\", is \"{}\", which may refuse or change what the completed "
                    "layers hold",
                    was.fraction_sums, is.fraction_sums));
  for (std::size_t c = 0; c < is.cells.size(); ++c) {
    const ManifestCell& a = was.cells[c];
    const ManifestCell& b = is.cells[c];
    if (a.sha256 == b.sha256) continue;
    std::vector<int> touched;
    for (int layer : kept) {
      const bool in_a = a.first_layer > 0 && layer >= a.first_layer && layer <= a.last_layer;
      const bool in_b = b.first_layer > 0 && layer >= b.first_layer && layer <= b.last_layer;
      if (in_a || in_b) touched.push_back(layer);
    }
    if (!touched.empty())
      out.push_back(
          fmt::format("cell '{}' has changed, and it reaches {} of the layers the job completed (layers {}), "
                      "which the change may alter",
                      b.name, touched.size(), ranges_text(touched)));
  }
  return out;
}

}  // namespace trivox
