#include "evaluation/mapped_index.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <optional>

namespace stvl::evaluation {
namespace {

constexpr int kDim = 8;

VoxelKey origin_of(const VoxelKey& k) { return {k.x & ~(kDim - 1), k.y & ~(kDim - 1), k.z & ~(kDim - 1)}; }
int offset_of(const VoxelKey& k) { return ((k.x & 7) << 6) | ((k.y & 7) << 3) | (k.z & 7); }
VoxelKey key_at(const VoxelKey& origin, int i) {
  return {origin.x + (i >> 6), origin.y + ((i >> 3) & 7), origin.z + (i & 7)};
}

// Calls f(i) for every set bit of m, in increasing order.
template <class F>
void for_each_bit(const std::array<std::uint64_t, 8>& m, F&& f) {
  for (int w = 0; w < 8; ++w)
    for (std::uint64_t bits = m[w]; bits; bits &= bits - 1) f(64 * w + __builtin_ctzll(bits));
}

void set_bit(std::array<std::uint64_t, 8>& m, int i) { m[i >> 6] |= std::uint64_t{1} << (i & 63); }

}  // namespace

std::uint32_t MappedIndex::intern(double d) {
  const auto [it, fresh] = distance_ids_.try_emplace(d, static_cast<std::uint32_t>(distances_.size()));
  if (fresh) distances_.push_back(d), counts_.push_back(0);
  return it->second;
}

void MappedIndex::update(const mapping::VoxelMap& map, Truth& truth) { walk(map, truth, nullptr); }

VoxelMatches MappedIndex::match(const mapping::VoxelMap& map, Truth& truth) {
  VoxelMatches m;
  ++stamp_;
  walk(map, truth, &m);
  for (auto it = leaves_.begin(); it != leaves_.end();)  // leaves gone from the map: forget them (memory)
    it = it->second.stamp == stamp_ ? std::next(it) : leaves_.erase(it);
  last_leaf_ = nullptr, last_origin_ = {1, 1, 1};  // no leaf's origin
  return m;
}

void MappedIndex::walk(const mapping::VoxelMap& map, Truth& truth, VoxelMatches* counts) {
  const std::size_t version = truth.version();
  last_leaf_ = nullptr, last_origin_ = {1, 1, 1};
  // The map's leaves come in the tree's order, mostly the same leaves as last time: follow the last walk's
  // chain and look a leaf up by its origin only where the chain does not hold it (a leaf came or went).
  Leaf* previous = nullptr;
  map.for_each_leaf([&](const VoxelKey& origin, const std::uint64_t* on) {
    Leaf* expected = previous ? previous->next : first_;
    if (!expected || expected->origin != origin) {
      expected = &leaves_[origin];
      expected->origin = origin;
    }
    (previous ? previous->next : first_) = expected;
    previous = expected;
    Leaf& leaf = *expected;
    leaf.stamp = stamp_;
    // Between evaluations, a leaf whose results are of an older truth is left for match(): while a body keeps
    // moving, each frame's results would be stale by the evaluation.
    if (!counts && leaf.version != 0 && leaf.version != version) return;
    visit_leaf(leaf, on, truth, version);
  });
  (previous ? previous->next : first_) = nullptr;  // every pointer in the chain is to a leaf of this walk
  compute_distances(truth);
  if (counts) count_matches(*counts);
}

void MappedIndex::visit_leaf(Leaf& leaf, const std::uint64_t* on, Truth& truth, std::size_t version) {
  const VoxelKey& origin = leaf.origin;
  if (leaf.version != version) {  // the truth changed since this leaf's results
    leaf.version = version;
    leaf.moving_done = {};
    const bool moving = truth.moving_distance_in(origin, {origin.x + 7, origin.y + 7, origin.z + 7});
    for (int w = 0; w < 8; ++w) {
      if (moving) leaf.distance_fixed[w] = 0;
      leaf.distance_done[w] &= leaf.distance_fixed[w];
    }
  }
  Mask todo_static{}, todo_moving{}, todo_distance{};
  for (int w = 0; w < 8; ++w) {
    leaf.on[w] = on[w];
    todo_static[w] = on[w] & ~leaf.static_done[w];
    todo_distance[w] = on[w] & ~leaf.distance_done[w];
  }
  for_each_bit(todo_static, [&](int i) {
    set_bit(leaf.static_done, i);
    if (truth.near_static(key_at(origin, i))) set_bit(leaf.static_near, i);
  });
  for (int w = 0; w < 8; ++w) todo_moving[w] = on[w] & ~leaf.static_near[w] & ~leaf.moving_done[w];
  for_each_bit(todo_moving, [&](int i) {
    set_bit(leaf.moving_done, i);
    const std::uint64_t bit = std::uint64_t{1} << (i & 63);
    if (truth.near_moving(key_at(origin, i))) leaf.moving_near[i >> 6] |= bit;
    else leaf.moving_near[i >> 6] &= ~bit;
  });
  for_each_bit(todo_distance, [&](int i) { distance_todo_.push_back({&leaf, i}); });
}

void MappedIndex::compute_distances(const Truth& truth) {
  // The surface distances, the costly part, in parallel (Truth::voxel_distance_to_surface_m only reads), then
  // recorded in the walk's order.
  struct Distance {
    std::optional<double> d_m;
    bool fixed = false;
  };
  std::vector<Distance> found(distance_todo_.size());
  const auto compute = [&](std::size_t begin, std::size_t end) {
    for (std::size_t t = begin; t < end; ++t)
      found[t].d_m = truth.voxel_distance_to_surface_m(
          key_at(distance_todo_[t].first->origin, distance_todo_[t].second), &found[t].fixed);
  };
  if (found.size() < 256) compute(0, found.size());
  else
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, found.size(), 64),
                      [&](const tbb::blocked_range<std::size_t>& r) { compute(r.begin(), r.end()); });
  for (std::size_t t = 0; t < found.size(); ++t) {
    Leaf& leaf = *distance_todo_[t].first;
    const int i = distance_todo_[t].second;
    leaf.distance_id[i] = found[t].d_m ? intern(*found[t].d_m) : kNoDistance;
    set_bit(leaf.distance_done, i);
    const std::uint64_t bit = std::uint64_t{1} << (i & 63);
    if (found[t].fixed) leaf.distance_fixed[i >> 6] |= bit;
    else leaf.distance_fixed[i >> 6] &= ~bit;
  }
  distance_todo_.clear();
}

