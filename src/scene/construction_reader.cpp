// Construction files (include/trivox/scene/construction.h): the scene reader's constructed
// geometry, on its own.
#include "trivox/scene/construction.h"

#include <cstdint>
#include <limits>
#include <string>

#include <fmt/format.h>

#include "scene/scene_parse.h"
#include "trivox/error.h"
#include "trivox/io/detail/regular_file.h"

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
  // A device or a FIFO is refused by what it is (io/detail/regular_file.h), never read.
  std::string text;
  try {
    text = read_regular_file(path, std::numeric_limits<std::uint64_t>::max());
  } catch (const IoError& e) {
    throw IoError(fmt::format("cannot read the construction file: {}", e.what()));
  }
  return parse_construction(text, path);
}

}  // namespace trivox
