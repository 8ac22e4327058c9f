// SPDX-License-Identifier: BSD-3-Clause
// Kept in its own small translation unit: NDT and GICP instantiations are
// heavy to compile (docs/design.md, "Dependencies and pitfalls").
#include "radargauss/peers/pcl_peers.hpp"

#include "radargauss/map/builder.hpp"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/registration/ndt.h>
#include <tbb/enumerable_thread_specific.h>

#include <chrono>

namespace radargauss {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Registration = pcl::Registration<pcl::PointXYZ, pcl::PointXYZ, float>;

struct PclPeerMatcher::Impl {
  PclMethod method;
  PclPeerOptions options;
  Cloud::Ptr target;
  pcl::KdTreeFLANN<pcl::PointXYZ> target_tree;  // GICP's crops
  mutable tbb::enumerable_thread_specific<std::shared_ptr<Registration>> registrations;

  // The map within `radius` of `origin`, expressed relative to it.
  Cloud::Ptr LocalTarget(const Eigen::Vector3f& origin, double radius) const {
    std::vector<int> indices;
    std::vector<float> squared_distances;
    target_tree.radiusSearch(pcl::PointXYZ(origin.x(), origin.y(), origin.z()), radius, indices, squared_distances);
    Cloud::Ptr local(new Cloud);
    local->reserve(indices.size());
    for (const int i : indices) {
      const pcl::PointXYZ& p = (*target)[i];
      local->push_back(pcl::PointXYZ(p.x - origin.x(), p.y - origin.y(), p.z - origin.z()));
    }
    return local;
  }

  std::shared_ptr<Registration> Make() const {
    if (method == PclMethod::kNdt) {
      auto ndt = std::make_shared<pcl::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ>>();
      ndt->setResolution(float(options.ndt_resolution));
      ndt->setStepSize(options.ndt_step_size);
      ndt->setMaximumIterations(options.max_iterations);
      ndt->setTransformationEpsilon(options.transformation_epsilon);
      ndt->setInputTarget(target);
      return ndt;
    }
    auto gicp = std::make_shared<pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ>>();
    gicp->setMaxCorrespondenceDistance(options.gicp_max_correspondence);
    gicp->setMaximumIterations(options.max_iterations);
    gicp->setTransformationEpsilon(options.transformation_epsilon);
    if (!options.gicp_local_target) gicp->setInputTarget(target);
    return gicp;
  }
};

namespace {

constexpr std::size_t kGicpNeighbours = 20;  // PCL's k_correspondences default, kept

}  // namespace

PclPeerMatcher::PclPeerMatcher(PclMethod method, const std::vector<Eigen::Vector3d>& map_cloud,
                               const PclPeerOptions& options)
    : impl_(std::make_unique<Impl>()) {
  impl_->method = method;
  impl_->options = options;
  impl_->target = Cloud::Ptr(new Cloud);
  const bool reduce = method == PclMethod::kGicp && options.gicp_local_target && options.gicp_target_voxel > 0.0;
  const std::vector<Eigen::Vector3d> points =
      reduce ? VoxelDownsample(map_cloud, options.gicp_target_voxel) : map_cloud;
  impl_->target->reserve(points.size());
  for (const Eigen::Vector3d& p : points)
    impl_->target->push_back(pcl::PointXYZ(float(p.x()), float(p.y()), float(p.z())));
  if (method == PclMethod::kGicp && options.gicp_local_target && !impl_->target->empty()) {
    impl_->target_tree.setInputCloud(impl_->target);
  }
}

PclPeerMatcher::~PclPeerMatcher() = default;

std::string PclPeerMatcher::Name() const { return impl_->method == PclMethod::kNdt ? "pcl-ndt" : "pcl-gicp"; }

ScanMatchingResult PclPeerMatcher::Match(const RadarScan& scan, const MatchingMap&, const SE3d& initial,
                                         const ScanPriors&) const {
  const auto start = std::chrono::steady_clock::now();
  ScanMatchingResult result;
  result.pose = initial;
  // GICP fits each point's covariance from its kGicpNeighbours nearest
  // neighbours in either cloud, and PCL aborts the process for fewer.
  const std::size_t needed = impl_->method == PclMethod::kGicp ? kGicpNeighbours : 3;
  if (scan.points.size() < needed) {
    result.reason = "too few points (" + std::to_string(scan.points.size()) + ", needs " + std::to_string(needed) + ")";
    return result;
  }
  std::shared_ptr<Registration>& registration = impl_->registrations.local();
  if (!registration) registration = impl_->Make();
  Cloud::Ptr source(new Cloud);
  for (const RadarPoint& p : scan.points) {
    source->push_back(pcl::PointXYZ(float(p.position.x()), float(p.position.y()), float(p.position.z())));
  }
  registration->setInputSource(source);
  // With a local target the guess and the result are relative to its origin.
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  if (impl_->method == PclMethod::kGicp && impl_->options.gicp_local_target) {
    origin = initial.translation();
    const Cloud::Ptr local = impl_->LocalTarget(origin.cast<float>(), impl_->options.gicp_crop_radius);
    if (local->size() < needed) {
      result.reason = "too few map points around the initial pose";
      return result;
    }
    registration->setInputTarget(local);
  }
  Eigen::Matrix4d guess = initial.Matrix();
  guess.topRightCorner<3, 1>() -= origin;
  Cloud aligned;
  registration->align(aligned, guess.cast<float>());
  Eigen::Matrix4d T = registration->getFinalTransformation().cast<double>();
  T.topRightCorner<3, 1>() += origin;
  // PCL stops at its iteration limit as converged: not converging is a
  // failure (NDT over a target too sparse for its grid, a divergence), whose
  // transformation is no result. The pose stays where the match began.
  result.converged = registration->hasConverged() && T.allFinite();
  if (result.converged) {
    Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
    result.pose = SE3d(SO3d::FromMatrix(R), T.topRightCorner<3, 1>());
  } else {
    result.reason = "PCL registration did not converge";
  }
  result.final_cost = registration->getFitnessScore();
  if (impl_->method == PclMethod::kNdt) {
    result.iterations =
        static_cast<pcl::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ>*>(registration.get())
            ->getFinalNumIteration();
  }
  result.n_geo = scan.points.size();
  result.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace radargauss