void MappedIndex::count_matches(VoxelMatches& counts) {
  for (const Leaf* leaf = first_; leaf; leaf = leaf->next) {
    for (int w = 0; w < 8; ++w) {
      counts.mapped += static_cast<std::size_t>(__builtin_popcountll(leaf->on[w]));
      counts.matched_mapped += static_cast<std::size_t>(
          __builtin_popcountll(leaf->on[w] & (leaf->static_near[w] | (leaf->moving_near[w] & leaf->moving_done[w]))));
    }
    for_each_bit(leaf->on, [&](int i) {
      if (leaf->distance_id[i] != kNoDistance) ++counts_[leaf->distance_id[i]];
    });
  }
}

std::map<double, std::size_t> MappedIndex::distance_counts() const {
  std::map<double, std::size_t> counts;
  for (std::size_t id = 0; id < distances_.size(); ++id)
    if (counts_[id] > 0) counts.emplace(distances_[id], counts_[id]);
  return counts;
}

const MappedIndex::Leaf* MappedIndex::leaf_of(const VoxelKey& key) const {
  const VoxelKey origin = origin_of(key);
  if (origin == last_origin_) return last_leaf_;
  const auto it = leaves_.find(origin);
  last_origin_ = origin;
  last_leaf_ = it == leaves_.end() ? nullptr : &it->second;
  return last_leaf_;
}

bool MappedIndex::contains(const VoxelKey& key) const {
  const Leaf* leaf = leaf_of(key);
  if (!leaf) return false;
  const int i = offset_of(key);
  return (leaf->on[i >> 6] >> (i & 63)) & 1u;
}

bool MappedIndex::near(const VoxelKey& key, int tol) const {
  return any_within(key, tol, [&](const VoxelKey& n) { return contains(n); });
}

}  // namespace stvl::evaluation
