// Every example scene reads, carries the keys the schema requires, and evaluates; every JSON
// snippet of the documentation is valid, and every one in docs/SCENE.md reads in its place.
#include <algorithm>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/test_support.h"
#include "trivox/error.h"
#include "trivox/scene/construction.h"
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

// The fenced ```json and ```jsonc blocks of a Markdown file, with the line each starts on.
struct DocBlock {
  std::string text;
  int line = 0;
};
std::vector<DocBlock> json_blocks(const std::string& doc) {
  std::vector<DocBlock> blocks;
  const std::string fence = "```";
  for (std::size_t at = doc.find(fence); at != std::string::npos;) {
    const std::size_t eol = doc.find('\n', at);
    if (eol == std::string::npos) break;
    const std::string lang = doc.substr(at + fence.size(), eol - at - fence.size());
    const std::size_t end = doc.find(fence, eol + 1);
    if (end == std::string::npos) break;
    if (lang == "json" || lang == "jsonc")
      blocks.push_back(
          {doc.substr(eol + 1, end - eol - 1),
           1 + static_cast<int>(std::count(doc.begin(), doc.begin() + static_cast<std::ptrdiff_t>(at), '\n'))});
    at = doc.find(fence, end + fence.size());
  }
  return blocks;
}

// A block as JSON: a whole value, or object members ("key": value, ...) as an object.
std::optional<json> block_json(const std::string& text, bool* members) {
  *members = false;
  try {
    return json::parse(text);
  } catch (const json::exception&) {
  }
  try {
    *members = true;
    return json::parse("{" + text + "}");
  } catch (const json::exception&) {
  }
  return std::nullopt;
}

// Every construction file of examples/constructions builds a volume that does not fold, and
// the README names it.
TEST(SceneExamples, EveryConstructionFileBuilds) {
  const std::string readme = read_text(kExamples.parent_path() / "README.md");
  int files = 0;
  for (const auto& e : fs::directory_iterator(kExamples.parent_path() / "constructions")) {
    if (e.path().extension() != ".json") continue;
    SCOPED_TRACE(e.path().string());
    const Constructed c = read_construction(e.path());
    EXPECT_FALSE(c.report.folds()) << c.report.describe();
    EXPECT_NE(readme.find("`constructions/" + e.path().filename().string() + "`"), std::string::npos);
    ++files;
  }
  EXPECT_GE(files, 7);
}

// examples/README.md's table has a row for every bundled scene.
TEST(SceneExamples, TheExamplesTableListsEveryScene) {
  const std::string readme = read_text(kExamples.parent_path() / "README.md");
  int scenes = 0;
  for (const char* folder : {"scenes", "shared_scenes"})
    for (const auto& e : fs::directory_iterator(kExamples.parent_path() / folder)) {
      if (e.path().extension() != ".json") continue;
      const std::string row = "| `" + std::string(folder) + "/" + e.path().filename().string() + "` |";
      EXPECT_NE(readme.find(row), std::string::npos) << "examples/README.md has no row " << row;
      ++scenes;
    }
  EXPECT_GE(scenes, 14);
}

bool keys_within(const json& object, const std::set<std::string>& keys) {
  for (const auto& item : object.items())
    if (!keys.count(item.key())) return false;
  return true;
}

// Every JSON snippet of the documentation can be pasted: each block is JSON (no comments, no
// "..."), or the members of an object.
TEST(SceneExamples, EveryJsonSnippetOfTheDocsIsValid) {
  std::vector<fs::path> docs = {kDocs.parent_path() / "README.md", kDocs.parent_path() / "examples" / "README.md"};
  for (const auto& e : fs::directory_iterator(kDocs))
    if (e.path().extension() == ".md") docs.push_back(e.path());
  int blocks = 0;
  for (const fs::path& path : docs)
    for (const DocBlock& b : json_blocks(read_text(path))) {
      bool members = false;
      EXPECT_TRUE(block_json(b.text, &members).has_value())
          << path.string() << ":" << b.line << ": not JSON, nor object members:\n"
          << b.text;
      ++blocks;
    }
  EXPECT_GE(blocks, 30);
}

