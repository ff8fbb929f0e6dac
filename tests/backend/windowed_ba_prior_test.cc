// The marginalisation prior's algebra (backend/windowed_ba/windowed_ba_prior.h): the Schur
// complement is the Gaussian marginal, keeps the minimiser, and KeepKeyframes keeps the right
// keyframes; malformed priors are rejected.
#include "backend/windowed_ba/windowed_ba_prior.h"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

namespace pldvo {
namespace {

Eigen::MatrixXd RandomInformation(int n, int rank, std::mt19937* rng) {
  std::normal_distribution<double> normal;
  Eigen::MatrixXd factor(rank, n);
  for (int i = 0; i < rank; ++i) {
    for (int j = 0; j < n; ++j) factor(i, j) = normal(*rng);
  }
  return factor.transpose() * factor;
}

// For a positive-definite H the marginal's information is the inverse of the kept block of the
// covariance H^-1, and the marginal's minimiser is the kept part of the full minimiser -H^-1 b.
TEST(WindowedBAPriorTest, SchurComplementIsTheGaussianMarginal) {
  std::mt19937 rng(11);
  const int n = 24;
  const Eigen::MatrixXd information = RandomInformation(n, n + 4, &rng);
  const Eigen::VectorXd gradient = Eigen::VectorXd::Random(n);
  std::vector<bool> keep(n, false);
  std::vector<int> kept_index;
  for (int i = 0; i < n; ++i) {
    keep[i] = (i % 3) != 0;
    if (keep[i]) kept_index.push_back(i);
  }
  Eigen::MatrixXd marginal_information;
  Eigen::VectorXd marginal_gradient;
  SchurComplement(information, gradient, keep, &marginal_information, &marginal_gradient);
  const Eigen::MatrixXd covariance = information.inverse();
  const Eigen::VectorXd minimiser = -covariance * gradient;
  const int m = static_cast<int>(kept_index.size());
  Eigen::MatrixXd kept_covariance(m, m);
  Eigen::VectorXd kept_minimiser(m);
  for (int i = 0; i < m; ++i) {
    kept_minimiser(i) = minimiser(kept_index[i]);
    for (int j = 0; j < m; ++j) kept_covariance(i, j) = covariance(kept_index[i], kept_index[j]);
  }
  EXPECT_LT((marginal_information.inverse() - kept_covariance).norm(),
            1e-9 * kept_covariance.norm());
  EXPECT_LT((-marginal_information.inverse() * marginal_gradient - kept_minimiser).norm(),
            1e-9 * kept_minimiser.norm());
}

// A singular eliminated block (a gauge direction inside it) adds nothing along that direction:
// eliminating a variable no row reads leaves the rest as it was.
TEST(WindowedBAPriorTest, SchurComplementIgnoresAnUnconstrainedEliminatedVariable) {
  std::mt19937 rng(12);
  Eigen::MatrixXd information = Eigen::MatrixXd::Zero(7, 7);
  information.topLeftCorner(6, 6) = RandomInformation(6, 8, &rng);
  Eigen::VectorXd gradient = Eigen::VectorXd::Zero(7);
  gradient.head(6) = Eigen::VectorXd::Random(6);
  std::vector<bool> keep(7, true);
  keep[6] = false;
  Eigen::MatrixXd kept_information;
  Eigen::VectorXd kept_gradient;
  SchurComplement(information, gradient, keep, &kept_information, &kept_gradient);
  EXPECT_LT((kept_information - information.topLeftCorner(6, 6)).norm(), 1e-12);
  EXPECT_LT((kept_gradient - gradient.head(6)).norm(), 1e-12);
}

TEST(WindowedBAPriorTest, KeepKeyframesMarginalisesTheOthers) {
  std::mt19937 rng(13);
  WindowedBAPrior prior;
  prior.marginalized_through_id = 3;
  prior.keyframe_ids = {4, 5, 7};
  prior.cam_from_world.assign(3, SE3());
  prior.information = RandomInformation(18, 24, &rng);
  prior.gradient = Eigen::VectorXd::Random(18);
  CheckWindowedBAPrior(prior);
  WindowedBAPrior kept;
  ASSERT_TRUE(KeepKeyframes(prior, {5, 7, 8}, &kept));
  EXPECT_EQ(kept.keyframe_ids, std::vector<int>({5, 7}));
  EXPECT_EQ(kept.marginalized_through_id, 3);
  // Covariance of the kept keyframes unchanged.
  EXPECT_LT(
      (kept.information.inverse() - prior.information.inverse().bottomRightCorner(12, 12)).norm(),
      1e-9 * prior.information.inverse().norm());
  EXPECT_FALSE(KeepKeyframes(prior, {8, 9}, &kept));
}

TEST(WindowedBAPriorTest, CheckRejectsMalformedPriors) {
  WindowedBAPrior prior;
  prior.marginalized_through_id = 3;
  prior.keyframe_ids = {4, 5};
  prior.cam_from_world.assign(2, SE3());
  prior.information = Eigen::MatrixXd::Identity(12, 12);
  prior.gradient = Eigen::VectorXd::Zero(12);
  EXPECT_NO_THROW(CheckWindowedBAPrior(prior));
  WindowedBAPrior bad = prior;
  bad.gradient = Eigen::VectorXd::Zero(6);
  EXPECT_THROW(CheckWindowedBAPrior(bad), std::invalid_argument);
  bad = prior;
  bad.keyframe_ids = {3, 5};  // 3 was marginalised
  EXPECT_THROW(CheckWindowedBAPrior(bad), std::invalid_argument);
  bad = prior;
  bad.keyframe_ids = {5, 4};
  EXPECT_THROW(CheckWindowedBAPrior(bad), std::invalid_argument);
  bad = prior;
  bad.information(2, 2) = std::nan("");
  EXPECT_THROW(CheckWindowedBAPrior(bad), std::invalid_argument);
}

}  // namespace
}  // namespace pldvo
