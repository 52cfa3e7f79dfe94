// Every example scene reads, carries the keys the schema requires, and evaluates; every JSON
// example in docs/SCENE.md parses (full scenes read, material functions build).
#include <fstream>
#include <set>
#include <sstream>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/test_support.h"
#include "trivox/scene/scene.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const fs::path kExamples = fs::path(TRIVOX_EXAMPLES_DIR) / "scenes";
const fs::path kDocs = fs::path(TRIVOX_EXAMPLES_DIR).parent_path() / "docs";

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<fs::path> example_scenes() {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(kExamples))
    if (e.path().extension() == ".json") out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

// The "required" list of the schema's top level, or of one of its $defs.
std::vector<std::string> required_keys(const json& schema, const std::string& def = "") {
  const json& node = def.empty() ? schema : schema.at("$defs").at(def);
  return node.at("required").get<std::vector<std::string>>();
}

// Evaluates each cell's material at its domain's centre and corners: fractions must obey
// the rules after the scene's policy.
void evaluate_cells(const Scene& scene) {
  for (const Cell& cell : scene.cells) {
    const ParamBox d = cell.volume.domain();
    std::vector<Vec3> uvw = {d.center()};
    for (int c = 0; c < 8; ++c)
      uvw.push_back({(c & 1) ? d.hi.x : d.lo.x, (c & 2) ? d.hi.y : d.lo.y, (c & 4) ? d.hi.z : d.lo.z});
    std::vector<Vec3> xyz;
    for (const Vec3& p : uvw) xyz.push_back(cell.volume.evaluate(p));
    const auto m = static_cast<std::size_t>(scene.num_materials());
    std::vector<float> f(uvw.size() * m);
    cell.material->evaluate_row(uvw, xyz, f);
    for (std::size_t s = 0; s < uvw.size(); ++s) {
      float sum = 0;
      for (std::size_t j = 0; j < m; ++j) {
        EXPECT_GE(f[s * m + j], 0.0f) << scene.source << " " << cell.name;
        sum += f[s * m + j];
      }
      EXPECT_LE(sum, 1.0f + 1e-6f) << scene.source << " " << cell.name;
    }
  }
}

TEST(SceneExamples, EveryExampleReadsAndHasTheSchemasRequiredKeys) {
  const json schema = json::parse(read_text(kDocs / "scene.schema.json"));
  const std::vector<std::string> top = required_keys(schema);
  const std::vector<std::string> cell_keys = required_keys(schema, "cell");
  const std::vector<std::string> material_keys = required_keys(schema, "material");
  const std::vector<fs::path> scenes = example_scenes();
  ASSERT_GE(scenes.size(), 4u);
  std::set<std::string> kinds;
  for (const fs::path& path : scenes) {
    SCOPED_TRACE(path.string());
    const std::string text = read_text(path);
    // Examples that read ../shared (the duck shell) need it beside the repository.
    if (text.find("/shared/data/") != std::string::npos && test::shared_data_dir().empty()) continue;
    const json doc = json::parse(text);
    for (const std::string& key : top) EXPECT_TRUE(doc.contains(key)) << "missing top-level key " << key;
    const json listed = doc.value("cells", json::array());
    std::vector<json> cells(listed.begin(), listed.end());
    for (const json& u : doc.value("unions", json::array()))
      for (const json& r : u.at("regions")) cells.push_back(r);
    for (const json& c : cells) {
      for (const std::string& key : cell_keys) EXPECT_TRUE(c.contains(key)) << "a cell lacks " << key;
      const json& material = c.at("material");
      kinds.insert(material.is_string() ? "material name" : material.at("kind").get<std::string>());
    }
    for (const json& m : doc.at("materials")) {
      if (m.is_string()) continue;  // a library material's name
      for (const std::string& key : material_keys) EXPECT_TRUE(m.contains(key)) << "a material lacks " << key;
    }
    const Scene scene = read_scene(path);
    EXPECT_FALSE(scene.cells.empty());
    evaluate_cells(scene);
  }
  for (const char* kind : {"spline_field", "porous_tiles", "twisting_curves", "expression"})
    EXPECT_TRUE(kinds.count(kind)) << "no example uses " << kind;
}

TEST(SceneExamples, DocumentationExamplesParse) {
  const std::string doc = read_text(kDocs / "SCENE.md");
  // Every fenced ```json block (found by plain search: <regex> trips GCC 12 warnings).
  std::vector<std::string> blocks;
  const std::string open = "```json\n", close = "```";
  for (std::size_t at = doc.find(open); at != std::string::npos; at = doc.find(open, at)) {
    const std::size_t body = at + open.size();
    const std::size_t end = doc.find(close, body);
    if (end == std::string::npos) break;
    blocks.push_back(doc.substr(body, end - body));
    at = end + close.size();
  }
  int scenes = 0, functions = 0;
  for (const std::string& text : blocks) {
    SCOPED_TRACE(text.substr(0, 200));
    const json j = json::parse(text);  // every block is valid JSON
    if (j.contains("cells")) {
      // Files in the documentation's scenes are named relative to docs/.
      evaluate_cells(parse_scene(text, kDocs / "SCENE.md"));
      ++scenes;
    } else if (j.contains("kind")) {
      // A material function: build it inside a scene that declares the names the docs use.
      json scene = {{"units", "mm"},
                    {"printer", "j750-hq"},
                    {"materials", json::array()},
                    {"cells", {{{"geometry", {{"file", "../examples/models/twisted_column.itd"}}}, {"material", j}}}}};
      for (const char* name : {"VeroCyan", "VeroMagenta", "VeroYellow", "VeroClear", "VeroWhite"})
        scene["materials"].push_back({{"name", name}, {"rgba", {0, 0, 0, 255}}});
      evaluate_cells(parse_scene(scene.dump(), kDocs / "SCENE.md"));
      ++functions;
    }
  }
  EXPECT_GE(scenes, 1);
  EXPECT_GE(functions, 6);  // one worked example per kind at least
}

}  // namespace
}  // namespace trivox
