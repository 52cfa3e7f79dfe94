#include <fmt/format.h>

#include "output/zip_reader.h"
#include "trivox/error.h"
#include "trivox/output/detail/gcvf_package.h"

namespace trivox {

GcvfPackageSummary read_gcvf_package(const std::filesystem::path& path,
                                     const std::function<void(const std::string&, const RgbaImage&)>& visit) {
  const detail::ZipReader zip(path);
  GcvfPackageSummary summary;
  for (const detail::ZipReader::Entry& e : zip.entries()) {
    const std::string bytes = zip.read(e);  // one entry in memory at a time
    ++summary.entries;
    if (e.name == "ConfigFile.xml") {
      summary.config_xml = bytes;
    } else if (std::filesystem::path(e.name).extension() == ".png") {
      visit(e.name, decode_png_rgba(bytes, fmt::format("{}: entry '{}'", path.string(), e.name)));
      ++summary.images;
    }
  }
  return summary;
}

}  // namespace trivox
