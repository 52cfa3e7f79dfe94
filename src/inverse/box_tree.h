// A bounding-volume hierarchy over a fixed list of boxes: which boxes hold a point, without
// testing every one. The global solver asks it for the Bezier pieces whose control box holds
// x; a finely knotted volume has thousands of pieces (the untangled duck: 6479), of which a
// handful hold any given point, and the solver runs for every pixel just outside a cell.
#pragma once

#include <vector>

#include "trivox/math.h"

namespace trivox::detail {

class BoxTree {
 public:
  BoxTree() = default;
  explicit BoxTree(std::vector<Box3> boxes);

  // Appends to `out`, in increasing order, the index of every box b with b.contains(p, tol):
  // exactly what testing all boxes in order gives. A node's box holds its children's, so a
  // point within tol of a child's box is within tol of every box above it.
  void query(Vec3 p, double tol, std::vector<int>& out) const;

  std::size_t size() const noexcept { return boxes_.size(); }

 private:
  struct Node {
    Box3 box;       // union of the boxes below
    int first = 0;  // leaf: its boxes are order_[first, first + count)
    int count = 0;  // 0 for an inner node, whose children are this + 1 and nodes_[right]
    int right = 0;
  };
  int build(int first, int count);

  std::vector<Box3> boxes_;
  std::vector<int> order_;
  std::vector<Node> nodes_;
};

}  // namespace trivox::detail
