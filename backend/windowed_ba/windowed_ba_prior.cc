#include "backend/windowed_ba/windowed_ba_prior.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace pldvo {

void CheckWindowedBAPrior(const WindowedBAPrior& prior) {
  const int n = 6 * static_cast<int>(prior.keyframe_ids.size());
  auto fail = [](const std::string& what) {
    throw std::invalid_argument(std::string(__FILE__) + ": windowed BA prior: " + what);
  };
  if (prior.cam_from_world.size() != prior.keyframe_ids.size() || prior.information.rows() != n ||
      prior.information.cols() != n || prior.gradient.size() != n) {
    fail("sizes disagree (6 per keyframe id)");
  }
  for (size_t k = 0; k < prior.keyframe_ids.size(); ++k) {
    if (prior.keyframe_ids[k] <=
        (k == 0 ? prior.marginalized_through_id : prior.keyframe_ids[k - 1])) {
      fail("keyframe ids must increase and lie above marginalized_through_id");
    }
    if (!prior.cam_from_world[k].translation().allFinite() ||
        !prior.cam_from_world[k].rotation_matrix().allFinite()) {
      fail("non-finite linearisation pose");
    }
  }
  if (!prior.information.allFinite() || !prior.gradient.allFinite()) fail("non-finite entries");
}

void SchurComplement(const Eigen::MatrixXd& information, const Eigen::VectorXd& gradient,
                     const std::vector<bool>& keep, Eigen::MatrixXd* kept_information,
                     Eigen::VectorXd* kept_gradient) {
  std::vector<int> k_index, m_index;
  for (int i = 0; i < static_cast<int>(keep.size()); ++i)
    (keep[i] ? k_index : m_index).push_back(i);
  const int nm = static_cast<int>(m_index.size());
  // Eigen 3.4 indexed views gather the kept (k) and marginalised (m) rows and columns.
  const Eigen::MatrixXd h_kk = information(k_index, k_index);
  const Eigen::MatrixXd h_km = information(k_index, m_index);
  const Eigen::MatrixXd h_mm = information(m_index, m_index);
  const Eigen::VectorXd b_k = gradient(k_index);
  const Eigen::VectorXd b_m = gradient(m_index);
  if (nm == 0) {
    *kept_information = h_kk;
    *kept_gradient = b_k;
    return;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(h_mm);
  const Eigen::VectorXd& values = eigen.eigenvalues();
  const double floor = 1e-12 * std::max(values.maxCoeff(), 0.0);
  Eigen::VectorXd inverse_values = Eigen::VectorXd::Zero(nm);
  for (int i = 0; i < nm; ++i) {
    if (values(i) > floor && values(i) > 0.0) inverse_values(i) = 1.0 / values(i);
  }
  const Eigen::MatrixXd h_km_v = h_km * eigen.eigenvectors();
  const Eigen::MatrixXd scaled = h_km_v * inverse_values.asDiagonal();
  *kept_information = h_kk - scaled * h_km_v.transpose();
  *kept_information = 0.5 * (*kept_information + kept_information->transpose());
  *kept_gradient = b_k - scaled * (eigen.eigenvectors().transpose() * b_m);
}

bool KeepKeyframes(const WindowedBAPrior& prior, const std::vector<int>& keep_ids,
                   WindowedBAPrior* kept) {
  std::vector<bool> keep;
  WindowedBAPrior out;
  out.marginalized_through_id = prior.marginalized_through_id;
  for (size_t k = 0; k < prior.keyframe_ids.size(); ++k) {
    const int id = prior.keyframe_ids[k];
    const bool stays = std::find(keep_ids.begin(), keep_ids.end(), id) != keep_ids.end();
    keep.insert(keep.end(), 6, stays);
    if (stays) {
      out.keyframe_ids.push_back(id);
      out.cam_from_world.push_back(prior.cam_from_world[k]);
    }
  }
  if (out.keyframe_ids.empty()) return false;
  SchurComplement(prior.information, prior.gradient, keep, &out.information, &out.gradient);
  *kept = std::move(out);
  return true;
}

}  // namespace pldvo
