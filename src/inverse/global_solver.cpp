// Global inversion by subdivision (the role of the paper's multivariate solver [11]):
// prune Bezier pieces whose control box misses x (or that a plane through x separates from
// it), prune boxes where Krawczyk's operator excludes a root, prove one-to-one boxes with
// the same interval Jacobian and run Newton there, split the rest, and classify what was
// found.
#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include "bezier_net.h"
#include "box_tree.h"
#include "newton.h"
#include "trivox/error.h"
#include "trivox/inverse/invert.h"
#include "trivox/spline/refine.h"

namespace trivox {

namespace {

// A box whose image is at most this many residual tolerances across, and whose centre is
// joined to a root already found, is not searched (GlobalSolver::solve): small enough that
// it cannot hold a second, separate regular root beside one at its centre, and large enough
// to stop the splitting along a collapsed set early.
constexpr double kJoinedImage = 100.0;

}  // namespace

std::string_view to_string(GlobalStatus s) noexcept {
  switch (s) {
    case GlobalStatus::kNone: return "none";
    case GlobalStatus::kUnique: return "unique";
    case GlobalStatus::kMultiple: return "multiple";
    case GlobalStatus::kDegenerate: return "degenerate";
    case GlobalStatus::kIncomplete: return "incomplete";
  }
  return "unknown";
}

// The volume's Bezier pieces in the order of their parameters (u fastest), and an index of
// their control boxes: the search starts from the pieces whose box holds x.
struct GlobalSolver::Pieces {
  std::vector<detail::BezierNet> nets;
  detail::BoxTree index;
};

GlobalSolver::GlobalSolver(const Volume& volume) : volume_(&volume) {
  auto pieces = std::make_unique<Pieces>();
  std::vector<Box3> bounds;
  for (const TensorSpline& piece : bezier_patches(volume.spline())) {
    detail::BezierNet net;
    for (int d = 0; d < 3; ++d) {
      net.order[static_cast<std::size_t>(d)] = piece.knots(d).order();
      net.box.lo[d] = piece.lo(d);
      net.box.hi[d] = piece.hi(d);
    }
    net.h.resize(static_cast<std::size_t>(piece.total_ctrl()));
    net.polynomial = true;
    for (int k = 0; k < piece.num_ctrl(2); ++k)
      for (int j = 0; j < piece.num_ctrl(1); ++j)
        for (int i = 0; i < piece.num_ctrl(0); ++i) {
          const auto p = piece.point(i, j, k);
          const double w = piece.weight(i, j, k);
          net.at(i, j, k) = {w * p[0], w * p[1], w * p[2], w};
          net.polynomial = net.polynomial && w == 1.0;
        }
    bounds.push_back(net.bounds());
    pieces->nets.push_back(std::move(net));
  }
  pieces->index = detail::BoxTree(std::move(bounds));
  pieces_ = std::move(pieces);
  // Typical |det J| (mean over a 5^3 grid) sets the scale for calling a root singular.
  const ParamBox& dom = volume.domain();
  double sum = 0.0;
  for (int k = 0; k < 5; ++k)
    for (int j = 0; j < 5; ++j)
      for (int i = 0; i < 5; ++i) {
        const Vec3 t{dom.lo.x + (i + 0.5) / 5 * dom.size().x, dom.lo.y + (j + 0.5) / 5 * dom.size().y,
                     dom.lo.z + (k + 0.5) / 5 * dom.size().z};
        Vec3 p;
        Mat3 J;
        volume.evaluate_jacobian(t, p, J);
        sum += std::abs(J.determinant());
      }
  typical_abs_det_ = sum > 0 ? sum / 125.0 : 1.0;
}

GlobalSolver::~GlobalSolver() = default;
GlobalSolver::GlobalSolver(GlobalSolver&&) noexcept = default;
GlobalSolver& GlobalSolver::operator=(GlobalSolver&&) noexcept = default;

namespace {

// Per-thread scratch of GlobalSolver::solve, so that a solve allocates nothing once its
// thread has solved a few: a pool of nets (the stack holds their indices; a finished box's
// net goes back to the free list and its storage is reused by the next halving).
struct Scratch {
  std::vector<detail::BezierNet> nets;
  std::vector<int> free, stack, first_pieces;
  std::vector<char> singular;  // per preimage, while classifying them
  std::vector<int> set_of;     // per preimage: another of its collapsed set (union-find)
  std::vector<Preimage> found;
  // Roots with a box joined to them farther away than roots merge: on a collapsed set.
  std::vector<Vec3> collapsed;
};

// One solve for one point x: its tolerances, the separating plane of the hint, and the three
// steps that read them, in the order solve() takes them: search (the subdivision, which
// collects Newton roots), merge (roots found twice become one, in (u, v, w) order) and
// classify (collapsed sets, singular roots, the status).
class Solve {
 public:
  Solve(const Volume& volume, Vec3 x, const GlobalSolveParams& params, std::optional<Vec3> outward, Scratch& sc)
      : volume_(volume),
        x_(x),
        params_(params),
        sc_(sc),
        dom_(volume.domain()),
        tol_(params.newton.residual_tolerance_model),
        // Boxes are kept when x is within the tolerance (plus rounding of the box itself).
        box_tol_(tol_ + 1e-12 * volume.bounds().diagonal()),
        dom_size_(dom_.size()),
        joined_tol_(10 * tol_) {
    // The separating plane's unit normal and offset (a zero hint is ignored).
    if (outward && norm(*outward) > 0 && std::isfinite(norm(*outward))) {
      normal_ = (1.0 / norm(*outward)) * *outward;
      use_plane_ = true;
    }
    plane_ = dot(normal_, x) - box_tol_;
    sc.free.clear();
    sc.stack.clear();
    sc.found.clear();
    sc.collapsed.clear();
    sc.first_pieces.clear();
    for (int i = static_cast<int>(sc.nets.size()) - 1; i >= 0; --i) sc.free.push_back(i);
  }

