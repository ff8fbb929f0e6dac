// The semi-dense inverse-depth map of one keyframe (Engel, Sturm, Cremers, ICCV 2013, Sec. 2):
// for every selected pixel (high image gradient, or on a traced edge) a Gaussian hypothesis of
// the inverse depth, mean D = idepth (1/m) and variance V = idepth_var ((1/m)^2), plus the
// bookkeeping of the semi-dense filter: validity counter (outlier removal), blacklist counter
// (pixels whose stereo keeps failing), the number of fused stereo observations and the id of the
// edge the pixel lies on, and the part of the hypothesis' error that is shared with the pixel's
// future stereo observations (the correlated-error fusion of Fuse). Storage is flat per-pixel
// arrays (row-major, index y * width + x); nothing is allocated per pixel.
#ifndef PLDVO_BACKEND_MAPPING_SEMI_DENSE_DEPTH_MAP_H_
#define PLDVO_BACKEND_MAPPING_SEMI_DENSE_DEPTH_MAP_H_

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "backend/mapping/mapping_options.h"
#include "core/image_pyramid.h"

namespace pldvo {

class SemiDenseDepthMap {
 public:
  SemiDenseDepthMap() = default;
  // An empty map (no candidates, nothing valid). Throws std::invalid_argument on a size <= 0.
  SemiDenseDepthMap(int width, int height);

  int width() const { return width_; }
  int height() const { return height_; }
  int num_pixels() const { return width_ * height_; }
  int Index(int x, int y) const { return y * width_ + x; }

  // Selects the candidates of a keyframe: |grad I| >= options.gradient_threshold at level 0 of
  // `keyframe`, or edge_id_map (CV_32S, -1 = none; may be empty) >= 0, at least
  // options.border_px from the border. Clears every hypothesis. Throws std::invalid_argument on
  // mismatched sizes.
  void SelectPixels(const ImagePyramid& keyframe, const cv::Mat& edge_id_map,
                    const MappingOptions& options);

  // Initialisations of every candidate (Engel 2013 Sec. 2.1). Constant: idepth, var. Random:
  // uniform in [idepth_min, idepth_max] from `seed`, variance var.
  void InitializeConstant(double idepth, double idepth_var, int validity);
  void InitializeRandom(double idepth_min, double idepth_max, double idepth_var, int seed,
                        int validity);
  // From a z-depth image (CV_32F metres, 0 = none): candidates with depth > 0 get 1/depth and
  // `idepth_var`; counted as observed (tests, ground-truth maps).
  void InitializeFromDepth(const cv::Mat& depth, double idepth_var, int validity);

  bool candidate(int i) const { return candidate_[i] != 0; }
  bool valid(int i) const { return valid_[i] != 0; }
  float idepth(int i) const { return idepth_[i]; }
  float idepth_var(int i) const { return idepth_var_[i]; }
  int edge_id(int i) const { return edge_id_[i]; }
  int validity(int i) const { return validity_[i]; }
  int blacklist(int i) const { return blacklist_[i]; }
  int num_observations(int i) const { return num_observations_[i]; }
  // A valid hypothesis with a positive inverse depth and at least one observation (hole-filled
  // guesses excluded): what the PLY export and the bootstrap refinement keep.
  bool observed(int i) const { return valid_[i] && idepth_[i] > 0.f && num_observations_[i] > 0; }
  // B of Fuse: the standard deviation of the hypothesis' error component that is shared with
  // the pixel's future stereo observations, 1/m; B^2 <= V.
  float idepth_shared_sd(int i) const { return idepth_shared_sd_[i]; }
  // The Beta(pi | a, b) posterior of the inlier ratio (outlier_model kInlierRatio) is kept as the
  // evidence beyond the prior: a = options.inlier_prior_count + inlier_evidence, b likewise with
  // outlier_evidence. Both are 0 for a new hypothesis.
  float inlier_evidence(int i) const { return inlier_evidence_[i]; }
  float outlier_evidence(int i) const { return outlier_evidence_[i]; }
  // Propagation carries the evidence to the new keyframe's hypothesis.
  void SetEvidence(int i, double inlier_evidence, double outlier_evidence) {
    inlier_evidence_[i] = static_cast<float>(inlier_evidence);
    outlier_evidence_[i] = static_cast<float>(outlier_evidence);
  }

  // Sets a new hypothesis: marks it valid and resets its observation count and evidence.
  // idepth_shared_sd is B of Fuse: 0 for a hypothesis whose error is independent of future stereo
  // observations (initialisation, propagation, hole filling), sqrt(rho V) for one created from a
  // stereo observation.
  void Set(int i, double idepth, double idepth_var, int validity, double idepth_shared_sd = 0.0);
  // Changes the mean only (regularisation); the pixel must be valid.
  void SetIdepth(int i, double idepth) { idepth_[i] = static_cast<float>(idepth); }
  void SetIdepthAndVar(int i, double idepth, double idepth_var) {
    idepth_[i] = static_cast<float>(idepth);
    idepth_var_[i] = static_cast<float>(idepth_var);
  }
  void Invalidate(int i) { valid_[i] = 0; }
  void SetCandidate(int i, bool candidate, int edge_id);
  void AddBlacklist(int i) {
    if (blacklist_[i] < INT16_MAX) ++blacklist_[i];
  }
  void CountObservation(int i) {
    if (num_observations_[i] < UINT16_MAX) ++num_observations_[i];
  }
  void SetValidity(int i, int validity) { validity_[i] = static_cast<int16_t>(validity); }

