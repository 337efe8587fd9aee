// Reinsertion optimisation (bvh/bvh2_reinsertion.h). Each pass takes the
// nodes of largest area as candidates and, in parallel, finds for each the
// place where moving it lowers the SAH cost most; then applies the moves in
// order of gain, one at a time, each checked on the tree as it then stands.
// A node whose search found nothing is settled: no candidate again until a
// move involves it, so later passes reach further down the areas (the same
// large nodes would mostly find nothing again).
//
// Moving node A (parent P, sibling B) next to node C: P goes away and B
// takes its place; a new inner node N with children A and C takes C's place.
// In the array, B's node moves into P's slot, C's into B's slot (beside A,
// so N's children stay side by side) and N into C's slot. The cost changes
// by the areas of inner nodes only: -area(P), +area(N), and the ancestors of
// P shrink while those of C (below their common ancestor) grow.
//
// The search for C (Bittner et al. 2013; madmann91/bvh's v2 reinsertion
// optimizer searches the same way): climbing from P, at each ancestor X the
// subtree beside the path is searched, where the gain available is area(P)
// plus how much the ancestors below X shrink once A is gone; descending into
// it, each node the move passes costs its growth by A, and a branch whose
// remaining gain cannot beat the best move found, even with N as small as A,
// is cut.
#include "raybench/bvh/bvh2_reinsertion.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace raybench {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
// A move must lower the cost by more than this fraction of the root's area:
// far above the rounding of Bvh2::sah_cost's sum (about n 2^-53 of it), so
// the cost it reports never rises, and far below any move worth making.
constexpr double kMinGain = 1e-6;

BBox merged(const BBox& a, const BBox& b) {
  BBox m = a;
  m.extend(b);
  return m;
}

double area(const BBox& b) { return b.half_area(); }  // in float, as Bvh2::sah_cost sums it

struct Move {
  std::uint32_t from = 0, to = kNone;  // node A, and node C it goes next to
  double gain = 0.0;                   // the cost's drop, area-weighted
};

class Reinserter {
 public:
  Reinserter(Bvh2& bvh, int max_depth)
      : nodes_(bvh.nodes),
        max_depth_(max_depth),
        parents_(nodes_.size(), kNone),
        heights_(nodes_.size(), 0),
        touched_(nodes_.size(), 0),
        settled_(nodes_.size(), 0),
        new_box_slot_(nodes_.size(), -1) {
    // Parents, and heights bottom-up (children come after their parent in
    // this breadth-first order).
    std::vector<std::uint32_t> order{0};
    for (std::size_t i = 0; i < order.size(); ++i) {
      const Bvh2Node& n = nodes_[order[i]];
      if (n.is_leaf()) continue;
      for (std::uint32_t c : {n.first_index, n.first_index + 1}) {
        parents_[c] = order[i];
        order.push_back(c);
      }
    }
    for (auto it = order.rbegin(); it != order.rend(); ++it) update_height(*it);
    reachable_ = std::move(order);
    root_area_ = area(nodes_[0].bounds);
  }

