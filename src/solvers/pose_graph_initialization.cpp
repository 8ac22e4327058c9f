// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/solvers/pose_graph_initialization.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <stdexcept>
#include <string>

#include "radargauss/core/conventions.hpp"
#include "radargauss/lie/nearest_rotation.hpp"

namespace radargauss {

namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

// Unknown index of each keyframe the edges connect to the fixed one; -1 for
// the fixed one and those no chain of edges reaches (they keep their poses).
std::vector<int> UnknownIndices(int n, int fixed, const std::vector<PoseGraphEdge>& edges, int& unknowns) {
  std::vector<std::vector<int>> neighbours(n);
  for (const PoseGraphEdge& edge : edges) {
    if (edge.from < 0 || edge.to < 0 || edge.from >= n || edge.to >= n) {
      throw std::invalid_argument("chordal initialization: an edge to a keyframe that is not there");
    }
    neighbours[edge.from].push_back(edge.to);
    neighbours[edge.to].push_back(edge.from);
  }
  std::vector<bool> reached(n, false);
  std::vector<int> stack = {fixed};
  reached[fixed] = true;
  while (!stack.empty()) {
    const int k = stack.back();
    stack.pop_back();
    for (const int m : neighbours[k]) {
      if (!reached[m]) stack.push_back(m), reached[m] = true;
    }
  }
  std::vector<int> index(n, -1);
  unknowns = 0;
  for (int k = 0; k < n; ++k) {
    if (reached[k] && k != fixed) index[k] = unknowns++;
  }
  return index;
}

// Adds `block` at block (row, col) of size `size` when both are unknowns.
template <typename Block>
void AddBlock(Triplets& triplets, int row, int col, int size, const Block& block) {
  if (row < 0 || col < 0) return;
  for (int r = 0; r < size; ++r)
    for (int c = 0; c < size; ++c) triplets.emplace_back(size * row + r, size * col + c, block(r, c));
}

// The mean of the edge's information diagonal (W^T W) over the three
// coordinates from `offset` (kRotationOffset or kTranslationOffset).
double EdgeWeight(const PoseGraphEdge& edge, int offset) {
  return (edge.sqrt_information.transpose() * edge.sqrt_information).diagonal().segment<3>(offset).mean();
}

// Solves H X = B (H symmetric positive definite, sparse); false when it is not.
bool SolveSparse(int rows, const Triplets& triplets, const Eigen::MatrixXd& B, Eigen::MatrixXd& X) {
  Eigen::SparseMatrix<double> H(rows, rows);
  H.setFromTriplets(triplets.begin(), triplets.end());
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(H);
  if (ldlt.info() != Eigen::Success) return false;
  X = ldlt.solve(B);
  return ldlt.info() == Eigen::Success && X.allFinite();
}

// Chordal relaxation: each edge asks R_j = R_i Z, i.e. row a of R_j equals
// Z^T times row a of R_i; the three rows are three right-hand sides of one
// sparse system, whose solutions are projected onto SO(3).
bool ChordalRotations(const std::vector<SE3d>& poses, const std::vector<PoseGraphEdge>& edges,
                      const std::vector<int>& index, int unknowns, std::vector<Eigen::Matrix3d>& rotations) {
  Triplets triplets;
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(3 * unknowns, 3);
  for (const PoseGraphEdge& edge : edges) {
    const double w = EdgeWeight(edge, kRotationOffset);
    const Eigen::Matrix3d A = edge.measured.rotation().Matrix().transpose();
    const int i = index[edge.from], j = index[edge.to];
    AddBlock(triplets, j, j, 3, w * Eigen::Matrix3d::Identity());
    AddBlock(triplets, i, i, 3, w * A.transpose() * A);
    AddBlock(triplets, j, i, 3, -w * A);
    AddBlock(triplets, i, j, 3, -w * A.transpose());
    if (i < 0 && j >= 0) B.middleRows<3>(3 * j) += w * A * poses[edge.from].rotation().Matrix().transpose();
    if (j < 0 && i >= 0) B.middleRows<3>(3 * i) += w * A.transpose() * poses[edge.to].rotation().Matrix().transpose();
  }
  Eigen::MatrixXd X;
  if (!SolveSparse(3 * unknowns, triplets, B, X)) return false;
  rotations.resize(poses.size());
  for (std::size_t k = 0; k < poses.size(); ++k) {
    if (index[k] < 0) {
      rotations[k] = poses[k].rotation().Matrix();
      continue;
    }
    rotations[k] = NearestRotation(X.middleRows<3>(3 * index[k]).transpose());
  }
  return true;
}

// Translations given the rotations: each edge asks t_j - t_i = R_i t_z, a
// weighted graph Laplacian with x, y, z as three right-hand sides.
bool LinearTranslations(const std::vector<SE3d>& poses, const std::vector<PoseGraphEdge>& edges,
                        const std::vector<int>& index, int unknowns, const std::vector<Eigen::Matrix3d>& rotations,
                        std::vector<Eigen::Vector3d>& translations) {
  Triplets triplets;
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(unknowns, 3);
  const auto one = [](double value) { return Eigen::Matrix<double, 1, 1>::Constant(value); };
  for (const PoseGraphEdge& edge : edges) {
    const double w = EdgeWeight(edge, kTranslationOffset);
    const Eigen::RowVector3d c = (rotations[edge.from] * edge.measured.translation()).transpose();
    const int i = index[edge.from], j = index[edge.to];
    AddBlock(triplets, i, i, 1, one(w));
    AddBlock(triplets, j, j, 1, one(w));
    AddBlock(triplets, i, j, 1, one(-w));
    AddBlock(triplets, j, i, 1, one(-w));
    if (j >= 0) B.row(j) += w * c;
    if (i >= 0) B.row(i) -= w * c;
    if (i < 0 && j >= 0) B.row(j) += w * poses[edge.from].translation().transpose();
    if (j < 0 && i >= 0) B.row(i) += w * poses[edge.to].translation().transpose();
  }
  Eigen::MatrixXd X;
  if (!SolveSparse(unknowns, triplets, B, X)) return false;
  translations.resize(poses.size());
  for (std::size_t k = 0; k < poses.size(); ++k) {
    translations[k] = index[k] < 0 ? poses[k].translation() : Eigen::Vector3d(X.row(index[k]).transpose());
  }
  return true;
}

}  // namespace

std::vector<SE3d> ChordalInitialization(const std::vector<SE3d>& poses, const std::vector<PoseGraphEdge>& edges,
                                        int fixed) {
  const int n = int(poses.size());
  if (fixed < 0 || fixed >= n) {
    throw std::invalid_argument("chordal initialization: no keyframe " + std::to_string(fixed));
  }
  int unknowns = 0;
  const std::vector<int> index = UnknownIndices(n, fixed, edges, unknowns);
  if (unknowns == 0) return poses;
  std::vector<Eigen::Matrix3d> rotations;
  std::vector<Eigen::Vector3d> translations;
  if (!ChordalRotations(poses, edges, index, unknowns, rotations) ||
      !LinearTranslations(poses, edges, index, unknowns, rotations, translations)) {
    return poses;
  }
  std::vector<SE3d> initial;
  for (int k = 0; k < n; ++k) initial.emplace_back(SO3d::FromMatrix(rotations[k]), translations[k]);
  return initial;
}

}  // namespace radargauss
