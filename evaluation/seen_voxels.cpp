#include "evaluation/seen_voxels.hpp"

#include <algorithm>

namespace stvl::evaluation {

void SeenVoxels::forget_before(double oldest_s) {
  entries_.erase(std::remove_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.time_s < oldest_s; }),
                 entries_.end());
}

}  // namespace stvl::evaluation