  // The subdivision from the pieces whose control box holds x: Newton roots into the
  // scratch's `found`, the boxes it visited into `boxes_visited`. False when it stopped at
  // params.max_boxes.
  bool search(const std::vector<detail::BezierNet>& pieces, const detail::BoxTree& index, int& boxes_visited);
  // The roots found, each once, in (u, v, w) order.
  void merge(std::vector<Preimage>& preimages);
  // Joins the preimages on one collapsed set, keeps each set's first, and sets the status.
  void classify(GlobalResult& result, double typical_abs_det, bool exhausted);

 private:
  int acquire() {
    if (sc_.free.empty()) {
      sc_.nets.emplace_back();
      return static_cast<int>(sc_.nets.size()) - 1;
    }
    const int id = sc_.free.back();
    sc_.free.pop_back();
    return id;
  }
  bool try_newton(const ParamBox& box);
  // Whether V maps the points at 1/4, 1/2 and 3/4 of the segment from a to b within 10 times
  // the tolerance of x (and b itself, when asked): a and b lie on one connected set of
  // (nearly) preimages of x, such as a face or edge collapsed onto x.
  bool joined(Vec3 a, Vec3 b, bool check_b) const {
    if (check_b && norm(volume_.evaluate(b) - x_) > joined_tol_) return false;
    for (double s : {0.25, 0.5, 0.75})
      if (norm(volume_.evaluate((1 - s) * a + s * b) - x_) > joined_tol_) return false;
    return true;
  }
  bool same_root(Vec3 a, Vec3 b) const {
    for (int d = 0; d < 3; ++d)
      if (std::abs(a[d] - b[d]) > params_.same_root_relative * dom_size_[d]) return false;
    return true;
  }
  bool on_collapsed_set(Vec3 r) const {
    return std::any_of(sc_.collapsed.begin(), sc_.collapsed.end(), [&](Vec3 c) { return c == r; });
  }
  bool joined_to_found(Vec3 c);
  void split(int id, const detail::BezierNet& net, Vec3 psize);
  int root_of(int i) const {
    while (sc_.set_of[static_cast<std::size_t>(i)] != i) i = sc_.set_of[static_cast<std::size_t>(i)];
    return i;
  }

