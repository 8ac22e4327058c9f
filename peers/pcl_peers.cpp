// SPDX-License-Identifier: BSD-3-Clause
// Kept in its own small translation unit: NDT and GICP instantiations are
// heavy to compile (docs/design.md, "Dependencies and pitfalls").
#include "radargauss/peers/pcl_peers.hpp"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>
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
  mutable tbb::enumerable_thread_specific<std::shared_ptr<Registration>> registrations;

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
    gicp->setInputTarget(target);
    return gicp;
  }
};

PclPeerMatcher::PclPeerMatcher(PclMethod method, const std::vector<Eigen::Vector3d>& map_cloud,
                               const PclPeerOptions& options)
    : impl_(std::make_unique<Impl>()) {
  impl_->method = method;
  impl_->options = options;
  impl_->target = Cloud::Ptr(new Cloud);
  impl_->target->reserve(map_cloud.size());
  for (const Eigen::Vector3d& p : map_cloud) impl_->target->push_back(pcl::PointXYZ(float(p.x()), float(p.y()), float(p.z())));
}

PclPeerMatcher::~PclPeerMatcher() = default;

std::string PclPeerMatcher::Name() const { return impl_->method == PclMethod::kNdt ? "pcl-ndt" : "pcl-gicp"; }

ScanMatchingResult PclPeerMatcher::Match(const RadarScan& scan, const MatchingMap&, const SE3d& initial) const {
  const auto start = std::chrono::steady_clock::now();
  ScanMatchingResult result;
  result.pose = initial;
  if (scan.points.size() < 3) {
    result.reason = "too few points";
    return result;
  }
  std::shared_ptr<Registration>& registration = impl_->registrations.local();
  if (!registration) registration = impl_->Make();
  Cloud::Ptr source(new Cloud);
  for (const RadarPoint& p : scan.points) {
    source->push_back(pcl::PointXYZ(float(p.position.x()), float(p.position.y()), float(p.position.z())));
  }
  registration->setInputSource(source);
  Cloud aligned;
  registration->align(aligned, initial.Matrix().cast<float>());
  const Eigen::Matrix4d T = registration->getFinalTransformation().cast<double>();
  if (T.allFinite()) {
    Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
    result.pose = SE3d(SO3d::FromMatrix(R), T.topRightCorner<3, 1>());
  }
  result.converged = registration->hasConverged() && T.allFinite();
  if (!result.converged) result.reason = "PCL registration did not converge";
  result.final_cost = registration->getFitnessScore();
  if (impl_->method == PclMethod::kNdt) {
    result.iterations = static_cast<pcl::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ>*>(
                            registration.get())->getFinalNumIteration();
  }
  result.n_geo = scan.points.size();
  result.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace radargauss
