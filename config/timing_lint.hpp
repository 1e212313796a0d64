#pragma once
// Lint across a scenario's camera timing and its layer's parameters (issue 43): settings that drop readings or mark
// sources stale whatever the map does, each with the fix computed from the timing.
#include <vector>

#include "config/ros_lint.hpp"
#include "config/scenario.hpp"

namespace stvl::config {

// For each camera:
//  - with timing (camera.timing, tf), transform_tolerance below the longest wait for the pose at a reading's stamp (the
//  odometry period and latency,
//    less the camera's shortest latency when stamped at capture): readings dropped as tf_timeout, every one when it
//    is below the shortest wait;
//  - a source's expected_update_rate shorter than the camera's longest gap between arrivals (its period and
//    jitter): the source marked stale between frames (STVL #333's 2 Hz camera).
// Latencies are taken as mean +- 3 jitter. The file is the scenario's; keys are the scenario's dotted keys.
std::vector<LintFinding> lint_timing(const Scenario& scenario);

}  // namespace stvl::config