// Every snippet of SCENE.md is read by the scene reader in its place: a complete scene as
// it is; a material function, a constructor, an inline geometry, a cell, or top-level or
// cell members inside a small scene around it. Files are named relative to docs/.
TEST(SceneExamples, EverySceneSnippetOfTheDocsReads) {
  const std::vector<DocBlock> blocks = json_blocks(read_text(kDocs / "SCENE.md"));
  const json library = {"VeroCyan", "VeroMagenta", "VeroYellow", "VeroClear", "VeroWhite"};
  const json column = {{"file", "../examples/models/twisted_column.itd"}};
  const auto scene_around = [&](const json& cell) {
    return json{{"units", "mm"}, {"printer", "j750-hq"}, {"materials", library}, {"cells", {cell}}};
  };
  const std::set<std::string> constructors = {"extrude", "ruled", "revolve", "sweep", "coons", "shell"};
  const std::set<std::string> top_members = {"printer", "materials", "fraction_sums", "dithering", "greyscale"};
  const std::set<std::string> cell_members = {"geometry", "placement", "trim", "material"};
  std::map<std::string, int> read;
  for (const DocBlock& b : blocks) {
    SCOPED_TRACE("docs/SCENE.md:" + std::to_string(b.line));
    if (b.text.find("/shared/data/") != std::string::npos && test::shared_data_dir().empty()) continue;
    bool members = false;
    const std::optional<json> j = block_json(b.text, &members);
    ASSERT_TRUE(j.has_value()) << b.text;
    ASSERT_TRUE(j->is_object()) << b.text;
    json scene;
    std::string what;
    if (!members && j->contains("units")) {
      scene = *j;
      what = "scene";
    } else if (!members && j->contains("kind")) {
      scene = scene_around({{"geometry", column}, {"material", *j}});
      what = "material function";
    } else if (!members && j->size() == 1 && constructors.count(j->begin().key())) {
      scene = scene_around({{"geometry", *j}, {"material", "VeroCyan"}});
      what = "constructor";
    } else if (!members && j->contains("geometry")) {
      scene = scene_around(*j);
      what = "cell";
    } else if (members && j->contains("unions")) {
      scene = {{"units", "mm"}, {"printer", "j750-hq"}, {"materials", library}};
      scene.update(*j);
      what = "volumes and unions";
    } else if (members && keys_within(*j, top_members)) {
      scene = scene_around({{"geometry", column}, {"material", "void"}});
      scene["materials"] = {"VeroCyan"};  // within the colour limit of any printer snippet
      if (j->contains("greyscale")) {     // a resin printer, with the material the block names
        scene["printer"] = "sl1s";
        scene["materials"] = {{{"name", "stiff"}, {"rgba", {200, 200, 200}}}};
      }
      scene.update(*j);
      what = "top-level members";
    } else if (members && keys_within(*j, cell_members)) {
      json cell = {{"geometry", column}, {"material", "VeroCyan"}};
      cell.update(*j);
      scene = scene_around(cell);
      what = "cell members";
    } else {
      ADD_FAILURE() << "a snippet of no known kind:\n" << b.text;
      continue;
    }
    SCOPED_TRACE(what);
    if (what == "constructor" && b.text.find("untangle") != std::string::npos) {
      // The untangled duck takes seconds to build. The snippet is the geometry of
      // examples/shared_scenes/duck.json (its file named from there), which the shared-data
      // tests read.
      const json duck = json::parse(read_text(kExamples.parent_path() / "shared_scenes" / "duck.json"));
      EXPECT_EQ(*j, duck.at("cells").at(0).at("geometry"));
      ++read[what];
      continue;
    }
    try {
      evaluate_cells(parse_scene(scene.dump(), kDocs / "SCENE.md"));
      ++read[what];
    } catch (const Error& e) {
      ADD_FAILURE() << e.what() << "\n" << b.text;
    }
  }
  EXPECT_GE(read["scene"], 1);
  EXPECT_GE(read["material function"], 10);  // a worked example per kind at least
  EXPECT_GE(read["constructor"], 5);
  EXPECT_GE(read["top-level members"], 8);
  EXPECT_GE(read["cell members"], 3);
  EXPECT_GE(read["volumes and unions"], 1);
}

}  // namespace
}  // namespace trivox