  // The update of one pixel with an inverse-depth observation D_obs of variance V_obs = s^2.
  // Correlated-error model (docs/mapping.md, "Correlated observation errors"): the observation's
  // error is beta u + w, u ~ N(0, 1) shared by every stereo observation of the pixel (the same
  // scene patch matched over similar baselines), beta = sqrt(rho) s, w ~ N(0, (1 - rho) s^2)
  // independent; rho = `correlation` (options.stereo_error_correlation for stereo, 0 for an
  // independent source). The hypothesis' error is B u + (independent part of variance
  // A = V - B^2). The fused D' = D + kappa (D_obs - D) minimises
  //   V' = (1 - kappa)^2 A + kappa^2 (1 - rho) s^2 + ((1 - kappa) B + kappa beta)^2,
  //   kappa = (A + B (B - beta)) / (A + (1 - rho) s^2 + (B - beta)^2),
  //   B' = (1 - kappa) B + kappa beta.
  // With rho = 0 (and B = 0) this is the EKF of Engel 2013, a product of Gaussians:
  //   D' = (V_obs D + V D_obs) / (V + V_obs),   V' = V V_obs / (V + V_obs);
  // with rho > 0, n observations of equal s into a flat prior give their mean with
  // V = rho s^2 + (1 - rho) s^2 / n (a floor).
  // Outliers, options.outlier_model:
  // - kValidityCounter: when |D_obs - D| > gate_sigmas sqrt(V + V_obs) the observation is an
  //   outlier: the validity counter drops by options.validity_decrement and the hypothesis is
  //   invalidated at <= 0. Otherwise the validity rises by options.validity_increment (capped).
  // - kInlierRatio (Vogiatzis & Hernandez 2011, Sec. 3): D_obs ~ pi N(D, V + V_obs) + (1 - pi)
  //   U[min_idepth, max_idepth], posterior N(D | mu, V) Beta(pi | a, b) by moment matching.
  //   With C1, C2 the normalised a N(D_obs | D, V + V_obs), b U (the inlier and outlier
  //   responsibilities) and (m, s^2) the Gaussian fusion above:
  //     mu' = C1 m + C2 D,   V' = C1 s^2 + C2 V + C1 C2 (m - D)^2,
  //     f = C1 (a+1)/(a+b+1) + C2 a/(a+b+1),   e = C1 (a+1)(a+2)/((a+b+1)(a+b+2))
  //       + C2 a(a+1)/((a+b+1)(a+b+2)),   a' = (e - f)/(f - e/f),   b' = a' (1 - f)/f;
  //   the hypothesis is invalidated when a'/(a'+b') < options.min_inlier_ratio. The first
  //   observation of a hypothesis without observations (random initialisation, hole filling) is
  //   taken as an inlier (C1 = 1): such a prior is as wide as the outlier density.
  // Returns true when fused (kInlierRatio: when C1 > C2).
  bool Fuse(int i, double idepth_obs, double idepth_obs_var, double correlation,
            const MappingOptions& options);
  // An observation that contradicts the hypothesis without a depth of its own (the SSD search's
  // best at an end of the prior interval): counted as an outlier of options.outlier_model
  // (validity_decrement; kInlierRatio: one more outlier count, C2 = 1), the depth unchanged.
  void CountOutlier(int i, const MappingOptions& options);
  // A stereo observation: correlation = options.stereo_error_correlation.
  bool Fuse(int i, double idepth_obs, double idepth_obs_var, const MappingOptions& options) {
    return Fuse(i, idepth_obs, idepth_obs_var, options.stereo_error_correlation, options);
  }

  int CountCandidates() const;
  int CountValid() const;

 private:
  int width_ = 0;
  int height_ = 0;
  std::vector<float> idepth_;
  std::vector<float> idepth_var_;
  std::vector<uint8_t> valid_;
  std::vector<uint8_t> candidate_;
  std::vector<int32_t> edge_id_;
  std::vector<int16_t> validity_;
  std::vector<int16_t> blacklist_;
  std::vector<uint16_t> num_observations_;
  std::vector<float> idepth_shared_sd_;
  std::vector<float> inlier_evidence_;
  std::vector<float> outlier_evidence_;
};

// Mean inverse depth of the valid hypotheses (0 when there are none).
double MeanInverseDepth(const SemiDenseDepthMap& map);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_MAPPING_SEMI_DENSE_DEPTH_MAP_H_
