// The per-voxel hot path allocates nothing: Volume::evaluate, Volume::evaluate_jacobian,
// invert() and invert_from_neighbour() run without a single call to operator new, and the
// global solver, once its thread has warmed its scratch, allocates only the preimages it
// returns. This file
// is a program of its own (trivox_alloc_tests) because it replaces the global allocation
// functions with counting ones, which would count every other test's allocations too.
#include <atomic>
#include <cstdlib>
#include <new>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "support/test_support.h"
#include "trivox/inverse/invert.h"
#include "trivox/spline/volume.h"

namespace {
std::atomic<long> g_allocations{0};

void* counted(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}

void* counted_aligned(std::size_t size, std::align_val_t align) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  const auto a = static_cast<std::size_t>(align);
  if (void* p = std::aligned_alloc(a, (size + a - 1) / a * a + (size == 0 ? a : 0))) return p;
  throw std::bad_alloc();
}
}  // namespace

void* operator new(std::size_t size) { return counted(size); }
void* operator new[](std::size_t size) { return counted(size); }
void* operator new(std::size_t size, std::align_val_t align) { return counted_aligned(size, align); }
void* operator new[](std::size_t size, std::align_val_t align) { return counted_aligned(size, align); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

namespace trivox {
namespace {

// Keeps results alive so that the calls are not optimised away.
volatile double g_sink = 0.0;

TEST(HotPathAllocations, TheCounterSeesAnAllocation) {
  const long before = g_allocations.load();
  std::vector<double> buffer(static_cast<std::size_t>(g_sink) + 16);
  g_sink = buffer.data()[3];
  EXPECT_GE(g_allocations.load() - before, 1);
}

struct Case {
  const char* name;
  Volume volume;
};

TEST(HotPathAllocations, EvaluationAndNewtonAllocateNothing) {
  VolumeOptions de_boor;
  de_boor.power_form = false;
  const Volume cubic = test::twisted_bent_box(40, 30, 60);
  std::vector<Case> cases;
  cases.push_back({"cubic, power form", cubic});
  cases.push_back({"cubic, de Boor", Volume(cubic.spline(), de_boor)});
  cases.push_back({"order 6, de Boor", test::twisted_bent_box(3, 2, 1, 9, 6)});
  cases.push_back({"rational annulus sector", test::annulus_sector(1.0, 2.0, 0.7)});
  std::mt19937 rng(48);
  std::uniform_real_distribution<double> U(0.05, 0.95);
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const Volume& v = c.volume;
    // Inputs prepared before counting: parameters, the points there, and neighbours.
    std::vector<Vec3> params, points;
    std::vector<NeighbourSolution> neighbours;
    for (int s = 0; s < 2000; ++s) {
      const Vec3 t{U(rng), U(rng), U(rng)};
      params.push_back(t);
      points.push_back(v.evaluate(t));
      const Vec3 n{t.x + 0.003, t.y - 0.002, t.z};
      NeighbourSolution ns{n, {}, {}};
      v.evaluate_jacobian(n, ns.x, ns.jacobian);
      neighbours.push_back(ns);
    }
    int converged = 0;
    double sum = 0.0;
    const long before = g_allocations.load();
    for (std::size_t s = 0; s < params.size(); ++s) {
      const Vec3 p = v.evaluate(params[s]);
      Vec3 q;
      Mat3 J;
      v.evaluate_jacobian(params[s], q, J);
      const InverseResult a = invert(v, points[s], v.domain().center());
      Mat3 next;
      const InverseResult b = invert_from_neighbour(v, points[s], neighbours[s], {}, &next);
      converged += (a.status == InverseStatus::kConverged) + (b.status == InverseStatus::kConverged);
      sum += p.x + q.y + J.m[2][2] + a.uvw.x + b.uvw.y + next.m[0][0];
    }
    const long allocations = g_allocations.load() - before;
    g_sink = sum;
    EXPECT_EQ(allocations, 0);
    EXPECT_EQ(converged, 2 * static_cast<int>(params.size()));  // the work was done
  }
}

// The slicer's global solves mostly prove a pixel just outside a face: each subdivides a
// few pieces, and the nets it halves come from per-thread scratch, so after a warm-up such a
// solve (no preimage to return) allocates nothing; one that finds a preimage allocates its
// result only.
TEST(HotPathAllocations, GlobalSolvesAllocateOnlyTheirResult) {
  const Volume v = test::twisted_bent_box(40, 30, 60);
  const GlobalSolver solver(v);
  std::mt19937 rng(52);
  std::uniform_real_distribution<double> U(0.05, 0.95);
  std::vector<Vec3> outside, normals, inside;
  for (int s = 0; s < 300; ++s) {
    const Vec3 t{U(rng), U(rng), 1.0};  // on the face w = 1, which faces +w
    Vec3 p;
    Mat3 J;
    v.evaluate_jacobian(t, p, J);
    Vec3 n = cross(J.column(0), J.column(1));
    if (dot(n, J.column(2)) < 0) n = -1.0 * n;
    n = (1.0 / norm(n)) * n;
    outside.push_back(p + 0.01 * n);
    normals.push_back(n);
    inside.push_back(v.evaluate({U(rng), U(rng), U(rng)}));
  }
  auto solve_all = [&](bool count) {
    int none = 0, unique = 0;
    long outside_allocations = 0, inside_allocations = 0;
    for (std::size_t s = 0; s < outside.size(); ++s) {
      const long before = g_allocations.load();
      const GlobalResult a = solver.solve(outside[s], {}, normals[s]);
      outside_allocations += g_allocations.load() - before;
      none += a.status == GlobalStatus::kNone;
      const long middle = g_allocations.load();
      const GlobalResult b = solver.solve(inside[s]);
      inside_allocations += g_allocations.load() - middle;
      unique += b.status == GlobalStatus::kUnique;
    }
    if (count) {
      EXPECT_EQ(outside_allocations, 0);
      EXPECT_LE(inside_allocations, static_cast<long>(inside.size()));  // the one preimage each
      EXPECT_EQ(none, static_cast<int>(outside.size()));                // the work was done
      EXPECT_EQ(unique, static_cast<int>(inside.size()));
    }
  };
  solve_all(false);  // warms this thread's scratch
  solve_all(true);
}

}  // namespace
}  // namespace trivox
