// Construction files (include/trivox/scene/construction.h): the scene reader's constructed
// geometry, on its own.
#include "trivox/scene/construction.h"

#include "scene/scene_parse.h"

namespace trivox {

Constructed parse_construction(std::string_view json_text, const std::filesystem::path& source,
                               const std::atomic<bool>* stop) {
  const std::string src = source.string();
  const detail::Json root = detail::parse_json_text(json_text, src);
  const detail::JsonView top(root, "", src);
  detail::SceneContext ctx(src, source.parent_path());
  ctx.set_stop(stop);
  return detail::parse_construction(top, ctx);
}

Constructed read_construction(const std::filesystem::path& path, const std::atomic<bool>* stop) {
  return parse_construction(detail::read_json_file(path, "construction", "directory"), path, stop);
}

}  // namespace trivox
