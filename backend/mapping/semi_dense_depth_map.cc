#include "backend/mapping/semi_dense_depth_map.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

namespace pldvo {

SemiDenseDepthMap::SemiDenseDepthMap(int width, int height) : width_(width), height_(height) {
  if (width <= 0 || height <= 0) {
    throw std::invalid_argument("SemiDenseDepthMap: size must be positive, got " +
                                std::to_string(width) + "x" + std::to_string(height));
  }
  const size_t n = static_cast<size_t>(width) * height;
  idepth_.assign(n, 0.f);
  idepth_var_.assign(n, 0.f);
  valid_.assign(n, 0);
  candidate_.assign(n, 0);
  edge_id_.assign(n, -1);
  validity_.assign(n, 0);
  blacklist_.assign(n, 0);
  num_observations_.assign(n, 0);
  idepth_shared_sd_.assign(n, 0.f);
  inlier_evidence_.assign(n, 0.f);
  outlier_evidence_.assign(n, 0.f);
}

void SemiDenseDepthMap::SelectPixels(const ImagePyramid& keyframe, const cv::Mat& edge_id_map,
                                     const MappingOptions& options) {
  if (keyframe.num_levels() < 1 || keyframe.width(0) != width_ || keyframe.height(0) != height_) {
    throw std::invalid_argument("SemiDenseDepthMap::SelectPixels: keyframe size differs from map");
  }
  if (!edge_id_map.empty() &&
      (edge_id_map.type() != CV_32S || edge_id_map.cols != width_ || edge_id_map.rows != height_)) {
    throw std::invalid_argument(
        "SemiDenseDepthMap::SelectPixels: edge_id_map must be CV_32S of the map's size");
  }
  std::fill(valid_.begin(), valid_.end(), 0);
  std::fill(candidate_.begin(), candidate_.end(), 0);
  std::fill(edge_id_.begin(), edge_id_.end(), -1);
  std::fill(validity_.begin(), validity_.end(), 0);
  std::fill(blacklist_.begin(), blacklist_.end(), 0);
  std::fill(num_observations_.begin(), num_observations_.end(), 0);
  std::fill(idepth_shared_sd_.begin(), idepth_shared_sd_.end(), 0.f);
  std::fill(inlier_evidence_.begin(), inlier_evidence_.end(), 0.f);
  std::fill(outlier_evidence_.begin(), outlier_evidence_.end(), 0.f);
  const float threshold_sq =
      static_cast<float>(options.gradient_threshold * options.gradient_threshold);
  const int b = options.border_px;
  const cv::Mat& level = keyframe.level(0);
  for (int y = b; y < height_ - b; ++y) {
    const float* row = level.ptr<float>(y);
    const int32_t* ids = edge_id_map.empty() ? nullptr : edge_id_map.ptr<int32_t>(y);
    for (int x = b; x < width_ - b; ++x) {
      const int i = Index(x, y);
      const float gx = row[3 * x + 1], gy = row[3 * x + 2];
      const int id = ids ? ids[x] : -1;
      edge_id_[i] = id;
      candidate_[i] = (id >= 0 || gx * gx + gy * gy >= threshold_sq) ? 1 : 0;
    }
  }
}

void SemiDenseDepthMap::InitializeConstant(double idepth, double idepth_var, int validity) {
  for (int i = 0; i < num_pixels(); ++i) {
    if (candidate_[i]) Set(i, idepth, idepth_var, validity);
  }
}

void SemiDenseDepthMap::InitializeRandom(double idepth_min, double idepth_max, double idepth_var,
                                         int seed, int validity) {
  std::mt19937 rng(static_cast<uint32_t>(seed));
  std::uniform_real_distribution<double> uniform(idepth_min, idepth_max);
  for (int i = 0; i < num_pixels(); ++i) {
    if (candidate_[i]) Set(i, uniform(rng), idepth_var, validity);
  }
}

void SemiDenseDepthMap::InitializeFromDepth(const cv::Mat& depth, double idepth_var, int validity) {
  if (depth.type() != CV_32F || depth.cols != width_ || depth.rows != height_) {
    throw std::invalid_argument(
        "SemiDenseDepthMap::InitializeFromDepth: depth must be CV_32F of the map's size");
  }
  for (int y = 0; y < height_; ++y) {
    const float* row = depth.ptr<float>(y);
    for (int x = 0; x < width_; ++x) {
      const int i = Index(x, y);
      if (!candidate_[i] || !(row[x] > 0.f)) continue;
      Set(i, 1.0 / row[x], idepth_var, validity);
      num_observations_[i] = 1;
    }
  }
}

void SemiDenseDepthMap::Set(int i, double idepth, double idepth_var, int validity,
                            double idepth_shared_sd) {
  idepth_[i] = static_cast<float>(idepth);
  idepth_var_[i] = static_cast<float>(idepth_var);
  idepth_shared_sd_[i] = static_cast<float>(idepth_shared_sd);
  valid_[i] = 1;
  validity_[i] = static_cast<int16_t>(validity);
  num_observations_[i] = 0;
  inlier_evidence_[i] = 0.f;
  outlier_evidence_[i] = 0.f;
}

void SemiDenseDepthMap::SetCandidate(int i, bool candidate, int edge_id) {
  candidate_[i] = candidate ? 1 : 0;
  edge_id_[i] = edge_id;
}

namespace {

// The Gaussian fusion of Fuse (header): the posterior mean, variance and shared sd of a prior
// (D, V, B) and an observation (D_obs, V_obs) whose error has the shared fraction rho.
struct GaussianPosterior {
  double idepth, idepth_var, shared_sd;
};

GaussianPosterior FuseGaussian(double prior, double prior_var, double prior_shared_sd,
                               double idepth_obs, double idepth_obs_var, double correlation) {
  if (correlation == 0.0 && prior_shared_sd == 0.0) {
    // Independent errors: the product of Gaussians.
    const double sum_var = prior_var + idepth_obs_var;
    return {(idepth_obs_var * prior + prior_var * idepth_obs) / sum_var,
            prior_var * idepth_obs_var / sum_var, 0.0};
  }
  // Correlated errors (header): A, B the prior's independent variance and shared sd, beta the
  // observation's shared sd, obs_independent_var its independent variance.
  const double b = std::min(prior_shared_sd, std::sqrt(prior_var));
  const double a = prior_var - b * b;
  const double beta = std::sqrt(correlation * idepth_obs_var);
  const double obs_independent_var = (1.0 - correlation) * idepth_obs_var;
  const double denominator = a + obs_independent_var + (b - beta) * (b - beta);
  const double kappa =
      denominator > 0.0 ? std::clamp((a + b * (b - beta)) / denominator, 0.0, 1.0) : 0.5;
  const double shared_sd = (1.0 - kappa) * b + kappa * beta;
  return {prior + kappa * (idepth_obs - prior),
          (1.0 - kappa) * (1.0 - kappa) * a + kappa * kappa * obs_independent_var +
              shared_sd * shared_sd,
          shared_sd};
}

}  // namespace

void SemiDenseDepthMap::CountOutlier(int i, const MappingOptions& options) {
  if (options.outlier_model == MappingOptions::OutlierModel::kInlierRatio) {
    outlier_evidence_[i] += 1.0f;
    const double a = options.inlier_prior_count + inlier_evidence_[i];
    const double b = options.inlier_prior_count + outlier_evidence_[i];
    if (a / (a + b) < options.min_inlier_ratio) valid_[i] = 0;
    return;
  }
  validity_[i] = static_cast<int16_t>(validity_[i] - options.validity_decrement);
  if (validity_[i] <= 0) valid_[i] = 0;
}

bool SemiDenseDepthMap::Fuse(int i, double idepth_obs, double idepth_obs_var, double correlation,
                             const MappingOptions& options) {
  const double prior = idepth_[i], prior_var = idepth_var_[i];
  const double diff = idepth_obs - prior;
  if (options.outlier_model == MappingOptions::OutlierModel::kInlierRatio) {
    // Vogiatzis & Hernandez 2011, Sec. 3 (header).
    constexpr double kInvSqrt2Pi = 0.3989422804014327;
    const double a = options.inlier_prior_count + inlier_evidence_[i];
    const double b = options.inlier_prior_count + outlier_evidence_[i];
    const double sum_var = prior_var + idepth_obs_var;
    const double c1_unnormalised =
        a * kInvSqrt2Pi / std::sqrt(sum_var) * std::exp(-0.5 * diff * diff / sum_var);
    const double c2_unnormalised = b / (options.max_idepth - options.min_idepth);
    // A hypothesis without observations (random initialisation, hole filling) is as wide as the
    // outlier density; its first observation is taken as an inlier, as in an unmapped pixel.
    const double c1 =
        num_observations_[i] == 0 ? 1.0 : c1_unnormalised / (c1_unnormalised + c2_unnormalised);
    const double c2 = 1.0 - c1;
    const double f = c1 * (a + 1.0) / (a + b + 1.0) + c2 * a / (a + b + 1.0);
    const double e = c1 * (a + 1.0) * (a + 2.0) / ((a + b + 1.0) * (a + b + 2.0)) +
                     c2 * a * (a + 1.0) / ((a + b + 1.0) * (a + b + 2.0));
    const double a_new = (e - f) / (f - e / f);
    const double b_new = a_new * (1.0 - f) / f;
    const GaussianPosterior fused = FuseGaussian(prior, prior_var, idepth_shared_sd_[i], idepth_obs,
                                                 idepth_obs_var, correlation);
    const double step = fused.idepth - prior;
    idepth_[i] = static_cast<float>(prior + c1 * step);
    idepth_var_[i] =
        static_cast<float>(c1 * fused.idepth_var + c2 * prior_var + c1 * c2 * step * step);
    idepth_shared_sd_[i] = static_cast<float>(c1 * fused.shared_sd + c2 * idepth_shared_sd_[i]);
    inlier_evidence_[i] = static_cast<float>(a_new - options.inlier_prior_count);
    outlier_evidence_[i] = static_cast<float>(b_new - options.inlier_prior_count);
    if (a_new / (a_new + b_new) < options.min_inlier_ratio) valid_[i] = 0;
    if (c1 <= c2) return false;
    CountObservation(i);
    return true;
  }
  const double gate = options.outlier_gate_sigmas;
  if (diff * diff > gate * gate * (prior_var + idepth_obs_var)) {
    CountOutlier(i, options);
    return false;
  }
  const GaussianPosterior fused =
      FuseGaussian(prior, prior_var, idepth_shared_sd_[i], idepth_obs, idepth_obs_var, correlation);
  idepth_[i] = static_cast<float>(fused.idepth);
  idepth_var_[i] = static_cast<float>(fused.idepth_var);
  idepth_shared_sd_[i] = static_cast<float>(fused.shared_sd);
  validity_[i] = static_cast<int16_t>(
      std::min(options.validity_max, validity_[i] + options.validity_increment));
  CountObservation(i);
  return true;
}

int SemiDenseDepthMap::CountCandidates() const {
  return static_cast<int>(std::count(candidate_.begin(), candidate_.end(), 1));
}

int SemiDenseDepthMap::CountValid() const {
  return static_cast<int>(std::count(valid_.begin(), valid_.end(), 1));
}

double MeanInverseDepth(const SemiDenseDepthMap& map) {
  double sum = 0.0;
  int count = 0;
  for (int i = 0; i < map.num_pixels(); ++i) {
    if (!map.valid(i)) continue;
    sum += map.idepth(i);
    ++count;
  }
  return count > 0 ? sum / count : 0.0;
}

}  // namespace pldvo