  // One pass; adds the moves made to `made`. False if there was no
  // candidate left to try.
  bool pass(float batch_fraction, std::size_t& made) {
    // Candidates: the nodes of largest area (ties by index), the root and
    // settled nodes excepted.
    std::vector<std::uint32_t> candidates;
    for (std::size_t i = 1; i < reachable_.size(); ++i)
      if (!settled_[reachable_[i]]) candidates.push_back(reachable_[i]);
    if (candidates.empty()) return false;
    const auto batch = std::clamp<std::size_t>(
        static_cast<std::size_t>(static_cast<double>(reachable_.size() - 1) * batch_fraction), 1, candidates.size());
    const auto larger = [&](std::uint32_t a, std::uint32_t b) {
      const float aa = nodes_[a].bounds.half_area(), ab = nodes_[b].bounds.half_area();
      return aa != ab ? aa > ab : a < b;
    };
    std::nth_element(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(batch - 1), candidates.end(),
                     larger);
    candidates.resize(batch);
    std::sort(candidates.begin(), candidates.end(), larger);

    std::vector<Move> moves(candidates.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, candidates.size()),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        std::vector<std::pair<double, std::uint32_t>> stack;
                        for (std::size_t i = r.begin(); i != r.end(); ++i) moves[i] = find_move(candidates[i], stack);
                      });
    std::erase_if(moves, [&](const Move& m) {
      const bool none = m.to == kNone || !(m.gain > kMinGain * root_area_);
      if (none) settled_[m.from] = 1;  // not a candidate again unless a move changes it
      return none;
    });
    std::stable_sort(moves.begin(), moves.end(), [](const Move& a, const Move& b) { return a.gain > b.gain; });

    std::fill(touched_.begin(), touched_.end(), 0);
    for (const Move& m : moves) made += try_move(m);
    return true;
  }

 private:
  std::uint32_t sibling_of(std::uint32_t x) const {
    const std::uint32_t first = nodes_[parents_[x]].first_index;
    return x == first ? first + 1 : first;
  }

  void update_height(std::uint32_t x) {
    const Bvh2Node& n = nodes_[x];
    heights_[x] = n.is_leaf() ? 0 : 1 + std::max(heights_[n.first_index], heights_[n.first_index + 1]);
  }

  // The best place for node `from` as the search above finds it (to = kNone
  // if none gains).
  Move find_move(std::uint32_t from, std::vector<std::pair<double, std::uint32_t>>& stack) const {
    Move best{from, kNone, 0.0};
    const BBox& box = nodes_[from].bounds;
    const double from_area = area(box);
    const std::uint32_t parent = parents_[from];
    double available = area(nodes_[parent].bounds);    // P goes away
    BBox remaining = nodes_[sibling_of(from)].bounds;  // the current ancestor's box without `from`
    std::uint32_t ancestor = parent, beside = sibling_of(from);
    for (;;) {
      // Places in the subtree beside the path; `ancestor` keeps its box.
      stack.assign(1, {available, beside});
      while (!stack.empty()) {
        const auto [gain_here, x] = stack.back();
        stack.pop_back();
        if (gain_here - from_area <= best.gain) continue;  // N is at least as large as A
        const double with = area(merged(nodes_[x].bounds, box));
        if (gain_here - with > best.gain) best = {from, x, gain_here - with};
        const Bvh2Node& n = nodes_[x];
        if (n.is_leaf()) continue;
        const double below = gain_here - (with - area(n.bounds));  // x grows to take A in
        stack.push_back({below, n.first_index + 1});
        stack.push_back({below, n.first_index});
      }
      if (ancestor == 0) break;
      if (ancestor != parent) {  // it shrinks once A is gone
        remaining.extend(nodes_[beside].bounds);
        available += area(nodes_[ancestor].bounds) - area(remaining);
      }
      beside = sibling_of(ancestor);
      ancestor = parents_[ancestor];
    }
    if (best.to == sibling_of(from)) best.to = kNone;  // already there (its gain is 0 anyway)
    return best;
  }

  // Makes move m if it is still possible, keeps the depth bound, touches no
  // node another move of this pass touched, and lowers the cost by more than
  // kMinGain of the root's area on the tree as it stands.
  bool try_move(const Move& m) {
    const std::uint32_t from = m.from, to = m.to, parent = parents_[from], sibling = sibling_of(from);
    const std::uint32_t touches[] = {from, to, sibling, parent, parents_[to]};
    for (std::uint32_t t : touches)
      if (touched_[t]) return false;
    if (to == parent || to == sibling) return false;
    int depth = 0;  // of `to`; and `to` must be neither below nor above `from`
    for (std::uint32_t x = to; x != 0; x = parents_[x], ++depth)
      if (x == from) return false;
    for (std::uint32_t x = parent; x != 0; x = parents_[x])
      if (x == to) return false;
    if (depth + 1 + std::max(heights_[from], heights_[to]) > max_depth_) return false;
    if (!(gain_now(from, to) > kMinGain * root_area_)) return false;
    for (std::uint32_t t : touches) touched_[t] = 1;
    move(from, to);
    return true;
  }

  // The cost's drop if `from` moved next to `to`, on the tree as it stands:
  // the new boxes of the ancestors of P and of `to`, computed bottom-up.
  double gain_now(std::uint32_t from, std::uint32_t to) {
    const std::uint32_t parent = parents_[from], sibling = sibling_of(from);
    new_boxes_.clear();
    const auto set = [&](std::uint32_t x, const BBox& b) {
      if (new_box_slot_[x] < 0) {
        new_box_slot_[x] = static_cast<int>(new_boxes_.size());
        new_boxes_.push_back({x, b});
      } else {
        new_boxes_[static_cast<std::size_t>(new_box_slot_[x])].second = b;
      }
    };
    const auto box = [&](std::uint32_t x) -> const BBox& {
      return new_box_slot_[x] < 0 ? nodes_[x].bounds : new_boxes_[static_cast<std::size_t>(new_box_slot_[x])].second;
    };
    const auto other_child = [&](std::uint32_t y, std::uint32_t x) {
      return nodes_[y].first_index == x ? x + 1 : nodes_[y].first_index;
    };
    // A goes: P's place holds B; P's ancestors lose A.
    set(parent, nodes_[sibling].bounds);
    BBox below = nodes_[sibling].bounds;
    for (std::uint32_t x = parent, y = parents_[parent]; y != kNone; x = y, y = parents_[y]) {
      below.extend(nodes_[other_child(y, x)].bounds);
      set(y, below);
    }
    // A comes in beside C: N in C's place; its ancestors (B's, past P, if C
    // is below B) take A in.
    const BBox n = merged(nodes_[from].bounds, nodes_[to].bounds);
    below = n;
    for (std::uint32_t x = to, y = parents_[to]; y != kNone; x = y, y = parents_[y]) {
      if (y == parent) continue;  // P is gone: B, on the path, is now a child of P's parent, as P was
      below = merged(below, box(other_child(y, x)));
      set(y, below);
    }
    double gain = area(nodes_[parent].bounds) - area(n);
    for (const auto& [x, b] : new_boxes_) {
      if (x != parent) gain += area(nodes_[x].bounds) - area(b);
      new_box_slot_[x] = -1;
    }
    return gain;
  }

  void move(std::uint32_t from, std::uint32_t to) {
    const std::uint32_t parent = parents_[from], sibling = sibling_of(from);
    const std::uint32_t pair = nodes_[parent].first_index;  // A's slot and B's
    const Bvh2Node b = nodes_[sibling], c = nodes_[to];
    const int b_height = heights_[sibling], c_height = heights_[to];
    // The nodes moved may have new places worth finding.
    settled_[from] = settled_[parent] = settled_[sibling] = settled_[to] = 0;
    nodes_[parent] = b;
    heights_[parent] = b_height;
    nodes_[sibling] = c;
    heights_[sibling] = c_height;
    nodes_[to] = Bvh2Node{merged(nodes_[from].bounds, c.bounds), pair, 0};
    if (!b.is_leaf()) parents_[b.first_index] = parents_[b.first_index + 1] = parent;
    if (!c.is_leaf()) parents_[c.first_index] = parents_[c.first_index + 1] = sibling;
    parents_[from] = parents_[sibling] = to;
    refit_from(to);
    refit_from(parent);
  }

  // Boxes and heights from x up to the root.
  void refit_from(std::uint32_t x) {
    for (; x != kNone; x = parents_[x]) {
      Bvh2Node& n = nodes_[x];
      if (!n.is_leaf()) n.bounds = merged(nodes_[n.first_index].bounds, nodes_[n.first_index + 1].bounds);
      update_height(x);
    }
  }

  std::vector<Bvh2Node>& nodes_;
  const int max_depth_;
  std::vector<std::uint32_t> parents_;    // kNone for the root (and for unreachable nodes)
  std::vector<int> heights_;              // levels below a node to its deepest leaf
  std::vector<std::uint32_t> reachable_;  // from the root; the root first
  std::vector<std::uint8_t> touched_;     // by a move of this pass
  std::vector<std::uint8_t> settled_;     // its last search found no move, and no move has changed it since
  std::vector<int> new_box_slot_;         // gain_now's scratch: index into new_boxes_, or -1
  std::vector<std::pair<std::uint32_t, BBox>> new_boxes_;
  double root_area_ = 0.0;
};

}  // namespace

std::size_t optimize_bvh2_reinsertion(Bvh2& bvh, const Bvh2ReinsertionOptions& options) {
  if (options.passes <= 0 || bvh.nodes.empty() || bvh.nodes[0].is_leaf() || bvh.prim_ids.empty()) return 0;
  Reinserter r(bvh, options.max_depth);
  std::size_t made = 0;
  for (int p = 0; p < options.passes && r.pass(options.batch_fraction, made); ++p) {
  }
  return made;
}

}  // namespace raybench
