#include "mlidar/slam/marginalization.hpp"

#include <algorithm>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "mlidar/slam/window_linearize.hpp"
#include "mlidar/slam/window_solver.hpp"

namespace mlidar::slam {
namespace {

bool touches(const std::vector<VariableId>& ids, VariableId id) { return std::find(ids.begin(), ids.end(), id) != ids.end(); }

/// The variables of the terms on `frame`: the pose, the poses and extrinsics its correspondences use (all of
/// them when the map is anchored at `frame`), the anchor, the prior's.
std::vector<VariableId> involved_variables(const WindowProblem& terms, const WindowState& state, int frame) {
  std::vector<VariableId> ids{{VariableId::Kind::kPose, frame}};
  const auto add = [&](VariableId id) {
    if (!touches(ids, id)) ids.push_back(id);
  };
  const auto add_term = [&](int term_frame, int lidar) {
    add({VariableId::Kind::kPose, term_frame});
    add({VariableId::Kind::kExtrinsic, lidar});
  };
  for (const PlaneCorrespondence& c : terms.planes) add_term(c.frame, c.lidar);
  for (const EdgeCorrespondence& c : terms.edges) add_term(c.frame, c.lidar);
  if (terms.anchor.frame >= 0 && !(terms.planes.empty() && terms.edges.empty())) add({VariableId::Kind::kPose, terms.anchor.frame});
  for (const VariableId& id : terms.prior.variables) add(id);
  std::erase_if(ids, [&](const VariableId& id) { return state.fixed(id); });
  return ids;
}

/// `state` with every block outside `ids` held fixed, so its layout spans `ids` only.
WindowState restricted_to(const WindowState& state, const std::vector<VariableId>& ids) {
  WindowState local = state;
  local.pose_fixed.assign(state.pose_fixed.size(), true);
  local.extrinsic_fixed.assign(state.extrinsic_fixed.size(), true);
  for (const VariableId& id : ids) {
    auto& flags = id.kind == VariableId::Kind::kPose ? local.pose_fixed : local.extrinsic_fixed;
    flags[static_cast<std::size_t>(id.index)] = false;
  }
  return local;
}

}  // namespace

SchurComplement schur_complement(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, const std::vector<int>& marginalized) {
  SchurComplement out;
  for (int k = 0; k < static_cast<int>(H.rows()); ++k)
    if (std::find(marginalized.begin(), marginalized.end(), k) == marginalized.end()) out.kept_columns.push_back(k);
  const Eigen::MatrixXd H_mm = H(marginalized, marginalized);
  const Eigen::MatrixXd H_rm = H(out.kept_columns, marginalized);
  // Eq 4.41, with the pseudo-inverse of H_mm: a direction of the marginalized state that no term observes
  // (a corridor's axis) carries nothing into the prior instead of an infinite gain.
  const Eigen::MatrixXd H_mm_inverse = symmetric_pseudo_inverse(H_mm);
  out.H = H(out.kept_columns, out.kept_columns) - H_rm * H_mm_inverse * H_rm.transpose();
  out.g = g(out.kept_columns) - H_rm * (H_mm_inverse * g(marginalized));
  out.H = 0.5 * (out.H + out.H.transpose());
  return out;
}

void factor_prior(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, Eigen::MatrixXd& jacobian, Eigen::VectorXd& residual) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(H);
  const Eigen::VectorXd& values = eigen.eigenvalues();
  const double cutoff = 1e-12 * std::max(values.size() > 0 ? values.maxCoeff() : 0.0, 0.0);
  std::vector<int> kept;
  for (int k = 0; k < static_cast<int>(values.size()); ++k)
    if (values(k) > cutoff && values(k) > 0.0) kept.push_back(k);
  // Eq 4.43-4.44: J* = Psi^1/2 P^T, r* = Psi^-1/2 P^T g.
  const Eigen::MatrixXd P = eigen.eigenvectors()(Eigen::all, kept);
  const Eigen::VectorXd psi = values(kept);
  jacobian = psi.cwiseSqrt().asDiagonal() * P.transpose();
  residual = psi.cwiseSqrt().cwiseInverse().asDiagonal() * (P.transpose() * g);
}

LinearPrior marginalize_frame(const WindowProblem& problem, const WindowState& state, int frame, double huber_delta_m) {
  check_problem(problem, state);
  // The terms on `frame`: its own correspondences, or every one when the map is attached to it.
  const bool anchor = problem.anchor.frame == frame;
  WindowProblem terms;
  std::copy_if(problem.planes.begin(), problem.planes.end(), std::back_inserter(terms.planes),
               [&](const PlaneCorrespondence& c) { return anchor || c.frame == frame; });
  std::copy_if(problem.edges.begin(), problem.edges.end(), std::back_inserter(terms.edges),
               [&](const EdgeCorrespondence& c) { return anchor || c.frame == frame; });
  terms.anchor = problem.anchor;
  terms.prior = problem.prior;
  const std::vector<VariableId> ids = involved_variables(terms, state, frame);
  if (ids.empty()) return {};  // a fixed pose whose terms touch no variable: nothing to carry
  const WindowState local = restricted_to(state, ids);
  const VariableLayout layout(local);
  const WindowLinearSystem system = linearize_window(terms, local, layout, huber_delta_m);
  const int pose_offset = layout.pose_offset.at(static_cast<std::size_t>(frame));
  std::vector<int> marginalized;
  for (int k = 0; pose_offset >= 0 && k < 6; ++k) marginalized.push_back(pose_offset + k);
  const SchurComplement reduced = schur_complement(system.H, system.g, marginalized);

  LinearPrior prior;
  for (const VariableId& id : ids) {  // layout order: poses ascending, then extrinsics; ids is a permutation of it
    if (id.kind == VariableId::Kind::kPose && id.index == frame) continue;
    prior.variables.push_back(id);
  }
  std::sort(prior.variables.begin(), prior.variables.end(),
            [&](const VariableId& a, const VariableId& b) { return layout.offset(a) < layout.offset(b); });
  for (const VariableId& id : prior.variables) prior.linearization_points.push_back(state.value(id));
  factor_prior(reduced.H, reduced.g, prior.jacobian, prior.residual);
  if (prior.jacobian.rows() == 0) prior = LinearPrior{};
  return prior;
}

void shift_window(WindowProblem& problem, WindowState& state, LinearPrior prior, const SE3& T_world_base_new) {
  for (VariableId& id : prior.variables) {
    if (id.kind != VariableId::Kind::kPose) continue;
    if (id.index == 0) throw std::invalid_argument("shift_window: the prior still holds pose 0; marginalize it first");
    --id.index;
  }
  state.T_world_base.erase(state.T_world_base.begin());
  state.pose_fixed.erase(state.pose_fixed.begin());
  state.T_world_base.push_back(T_world_base_new);
  state.pose_fixed.push_back(false);
  problem.planes.clear();
  problem.edges.clear();
  problem.anchor = {};
  problem.prior = std::move(prior);
}

}  // namespace mlidar::slam
