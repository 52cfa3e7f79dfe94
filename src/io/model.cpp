// read_model: picks the reader by file extension, or by the first character of the content
// when the extension says nothing ('<' is XML, '[' is IRIT text, a digit is a GoTools header).
#include <cstdint>
#include <limits>
#include <string>
#include <system_error>

#include <fmt/format.h>

#include "trivox/error.h"
#include "trivox/io/detail/regular_file.h"
#include "trivox/io/model.h"
#include "trivox/limits.h"

namespace trivox {

std::vector<int> Model::volume_indices() const {
  std::vector<int> out;
  for (std::size_t i = 0; i < patches.size(); ++i)
    if (patches[i].spline.param_dim() == 3) out.push_back(static_cast<int>(i));
  return out;
}

namespace {

std::string read_file(const std::filesystem::path& path, const std::atomic<bool>* stop) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw IoError(fmt::format("cannot read model '{}': it is a directory", path.string()));
  // A device or a FIFO is refused by what it is (regular_file.h), not read until memory runs out.
  try {
    return read_regular_file(path, input_file_byte_limit(), stop);
  } catch (const IoError& e) {
    throw IoError(fmt::format("cannot read model: {}", e.what()));
  }
}

std::string lowercase(std::string s) {
  for (char& c : s)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return s;
}

}  // namespace

Model read_model(const std::filesystem::path& path, const std::atomic<bool>* stop) {
  const std::string source = path.string();
  const std::string text = read_file(path, stop);
  const std::string ext = lowercase(path.extension().string());
  if (ext == ".itd") return read_itd(text, source, stop);
  if (ext == ".xml") return read_gismo_xml(text, source, stop);
  if (ext == ".g2") return read_g2(text, source, stop);

  // Unknown extension: sniff. A UTF-8 byte order mark may precede an XML file.
  std::string_view head = text;
  if (head.substr(0, 3) == "\xEF\xBB\xBF") head.remove_prefix(3);
  const std::size_t first = head.find_first_not_of(" \t\r\n");
  if (first != std::string_view::npos && head[first] == '<') return read_gismo_xml(text, source, stop);
  if (first != std::string_view::npos && head[first] == '[') return read_itd(text, source, stop);
  // A GoTools file starts with an object header: a class number such as 700.
  if (first != std::string_view::npos && head[first] >= '0' && head[first] <= '9') return read_g2(text, source, stop);
  throw InputError(
      source, 0, "",
      fmt::format("unknown model format '{}': expected IRIT text (.itd), G+Smo XML (.xml) or GoTools (.g2)", ext));
}

std::optional<ModelFormat> model_format_of(const std::filesystem::path& path) {
  const std::string ext = lowercase(path.extension().string());
  if (ext == ".itd") return ModelFormat::kItd;
  if (ext == ".xml") return ModelFormat::kGismoXml;
  if (ext == ".g2") return ModelFormat::kG2;
  return std::nullopt;
}

void write_model(std::ostream& out, const Model& model, ModelFormat format) {
  switch (format) {
    case ModelFormat::kItd: write_itd(out, model); return;
    case ModelFormat::kGismoXml: write_gismo_xml(out, model); return;
    case ModelFormat::kG2: write_g2(out, model); return;
  }
}

}  // namespace trivox
