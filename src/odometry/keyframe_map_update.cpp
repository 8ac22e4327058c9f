// SPDX-License-Identifier: BSD-3-Clause
// A keyframe's map update, on the scan's path or behind its step
// (docs/design/odometry.md, "The map update behind the step").
#include <chrono>
#include <memory>
#include <utility>
#include <vector>

#include <tbb/task_group.h>

#include "radargauss/odometry/radar_odometry.hpp"

namespace radargauss {

struct RadarOdometry::MapUpdateTask {
  tbb::task_group group;
};

std::unique_ptr<RadarOdometry::MapUpdateTask, RadarOdometry::WaitAndDelete> RadarOdometry::NewMapUpdateTask() {
  return std::unique_ptr<MapUpdateTask, WaitAndDelete>(new MapUpdateTask);
}

void RadarOdometry::WaitAndDelete::operator()(MapUpdateTask* task) const {
  try {
    task->group.wait();
  } catch (...) {  // a failed update of a run that is going: nothing reads its map
  }
  delete task;
}

void RadarOdometry::InsertKeyframe(const RadarScan& scan, const std::vector<std::size_t>& static_points,
                                   const SE3d& pose, std::size_t step) {
  std::vector<Eigen::Vector3d> points;
  std::vector<double> rcs;
  points.reserve(static_points.size());
  for (const std::size_t i : static_points) {
    points.push_back(pose * scan.points[i].position);
    if (scan.has_rcs) rcs.push_back(scan.points[i].rcs);
  }
  last_keyframe_ = pose;
  const auto update = [this, points = std::move(points), rcs = std::move(rcs), pose] {
    const auto start = std::chrono::steady_clock::now();
    map_.Insert(points, rcs, pose);
    map_.Evict(pose.translation());
    pending_update_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  };
  if (!map_update_) {
    update();
    return;
  }
  pending_step_ = step;
  map_update_->group.run([this, update = std::move(update)] {
    update();
    map_bytes_ = map_.MemoryBytes();  // off the path too
  });
}

void RadarOdometry::FinishMapUpdate() const {
  if (!pending_step_) return;
  const std::size_t step = *pending_step_;
  pending_step_.reset();
  map_update_->group.wait();  // the waiting thread helps with the update's own parallel loops
  RecordMap(step, false);
}

void RadarOdometry::RecordMap(std::size_t step, bool measure) const {
  if (measure) map_bytes_ = map_.MemoryBytes();
  OdometryStep& s = steps_.at(step);
  s.active_gaussians = map_.gaussians();
  s.active_map_bytes = map_bytes_;
  s.map_update_ms = pending_update_ms_;
}

}  // namespace radargauss
