// Texture material functions of a scene (docs/SCENE.md, "texture"): the image files they name
// and how they are sampled.
#include <fmt/format.h>

#include "scene/scene_parse.h"
#include "trivox/error.h"
#include "trivox/material/detail/volume_texture.h"
#include "trivox/output/png_io.h"

namespace trivox::detail {

namespace {

// A stack of PNG files, each one z slice, as RGBA channels in [0, 1].
VolumeImage read_png_stack(const std::vector<std::pair<std::filesystem::path, JsonView>>& files) {
  VolumeImage image;
  image.channels = 4;
  for (const auto& [path, field] : files) {
    RgbaImage slice;
    try {
      slice = read_png_rgba(path);
    } catch (const Error& e) {
      field.fail(fmt::format("cannot use the PNG file \"{}\": {}", field.string(), e.what()));
    }
    if (image.nz == 0) {
      image.nx = slice.width_px;
      image.ny = slice.height_px;
    } else if (slice.width_px != image.nx || slice.height_px != image.ny) {
      field.fail(fmt::format("the PNG file is {} x {} px but the first of the stack is {} x {}", slice.width_px,
                             slice.height_px, image.nx, image.ny));
    }
    for (std::uint8_t v : slice.rgba) image.values.push_back(static_cast<float>(v) / 255.0f);
    ++image.nz;
  }
  return image;
}

RawSampleType raw_type(const JsonView& v) {
  const std::string& s = v.string();
  if (s == "uint8") return RawSampleType::kUint8;
  if (s == "uint16") return RawSampleType::kUint16;
  if (s == "float32") return RawSampleType::kFloat32;
  v.fail(fmt::format("expected \"uint8\", \"uint16\" or \"float32\", got \"{}\"", s));
}

TextureWrap wrap_mode(const JsonView& v) {
  const std::string& s = v.string();
  if (s == "clamp") return TextureWrap::kClamp;
  if (s == "repeat") return TextureWrap::kRepeat;
  if (s == "mirror") return TextureWrap::kMirror;
  v.fail(fmt::format("expected \"clamp\", \"repeat\" or \"mirror\", got \"{}\"", s));
}

}  // namespace

std::shared_ptr<const VolumeImage> SceneContext::volume_image(const JsonView& node) {
  node.expect_object({"png", "tiff", "raw", "size", "channels", "type", "byte_order"});
  const int sources = (node.find("png") ? 1 : 0) + (node.find("tiff") ? 1 : 0) + (node.find("raw") ? 1 : 0);
  if (sources != 1) node.fail("give exactly one of \"png\", \"tiff\" and \"raw\"");
  if (!node.find("raw"))
    for (const char* key : {"size", "channels", "type", "byte_order"})
      if (const auto k = node.find(key)) k->fail(fmt::format("\"{}\" belongs to \"raw\" images only", key));
  const std::string key = base_dir_.string() + "\n" + node.json().dump();
  if (const auto it = images_.find(key); it != images_.end()) return it->second;

  VolumeImage image;
  if (const auto png = node.find("png")) {
    std::vector<std::pair<std::filesystem::path, JsonView>> files;
    if (png->is_string()) {
      files.emplace_back(existing_file(*png, "PNG file"), *png);
    } else {
      for (const JsonView& f : png->elements(1)) files.emplace_back(existing_file(f, "PNG file"), f);
    }
    image = read_png_stack(files);
  } else if (const auto tiff = node.find("tiff")) {
    const std::filesystem::path path = existing_file(*tiff, "TIFF file");
    try {
      image = read_tiff_volume(path);
    } catch (const Error& e) {
      tiff->fail(fmt::format("cannot use the TIFF file \"{}\": {}", tiff->string(), e.what()));
    }
  } else {
    const JsonView raw = node.at("raw");
    const std::filesystem::path path = existing_file(raw, "raw file");
    RawVolumeLayout layout;
    const std::vector<JsonView> size = node.at("size").elements(3, 3);
    layout.nx = size[0].integer_in(1, 1 << 16);
    layout.ny = size[1].integer_in(1, 1 << 16);
    layout.nz = size[2].integer_in(1, 1 << 16);
    if (const auto c = node.find("channels")) layout.channels = c->integer_in(1, 64);
    if (const auto t = node.find("type")) layout.type = raw_type(*t);
    if (const auto b = node.find("byte_order")) {
      const std::string& order = b->string();
      if (order != "little" && order != "big")
        b->fail(fmt::format("expected \"little\" or \"big\", got \"{}\"", order));
      layout.big_endian = order == "big";
    }
    try {
      image = read_raw_volume(path, layout);
    } catch (const Error& e) {
      raw.fail(fmt::format("cannot use the raw file \"{}\": {}", raw.string(), e.what()));
    }
  }
  auto shared = std::make_shared<const VolumeImage>(std::move(image));
  images_.emplace(key, shared);
  return shared;
}

namespace {

// "filter", "wrap" and "repeats" of a texture or a texture scalar source.
TextureSampling parse_sampling(const JsonView& node) {
  TextureSampling sampling;
  if (const auto f = node.find("filter")) {
    const std::string& s = f->string();
    if (s == "nearest")
      sampling.filter = TextureFilter::kNearest;
    else if (s == "trilinear")
      sampling.filter = TextureFilter::kTrilinear;
    else
      f->fail(fmt::format("expected \"nearest\" or \"trilinear\", got \"{}\"", s));
  }
  if (const auto w = node.find("wrap")) {
    if (w->is_string()) {
      sampling.wrap.fill(wrap_mode(*w));
    } else {
      const std::vector<JsonView> modes = w->elements(3, 3);
      for (std::size_t d = 0; d < 3; ++d) sampling.wrap[d] = wrap_mode(modes[d]);
    }
  }
  if (const auto r = node.find("repeats")) {
    if (r->is_number()) {
      const double v = r->number();
      sampling.repeats = {v, v, v};
    } else {
      const std::vector<double> v = r->numbers(3, 3);
      sampling.repeats = {v[0], v[1], v[2]};
    }
    try {
      sampling.validate();
    } catch (const Error& e) {
      r->fail(e.what());
    }
  }
  return sampling;
}

}  // namespace

std::shared_ptr<const MaterialFunction> parse_texture(const JsonView& node, SceneContext& ctx,
                                                      const ParamBox& cell_domain) {
  node.expect_object({"kind", "image", "channels", "filter", "wrap", "repeats"});
  const JsonView image_node = node.at("image");
  std::shared_ptr<const VolumeImage> image = ctx.volume_image(image_node);
  VolumeTexture texture(image, parse_sampling(node));
  const JsonView channels = node.at("channels");
  std::vector<int> materials;
  for (const JsonView& c : channels.elements(1, static_cast<std::size_t>(image->channels))) {
    const int j = ctx.material_ref(c);
    for (std::size_t k = 0; k < materials.size(); ++k)
      if (j != kVoidMaterial && materials[k] == j)
        c.fail(fmt::format("material \"{}\" is channel {} already", c.string(), k));
    materials.push_back(j);
  }
  return std::make_shared<TextureMaterial>(std::move(texture), std::move(materials), ctx.num_materials(), cell_domain);
}

std::shared_ptr<const MaterialFunction> parse_texture_scalar(const JsonView& node, SceneContext& ctx,
                                                             const ParamBox& cell_domain) {
  node.expect_object({"texture", "channel", "filter", "wrap", "repeats"});
  std::shared_ptr<const VolumeImage> image = ctx.volume_image(node.at("texture"));
  int channel = 0;
  if (const auto c = node.find("channel")) channel = c->integer_in(0, image->channels - 1);
  std::vector<int> materials(static_cast<std::size_t>(channel + 1), kVoidMaterial);
  materials.back() = 0;
  return std::make_shared<TextureMaterial>(VolumeTexture(image, parse_sampling(node)), std::move(materials), 1,
                                           cell_domain);
}

}  // namespace trivox::detail
