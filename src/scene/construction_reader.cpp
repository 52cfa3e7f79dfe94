// Construction files (include/trivox/scene/construction.h): the scene reader's constructed
// geometry, on its own.
#include "trivox/scene/construction.h"

#include <fstream>
#include <iterator>

#include <fmt/format.h>

#include "scene/scene_parse.h"
#include "trivox/error.h"

namespace trivox {

Constructed parse_construction(std::string_view json_text, const std::filesystem::path& source) {
  const std::string src = source.string();
  const detail::Json root = detail::parse_json_text(json_text, src);
  const detail::JsonView top(root, "", src);
  detail::SceneContext ctx(src, source.parent_path());
  return detail::parse_construction(top, ctx);
}

Constructed read_construction(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw IoError(fmt::format("cannot read the construction file {}: it is a directory", path.string()));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(fmt::format("cannot open the construction file {}", path.string()));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw IoError(fmt::format("cannot read the construction file {}", path.string()));
  return parse_construction(text, path);
}

}  // namespace trivox
