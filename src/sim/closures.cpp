#include "sim/closures.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

namespace depotwin {

void assemble_closures(BoundModel& bound) {
  const mjModel* m = bound.model.get();
  mjData* d = bound.data.get();
  if (m->neq == 0) return;
  std::vector<bool> held(m->nv, false);
  for (const Servo& servo : bound.joints) held[servo.dof_adr] = true;
  if (bound.has_shutter) held[bound.shutter.dof_adr] = true;
  std::vector<int> free_dofs;
  for (int dof = 0; dof < m->nv; ++dof)
    if (!held[dof]) free_dofs.push_back(dof);
  if (free_dofs.empty()) return;

  // the equality rows of the constraint Jacobian (dense or sparse), split into held / free
  Eigen::MatrixXd jacobian_free, jacobian_held;
  Eigen::VectorXd residual;
  const auto equality_rows = [&]() {
    mj_fwdPosition(m, d);
    std::vector<int> rows;
    for (int row = 0; row < d->nefc; ++row)
      if (d->efc_type[row] == mjCNSTR_EQUALITY) rows.push_back(row);
    const int n = static_cast<int>(rows.size());
    Eigen::MatrixXd full = Eigen::MatrixXd::Zero(n, m->nv);
    residual.resize(n);
    for (int i = 0; i < n; ++i) {
      const int row = rows[i];
      residual[i] = d->efc_pos[row];
      if (mj_isSparse(m)) {
        for (int k = 0; k < d->efc_J_rownnz[row]; ++k)
          full(i, d->efc_J_colind[d->efc_J_rowadr[row] + k]) = d->efc_J[d->efc_J_rowadr[row] + k];
      } else {
        for (int col = 0; col < m->nv; ++col) full(i, col) = d->efc_J[row * m->nv + col];
      }
    }
    jacobian_free.resize(n, static_cast<int>(free_dofs.size()));
    for (size_t c = 0; c < free_dofs.size(); ++c) jacobian_free.col(c) = full.col(free_dofs[c]);
    jacobian_held = full;
    return n;
  };

  // positions: dq = -J_free^+ r until the residual is below 1e-12 m
  std::vector<mjtNum> step(m->nv, 0.0);
  for (int iteration = 0; iteration < 50; ++iteration) {
    if (equality_rows() == 0 || residual.cwiseAbs().maxCoeff() < 1e-12) break;
    const Eigen::VectorXd dq = -jacobian_free.completeOrthogonalDecomposition().solve(residual);
    std::fill(step.begin(), step.end(), 0.0);
    for (size_t c = 0; c < free_dofs.size(); ++c) step[free_dofs[c]] = dq[c];
    mj_integratePos(m, d->qpos, step.data(), 1.0);
  }

  // velocities: J_free v_free = -J_held v_held (least norm)
  if (equality_rows() == 0) return;
  Eigen::VectorXd held_velocity = Eigen::VectorXd::Zero(m->nv);
  for (int dof = 0; dof < m->nv; ++dof)
    if (held[dof]) held_velocity[dof] = d->qvel[dof];
  const Eigen::VectorXd v_free =
      -jacobian_free.completeOrthogonalDecomposition().solve(jacobian_held * held_velocity);
  for (size_t c = 0; c < free_dofs.size(); ++c) d->qvel[free_dofs[c]] = v_free[c];
}

double constraint_violation_mm(const mjData& data) {
  const mjData* d = &data;
  double largest = 0.0;
  for (int row = 0; row < d->nefc; ++row)
    if (d->efc_type[row] == mjCNSTR_EQUALITY)
      largest = std::max(largest, std::abs(d->efc_pos[row]));
  return m_to_mm(largest);
}

}  // namespace depotwin
