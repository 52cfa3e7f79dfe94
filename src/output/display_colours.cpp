#include "trivox/output/display_colours.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace trivox {

namespace {

struct Lab {
  double l, a, b;
};

double linear(double u) noexcept {
  u /= 255.0;
  return u <= 0.04045 ? u / 12.92 : std::pow((u + 0.055) / 1.055, 2.4);
}
double gamma_encoded(double v) noexcept {
  const double u = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
  return std::clamp(u * 255.0, 0.0, 255.0);
}

// D65 reference white and the sRGB primaries (IEC 61966-2-1).
constexpr double kXn = 0.95047, kYn = 1.0, kZn = 1.08883;
constexpr double kDelta = 6.0 / 29.0;

double f(double t) noexcept {
  return t > kDelta * kDelta * kDelta ? std::cbrt(t) : t / (3 * kDelta * kDelta) + 4.0 / 29.0;
}
double f_inverse(double t) noexcept { return t > kDelta ? t * t * t : 3 * kDelta * kDelta * (t - 4.0 / 29.0); }

Lab to_lab(const Rgb& c) noexcept {
  const double r = linear(c[0]), g = linear(c[1]), b = linear(c[2]);
  const double x = 0.4124564 * r + 0.3575761 * g + 0.1804375 * b;
  const double y = 0.2126729 * r + 0.7151522 * g + 0.0721750 * b;
  const double z = 0.0193339 * r + 0.1191920 * g + 0.9503041 * b;
  const double fx = f(x / kXn), fy = f(y / kYn), fz = f(z / kZn);
  return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

Rgb to_rgb(const Lab& c) noexcept {
  const double fy = (c.l + 16.0) / 116.0, fx = fy + c.a / 500.0, fz = fy - c.b / 200.0;
  const double x = kXn * f_inverse(fx), y = kYn * f_inverse(fy), z = kZn * f_inverse(fz);
  const double r = 3.2404542 * x - 1.5371385 * y - 0.4985314 * z;
  const double g = -0.9692660 * x + 1.8760108 * y + 0.0415560 * z;
  const double b = 0.0556434 * x - 0.2040259 * y + 1.0572252 * z;
  return {static_cast<std::uint8_t>(std::lround(gamma_encoded(r))),
          static_cast<std::uint8_t>(std::lround(gamma_encoded(g))),
          static_cast<std::uint8_t>(std::lround(gamma_encoded(b)))};
}

Rgb rgb_of(const Rgba& c) noexcept { return {c[0], c[1], c[2]}; }

// Fallbacks when no lightness works: saturated hues and greys far apart.
constexpr Rgb kSeparated[] = {{230, 25, 75},   {60, 180, 75},  {0, 130, 200},  {245, 130, 48}, {145, 30, 180},
                              {70, 240, 240},  {240, 50, 230}, {210, 245, 60}, {0, 128, 128},  {170, 110, 40},
                              {128, 0, 0},     {0, 0, 128},    {128, 128, 0},  {255, 225, 25}, {0, 0, 0},
                              {128, 128, 128}, {255, 250, 200}};

}  // namespace

double colour_difference(const Rgb& a, const Rgb& b) noexcept {
  const Lab p = to_lab(a), q = to_lab(b);
  return std::sqrt((p.l - q.l) * (p.l - q.l) + (p.a - q.a) * (p.a - q.a) + (p.b - q.b) * (p.b - q.b));
}

std::vector<SimilarColours> similar_colours(const std::vector<Rgba>& materials) {
  std::vector<SimilarColours> pairs;
  for (std::size_t i = 0; i < materials.size(); ++i)
    for (std::size_t j = i + 1; j < materials.size(); ++j) {
      const double d = colour_difference(rgb_of(materials[i]), rgb_of(materials[j]));
      if (d < kDistinctColourDifference) pairs.push_back({static_cast<int>(i), static_cast<int>(j), d});
    }
  return pairs;
}

Rgba preview_background(const std::vector<Rgba>& materials) {
  constexpr Rgba kCandidates[] = {
      {0, 0, 0, 255}, {255, 255, 255, 255}, {64, 64, 64, 255}, {128, 128, 128, 255}, {192, 192, 192, 255}};
  Rgba best = kCandidates[0];
  double best_nearest = -1;
  for (const Rgba& c : kCandidates) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const Rgba& m : materials) nearest = std::min(nearest, colour_difference(rgb_of(c), rgb_of(m)));
    if (nearest >= kDisplayColourSeparation) return c;
    if (nearest > best_nearest) best = c, best_nearest = nearest;
  }
  return best;
}

std::vector<Rgb> display_colours(const std::vector<Rgba>& materials, const Rgba& background) {
  std::vector<Rgb> shown;
  const Rgb back = rgb_of(background);
  const auto distinct_from_shown = [&](const Rgb& c) {
    return colour_difference(c, back) >= kDistinctColourDifference &&
           std::all_of(shown.begin(), shown.end(),
                       [&](const Rgb& s) { return colour_difference(c, s) >= kDistinctColourDifference; });
  };
  for (const Rgba& m : materials) {
    const Rgb own = rgb_of(m);
    if (distinct_from_shown(own)) {  // the usual case: the material's own colour
      shown.push_back(own);
      continue;
    }
    const auto acceptable = [&](const Rgb& c) {
      return colour_difference(c, back) >= kDisplayColourSeparation &&
             std::all_of(shown.begin(), shown.end(),
                         [&](const Rgb& s) { return colour_difference(c, s) >= kDisplayColourSeparation; });
    };
    const Lab lab = to_lab(own);
    Rgb chosen = own;
    bool found = false;
    for (int step = 1; step <= 6 && !found; ++step)
      for (int sign : {-1, 1}) {
        const double l = lab.l + sign * 15.0 * step;
        if (l < 0.0 || l > 100.0) continue;
        const Rgb c = to_rgb({l, lab.a, lab.b});
        if (acceptable(c)) {
          chosen = c;
          found = true;
          break;
        }
      }
    for (const Rgb& c : kSeparated) {
      if (found) break;
      if (acceptable(c)) {
        chosen = c;
        found = true;
      }
    }
    shown.push_back(chosen);  // beyond every fallback (dozens of materials): the own colour
  }
  return shown;
}

}  // namespace trivox
