// Internal to trivox, not part of its stable interface (docs/ARCHITECTURE.md, "Public surface").

// Volumetric textures: a volume image (io/detail/volume_image.h) sampled over the parametric domain
// of a cell, and the material function that reads material fractions from its channels.
//
// Coordinates: the cell's parameters are normalised to [0,1]^3 (as for the procedural kinds)
// and multiplied by `repeats` per direction, giving texture coordinates t. The image covers
// t in [0,1]^3 with its samples at the cell centres: sample i of n along an axis sits at
// t = (i + 1/2) / n. Outside [0,1] the wrap mode of that axis applies: clamp (the edge sample
// continues), repeat (the image tiles the axis) or mirror (it tiles, every other copy
// reflected, so the edges meet seamlessly).
//
// Filtering: nearest takes the sample whose cell holds t (index floor(t n), wrapped);
// trilinear blends the 8 samples around t with weights linear in the distance along each axis
// (indices floor(t n - 1/2) and the next, wrapped). A 2D image (one slice, nz = 1) is constant
// along w: the texture over (u,v) carried through w.
#pragma once

#include <array>
#include <memory>
#include <span>
#include <vector>

#include "trivox/io/detail/volume_image.h"
#include "trivox/material/material_function.h"

namespace trivox {

enum class TextureFilter { kNearest, kTrilinear };
enum class TextureWrap { kClamp, kRepeat, kMirror };

struct TextureSampling {
  TextureFilter filter = TextureFilter::kTrilinear;
  std::array<TextureWrap, 3> wrap{TextureWrap::kClamp, TextureWrap::kClamp, TextureWrap::kClamp};
  Vec3 repeats{1.0, 1.0, 1.0};  // image copies per unit of normalised parameter, > 0

  // Throws Error naming the field when a repeat is not finite and > 0.
  void validate() const;
};

class VolumeTexture {
 public:
  // Throws Error when the image or the sampling is invalid.
  VolumeTexture(std::shared_ptr<const VolumeImage> image, TextureSampling sampling);

  const VolumeImage& image() const noexcept { return *image_; }
  const TextureSampling& sampling() const noexcept { return sampling_; }

  // Every channel at normalised parameters p (repeats applied here): out[c], c < channels.
  void sample(Vec3 p, std::span<float> out) const noexcept;

 private:
  std::shared_ptr<const VolumeImage> image_;
  TextureSampling sampling_;
};

// The index that sample i along an axis of n samples reads under `wrap` (i may be any integer).
int wrap_index(int i, int n, TextureWrap wrap) noexcept;

// Fractions from a texture: channel c is the fraction of material channel_materials[c]
// (kVoidMaterial: the channel is ignored); materials no channel names get 0. The cell's
// domain maps onto [0,1]^3.
class TextureMaterial final : public MaterialFunction {
 public:
  // channel_materials: 1 .. image channels entries, each a material index < num_materials or
  // kVoidMaterial, no material twice. Throws Error naming the rule.
  TextureMaterial(VolumeTexture texture, std::vector<int> channel_materials, int num_materials,
                  const ParamBox& cell_domain);

  std::string_view kind() const noexcept override { return "texture"; }
  void evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz, std::span<float> fractions) const override;
  // Nearest and trilinear filtering give values within the hull of the image's samples: each
  // channel's and the mapped channels' sum's smallest and largest sample (found once).
  FractionEnclosure enclose(const ParamBox& box, const Box3& xyz) const override;

 private:
  VolumeTexture texture_;
  std::vector<int> channel_materials_;
  std::vector<Interval> channel_range_;  // per channel, over every sample
  Interval sum_range_;                   // of the channels that name a material
  AffineParamMap map_;
};

}  // namespace trivox