  const Volume& volume_;
  const Vec3 x_;
  const GlobalSolveParams& params_;
  Scratch& sc_;
  const ParamBox& dom_;
  const double tol_, box_tol_;
  const Vec3 dom_size_;
  const double joined_tol_;
  Vec3 normal_{};
  bool use_plane_ = false;
  double plane_ = 0.0;
};

bool Solve::try_newton(const ParamBox& box) {
  const InverseResult r = detail::newton_in_box(volume_, x_, box.center(), dom_, params_.newton);
  if (r.status != InverseStatus::kConverged) return false;
  // Keep the root only when it lies in this box (up to a sliver): a root elsewhere is
  // found again by the box that holds it.
  Vec3 slack;
  for (int d = 0; d < 3; ++d) slack[d] = 1e-9 * dom_size_[d];
  if (!ParamBox{box.lo - slack, box.hi + slack}.contains(r.uvw)) return false;
  Vec3 p;
  Mat3 J;
  volume_.evaluate_jacobian(r.uvw, p, J);
  sc_.found.push_back({r.uvw, r.residual, J.determinant()});
  return true;
}

// A box joined to a root may hold a second root of the same set, farther from it than
// roots merge (a collapsed edge, or a singular point where V is flat to second order):
// Newton from the box's centre finds it, as the box's own search would have. Then the root
// lies on a collapsed set, as the classification would find from the two roots. Once a root
// is known to lie on one, its other joined boxes need no Newton run.
bool Solve::joined_to_found(Vec3 c) {
  for (const Preimage& r : sc_.found) {
    if (!joined(r.uvw, c, true)) continue;
    if (!same_root(r.uvw, c) && !on_collapsed_set(r.uvw)) {
      const InverseResult n = detail::newton_in_box(volume_, x_, c, dom_, params_.newton);
      if (n.status == InverseStatus::kConverged && !same_root(r.uvw, n.uvw) && joined(r.uvw, n.uvw, false))
        sc_.collapsed.push_back(r.uvw);
    }
    return true;
  }
  return false;
}

// Halves box `id` (whose net is `net`, on the free list) along its longest extent among the
// directions not yet split to nothing, and pushes the halves, left on top.
void Solve::split(int id, const detail::BezierNet& net, Vec3 psize) {
  int split_dir = 0;
  double best = -1.0;
  const std::array<double, 3> lengths = net.extents();
  for (int d = 0; d < 3; ++d) {
    const double e = lengths[static_cast<std::size_t>(d)];
    if (e > best && psize[d] > 1e-12 * dom_size_[d]) {
      best = e;
      split_dir = d;
    }
  }
  // The parent is on the free list; keep it out of the halves' way (acquire() may also
  // grow the pool, which moves the nets, so the parent is looked up again).
  sc_.free.pop_back();
  const int left = acquire(), right = acquire();
  sc_.nets[static_cast<std::size_t>(id)].halve_into(split_dir, sc_.nets[static_cast<std::size_t>(left)],
                                                    sc_.nets[static_cast<std::size_t>(right)]);
  sc_.free.push_back(id);
  sc_.stack.push_back(right);
  sc_.stack.push_back(left);
}

bool Solve::search(const std::vector<detail::BezierNet>& pieces, const detail::BoxTree& index, int& boxes_visited) {
  // Depth-first over a stack; pieces are pushed in reverse so that they pop in order,
  // which keeps the search (and so its result) deterministic.
  index.query(x_, box_tol_, sc_.first_pieces);
  for (auto it = sc_.first_pieces.rbegin(); it != sc_.first_pieces.rend(); ++it) {
    const detail::BezierNet& piece = pieces[static_cast<std::size_t>(*it)];
    // The plane test of the loop below, made before copying the net.
    if (use_plane_ && piece.max_along(normal_) < plane_) continue;
    const int id = acquire();
    sc_.nets[static_cast<std::size_t>(id)] = piece;
    sc_.stack.push_back(id);
  }

  while (!sc_.stack.empty()) {
    const int id = sc_.stack.back();
    sc_.stack.pop_back();
    sc_.free.push_back(id);  // its net stays valid until the next acquire()
    const detail::BezierNet& net = sc_.nets[static_cast<std::size_t>(id)];
    const Box3 b = net.bounds();
    if (!b.contains(x_, box_tol_)) continue;
    if (use_plane_ && net.max_along(normal_) < plane_) continue;
    if (++boxes_visited > params_.max_boxes) return false;
    if (params_.stop != nullptr && boxes_visited % 64 == 0 && params_.stop->load(std::memory_order_relaxed))
      throw CancelledError("stopped during a global solve");
    // A small box whose centre is joined to a root already found (see joined()) lies on that
    // root's collapsed set, or at the root itself: what it holds is that root again. Near a
    // collapsed edge the set of parameters that map within the tolerance of x is a long thin
    // region, and without this every box along it would be split down to a leaf whose Newton
    // run adds one more near-duplicate root (thousands, past the box budget).
    if (!sc_.found.empty() && b.diagonal() <= kJoinedImage * tol_ && joined_to_found(net.box.center())) continue;
    // A box whose image is below the tolerance is a leaf: whatever root it holds is found by
    // Newton from its centre.
    const Vec3 psize = net.box.size();
    const bool tiny = b.diagonal() <= tol_ || (psize.x <= 1e-12 * dom_size_.x && psize.y <= 1e-12 * dom_size_.y &&
                                               psize.z <= 1e-12 * dom_size_.z);
    if (tiny) {
      try_newton(net.box);
      continue;
    }
    Mat3 lo, hi;
    if (net.jacobian_bounds(lo, hi, b)) {
      Vec3 p;
      Mat3 Jc;
      volume_.evaluate_jacobian(net.box.center(), p, Jc);
      const detail::BoxVerdict verdict = detail::krawczyk_verdict(net.box, lo, hi, Jc, p, x_, box_tol_);
      if (verdict == detail::BoxVerdict::kNoRoot) continue;
      if (verdict == detail::BoxVerdict::kInjective && try_newton(net.box)) continue;  // its only root
    }
    split(id, net, psize);
  }
  return true;
}

void Solve::merge(std::vector<Preimage>& preimages) {
  std::vector<Preimage>& found = sc_.found;
  std::sort(found.begin(), found.end(), [](const Preimage& a, const Preimage& b) {
    return std::tie(a.uvw.x, a.uvw.y, a.uvw.z) < std::tie(b.uvw.x, b.uvw.y, b.uvw.z);
  });
  for (const Preimage& p : found) {
    const bool duplicate =
        std::any_of(preimages.begin(), preimages.end(), [&](const Preimage& q) { return same_root(p.uvw, q.uvw); });
    if (!duplicate) preimages.push_back(p);
  }
}

// Two preimages joined by a segment that V maps onto x lie on one degenerate set (a face or
// edge collapsed to a point or line), not on two sheets of a fold. Each such set is reported
// once, by its first preimage in (u, v, w) order; it is singular. A preimage on its own is
// singular when |det J| is below the threshold.
void Solve::classify(GlobalResult& result, double typical_abs_det, bool exhausted) {
  const std::size_t n = result.preimages.size();
  std::vector<char>& singular = sc_.singular;
  std::vector<int>& set_of = sc_.set_of;
  singular.assign(n, 0);
  set_of.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    set_of[i] = static_cast<int>(i);
    singular[i] = !(std::abs(result.preimages[i].det) > params_.singular_relative * typical_abs_det);
  }
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      if (root_of(static_cast<int>(i)) == root_of(static_cast<int>(j))) continue;
      if (!joined(result.preimages[i].uvw, result.preimages[j].uvw, false)) continue;
      const int a = root_of(static_cast<int>(i)), b = root_of(static_cast<int>(j));
      set_of[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);  // the first stays the set's
      singular[static_cast<std::size_t>(std::min(a, b))] = 1;
    }
  // A root that a distant box was joined to during the search lies on a collapsed set too,
  // even when no second root of that set was kept.
  for (const Vec3& c : sc_.collapsed)
    for (std::size_t i = 0; i < n; ++i)
      if (same_root(c, result.preimages[i].uvw)) {
        singular[static_cast<std::size_t>(root_of(static_cast<int>(i)))] = 1;
        break;
      }
  std::size_t kept = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (root_of(static_cast<int>(i)) == static_cast<int>(i)) {
      result.preimages[kept] = result.preimages[i];
      singular[kept] = singular[i];
      ++kept;
    }
  result.preimages.resize(kept);
  int regular = 0;
  for (std::size_t i = 0; i < kept; ++i)
    if (!singular[i]) ++regular;
  if (exhausted)
    result.status = GlobalStatus::kIncomplete;
  else if (result.preimages.empty())
    result.status = GlobalStatus::kNone;
  else if (regular >= 2)
    result.status = GlobalStatus::kMultiple;
  else if (regular == 1)
    result.status = GlobalStatus::kUnique;
  else
    result.status = GlobalStatus::kDegenerate;
}

}  // namespace

