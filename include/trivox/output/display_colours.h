// Colours for a person to look at: how far apart two material colours look (CIE76 colour
// difference in CIELAB, D65), and the opaque display colours previews use, chosen so that no
// two materials look alike there even when their image colours do (VeroWhite and
// Agilus30White differ by about 3: a person cannot tell them apart in a dithered preview).
// The printer images keep the exact colours; only previews use the display colours.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace trivox {

using Rgb = std::array<std::uint8_t, 3>;
using Rgba = std::array<std::uint8_t, 4>;

// Below this colour difference two materials count as nearly equal: hard to tell apart in a
// preview, where dithering mixes them voxel by voxel. (A difference of about 2.3 is the
// smallest a person notices side by side on large patches.)
inline constexpr double kDistinctColourDifference = 10.0;

// A display colour chosen to replace a nearly equal one keeps at least this difference from
// the other materials' and the background: clearly apart at a glance.
inline constexpr double kDisplayColourSeparation = 25.0;

// CIE76 colour difference (Euclidean distance in CIELAB, D65 white) of two sRGB colours.
double colour_difference(const Rgb& a, const Rgb& b) noexcept;

// Two materials (indices into the list) whose colours differ by less than
// kDistinctColourDifference, with that difference.
struct SimilarColours {
  int first = 0, second = 0;  // first < second
  double difference = 0;
};
// Every such pair, in order of (first, second). Alpha is ignored: previews are opaque.
std::vector<SimilarColours> similar_colours(const std::vector<Rgba>& materials);

// The background of the previews (a person's view, not the printer's images, which keep the
// background their format needs): the first of black, white, and the greys 64, 128 and 192
// that is at least kDisplayColourSeparation from every material's colour; when none is, the
// one farthest from its nearest material. A dark material (Agilus30Black, #282828) is then
// shown on white, not lost on black.
Rgba preview_background(const std::vector<Rgba>& materials);

// The preview colour of every material: its own RGB, unless it is nearly equal to the display
// colour of an earlier material or to the background; then the first colour at least kDisplayColourSeparation from
// every earlier material's display colour and from the background, found by changing its
// CIELAB lightness in steps of 15 (darker first), then from a fixed list of well-separated
// colours. Deterministic.
std::vector<Rgb> display_colours(const std::vector<Rgba>& materials, const Rgba& background);

}  // namespace trivox
