#include "raster/blue_noise.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace trivox {

namespace {

constexpr int kSize = kBlueNoiseTileSize;
constexpr int kCells = kBlueNoiseTileCells;
// The filter reaches this far along each axis; beyond it the Gaussian weight (sigma 1.5) is
// below one unit of the 2^30 scale.
constexpr int kReach = 10;

// exp(-d^2 / (2 sigma^2)) for sigma = 1.5, scaled by 2^30, for d^2 = 0 .. 2 kReach^2: powers
// of q = exp(-1 / 4.5) by fixed-point multiplication (q = 3439140958 / 2^32), so no libm
// routine, and no floating point at all, takes part.
std::vector<std::int64_t> gaussian_table() {
  constexpr std::uint64_t kQ = 3439140958u;
  std::vector<std::int64_t> w(2 * kReach * kReach + 1);
  std::uint64_t value = std::uint64_t{1} << 30;
  for (std::int64_t& entry : w) {
    entry = static_cast<std::int64_t>(value);
    value = (value * kQ + (std::uint64_t{1} << 31)) >> 32;
  }
  return w;
}

// The binary pattern and its filtered energy, updated incrementally (toroidal wrap).
class Pattern {
 public:
  Pattern() : weights_(gaussian_table()), on_(kCells, 0), energy_(kCells, 0) {}

  bool on(int cell) const noexcept { return on_[static_cast<std::size_t>(cell)] != 0; }
  void set(int cell, bool value) {
    on_[static_cast<std::size_t>(cell)] = value ? 1 : 0;
    const int cx = cell % kSize, cy = cell / kSize;
    for (int dy = -kReach; dy <= kReach; ++dy) {
      const int y = (cy + dy + kSize) % kSize;
      for (int dx = -kReach; dx <= kReach; ++dx) {
        const int x = (cx + dx + kSize) % kSize;
        const std::int64_t w = weights_[static_cast<std::size_t>(dx * dx + dy * dy)];
        energy_[static_cast<std::size_t>(y * kSize + x)] += value ? w : -w;
      }
    }
  }
  // The set cell with the highest energy (the tightest cluster), first in row-major order on
  // ties.
  int tightest_cluster() const noexcept { return extreme(true); }
  // The unset cell with the lowest energy (the largest void).
  int largest_void() const noexcept { return extreme(false); }

 private:
  int extreme(bool set_cells) const noexcept {
    int best = -1;
    for (int c = 0; c < kCells; ++c) {
      if (on(c) != set_cells) continue;
      const std::int64_t e = energy_[static_cast<std::size_t>(c)];
      const std::int64_t b = best < 0 ? 0 : energy_[static_cast<std::size_t>(best)];
      if (best < 0 || (set_cells ? e > b : e < b)) best = c;
    }
    return best;
  }

  std::vector<std::int64_t> weights_;
  std::vector<std::uint8_t> on_;
  std::vector<std::int64_t> energy_;
};

std::uint64_t splitmix64(std::uint64_t& state) noexcept {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

std::array<std::uint16_t, kCells> make_tile() {
  // Initial pattern: a tenth of the cells, placed by a fixed pseudo-random sequence, then
  // relaxed by moving the tightest cluster's point into the largest void until that move is
  // a no-op (capped, although it converges in a few hundred moves).
  constexpr int kInitial = kCells / 10;
  Pattern initial;
  std::uint64_t state = 0x7472697630783031ull;
  for (int placed = 0; placed < kInitial;) {
    const auto cell = static_cast<int>(splitmix64(state) % kCells);
    if (initial.on(cell)) continue;
    initial.set(cell, true);
    ++placed;
  }
  for (int move = 0; move < 16 * kCells; ++move) {
    const int cluster = initial.tightest_cluster();
    initial.set(cluster, false);
    const int gap = initial.largest_void();
    initial.set(gap, true);
    if (gap == cluster) break;
  }

  std::array<std::uint16_t, kCells> rank{};
  // Ranks below the initial count: remove the tightest cluster, last rank first.
  Pattern down = initial;
  for (int ones = kInitial; ones > 0; --ones) {
    const int cluster = down.tightest_cluster();
    down.set(cluster, false);
    rank[static_cast<std::size_t>(cluster)] = static_cast<std::uint16_t>(ones - 1);
  }
  // Ranks from the initial count up: fill the largest void. (Past half full this is also
  // the tightest cluster of the unset cells, whose energy is the filter's total minus the
  // set cells' energy.)
  Pattern up = initial;
  for (int ones = kInitial; ones < kCells; ++ones) {
    const int gap = up.largest_void();
    up.set(gap, true);
    rank[static_cast<std::size_t>(gap)] = static_cast<std::uint16_t>(ones);
  }
  return rank;
}

}  // namespace

const std::array<std::uint16_t, kBlueNoiseTileCells>& blue_noise_tile() {
  static const std::array<std::uint16_t, kCells> tile = make_tile();
  return tile;
}

}  // namespace trivox
