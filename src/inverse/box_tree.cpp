#include "box_tree.h"

#include <algorithm>
#include <numeric>

namespace trivox::detail {

namespace {
constexpr int kLeafBoxes = 4;
}  // namespace

BoxTree::BoxTree(std::vector<Box3> boxes) : boxes_(std::move(boxes)), order_(boxes_.size()) {
  std::iota(order_.begin(), order_.end(), 0);
  if (!boxes_.empty()) {
    nodes_.reserve(2 * boxes_.size());
    build(0, static_cast<int>(boxes_.size()));
  }
}

int BoxTree::build(int first, int count) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Box3 box, centres;
  for (int i = first; i < first + count; ++i) {
    const Box3& b = boxes_[static_cast<std::size_t>(order_[static_cast<std::size_t>(i)])];
    box.expand(b);
    if (!b.empty()) centres.expand(0.5 * (b.lo + b.hi));
  }
  nodes_[static_cast<std::size_t>(index)].box = box;
  if (count <= kLeafBoxes || centres.empty()) {
    nodes_[static_cast<std::size_t>(index)].first = first;
    nodes_[static_cast<std::size_t>(index)].count = count;
    return index;
  }
  // Median split along the widest spread of the centres; ties broken by index so that the
  // tree (and nothing else: queries sort their answer) is the same on every run.
  const Vec3 spread = centres.size();
  const int axis = spread.x >= spread.y && spread.x >= spread.z ? 0 : (spread.y >= spread.z ? 1 : 2);
  const int half = count / 2;
  const auto begin = order_.begin() + first;
  std::nth_element(begin, begin + half, begin + count, [&](int a, int b) {
    const Box3& ba = boxes_[static_cast<std::size_t>(a)];
    const Box3& bb = boxes_[static_cast<std::size_t>(b)];
    const double ca = ba.lo[axis] + ba.hi[axis], cb = bb.lo[axis] + bb.hi[axis];
    return ca < cb || (ca == cb && a < b);
  });
  build(first, half);
  const int right = build(first + half, count - half);
  nodes_[static_cast<std::size_t>(index)].right = right;
  return index;
}

void BoxTree::query(Vec3 p, double tol, std::vector<int>& out) const {
  if (nodes_.empty()) return;
  const std::size_t start = out.size();
  int stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[static_cast<std::size_t>(stack[--top])];
    if (!node.box.contains(p, tol)) continue;
    if (node.count > 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        const int b = order_[static_cast<std::size_t>(i)];
        if (boxes_[static_cast<std::size_t>(b)].contains(p, tol)) out.push_back(b);
      }
      continue;
    }
    const int left = static_cast<int>(&node - nodes_.data()) + 1;
    stack[top++] = node.right;
    stack[top++] = left;
  }
  std::sort(out.begin() + static_cast<std::ptrdiff_t>(start), out.end());
}

}  // namespace trivox::detail
