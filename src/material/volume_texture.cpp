#include "trivox/material/detail/volume_texture.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "material/enclosure_util.h"
#include "trivox/error.h"

namespace trivox {

void TextureSampling::validate() const {
  const double r[3] = {repeats.x, repeats.y, repeats.z};
  for (int d = 0; d < 3; ++d)
    if (!(std::isfinite(r[d]) && r[d] > 0.0))
      throw Error(fmt::format("texture repeats[{}] = {} is not a finite number > 0", d, r[d]));
}

int wrap_index(int i, int n, TextureWrap wrap) noexcept {
  switch (wrap) {
    case TextureWrap::kClamp: return std::clamp(i, 0, n - 1);
    case TextureWrap::kRepeat: return ((i % n) + n) % n;
    case TextureWrap::kMirror: {
      const int j = ((i % (2 * n)) + 2 * n) % (2 * n);
      return j < n ? j : 2 * n - 1 - j;
    }
  }
  return 0;
}

VolumeTexture::VolumeTexture(std::shared_ptr<const VolumeImage> image, TextureSampling sampling)
    : image_(std::move(image)), sampling_(sampling) {
  if (!image_) throw Error("a volume texture needs an image");
  image_->validate();
  sampling_.validate();
}

namespace {

// A coordinate far outside the image (a huge repeat count) still gives a valid int index.
int floor_index(double s) noexcept { return static_cast<int>(std::floor(std::clamp(s, -1e9, 1e9))); }

}  // namespace

void VolumeTexture::sample(Vec3 p, std::span<float> out) const noexcept {
  const VolumeImage& im = *image_;
  const int n[3] = {im.nx, im.ny, im.nz};
  const double t[3] = {p.x * sampling_.repeats.x, p.y * sampling_.repeats.y, p.z * sampling_.repeats.z};
  const auto channels = static_cast<std::size_t>(im.channels);
  if (sampling_.filter == TextureFilter::kNearest) {
    int i[3];
    for (int d = 0; d < 3; ++d)
      i[d] = wrap_index(floor_index(t[d] * n[d]), n[d], sampling_.wrap[static_cast<std::size_t>(d)]);
    for (std::size_t c = 0; c < channels; ++c) out[c] = im.at(i[0], i[1], i[2], static_cast<int>(c));
    return;
  }
  int lo[3], hi[3];
  double f[3];
  for (int d = 0; d < 3; ++d) {
    const double s = t[d] * n[d] - 0.5;
    const int i0 = floor_index(s);
    f[d] = s - i0;
    lo[d] = wrap_index(i0, n[d], sampling_.wrap[static_cast<std::size_t>(d)]);
    hi[d] = wrap_index(i0 + 1, n[d], sampling_.wrap[static_cast<std::size_t>(d)]);
  }
  for (std::size_t c = 0; c < channels; ++c) {
    double v = 0.0;
    for (int corner = 0; corner < 8; ++corner) {
      double w = 1.0;
      int idx[3];
      for (int d = 0; d < 3; ++d) {
        const bool upper = ((corner >> d) & 1) != 0;
        w *= upper ? f[d] : 1.0 - f[d];
        idx[d] = upper ? hi[d] : lo[d];
      }
      if (w != 0.0) v += w * im.at(idx[0], idx[1], idx[2], static_cast<int>(c));
    }
    out[c] = static_cast<float>(v);
  }
}

TextureMaterial::TextureMaterial(VolumeTexture texture, std::vector<int> channel_materials, int num_materials,
                                 const ParamBox& cell_domain)
    : MaterialFunction(num_materials),
      texture_(std::move(texture)),
      channel_materials_(std::move(channel_materials)),
      map_(AffineParamMap::between(cell_domain, kUnitParamBox)) {
  const int channels = texture_.image().channels;
  if (channel_materials_.empty() || static_cast<int>(channel_materials_.size()) > channels)
    throw Error(fmt::format("a texture with {} channel(s) maps 1 to {} of them to materials, not {}", channels,
                            channels, channel_materials_.size()));
  for (std::size_t c = 0; c < channel_materials_.size(); ++c) {
    const int j = channel_materials_[c];
    if (j == kVoidMaterial) continue;
    if (j < 0 || j >= num_materials)
      throw Error(
          fmt::format("texture channel {} names material {}, not one of the {} materials", c, j, num_materials));
    for (std::size_t k = 0; k < c; ++k)
      if (channel_materials_[k] == j)
        throw Error(fmt::format("texture channels {} and {} name the same material", k, c));
  }
  // The hull of the samples, for enclose(): every filtered value is a convex combination.
  const VolumeImage& im = texture_.image();
  channel_range_.assign(channel_materials_.size(),
                        Interval{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()});
  sum_range_ = channel_range_.front();
  const std::size_t samples =
      static_cast<std::size_t>(im.nx) * static_cast<std::size_t>(im.ny) * static_cast<std::size_t>(im.nz);
  const auto stride = static_cast<std::size_t>(channels);
  for (std::size_t i = 0; i < samples; ++i) {
    double sum = 0.0;
    for (std::size_t c = 0; c < channel_materials_.size(); ++c) {
      const double v = im.values[i * stride + c];
      channel_range_[c] = {std::min(channel_range_[c].lo, v), std::max(channel_range_[c].hi, v)};
      if (channel_materials_[c] != kVoidMaterial) sum += v;
    }
    sum_range_ = {std::min(sum_range_.lo, sum), std::max(sum_range_.hi, sum)};
  }
}

FractionEnclosure TextureMaterial::enclose(const ParamBox&, const Box3&) const {
  FractionEnclosure e;
  e.fractions.assign(static_cast<std::size_t>(num_materials()), Interval::point(0.0));
  for (std::size_t c = 0; c < channel_materials_.size(); ++c)
    if (channel_materials_[c] != kVoidMaterial)
      e.fractions[static_cast<std::size_t>(channel_materials_[c])] = channel_range_[c];
  e.sum = sum_range_;
  e.finite = std::isfinite(sum_range_.lo) && std::isfinite(sum_range_.hi);
  for (const Interval& f : e.fractions) e.finite = e.finite && std::isfinite(f.lo) && std::isfinite(f.hi);
  // Filtering blends in float.
  return detail::as_floats(e);
}

void TextureMaterial::evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3>, std::span<float> fractions) const {
  const auto m = static_cast<std::size_t>(num_materials());
  float sample[64];
  for (std::size_t s = 0; s < uvw.size(); ++s) {
    const Vec3 p = map_(uvw[s]);
    const Vec3 clamped{std::clamp(p.x, 0.0, 1.0), std::clamp(p.y, 0.0, 1.0), std::clamp(p.z, 0.0, 1.0)};
    texture_.sample(clamped, sample);
    float* out = fractions.data() + s * m;
    std::fill(out, out + m, 0.0f);
    for (std::size_t c = 0; c < channel_materials_.size(); ++c)
      if (channel_materials_[c] != kVoidMaterial) out[static_cast<std::size_t>(channel_materials_[c])] = sample[c];
  }
}

}  // namespace trivox