GlobalResult GlobalSolver::solve(Vec3 x, const GlobalSolveParams& params, std::optional<Vec3> outward) const {
  thread_local Scratch scratch;
  Solve solve(*volume_, x, params, outward, scratch);
  GlobalResult result;
  const bool exhausted = !solve.search(pieces_->nets, pieces_->index, result.boxes_visited);
  solve.merge(result.preimages);
  solve.classify(result, typical_abs_det_, exhausted);
  return result;
}

namespace {

// The largest dot(direction, V) over the nets' images, to within `tolerance`, from above.
double supremum_along(const std::vector<detail::BezierNet>& pieces, Vec3 direction, double tolerance,
                      std::int64_t max_points) {
  struct Entry {
    double upper;  // max_along(direction) of the net's control points
    std::size_t order;
    detail::BezierNet net;
  };
  // The net with the largest bound first; equal bounds in the order they were made, so the
  // search (and the box it gives) does not depend on the heap's ties.
  auto later = [](const Entry& a, const Entry& b) {
    return a.upper < b.upper || (a.upper == b.upper && a.order > b.order);
  };
  std::vector<Entry> heap;
  double attained = -HUGE_VAL;  // the largest value at a point of the image seen so far
  std::size_t made = 0;
  auto push = [&](detail::BezierNet net) {
    // A Bezier net's corner control points lie on the volume: exact values of the image.
    for (int k : {0, net.order[2] - 1})
      for (int j : {0, net.order[1] - 1})
        for (int i : {0, net.order[0] - 1})
          attained = std::max(
              attained,
              dot(direction, net.euclidean(static_cast<std::size_t>(i + net.order[0] * (j + net.order[1] * k)))));
    const double upper = net.max_along(direction);
    heap.push_back({upper, made++, std::move(net)});
    std::push_heap(heap.begin(), heap.end(), later);
  };
  for (const detail::BezierNet& net : pieces) push(net);
  for (std::int64_t work = 0; !heap.empty();) {
    std::pop_heap(heap.begin(), heap.end(), later);
    Entry top = std::move(heap.back());
    heap.pop_back();
    // Every net left is bounded by top.upper; the image reaches `attained`.
    if (top.upper - attained <= tolerance || work >= max_points) return top.upper;
    work += static_cast<std::int64_t>(top.net.h.size());
    const std::array<double, 3> extent = top.net.extents();
    const int d = static_cast<int>(std::max_element(extent.begin(), extent.end()) - extent.begin());
    auto halves = top.net.halve(d);
    push(std::move(halves[0]));
    push(std::move(halves[1]));
  }
  return attained;
}

}  // namespace

Box3 GlobalSolver::image_bounds(double tolerance_model, std::int64_t max_points) const {
  Box3 box;
  if (pieces_->nets.empty()) return box;
  for (int a = 0; a < 3; ++a) {
    Vec3 e{};
    e[a] = 1.0;
    box.hi[a] = supremum_along(pieces_->nets, e, tolerance_model, max_points);
    box.lo[a] = -supremum_along(pieces_->nets, -1.0 * e, tolerance_model, max_points);
  }
  // The bounds hold the exact image; evaluating V rounds, by a few units in the last place of
  // the coordinates, so the box is widened by that much to hold every evaluated point too.
  double magnitude = 0;
  for (int a = 0; a < 3; ++a) magnitude = std::max({magnitude, std::abs(box.lo[a]), std::abs(box.hi[a])});
  const double pad = 64 * std::numeric_limits<double>::epsilon() * magnitude;
  box = Box3{box.lo - Vec3{pad, pad, pad}, box.hi + Vec3{pad, pad, pad}};
  return box;
}

}  // namespace trivox
