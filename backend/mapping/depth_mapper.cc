#include "backend/mapping/depth_mapper.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "backend/mapping/depth_regularizer.h"
#include "backend/mapping/line_stereo.h"
#include "backend/mapping/pixel_stripes.h"
#include "core/wall_clock.h"

namespace pldvo {

DepthMapper::DepthMapper(const PinholeCamera& camera, const MappingOptions& options)
    : camera_(camera), options_(options) {
  const std::string camera_error = camera.Check();
  if (!camera_error.empty()) throw std::invalid_argument("DepthMapper: camera: " + camera_error);
  const std::string error = options.Check();
  if (!error.empty()) throw std::invalid_argument("DepthMapper: " + error);
}

StereoObservation FuseObservations(const StereoObservation& line, const StereoObservation& ssd) {
  const double line_weight = ssd.idepth_var / (line.idepth_var + ssd.idepth_var);
  const double ssd_weight = 1.0 - line_weight;
  StereoObservation fused = ssd;
  fused.idepth = line_weight * line.idepth + ssd_weight * ssd.idepth;
  fused.idepth_var = line.idepth_var * line_weight;  // = 1 / (1 / var_line + 1 / var_ssd)
  fused.disparity_var =
      line.disparity_var * ssd.disparity_var / (line.disparity_var + ssd.disparity_var);
  fused.pixel_in_cur = line_weight * line.pixel_in_cur + ssd_weight * ssd.pixel_in_cur;
  // Only the line's match carries the keyframe edge's shared error, scaled by its weight.
  fused.shared_idepth_var = line_weight * line_weight * line.shared_idepth_var;
  return fused;
}

void FrameUpdateStats::AddCounts(const FrameUpdateStats& other) {
  line_attempts += other.line_attempts;
  line_ok += other.line_ok;
  line_refined += other.line_refined;
  line_fallback += other.line_fallback;
  line_rejected += other.line_rejected;
  line_out_of_range += other.line_out_of_range;
  line_narrow_prior += other.line_narrow_prior;
  ssd_attempts += other.ssd_attempts;
  ssd_ok += other.ssd_ok;
  ssd_interval_end += other.ssd_interval_end;
  ssd_skipped += other.ssd_skipped;
  fused += other.fused;
  created += other.created;
  not_created += other.not_created;
  outliers += other.outliers;
  removed += other.removed;
  filled += other.filled;
  num_edge_pixels += other.num_edge_pixels;
}

void DepthMapper::SetKeyframe(const cv::Mat& image, const EdgeTrace& edges) {
  if (image.empty() || image.cols != camera_.width || image.rows != camera_.height ||
      image.channels() != 1) {
    throw std::invalid_argument("DepthMapper: keyframe must be a gray image of the camera's size");
  }
  if (!edges.id_map.empty() &&
      (edges.id_map.cols != image.cols || edges.id_map.rows != image.rows)) {
    throw std::invalid_argument("DepthMapper: edge id map size differs from the image");
  }
  keyframe_ = ImagePyramid(image, 1);
  edges_ = edges;
  map_ = SemiDenseDepthMap(image.cols, image.rows);
  map_.SelectPixels(keyframe_, edges_.id_map, options_);
  line_in_ref_by_id_.clear();
  line_cov_in_ref_by_id_.clear();
  for (const TracedLine& line : edges_.lines) {
    if (line.id < 0) continue;
    if (line.id >= static_cast<int>(line_in_ref_by_id_.size())) {
      line_in_ref_by_id_.resize(line.id + 1, Eigen::Vector3d::Zero());
      line_cov_in_ref_by_id_.resize(line.id + 1, Eigen::Matrix3d::Zero());
    }
    line_in_ref_by_id_[line.id] = line.segment.line;
    line_cov_in_ref_by_id_[line.id] = line.segment.line_cov;
  }
}

void DepthMapper::InitializeKeyframe(const cv::Mat& image, const EdgeTrace& edges) {
  SetKeyframe(image, edges);
  if (options_.init == MappingOptions::Init::kRandom) {
    map_.InitializeRandom(options_.init_idepth_min, options_.init_idepth_max,
                          options_.init_idepth_var, options_.init_seed, options_.validity_initial);
  } else {
    map_.InitializeConstant(options_.init_idepth, options_.init_idepth_var,
                            options_.validity_initial);
  }
}

void DepthMapper::InitializeKeyframeFromDepth(const cv::Mat& image, const EdgeTrace& edges,
                                              const cv::Mat& depth, double idepth_var) {
  SetKeyframe(image, edges);
  map_.InitializeFromDepth(depth, idepth_var, options_.validity_initial);
}

bool DepthMapper::PriorInterval(int index, double* idepth_min, double* idepth_max,
                                double* idepth_centre) const {
  *idepth_min = options_.min_idepth;
  *idepth_max = options_.max_idepth;
  *idepth_centre = options_.init_idepth;
  if (!map_.valid(index)) return true;
  const double d = map_.idepth(index);
  const double range = options_.search_sigmas * std::sqrt(map_.idepth_var(index));
  *idepth_min = std::max(options_.min_idepth, d - range);
  *idepth_max = std::min(options_.max_idepth, d + range);
  *idepth_centre = std::clamp(d, *idepth_min, *idepth_max);
  return *idepth_max > *idepth_min;
}

StereoStatus DepthMapper::ObserveOnLine(int index, const EpipolarGeometry& geometry,
                                        const MatchedLine& line_in_cur, double idepth_min,
                                        double idepth_max, const ImagePyramid* current,
                                        const EpipolarPatch* patch,
                                        StereoObservation* observation) const {
  const Eigen::Vector2d pixel(index % map_.width(), index / map_.width());
  const int edge = map_.edge_id(index);
  // The foot point of the pixel on l1 and l1's position variance there (the pixel itself and
  // 0 when l1 is unknown).
  Eigen::Vector2d edge_pixel = pixel;
  double ref_line_position_var = 0.0;
  if (edge < static_cast<int>(line_in_ref_by_id_.size())) {
    const Eigen::Vector3d& l1 = line_in_ref_by_id_[edge];
    edge_pixel -= (l1.x() * pixel.x() + l1.y() * pixel.y() + l1.z()) * l1.head<2>();
    if (options_.line_stereo_keyframe_line_var) {
      const Eigen::Vector3d foot(edge_pixel.x(), edge_pixel.y(), 1.0);
      ref_line_position_var = foot.dot(line_cov_in_ref_by_id_[edge] * foot);
    }
  }
  return LineGuidedStereo(geometry, pixel, edge_pixel, ref_line_position_var,
                          line_in_cur.line_in_cur, idepth_min, idepth_max, options_, current, patch,
                          observation);
}

std::vector<char> DepthMapper::InconsistentLineMatches(
    const EpipolarGeometry& geometry, const std::vector<MatchedLine>& lines_in_cur) const {
  std::vector<int> inside(lines_in_cur.size(), 0), outside(lines_in_cur.size(), 0);
  for (int i = 0; i < map_.num_pixels(); ++i) {
    const int edge = map_.edge_id(i);
    if (edge < 0 || edge >= static_cast<int>(lines_in_cur.size()) || !lines_in_cur[edge].matched ||
        !map_.valid(i) || !map_.candidate(i)) {
      continue;
    }
    double idepth_min, idepth_max, idepth_centre;
    if (!PriorInterval(i, &idepth_min, &idepth_max, &idepth_centre)) continue;
    StereoObservation observation;
    const StereoStatus status = ObserveOnLine(i, geometry, lines_in_cur[edge], idepth_min,
                                              idepth_max, nullptr, nullptr, &observation);
    inside[edge] += status == StereoStatus::kOk;
    outside[edge] += status == StereoStatus::kLineOutOfRange;
  }
  std::vector<char> inconsistent(lines_in_cur.size(), 0);
  for (size_t e = 0; e < lines_in_cur.size(); ++e) {
    const int votes = inside[e] + outside[e];
    inconsistent[e] = votes >= options_.line_match_min_votes &&
                      outside[e] > options_.line_match_max_outside_fraction * votes;
  }
  return inconsistent;
}

bool DepthMapper::NarrowPrior(int index, const Eigen::Vector2d& pixel,
                              const EpipolarGeometry& geometry, double idepth_min,
                              double idepth_max) const {
  if (!(options_.line_stereo_min_interval_px > 0.0) || !map_.valid(index) ||
      map_.num_observations(index) == 0) {
    return false;
  }
  Eigen::Vector2d end_far, end_near;
  return geometry.Project(pixel, idepth_min, &end_far) &&
         geometry.Project(pixel, idepth_max, &end_near) &&
         (end_near - end_far).norm() < options_.line_stereo_min_interval_px;
}

bool DepthMapper::UninformativeSearch(int index, const Eigen::Vector2d& pixel,
                                      const EpipolarGeometry& geometry, const EpipolarPatch& patch,
                                      double idepth_min, double idepth_max) const {
  const double ratio = options_.uninformative_search_ratio;
  if (!(ratio > 0.0)) return false;
  // |d pixel / d idepth| = const / q_z^2 with q_z linear in the inverse depth: with both ends in
  // front of the current camera its largest value over the interval is at an end.
  Eigen::Vector2d end_far, end_near;
  if (!geometry.Project(pixel, idepth_min, &end_far) ||
      !geometry.Project(pixel, idepth_max, &end_near)) {
    return false;
  }
  const double jacobian_sq = std::max(geometry.IdepthJacobian(pixel, idepth_min).squaredNorm(),
                                      geometry.IdepthJacobian(pixel, idepth_max).squaredNorm());
  if (!std::isfinite(jacobian_sq) || !(jacobian_sq > 0.0)) return false;
  const double sigma = options_.sigma_epipolar_px;
  const double min_idepth_var = GeometricDisparityVar(patch, sigma * sigma) / jacobian_sq;
  return min_idepth_var > ratio * map_.idepth_var(index);
}

void DepthMapper::UpdatePixel(int index, const ImagePyramid& current,
                              const EpipolarGeometry& geometry,
                              const std::vector<MatchedLine>& lines_in_cur,
                              const NewHypothesisRule& rule, FrameUpdateStats* stats) {
  const Eigen::Vector2d pixel(index % map_.width(), index / map_.width());
  const bool valid = map_.valid(index);
  double idepth_min, idepth_max, idepth_centre;
  if (!PriorInterval(index, &idepth_min, &idepth_max, &idepth_centre)) return;
  EpipolarPatch patch;
  const StereoStatus patch_status =
      MakeEpipolarPatch(keyframe_, geometry, pixel, idepth_centre, options_, &patch);
  StereoObservation observation;
  StereoStatus status = StereoStatus::kBadGeometry;

  const int edge = map_.edge_id(index);
  const bool matched = options_.use_line_stereo && edge >= 0 &&
                       edge < static_cast<int>(lines_in_cur.size()) && lines_in_cur[edge].matched;
  // A converged hypothesis is refined by the SSD within its interval instead of the line.
  const bool narrow = matched && NarrowPrior(index, pixel, geometry, idepth_min, idepth_max);
  stats->line_narrow_prior += narrow;
  const bool has_line = matched && !narrow;
  using SsdUse = MappingOptions::LineStereoSsd;
  const bool ssd_first =
      has_line && options_.line_stereo_ssd == SsdUse::kFirst && patch_status == StereoStatus::kOk;
  if (ssd_first) {
    // A failed search here does not blacklist the pixel: the line-guided match may still work.
    ++stats->ssd_attempts;
    status = SearchEpipolarSsd(current, geometry, patch, pixel, idepth_min, idepth_max, options_,
                               &observation);
    stats->ssd_ok += status == StereoStatus::kOk;
  }
  if (has_line && status != StereoStatus::kOk) {
    ++stats->line_attempts;
    // Without line_stereo_prior_interval only the global bounds apply to the line-guided match;
    // the fusion's outlier gate judges it against the prior.
    const bool prior = options_.line_stereo_prior_interval;
    status =
        ObserveOnLine(index, geometry, lines_in_cur[edge], prior ? idepth_min : options_.min_idepth,
                      prior ? idepth_max : options_.max_idepth, &current,
                      patch_status == StereoStatus::kOk ? &patch : nullptr, &observation);
    if (status == StereoStatus::kOk) {
      ++stats->line_ok;
      const SsdUse use = options_.line_stereo_ssd;
      if ((use == SsdUse::kRefine || use == SsdUse::kRefineMorePrecise || use == SsdUse::kFuse) &&
          patch_status == StereoStatus::kOk) {
        const double range = options_.search_sigmas * std::sqrt(observation.idepth_var);
        StereoObservation refined;
        if (SearchEpipolarSsd(current, geometry, patch, pixel,
                              std::max(idepth_min, observation.idepth - range),
                              std::min(idepth_max, observation.idepth + range), options_,
                              &refined) == StereoStatus::kOk &&
            (use != SsdUse::kRefineMorePrecise || refined.idepth_var < observation.idepth_var)) {
          observation = use == SsdUse::kFuse ? FuseObservations(observation, refined) : refined;
          ++stats->line_refined;
        }
      }
    } else if (status == StereoStatus::kLineIllConditioned) {
      ++stats->line_fallback;
    } else {
      ++stats->line_rejected;
      stats->line_out_of_range += status == StereoStatus::kLineOutOfRange;
      return;
    }
  }
  if (status != StereoStatus::kOk) {
    if (patch_status != StereoStatus::kOk || ssd_first) return;
    if (valid && UninformativeSearch(index, pixel, geometry, patch, idepth_min, idepth_max)) {
      ++stats->ssd_skipped;
      return;
    }
    ++stats->ssd_attempts;
    status = SearchEpipolarSsd(current, geometry, patch, pixel, idepth_min, idepth_max, options_,
                               &observation);
    if (status == StereoStatus::kNotUnique || status == StereoStatus::kLargeError) {
      map_.AddBlacklist(index);
    }
    if (status == StereoStatus::kIntervalEnd) {
      ++stats->ssd_interval_end;
      if (valid && options_.ssd_interval_end == MappingOptions::IntervalEndMinimum::kOutlier) {
        map_.CountOutlier(index, options_);
        ++stats->outliers;
      }
    }
    if (status != StereoStatus::kOk) return;
    ++stats->ssd_ok;
  }
  // Every stereo observation of the pixel (SSD or line-guided) shares part of its error with the
  // others (options.stereo_error_correlation, SemiDenseDepthMap::Fuse); a line-guided one also
  // its keyframe edge's error, shared_idepth_var.
  const double rho = options_.stereo_error_correlation;
  const double correlation =
      rho + (1.0 - rho) * observation.shared_idepth_var / observation.idepth_var;
  if (valid) {
    if (map_.Fuse(index, observation.idepth, observation.idepth_var, correlation, options_)) {
      ++stats->fused;
    } else {
      ++stats->outliers;
    }
  } else {
    if (rule.max_sigma > 0.0 && observation.idepth_var > rule.max_sigma * rule.max_sigma) {
      ++stats->not_created;
      return;
    }
    // With a prior, the hypothesis is its inverse-variance fusion with the observation; the
    // observation's weight w scales the shared error's standard deviation too.
    double idepth = observation.idepth;
    double idepth_var = observation.idepth_var;
    double w = 1.0;
    if (rule.prior_var > 0.0) {
      w = rule.prior_var / (rule.prior_var + observation.idepth_var);
      idepth = rule.prior_idepth + w * (observation.idepth - rule.prior_idepth);
      idepth_var = w * observation.idepth_var;
    }
    map_.Set(index, idepth, idepth_var, options_.validity_initial,
             w * std::sqrt(correlation * observation.idepth_var));
    map_.CountObservation(index);
    ++stats->created;
  }
}

DepthMapper::NewHypothesisRule DepthMapper::MakeNewHypothesisRule() const {
  NewHypothesisRule rule;
  const double gate = options_.new_hypothesis_max_relative_sigma;
  const double prior = options_.new_hypothesis_prior_relative_sigma;
  if (gate <= 0.0 && prior <= 0.0) return rule;  // no pass over the map
  // Relative to the map's scale; a map without hypotheses (mean 0) has none: no gate, no prior.
  const double mean = MeanInverseDepth(map_);
  rule.max_sigma = gate * mean;
  rule.prior_idepth = mean;
  rule.prior_var = (prior * mean) * (prior * mean);
  return rule;
}

FrameUpdateStats DepthMapper::UpdateWithFrame(const cv::Mat& image, const SE3& cur_from_ref,
                                              const std::vector<MatchedLine>& lines_in_cur,
                                              const Matrix6d& pose_covariance,
                                              double line_cov_scale) {
  if (image.empty() || image.cols != map_.width() || image.rows != map_.height() ||
      image.channels() != 1) {
    throw std::invalid_argument(
        "DepthMapper::UpdateWithFrame: frame must be a gray image of the keyframe's size");
  }
  if (!(line_cov_scale > 0.0) || !std::isfinite(line_cov_scale)) {
    throw std::invalid_argument("DepthMapper::UpdateWithFrame: line_cov_scale must be positive");
  }
  FrameUpdateStats stats;
  const ImagePyramid current(image, 1);
  const EpipolarGeometry geometry(camera_, cur_from_ref, pose_covariance);
  if (!(cur_from_ref.translation().norm() > 0.0)) return stats;  // no baseline, no stereo
  // Matches whose line most of the edge's hypotheses contradict are left out for this frame; the
  // edge's pixels then search like pixels without a line. The kept lines' Sigma_l2 take the
  // line noise scale.
  const std::vector<MatchedLine>* lines = &lines_in_cur;
  std::vector<MatchedLine> kept;
  const bool check_matches = options_.line_match_max_outside_fraction < 1.0;
  if (options_.use_line_stereo && (check_matches || line_cov_scale != 1.0)) {
    kept = lines_in_cur;
    for (MatchedLine& line : kept) line.line_in_cur.cov *= line_cov_scale;
    const std::vector<char> inconsistent =
        check_matches ? InconsistentLineMatches(geometry, kept) : std::vector<char>();
    for (size_t e = 0; e < inconsistent.size(); ++e) {
      if (!inconsistent[e]) continue;
      kept[e].matched = false;
      stats.dropped_line_matches.push_back(static_cast<int>(e));
    }
    lines = &kept;
  }
  const NewHypothesisRule new_hypothesis = MakeNewHypothesisRule();
  // Two passes (edge pixels, then the rest) so that each is timed on its own, each in stripes of
  // pixels (pixel_stripes.h).
  const int stripes = NumStripes(options_);
  for (int pass = 0; pass < 2; ++pass) {
    const auto start = WallClock::now();
    std::vector<FrameUpdateStats> stripe_stats(stripes);
    ForEachStripe(stripes, [&](int stripe) {
      FrameUpdateStats* counts = &stripe_stats[stripe];
      const int end = map_.num_pixels() * (stripe + 1) / stripes;
      for (int i = map_.num_pixels() * stripe / stripes; i < end; ++i) {
        if (!map_.candidate(i) || (map_.edge_id(i) >= 0) != (pass == 0)) continue;
        if (map_.blacklist(i) >= options_.blacklist_threshold) continue;
        if (pass == 0) ++counts->num_edge_pixels;
        UpdatePixel(i, current, geometry, *lines, new_hypothesis, counts);
      }
    });
    for (const FrameUpdateStats& counts : stripe_stats) stats.AddCounts(counts);
    (pass == 0 ? stats.edge_stereo_ms : stats.other_stereo_ms) = MsSince(start);
  }
  if (options_.regularize) {
    stats.removed = RemoveIsolatedHypotheses(options_, &map_);
    stats.filled = FillHoles(options_, &map_);
  }
  return stats;
}

LineDepthFusionStats DepthMapper::FuseLineDepths(const std::vector<KeyframeLine>& lines) {
  LineDepthFusionStats stats;
  std::map<int, const KeyframeLine*> line_of_edge;
  for (const KeyframeLine& line : lines) line_of_edge[line.edge_id] = &line;
  const double max_miss_ratio = kLineDepthMissPx / std::max(camera_.fx, camera_.fy);
  for (int i = 0; i < map_.num_pixels(); ++i) {
    if (!map_.valid(i) || map_.edge_id(i) < 0) continue;
    const auto it = line_of_edge.find(map_.edge_id(i));
    if (it == line_of_edge.end()) continue;
    ++stats.pixels;
    const Eigen::Vector2d pixel(i % map_.width(), i / map_.width());
    double idepth, idepth_var;
    if (!RayLineInverseDepthAndVariance(camera_, pixel, *it->second, max_miss_ratio, &idepth,
                                        &idepth_var) ||
        !(idepth_var > 0.0)) {
      ++stats.skipped;
      continue;
    }
    // The edge BA's line depth is independent of the pixel's stereo observations.
    if (map_.Fuse(i, idepth, idepth_var, 0.0, options_)) {
      ++stats.fused;
    } else {
      ++stats.outliers;
    }
  }
  return stats;
}

int DepthMapper::ApplyIdepthCorrections(const std::vector<IdepthCorrection>& corrections,
                                        const SE3* new_from_old, double idepth_scale) {
  if (!(idepth_scale > 0.0) || !std::isfinite(idepth_scale)) {
    throw std::invalid_argument("ApplyIdepthCorrections: idepth_scale must be positive, got " +
                                std::to_string(idepth_scale));
  }
  int applied = 0;
  std::vector<char> corrected(map_.num_pixels(), 0);
  for (const IdepthCorrection& correction : corrections) {
    const int i = correction.pixel_index;
    if (i < 0 || i >= map_.num_pixels() || !map_.valid(i)) continue;
    corrected[i] = 1;
    const double idepth = map_.idepth(i) + correction.delta_idepth;
    if (!(idepth > 0.0) || !(idepth <= options_.max_idepth)) continue;
    map_.SetIdepth(i, idepth);
    ++applied;
  }
  if (new_from_old == nullptr && idepth_scale == 1.0) return applied;
  const Eigen::Matrix3d rotation =
      new_from_old != nullptr ? new_from_old->rotation_matrix() : Eigen::Matrix3d::Identity();
  const Eigen::Vector3d translation =
      new_from_old != nullptr ? new_from_old->translation() : Eigen::Vector3d::Zero();
  for (int i = 0; i < map_.num_pixels(); ++i) {
    if (corrected[i] || !map_.valid(i)) continue;
    const double idepth = map_.idepth(i);
    const Eigen::Vector2d pixel(i % map_.width(), i / map_.width());
    const double c = rotation.row(2).dot(camera_.Unproject(pixel));
    const double denominator = c + translation.z() * idepth;
    if (!(denominator > 0.0)) continue;
    const double moved = idepth_scale * idepth / denominator;
    if (!(moved > 0.0) || !(moved <= options_.max_idepth)) continue;
    const double jacobian = idepth_scale * c / (denominator * denominator);
    map_.SetIdepthAndVar(i, moved, jacobian * jacobian * map_.idepth_var(i));
    ++applied;
  }
  return applied;
}

SemiDenseDepthMap DepthMapper::RegularizedMap(bool smooth, bool line_regularize,
                                              LineRegularizationStats* stats) const {
  SemiDenseDepthMap result;
  if (smooth) {
    SmoothDepthMap(map_, options_, &result);
  } else {
    result = map_;
  }
  if (edges_.lines.empty() || !(options_.line_depth_gate || line_regularize)) return result;
  const LineRegularizer regularizer(options_);
  if (options_.line_depth_gate) regularizer.UnlinkOutliers(camera_, edges_, &result);
  if (line_regularize) {
    const LineRegularizationStats line_stats = regularizer.Regularize(camera_, edges_, &result);
    if (stats) *stats = line_stats;
  }
  return result;
}

PropagationStats DepthMapper::PropagateToNewKeyframe(const cv::Mat& image, const EdgeTrace& edges,
                                                     const SE3& new_from_old,
                                                     const AffineBrightness& brightness) {
  return PropagateToNewKeyframe(RegularizedMap(options_.regularize, options_.line_regularization),
                                image, edges, new_from_old, brightness);
}

PropagationStats DepthMapper::PropagateToNewKeyframe(const SemiDenseDepthMap& old_regularized,
                                                     const cv::Mat& image, const EdgeTrace& edges,
                                                     const SE3& new_from_old,
                                                     const AffineBrightness& brightness) {
  const ImagePyramid old_keyframe = keyframe_;
  SetKeyframe(image, edges);
  PropagationStats stats;
  map_ = PropagateDepthMap(old_regularized, old_keyframe, keyframe_, edges_.id_map, camera_,
                           new_from_old, options_, &stats, brightness);
  return stats;
}

}  // namespace pldvo
